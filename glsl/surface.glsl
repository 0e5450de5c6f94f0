// surface.glsl: what shading needs to know about a hit: position, normals, uv, material.

// Offset for a new ray leaving point p: scaled with the point's magnitude because
// float32 spacing grows with it; keeps rays from re-hitting the surface they leave.
float ray_offset(vec3 p)
{
    vec3 a = abs(p);
    return 1e-4 * (1.0 + max(a.x, max(a.y, a.z)));
}

// What shading needs to know about a hit.
struct Surface {
    vec3 position;        // world
    vec3 geometric;       // world, unit, outward (the side the primitive faces)
    vec3 shading;         // world, unit, outward (interpolated vertex normals, else geometric)
    vec2 uv;
    vec3 color;           // the vertex colour (glsl/scene_access.glsl vertex_color), else white
    uint material;        // material index
    bool volume_boundary; // the hit is on a volume instance's boundary
    uint instance;
};

// Computes the surface at a hit: normals (object space, moved to the world by the
// inverse transpose of the placement, which is the transpose of world-to-object), uv and
// the material (the primitive's own, else the instance's, else the default).
Surface surface_at(Hit hit, vec3 origin, vec3 direction, float time)
{
    Surface surface;
    surface.position = origin + hit.t * direction;
    surface.instance = hit.instance;
    surface.volume_boundary = false;
    surface.color = vec3(1.0);
    uvec4 record = packed_texel(primitive_offset + hit.primitive);
    uint info = primitive_info(hit.primitive);
    uint type = primitive_type(info);
    vec4 a, b, c;
    uvec3 normal_words;
    primitive_geometry(record, type, a, b, c, normal_words);
    vec3 object_point = surface.position;
    mat3 normal_to_world = mat3(1.0);
    uint instance_material = NONE;
    if (HAS_INSTANCES && hit.instance != NONE) {
        uint instance_base = instance_offset + hit.instance * uint(PACKED_INSTANCE_STRIDE);
        uvec4 instance_head = packed_texel(instance_base);
        instance_material = instance_head.y;
        surface.volume_boundary = HAS_VOLUMES && (instance_head.z & uint(INSTANCE_VOLUME)) != 0u;
        vec4 row0 = packed_vec4(instance_base + 1u), row1 = packed_vec4(instance_base + 2u),
             row2 = packed_vec4(instance_base + 3u);
        vec3 object_direction;
        to_object(hit.instance, origin, direction, object_point, object_direction);
        object_point += hit.t * object_direction;
        // Columns are the rows of world-to-object: transpose(M) * n.
        normal_to_world = mat3(row0.xyz, row1.xyz, row2.xyz);
    }
    uint own_material = info & uint(PRIMITIVE_INFO_MATERIAL_MASK);
    surface.material = own_material != uint(PRIMITIVE_NO_MATERIAL) ? own_material
                     : instance_material != NONE ? instance_material : default_material;
    uint material_base = material_offset + surface.material * uint(PACKED_MATERIAL_STRIDE);
    uint normal_map = HAS_TEXTURES ? packed_texel(material_base + 2u).w : NONE;
    vec3 normal = vec3(0.0, 1.0, 0.0);
    vec3 shading_normal = normal;
    vec3 tangent = vec3(0.0);     // object-space direction of increasing u (for normal maps)
    float handedness = 1.0;
    vec2 uv = hit.barycentric;
    // In the variants without spheres or without flat primitives, the kind is known.
    bool flat_primitive = HAS_FLAT
                          && (!HAS_SPHERES || type == uint(PRIMITIVE_TRIANGLE) || type == uint(PRIMITIVE_QUAD));
    if (HAS_SPHERES && !flat_primitive) {
        vec3 center = a.xyz;
        if (HAS_MOVING_SPHERES && type == uint(PRIMITIVE_MOVING_SPHERE))
            center = mix(a.xyz, b.xyz, time);
        normal = (object_point - center) / a.w;
        shading_normal = normal;
        if (HAS_TEXTURES)
            uv = sphere_uv(normal);
        tangent = vec3(normal.z, 0.0, -normal.x);
    }
    if (HAS_FLAT && flat_primitive) {
        vec3 edge1 = b.xyz, edge2 = c.xyz;
        normal = cross(edge1, edge2);
        shading_normal = normal;
        tangent = edge1;      // quads and bare triangles: u runs along the first edge
        if (HAS_TRIANGLES && type == uint(PRIMITIVE_TRIANGLE)) {
            // Vertex normals and uvs, interpolated by barycentrics.
            vec3 weights = vec3(1.0 - hit.barycentric.x - hit.barycentric.y, hit.barycentric);
            if (HAS_VERTEX_COLORS && color_offset != NONE)
                surface.color = weights.x * vertex_color(record.x) + weights.y * vertex_color(record.y)
                                + weights.z * vertex_color(record.z);
            vec3 n0, n1, n2;
            if (vertex_normals(normal_words, n0, n1, n2)) {
                vec3 interpolated = weights.x * n0 + weights.y * n1 + weights.z * n2;
                if (dot(interpolated, interpolated) > 0.0)
                    shading_normal = interpolated;
            }
            if (HAS_TEXTURES && (info & uint(PRIMITIVE_INFO_HAS_UVS)) != 0u) {
                vec2 uv0 = vertex_uv(record.x), uv1 = vertex_uv(record.y), uv2 = vertex_uv(record.z);
                uv = weights.x * uv0 + weights.y * uv1 + weights.z * uv2;
                // The tangent follows the uv layout: solve edge = du * T + dv * B.
                vec2 duv1 = uv1 - uv0, duv2 = uv2 - uv0;
                float determinant = duv1.x * duv2.y - duv2.x * duv1.y;
                if (abs(determinant) > 1e-12) {
                    tangent = (edge1 * duv2.y - edge2 * duv1.y) / determinant;
                    vec3 bitangent = (edge2 * duv1.x - edge1 * duv2.x) / determinant;
                    handedness = dot(cross(normal, tangent), bitangent) < 0.0 ? -1.0 : 1.0;
                }
            }
        }
    }
    if (normal_map != NONE) {
        // Tangent-space normal map, applied in object space so that the result moves to
        // the world like any normal (inverse transpose), under any placement.
        vec3 n = normalize(shading_normal);
        vec3 t = tangent - n * dot(n, tangent);
        if (dot(t, t) < 1e-20)
            t = abs(n.x) < 0.9 ? cross(n, vec3(1.0, 0.0, 0.0)) : cross(n, vec3(0.0, 1.0, 0.0));
        t = normalize(t);
        vec3 b = handedness * cross(n, t);
        vec3 mapped = image_lookup(normal_map, uv) * 2.0 - 1.0;
        shading_normal = mapped.x * t + mapped.y * b + mapped.z * n;
    }
    surface.geometric = normalize(normal_to_world * normal);
    surface.shading = normalize(normal_to_world * shading_normal);
    // Keep the shading normal on the geometric side, or light leaks through.
    if (dot(surface.shading, surface.geometric) < 0.0)
        surface.shading = surface.geometric;
    surface.uv = uv;
    return surface;
}
