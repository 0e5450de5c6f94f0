// intersect.glsl: ray tests against one primitive or one box, and the move of a ray into
// an instance's object coordinates.

struct Hit {
    float t;
    uint primitive;   // slot in the primitive section
    uint instance;    // NONE: a world primitive
    vec2 barycentric; // triangles: (b1, b2) of v1, v2; quads: (a, b) along the edges
};

// A ray in the coordinates of the BVH level being walked (the world's, or an instance's
// object's: there the direction is not unit length), with what the box and sphere tests
// derive from its direction, computed once per ray and level.
struct TraversalRay {
    vec3 origin;
    vec3 direction;
    vec3 inverse_direction;   // 1 / direction, for the box tests
    vec3 unit;                // direction / |direction|, for the sphere tests
    float inverse_length;     // 1 / |direction|: the sphere tests' distances along unit scaled
};

TraversalRay traversal_ray(vec3 origin, vec3 direction)
{
    TraversalRay ray;
    ray.origin = origin;
    ray.direction = direction;
    // No infinities: a component smaller than TRAVERSAL_SMALLEST_DIRECTION (core/packed_layout.h)
    // becomes that, with its sign (-0 as +0), so that a slab test multiplies no zero by an
    // infinity, and the threaded walk's octant (its inverse's signs) matches its boxes.
    const float smallest = TRAVERSAL_SMALLEST_DIRECTION;
    vec3 smallest_signed = mix(vec3(smallest), vec3(-smallest), lessThan(direction, vec3(0.0)));
    ray.inverse_direction = 1.0 / mix(direction, smallest_signed, lessThan(abs(direction), vec3(smallest)));
    float direction_length = length(direction);
    ray.unit = direction / direction_length;
    ray.inverse_length = 1.0 / direction_length;
    return ray;
}

// intersect_sphere for a direction given as its unit vector and the inverse of its length:
// a traversal computes those once per ray (TraversalRay), not once per sphere, and a
// sphere test then divides once (a division is the dearest instruction of the threaded
// walk's iteration: docs/performance.md, the log).
float intersect_sphere_along(vec3 center, float radius, vec3 origin, vec3 unit, float inverse_length, float t_max)
{
    vec3 to_origin = origin - center;
    float b = dot(to_origin, unit);
    vec3 closest_offset = to_origin - b * unit;
    float discriminant = radius * radius - dot(closest_offset, closest_offset);
    if (discriminant < 0.0)
        return INFINITY;
    float root = sqrt(discriminant);
    float c = dot(to_origin, to_origin) - radius * radius;
    float q = -b - (b >= 0.0 ? root : -root);
    // The roots in order, by the integer order of their bits (one instruction each; a float
    // minimum or maximum is three on llvmpipe, docs/performance.md): that is their order
    // unless both are negative, and then neither is a hit whichever comes first.
    int root_bits = floatBitsToInt(c / q * inverse_length), other_bits = floatBitsToInt(q * inverse_length);
    float t_near = intBitsToFloat(min(root_bits, other_bits));
    float t_far = intBitsToFloat(max(root_bits, other_bits));
    if (t_near > 0.0 && t_near < t_max)
        return t_near;
    if (t_far > 0.0 && t_far < t_max)
        return t_far;
    return INFINITY;
}

// Nearest root of |origin + t*direction - center| = radius with t in (0, t_max), or
// INFINITY, for a direction of any length (instances scale it). The discriminant is
// computed from the squared distance of the centre to the ray's closest point, which
// keeps float32 precise for the radius-1000 ground sphere (Haines et al., Ray Tracing
// Gems, ch. 7).
float intersect_sphere(vec3 center, float radius, vec3 origin, vec3 direction, float t_max)
{
    float direction_length = length(direction);
    return intersect_sphere_along(center, radius, origin, direction / direction_length, 1.0 / direction_length,
                                  t_max);
}

// Moller-Trumbore for a triangle (corner, edge1, edge2), or the parallelogram spanned by
// the same vectors when quad is true. Returns t and the two edge coordinates.
float intersect_flat(vec3 corner, vec3 edge1, vec3 edge2, bool quad, vec3 origin, vec3 direction, float t_max,
                     out vec2 coordinates)
{
    coordinates = vec2(0.0);
    vec3 p = cross(direction, edge2);
    float determinant = dot(edge1, p);
    if (abs(determinant) < 1e-20)
        return INFINITY;
    float inverse = 1.0 / determinant;
    vec3 s = origin - corner;
    float u = dot(s, p) * inverse;
    vec3 q = cross(s, edge1);
    float v = dot(direction, q) * inverse;
    bool inside = quad ? (u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0) : (u >= 0.0 && v >= 0.0 && u + v <= 1.0);
    if (!inside)
        return INFINITY;
    float t = dot(edge2, q) * inverse;
    coordinates = vec2(u, v);
    return t > 0.0 && t < t_max ? t : INFINITY;
}

// The slab test for a box given by its corners in the order the ray meets them (near: the
// corner whose planes it enters by, far: the one it leaves by; core/packed_layout.h
// "threaded walk"): the entry distance of the ray into the box, or INFINITY when it misses
// or enters beyond t_max. The minima and maxima are taken of the distances' bits as
// integers: for floats that are not NaN (with traversal_ray's inverse none is) integer
// order is float order wherever it matters here, since the entry is at least +0 and any
// negative exit (sign bit: a negative integer) is a miss either way. llvmpipe compiles a
// float min or max to three instructions, to return the operand that is not NaN, an
// integer one to one (docs/performance.md, the log); NIR turns a select written as a
// float min back into that.
float intersect_ordered_box(vec3 near, vec3 far, vec3 origin, vec3 inverse_direction, float t_max)
{
    ivec3 t_near = floatBitsToInt((near - origin) * inverse_direction);
    ivec3 t_far = floatBitsToInt((far - origin) * inverse_direction);
    int enter = max(max(t_near.x, t_near.y), max(t_near.z, 0));
    int leave = min(min(t_far.x, t_far.y), min(t_far.z, floatBitsToInt(t_max)));
    return enter <= leave ? intBitsToFloat(enter) : INFINITY;
}

// Entry distance of the ray into a box, or INFINITY when it misses or enters beyond t_max:
// intersect_ordered_box with the corners ordered by the signs of the inverse direction,
// by selects (one instruction each on llvmpipe) rather than a minimum and a maximum per
// axis (three each).
float intersect_box(vec3 box_min, vec3 box_max, vec3 origin, vec3 inverse_direction, float t_max)
{
    bvec3 down = lessThan(inverse_direction, vec3(0.0));
    return intersect_ordered_box(mix(box_min, box_max, down), mix(box_max, box_min, down), origin, inverse_direction,
                                 t_max);
}

// Whether the hit at distance t along the ray (in the primitive's own coordinates; edge
// coordinates as intersect_flat returns them) falls where an alpha-masked material
// (MATERIAL_FLAG_ALPHA_MASK of core/packed_layout.h) has no surface: there alpha, the
// material's factor times its alpha image's A channel at the hit's uv, is below the
// cutoff. The material is resolved as surface_at resolves it (the primitive's own, else
// the instance's, else the default). Only the variants with masks have this test, so
// that other scenes pay nothing for it in the traversal.
bool alpha_masked(uint slot, uvec4 record, uint type, vec4 sphere, vec3 origin, vec3 direction, float t,
                  vec2 coordinates, uint instance)
{
    uint info = primitive_info(slot);
    uint material = info & uint(PRIMITIVE_INFO_MATERIAL_MASK);
    if (material == uint(PRIMITIVE_NO_MATERIAL)) {
        uint instance_material = HAS_INSTANCES && instance != NONE
                                 ? packed_texel(instance_offset + instance * uint(PACKED_INSTANCE_STRIDE)).y : NONE;
        material = instance_material != NONE ? instance_material : default_material;
    }
    uint base = material_offset + material * uint(PACKED_MATERIAL_STRIDE);
    if ((packed_texel(base).x & uint(MATERIAL_FLAG_ALPHA_MASK)) == 0u)
        return false;
    uvec4 mask = packed_texel(base + 5u);
    float alpha = uintBitsToFloat(mask.x);
    if (HAS_TEXTURES && mask.z != NONE) {
        vec2 uv = coordinates;
        if (HAS_SPHERES && type != uint(PRIMITIVE_TRIANGLE) && type != uint(PRIMITIVE_QUAD))
            uv = sphere_uv((origin + t * direction - sphere.xyz) / sphere.w);
        if (HAS_TRIANGLES && type == uint(PRIMITIVE_TRIANGLE) && (info & uint(PRIMITIVE_INFO_HAS_UVS)) != 0u)
            uv = (1.0 - coordinates.x - coordinates.y) * vertex_uv(record.x) + coordinates.x * vertex_uv(record.y)
                 + coordinates.y * vertex_uv(record.z);
        alpha *= image_lookup_rgba(mask.z, uv).a;
    }
    return alpha < uintBitsToFloat(mask.y);
}

// Tests one primitive (by slot, its record and the texels behind it already read:
// glsl/scene_access.glsl primitive_geometry_addresses) of the current level; on a nearer
// hit updates hit (a hit where an alpha mask has no surface is none).
void intersect_primitive(uint slot, uvec4 record, uint type, uvec4 g0, uvec4 g1, uvec4 g2, TraversalRay ray,
                         float time, uint instance, inout Hit hit)
{
    vec4 a, b, c;
    uvec3 normal_words;
    primitive_geometry_of(record, type, g0, g1, g2, a, b, c, normal_words);
    float t = INFINITY;
    vec2 coordinates = vec2(0.0);
    if (ONLY_SPHERES) {
        t = intersect_sphere_along(a.xyz, a.w, ray.origin, ray.unit, ray.inverse_length, hit.t);
    } else {
        bool flat_primitive = type == uint(PRIMITIVE_TRIANGLE) || type == uint(PRIMITIVE_QUAD);
        if (HAS_MOVING_SPHERES && type == uint(PRIMITIVE_MOVING_SPHERE))
            a.xyz = mix(a.xyz, b.xyz, time);
        if (HAS_SPHERES && !flat_primitive)
            t = intersect_sphere_along(a.xyz, a.w, ray.origin, ray.unit, ray.inverse_length, hit.t);
        if (HAS_FLAT && flat_primitive)
            t = intersect_flat(a.xyz, b.xyz, c.xyz, type == uint(PRIMITIVE_QUAD), ray.origin, ray.direction, hit.t,
                               coordinates);
    }
    if (HAS_ALPHA_MASK && t < hit.t
        && alpha_masked(slot, record, type, a, ray.origin, ray.direction, t, coordinates, instance))
        t = INFINITY;
    if (t < hit.t) {
        hit.t = t;
        hit.primitive = slot;
        hit.instance = instance;
        hit.barycentric = coordinates;
    }
}

// Moves a world ray into object coordinates by the rows of a world-to-object matrix (the
// direction is not renormalised, so t keeps meaning the world ray's parameter).
void apply_world_to_object(vec4 row0, vec4 row1, vec4 row2, vec3 origin, vec3 direction, out vec3 object_origin,
                           out vec3 object_direction)
{
    object_origin = vec3(dot(row0.xyz, origin) + row0.w, dot(row1.xyz, origin) + row1.w, dot(row2.xyz, origin) + row2.w);
    object_direction = vec3(dot(row0.xyz, direction), dot(row1.xyz, direction), dot(row2.xyz, direction));
}

// Moves a world ray into an instance's object coordinates.
void to_object(uint instance, vec3 origin, vec3 direction, out vec3 object_origin, out vec3 object_direction)
{
    uint base = instance_offset + instance * uint(PACKED_INSTANCE_STRIDE);
    apply_world_to_object(packed_vec4(base + 1u), packed_vec4(base + 2u), packed_vec4(base + 3u), origin, direction,
                          object_origin, object_direction);
}
