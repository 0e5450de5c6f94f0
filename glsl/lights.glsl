// lights.glsl: light sampling: choosing a light, a direction towards it and its density,
// and the multiple importance sampling (MIS) weights that combine light sampling with
// BSDF sampling (the light records are core/packed_layout.h "lights").

// ---- choosing a light
//
// By power (choose_light, light_power_probability): a binary search of the cdf the packer
// wrote, the same wherever the point is. By the point (choose_light_at,
// light_choice_probability), for scenes of 2 to LOCAL_CHOICE_MAX lights: each light's
// chance follows an estimate of the irradiance it gives the point (light_importance: its
// power over the squared distance, the light's own orientation, a spot's cone), mixed
// with its power-based chance (POWER_SHARE of it) so that every light that could light
// the point keeps a chance. The estimate leaves out the receiver's orientation, so the
// probability MIS needs when a path hits an emitter depends only on the position of the
// vertex it came from and the importances' total there. By the light tree
// (walk_light_tree), for scenes of more lights, where a loop over all of them would cost
// more than it saves: a walk from the root that takes each child in proportion to an
// estimate of what its lights give the point (tree_node_importance), as pbrt-v4's BVH
// light sampler does, the receiver's normal included. What the probability at an emitter
// hit needs besides the vertex's position (the total, or the tree's normal) is the choice
// memo, which the path carries to its next hit (choose_light_at, light_choice_probability).
const uint LOCAL_CHOICE_MAX = uint(LIGHT_LOCAL_CHOICE_MAX);
const float POWER_SHARE = 0.25;
const vec3 LUMINANCE = vec3(LUMINANCE_R, LUMINANCE_G, LUMINANCE_B);   // as the packer's powers

// The probability that choose_light() picks light.
float light_power_probability(uint light)
{
    if (!HAS_MANY_LIGHTS)
        return 1.0;
    float cdf = packed_vec4(light_offset + light * uint(PACKED_LIGHT_STRIDE) + 1u).w;
    float before = light > 0u ? packed_vec4(light_offset + (light - 1u) * uint(PACKED_LIGHT_STRIDE) + 1u).w : 0.0;
    return cdf - before;
}

// Picks a light by power: binary search of the cumulative probabilities.
uint choose_light(float u);

// An estimate of the irradiance light gives point p, up to one factor common to all
// lights (luminance, no occlusion): what choose_light_at weighs by. With a surface normal
// n (facing the side light is gathered on; 0: none, a point in a medium), times the
// receiver's cosine: exact for a point, spot or sun, for an area light the largest over a
// sphere of radius sqrt(area) about its centre; 0 below the surface (the power share of
// mixed_probability still leaves every light a chance).
float light_importance(uint light, vec3 p, vec3 n)
{
    uint base = light_offset + light * uint(PACKED_LIGHT_STRIDE);
    uvec4 head = packed_texel(base);
    vec4 where = packed_vec4(base + 1u);
    vec4 colour = packed_vec4(base + 2u);
    if (HAS_ENVIRONMENT_LIGHT && head.x == uint(LIGHT_ENVIRONMENT))
        return colour.w;
    if (HAS_DELTA_LIGHTS && head.x == uint(LIGHT_SUN))
        return dot(colour.rgb, LUMINANCE) * (n == vec3(0.0) ? 1.0 : max(dot(n, where.xyz), 0.0));
    vec3 to_light = where.xyz - p;
    float distance_squared = max(dot(to_light, to_light), 1e-20);
    float receiving = 1.0;
    if (n != vec3(0.0)) {
        // cos(max(receiver angle - the sphere's angle, 0)), 0 past a right angle.
        float distance = sqrt(distance_squared);
        float cos_i = clamp(dot(n, to_light) / distance, -1.0, 1.0), sin_i = sqrt(max(1.0 - cos_i * cos_i, 0.0));
        float radius = !HAS_DELTA_LIGHTS || head.x <= uint(LIGHT_TRIANGLE) ? sqrt(packed_vec4(base + 3u).x) : 0.0;
        float sin_r = min(radius / distance, 1.0), cos_r = sqrt(max(1.0 - sin_r * sin_r, 0.0));
        receiving = cos_i >= cos_r ? 1.0 : max(cos_i * cos_r + sin_i * sin_r, 0.0);
    }
    if (!HAS_DELTA_LIGHTS || head.x <= uint(LIGHT_TRIANGLE)) {
        // Radiance x the solid angle it covers (at most a hemisphere): the projected area
        // over the squared distance; a sphere's projected area is a quarter of its area.
        float area = max(packed_vec4(base + 3u).x, 1e-30);
        float facing = HAS_SPHERE_LIGHTS && head.x == uint(LIGHT_SPHERE) ? 0.25 : abs(dot(colour.xyz, to_light)) * inversesqrt(distance_squared);
        return receiving * colour.w / area * min(area * facing / distance_squared, 2.0 * PI);
    }
    vec3 attenuation = uintBitsToFloat(head.yzw);
    float distance = sqrt(distance_squared);
    float falloff = attenuation == vec3(0.0) ? distance_squared
                  : attenuation.x + attenuation.y * distance + attenuation.z * distance_squared;
    float importance = dot(colour.rgb, LUMINANCE) / max(falloff, 1e-12);
    if (HAS_DELTA_LIGHTS && head.x == uint(LIGHT_SPOT)) {
        vec4 spot = packed_vec4(base + 3u);
        importance *= smoothstep(colour.w, max(spot.w, colour.w + 1e-6), dot(-to_light / distance, spot.xyz));
    }
    return importance * receiving;
}

// ---- the light tree (core/packed_layout.h "light tree", built by core/light_tree.c)

// A receiver's normal as a float that the pass state keeps exactly: octahedral, 12 bits a
// coordinate, 1 + the 24-bit code (an integer a float holds exactly); 0: no normal.
float encode_receiver(vec3 n)
{
    if (n == vec3(0.0))
        return 0.0;
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 f = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    uvec2 q = uvec2(clamp(round((f * 0.5 + 0.5) * 4095.0), 0.0, 4095.0));
    return float(1u + (q.x << 12u | q.y));
}

// The normal encode_receiver() kept (unit length), or 0.
vec3 decode_receiver(float code)
{
    if (code <= 0.0)
        return vec3(0.0);
    uint bits = uint(code) - 1u;
    vec2 f = vec2(float(bits >> 12u), float(bits & 4095u)) / 4095.0 * 2.0 - 1.0;
    vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float t = max(-n.z, 0.0);
    n.x += n.x >= 0.0 ? -t : t;
    n.y += n.y >= 0.0 ? -t : t;
    return normalize(n);
}

// Whether lights are chosen by walking the light tree in this scene (more than
// LOCAL_CHOICE_MAX lights; the variant leaves the walk out otherwise).
bool chooses_by_tree() { return HAS_LIGHT_TREE && light_tree_offset != NONE; }

// An estimate of what the lights of a tree node (its three texels) give point p, in the
// units of light_importance: the infinite lights' irradiance, plus the finite lights'
// intensity over the squared distance to the centre of their box (at least the box's
// half-diagonal squared, so that a point inside or near the box does not blow it up),
// times two bounds of pbrt-v4's LightBounds::Importance:
// - the emitters' facing: the largest cosine any of their normals can make with a
//   direction from the box to p (two-sided: emitters shine from both faces), the angle to
//   the cone's axis less the cone's half-angle and the half-angle the box's bounding
//   sphere covers, taken a thousandth of a radian smaller still (the axis is stored
//   octahedral, about 1e-4 rad off), so never zero; for a node of spots alone
//   (LIGHT_TREE_ONE_SIDED), 1 where that angle, measured from +axis, is within the cone,
//   0 beyond it: a spot lights nothing outside its outer cone;
// - the receiver's: with a surface normal n (facing the side light is gathered on; 0 for
//   a point in a medium, which leaves it out), the largest cosine n can make with a
//   direction from p to the box, the angle less the box's and a hundredth of a radian
//   (more than encode_receiver's rounding of n), and 0 past a right angle: one-sided, as
//   direct light is gathered from above the surface only (glsl/direct_light.glsl), so a
//   box wholly below the surface gets nothing, and every light that can light the point
//   keeps a chance;
// - for a node of infinite lights alone, the receiver's largest cosine with the directions
//   they come from (a sun's angular radius; an environment's are all).
float tree_node_importance(uvec4 t0, uvec4 t1, uvec4 t2, vec3 p, vec3 n)
{
    float intensity = uintBitsToFloat(t0.w);
    vec3 low = uintBitsToFloat(t0.xyz), high = uintBitsToFloat(t1.xyz);
    vec3 half_size = 0.5 * (high - low);
    vec3 to_p = p - 0.5 * (low + high);
    float radius_squared = dot(half_size, half_size);
    float distance_squared = dot(to_p, to_p);
    float cos_spread = uintBitsToFloat(t2.y);
    float distance = sqrt(distance_squared);
    float sin_box = distance_squared > radius_squared ? sqrt(radius_squared / distance_squared) : 1.0;
    float cos_box = sqrt(max(1.0 - sin_box * sin_box, 0.0));
    const float COS_MARGIN = 0.9999995, SIN_MARGIN = 0.001;   // of a thousandth of a radian
    // The receiver's bounds' margin: 0.01 rad.
    const float COS_RECEIVER_MARGIN = 0.99995, SIN_RECEIVER_MARGIN = 0.0099998;
    vec3 axis = decode_normal(t2.x);
    float cos_cone = min(cos_spread, 1.0), sin_cone = sqrt(max(1.0 - cos_cone * cos_cone, 0.0));
    float facing = 1.0;
    if (cos_spread > -1.0) {
        float axis_cosine = clamp(dot(axis, to_p) / max(distance, 1e-30), -1.0, 1.0);
        float cos_axis = abs(axis_cosine);
        // cos(max(axis angle - spread - box angle - margin, 0)) by the angle-difference
        // identities, without acos, asin and cos (each a long polynomial on llvmpipe, in a
        // loop that runs them for both children at every level); an angle that goes below
        // zero on the way gives 1.
        float sin_axis = sqrt(max(1.0 - cos_axis * cos_axis, 0.0));
        // axis angle - spread
        float cos_a = cos_axis * cos_cone + sin_axis * sin_cone, sin_a = sin_axis * cos_cone - cos_axis * sin_cone;
        // ... - box angle
        float cos_b = cos_a * cos_box + sin_a * sin_box, sin_b = sin_a * cos_box - cos_a * sin_box;
        // ... - margin
        float cos_c = cos_b * COS_MARGIN + sin_b * SIN_MARGIN, sin_c = sin_b * COS_MARGIN - cos_b * SIN_MARGIN;
        facing = sin_a <= 0.0 || sin_b <= 0.0 || sin_c <= 0.0 ? 1.0 : cos_c;
        if ((t2.w & uint(LIGHT_TREE_ONE_SIDED)) != 0u) {
            // spread + box angle, then + margin; at or past pi the point is lit from anywhere.
            float cos_s = cos_cone * cos_box - sin_cone * sin_box, sin_s = sin_cone * cos_box + cos_cone * sin_box;
            float cos_t = cos_s * COS_MARGIN - sin_s * SIN_MARGIN, sin_t = sin_s * COS_MARGIN + cos_s * SIN_MARGIN;
            bool everywhere = (sin_s <= 0.0 && cos_s < 0.0) || (sin_t <= 0.0 && cos_t < 0.0);
            facing = everywhere || axis_cosine >= cos_t ? 1.0 : 0.0;
        }
    }
    if (n != vec3(0.0)) {
        // cos(max(receiver angle - box angle - margin, 0)), 0 past a right angle; the
        // receiver angle runs to pi, so "below zero" is told by the cosines.
        float cos_i = clamp(-dot(n, to_p) / max(distance, 1e-30), -1.0, 1.0);
        float sin_i = sqrt(max(1.0 - cos_i * cos_i, 0.0));
        // receiver angle - box angle
        float cos_d = cos_i * cos_box + sin_i * sin_box, sin_d = sin_i * cos_box - cos_i * sin_box;
        // ... - margin
        float cos_e = cos_d * COS_RECEIVER_MARGIN + sin_d * SIN_RECEIVER_MARGIN;
        facing *= cos_i >= cos_box ? 1.0 : max(cos_e, 0.0);
    }
    // A node of infinite lights alone has an empty box (infinite corners): no finite part.
    float finite = intensity > 0.0 ? intensity * facing / max(max(distance_squared, radius_squared), 1e-30) : 0.0;
    // Its cone holds the directions its lights come from: their irradiance times the
    // receiver's largest cosine with those (the same bound, margin and one side as above).
    // Only such nodes have irradiance (the root, which has both, is never weighed).
    float from_sky = 1.0;
    if (n != vec3(0.0) && cos_spread > -1.0) {
        float cos_i = clamp(dot(n, axis), -1.0, 1.0), sin_i = sqrt(max(1.0 - cos_i * cos_i, 0.0));
        // receiver angle - the cone's half-angle, then - margin
        float cos_d = cos_i * cos_cone + sin_i * sin_cone, sin_d = sin_i * cos_cone - cos_i * sin_cone;
        from_sky = cos_i >= cos_cone ? 1.0 : max(cos_d * COS_RECEIVER_MARGIN + sin_d * SIN_RECEIVER_MARGIN, 0.0);
    }
    return uintBitsToFloat(t1.w) * from_sky + finite;
}

// Walks the light tree from the root to a leaf for point p with normal n (0: none) and
// returns its light; chance receives the probability of that walk. Each interior node's children are estimated
// (tree_node_importance) and the second is taken with its share of the two (half when
// both are zero): by u (uniform in [0, 1), rescaled at each level to what is left of it)
// or, when by_trail, by the bits of trail (packed_layout.h, lights: the walk to one
// light's leaf), which gives the probability that u would have taken it.
uint walk_light_tree(vec3 p, vec3 n, bool by_trail, uint trail, float u, out float chance)
{
    chance = 1.0;
    uint child = packed_texel(light_tree_offset + 2u).z;   // the root's
    // At most LIGHT_TREE_MAX_DEPTH levels (a trail's bits); the loop ends at the leaf.
    for (uint level = 0u; level < uint(LIGHT_TREE_MAX_DEPTH) && (child & LIGHT_TREE_LEAF) == 0u; level++) {
        work++;
        uint base = light_tree_offset + child * uint(PACKED_LIGHT_TREE_NODE_STRIDE);
        uvec4 first2 = packed_texel(base + 2u), second2 = packed_texel(base + 5u);
        float first_importance = tree_node_importance(packed_texel(base), packed_texel(base + 1u), first2, p, n);
        float second_importance = tree_node_importance(packed_texel(base + 3u), packed_texel(base + 4u), second2, p, n);
        float both = first_importance + second_importance;
        float second_share = both > 0.0 ? second_importance / both : 0.5;
        float first_share = 1.0 - second_share;
        bool second = by_trail ? ((trail >> level) & 1u) != 0u : u >= first_share;
        // What is left of u, uniform again within the branch taken.
        u = second ? (u - first_share) / max(second_share, 1e-30) : u / max(first_share, 1e-30);
        u = min(u, 0.99999994);
        chance *= second ? second_share : first_share;
        child = second ? second2.z : first2.z;
    }
    return child & ~LIGHT_TREE_LEAF;
}

// Whether lights are chosen by the point (see above) in this scene. The variant leaves the
// code out when the host knows they are not (HAS_LIGHT_CHOICE): llvmpipe would run its
// loops once however many lights there are.
bool chooses_by_point() { return HAS_LIGHT_CHOICE && light_count > 1u && light_count <= LOCAL_CHOICE_MAX; }

// The probability that choose_light_at(u, p, n) picks light (importance: its
// light_importance at p, total: the sum over all lights).
float mixed_probability(uint light, float importance, float total)
{
    float power = light_power_probability(light);
    return total > 0.0 ? mix(importance / total, power, POWER_SHARE) : power;
}

// The probability that choose_light_at() picks light for point p, where it left memo.
float light_choice_probability(uint light, vec3 p, vec2 memo)
{
    if (chooses_by_tree()) {
        float chance;
        uint trail = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE) + 4u).y;
        walk_light_tree(p, decode_receiver(memo.y), true, trail, 0.0, chance);
        return chance;
    }
    if (!chooses_by_point())
        return light_power_probability(light);
    return mixed_probability(light, light_importance(light, p, decode_receiver(memo.y)), memo.x);
}

// Picks a light for point p, on a surface of normal n facing the side light is gathered on
// (0: a point in a medium), from u uniform in [0, 1) (see above); probability receives the
// chance it had, memo what light_choice_probability() needs to find that chance again for
// the same point: y the normal as encode_receiver() keeps it (the choice uses that
// rounded normal, so that both agree), x the sum of all lights' importance at p (chosen by
// the point; 0 by the tree or by power).
uint choose_light_at(float u, vec3 p, vec3 n, out float probability, out vec2 memo)
{
    memo = vec2(0.0, encode_receiver(n));
    vec3 normal = decode_receiver(memo.y);
    if (chooses_by_tree())
        return walk_light_tree(p, normal, false, 0u, u, probability);
    if (!chooses_by_point()) {
        uint light = choose_light(u);
        probability = light_power_probability(light);
        return light;
    }
    float importance[LOCAL_CHOICE_MAX];
    for (uint l = 0u; l < light_count; l++) {
        work++;
        importance[l] = light_importance(l, p, normal);
        memo.x += importance[l];
    }
    uint chosen = light_count - 1u;
    probability = mixed_probability(chosen, importance[chosen], memo.x);
    float cumulative = 0.0;
    bool found = false;
    for (uint l = 0u; l + 1u < light_count; l++) {
        work++;
        float q = mixed_probability(l, importance[l], memo.x);
        cumulative += q;
        if (!found && u < cumulative) {
            found = true;
            chosen = l;
            probability = q;
        }
    }
    return chosen;
}

uint choose_light(float u)
{
    if (!HAS_MANY_LIGHTS)
        return 0u;
    uint low = 0u, high = light_count - 1u;
    while (low < high) {
        work++;
        uint middle = (low + high) / 2u;
        if (u < packed_vec4(light_offset + middle * uint(PACKED_LIGHT_STRIDE) + 1u).w)
            high = middle;
        else
            low = middle + 1u;
    }
    return low;
}

// The light record head of an area light and its primitive's geometry (sphere: centre
// and radius in a; quad and triangle: corner in a, edges in b and c).
void area_light_geometry(uint light, out uvec4 head, out vec4 a, out vec4 b, out vec4 c)
{
    head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
    uint type = head.x == uint(LIGHT_SPHERE) ? uint(PRIMITIVE_SPHERE)
              : head.x == uint(LIGHT_QUAD) ? uint(PRIMITIVE_QUAD) : uint(PRIMITIVE_TRIANGLE);
    uvec3 normal_words;
    primitive_geometry(packed_texel(primitive_offset + head.y), type, a, b, c, normal_words);
}

// The area light of an emissive world primitive (by slot), or NONE: the area lights
// come first in the light list, in primitive order (packed_layout.h), so a binary search.
uint area_light_of(uint slot)
{
    if (!HAS_MANY_LIGHTS)
        return area_light_count > 0u && packed_texel(light_offset).y == slot ? 0u : NONE;
    uint low = 0u, high = area_light_count;
    while (low < high) {
        work++;
        uint middle = (low + high) / 2u;
        if (packed_texel(light_offset + middle * uint(PACKED_LIGHT_STRIDE)).y < slot)
            low = middle + 1u;
        else
            high = middle;
    }
    return low < area_light_count && packed_texel(light_offset + low * uint(PACKED_LIGHT_STRIDE)).y == slot ? low
                                                                                                           : NONE;
}

// ---- rectangles by solid angle (Urena, Fajardo and King, "An Area-Preserving
// Parametrization for Spherical Rectangles", EGSR 2013): a point seen from p is drawn
// uniformly in the solid angle the rectangle covers, so a nearby or slanted light is not
// sampled mostly where it looks small. Parallelograms that are not rectangles, and
// rectangles that cover less than RECTANGLE_MIN_SOLID_ANGLE (where float32 angles lose
// their relative precision), are sampled by area instead; the choice depends on p and
// the quad alone, so sampling and the density MIS asks for agree.
const float RECTANGLE_MIN_SOLID_ANGLE = 1e-3;

struct SphericalRectangle {
    vec3 x, y, z;              // the rectangle's frame: edges (unit) and the normal facing away from p
    float z0;                  // the plane's signed distance along z (< 0: z points away from p)
    float x0, y0, x1, y1;      // the rectangle's extent in the frame, relative to p
    float b0, b1, k;           // the parametrization's constants
    float solid_angle;
};

// The spherical rectangle of the quad (corner, edge_x, edge_y) seen from p; false when
// the quad is not a rectangle or covers too small a solid angle for this method.
bool spherical_rectangle(vec3 corner, vec3 edge_x, vec3 edge_y, vec3 p, out SphericalRectangle r)
{
    float length_x = length(edge_x), length_y = length(edge_y);
    r.x = edge_x / length_x;
    r.y = edge_y / length_y;
    r.z = cross(r.x, r.y);
    vec3 d = corner - p;
    r.z0 = dot(d, r.z);
    if (r.z0 > 0.0) {
        r.z = -r.z;
        r.z0 = -r.z0;
    }
    r.x0 = dot(d, r.x);
    r.y0 = dot(d, r.y);
    r.x1 = r.x0 + length_x;
    r.y1 = r.y0 + length_y;
    // The normals of the great circles through its edges, and its inner angles.
    vec3 n0 = normalize(vec3(0.0, r.z0, -r.y0));
    vec3 n1 = normalize(vec3(-r.z0, 0.0, r.x1));
    vec3 n2 = normalize(vec3(0.0, -r.z0, r.y1));
    vec3 n3 = normalize(vec3(r.z0, 0.0, -r.x0));
    float g0 = acos(clamp(-dot(n0, n1), -1.0, 1.0));
    float g1 = acos(clamp(-dot(n1, n2), -1.0, 1.0));
    float g2 = acos(clamp(-dot(n2, n3), -1.0, 1.0));
    float g3 = acos(clamp(-dot(n3, n0), -1.0, 1.0));
    r.b0 = n0.z;
    r.b1 = n2.z;
    r.k = 2.0 * PI - g2 - g3;
    r.solid_angle = g0 + g1 - r.k;
    bool rectangle = HAS_RECTANGLE_LIGHTS && abs(dot(r.x, r.y)) < 1e-4;
    // A point in the rectangle's own plane (within a ray offset: a pbr emitter's own
    // surface, which scatters on) would see it as a whole hemisphere on either side, as the
    // sign of float noise in z0 says: it sees the light edge-on, which area sampling gives
    // (a density that is infinite there, so no light).
    bool off_plane = -r.z0 > 4.0 * ray_offset(p);
    return rectangle && off_plane && r.solid_angle > RECTANGLE_MIN_SOLID_ANGLE;
}

// The point of the rectangle at (u, v) of its solid-angle parametrization, in the frame
// relative to p (add p to have it in the world): uniform in solid angle for uniform u.
vec2 spherical_rectangle_point(SphericalRectangle r, vec2 u)
{
    float au = u.x * r.solid_angle + r.k;
    float fu = (cos(au) * r.b0 - r.b1) / sin(au);
    float cu = clamp((fu >= 0.0 ? 1.0 : -1.0) * inversesqrt(fu * fu + r.b0 * r.b0), -1.0, 1.0);
    float xu = clamp(-(cu * r.z0) * inversesqrt(max(1.0 - cu * cu, 1e-20)), r.x0, r.x1);
    float d = sqrt(xu * xu + r.z0 * r.z0);
    float h0 = r.y0 * inversesqrt(d * d + r.y0 * r.y0);
    float h1 = r.y1 * inversesqrt(d * d + r.y1 * r.y1);
    float hv = h0 + u.y * (h1 - h0);
    float yv = hv * hv < 1.0 - 1e-6 ? clamp(hv * d * inversesqrt(1.0 - hv * hv), r.y0, r.y1) : r.y1;
    return vec2(xu, yv);
}

// Solid-angle density, seen from p, of the direction light sampling would pick towards
// point x on area light (normal n there), given its record head and geometry. Spheres
// are sampled by their visible cone, rectangles by their spherical rectangle, other
// quads and triangles by area.
float area_light_pdf(uvec4 head, vec4 a, vec4 edge1, vec4 edge2, vec3 p, vec3 x, vec3 n)
{
    SphericalRectangle rectangle;
    if (head.x == uint(LIGHT_QUAD) && spherical_rectangle(a.xyz, edge1.xyz, edge2.xyz, p, rectangle))
        return 1.0 / rectangle.solid_angle;
    if (HAS_SPHERE_LIGHTS && head.x == uint(LIGHT_SPHERE)) {
        float distance_squared = dot(a.xyz - p, a.xyz - p);
        if (distance_squared <= a.w * a.w)
            return 0.0;
        float cos_max = sqrt(max(0.0, 1.0 - a.w * a.w / distance_squared));
        return 1.0 / (2.0 * PI * max(1.0 - cos_max, 1e-12));
    }
    if (!HAS_FLAT_LIGHTS)
        return 0.0;
    float area = length(cross(edge1.xyz, edge2.xyz)) * (head.x == uint(LIGHT_QUAD) ? 1.0 : 0.5);
    vec3 to_light = x - p;
    float distance_squared = dot(to_light, to_light);
    float cosine = abs(dot(n, to_light)) * inversesqrt(distance_squared);
    return cosine > 1e-8 ? distance_squared / (cosine * area) : 0.0;
}

// The same by light index.
float light_direction_pdf(uint light, vec3 p, vec3 x, vec3 n)
{
    uvec4 head;
    vec4 a, edge1, edge2;
    area_light_geometry(light, head, a, edge1, edge2);
    return area_light_pdf(head, a, edge1, edge2, p, x, n);
}

// A direction from p towards a point on light (u uniform): the direction, the distance to
// the light along it, the emitted radiance there and the solid-angle density. Returns
// false when p sees nothing of the light (inside a sphere light, behind nothing).
bool sample_light(uint light, vec3 p, vec2 u, out vec3 direction, out float distance, out vec3 emitted,
                  out float pdf)
{
    uvec4 head;
    vec4 a, edge1, edge2;
    area_light_geometry(light, head, a, edge1, edge2);
    vec3 x, n;
    vec2 uv = u;
    direction = vec3(0.0, 1.0, 0.0);
    distance = 0.0;
    pdf = 0.0;
    emitted = vec3(0.0);
    if (HAS_SPHERE_LIGHTS && head.x == uint(LIGHT_SPHERE)) {
        vec3 axis = a.xyz - p;
        float distance_squared = dot(axis, axis);
        if (distance_squared <= a.w * a.w)
            return false;
        float axis_length = sqrt(distance_squared);
        axis /= axis_length;
        float cos_max = sqrt(max(0.0, 1.0 - a.w * a.w / distance_squared));
        float cos_theta;
        direction = random_in_cone(axis, cos_max, u, cos_theta);
        distance = intersect_sphere(a.xyz, a.w, p, direction, INFINITY);
        if (distance == INFINITY)
            distance = axis_length * cos_theta;  // grazing the rim: close enough
        x = p + distance * direction;
        n = normalize(x - a.xyz);
        uv = vec2(0.5 + atan(-n.z, n.x) / (2.0 * PI), acos(clamp(-n.y, -1.0, 1.0)) / PI);
        pdf = 1.0 / (2.0 * PI * max(1.0 - cos_max, 1e-12));
    } else if (HAS_FLAT_LIGHTS) {
        SphericalRectangle rectangle;
        bool by_solid_angle = head.x == uint(LIGHT_QUAD) && spherical_rectangle(a.xyz, edge1.xyz, edge2.xyz, p,
                                                                                   rectangle);
        if (by_solid_angle) {
            vec2 local = spherical_rectangle_point(rectangle, u);
            uv = vec2((local.x - rectangle.x0) / (rectangle.x1 - rectangle.x0),
                      (local.y - rectangle.y0) / (rectangle.y1 - rectangle.y0));
        } else if (HAS_TRIANGLE_LIGHTS && head.x == uint(LIGHT_TRIANGLE) && u.x + u.y > 1.0) {
            uv = vec2(1.0) - u;   // fold the square onto the triangle: still uniform
        }
        x = a.xyz + uv.x * edge1.xyz + uv.y * edge2.xyz;
        n = normalize(cross(edge1.xyz, edge2.xyz));
        vec3 to_light = x - p;
        distance = length(to_light);
        if (distance < 1e-12)
            return false;
        direction = to_light / distance;
        pdf = area_light_pdf(head, a, edge1, edge2, p, x, n);   // the geometry is at hand
        if (pdf == 0.0)
            return false;
    } else {
        return false;
    }
    Material material = material_record(primitive_info(head.y) & uint(PRIMITIVE_INFO_MATERIAL_MASK));
    emitted = emissive_emitted(material, x, uv) * emitted_side(material, direction, n);
    return true;
}

// Point, spot and sun lights seen from p: the direction to the light, its distance
// (INFINITY for the sun) and the light arriving, per unit area facing it (irradiance):
// point and spot: intensity / falloff(distance) (inverse square, or the seed report's
// c + l d + q d^2), the spot shaped by a smooth edge between its inner and outer cones;
// sun: its irradiance, from a direction drawn in its disc (soft shadows).
bool sample_delta_light(uint light, vec3 p, vec2 u, out vec3 direction, out float distance, out vec3 incident)
{
    uint base = light_offset + light * uint(PACKED_LIGHT_STRIDE);
    uvec4 head = packed_texel(base);
    vec4 where = packed_vec4(base + 1u);
    vec4 colour = packed_vec4(base + 2u);
    incident = colour.rgb;
    if (head.x == uint(LIGHT_SUN)) {
        float cos_theta;
        direction = random_in_cone(normalize(where.xyz), colour.w, u, cos_theta);
        distance = INFINITY;
        return true;
    }
    vec3 to_light = where.xyz - p;
    distance = length(to_light);
    if (distance < 1e-12)
        return false;
    direction = to_light / distance;
    vec3 attenuation = uintBitsToFloat(head.yzw);
    float falloff = attenuation == vec3(0.0) ? distance * distance
                  : attenuation.x + attenuation.y * distance + attenuation.z * distance * distance;
    incident /= max(falloff, 1e-12);
    if (head.x == uint(LIGHT_SPOT)) {
        vec4 spot = packed_vec4(base + 3u);
        incident *= smoothstep(colour.w, max(spot.w, colour.w + 1e-6), dot(-direction, spot.xyz));
    }
    return true;
}

// The power heuristic (exponent 2) of MIS: the weight of the strategy whose density is
// chosen against the other's.
float power_heuristic(float chosen, float other)
{
    float a = chosen * chosen, b = other * other;
    return a + b > 0.0 ? a / (a + b) : 0.0;
}

// ---- one light sample, whatever the light's kind

struct LightSample {
    vec3 direction;   // from the point towards the light (unit)
    float distance;   // to the light along direction; INFINITY for the sun and the sky
    vec3 emitted;     // radiance arriving (area lights, environment) or irradiance (delta lights)
    float pdf;        // solid-angle density of direction (1 for delta lights)
    bool delta;       // point, spot or sun: no other strategy can find it, so no MIS
    uint slot;        // an area light's primitive, which the shadow ray may hit; else NONE
};

// A sample of light (by index) as seen from p, from two uniform numbers; false when p
// gets nothing from it.
bool sample_light_from(uint light, vec3 p, vec2 u, out LightSample s)
{
    s.pdf = 1.0;
    s.delta = false;
    uvec4 head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
    bool found;
    if (HAS_ENVIRONMENT_LIGHT && head.x == uint(LIGHT_ENVIRONMENT)) {
        found = sample_environment(light, u, s.direction, s.emitted, s.pdf);
        s.distance = INFINITY;
    } else if (HAS_DELTA_LIGHTS && head.x >= uint(LIGHT_POINT)) {
        found = sample_delta_light(light, p, u, s.direction, s.distance, s.emitted);
        s.delta = true;
    } else if (HAS_AREA_LIGHTS) {
        found = sample_light(light, p, u, s.direction, s.distance, s.emitted, s.pdf) && !(s.pdf <= 0.0);
    } else {
        found = false;
        s.direction = vec3(0.0, 1.0, 0.0);
        s.distance = 0.0;
        s.emitted = vec3(0.0);
    }
    s.slot = s.delta || (HAS_ENVIRONMENT_LIGHT && head.x == uint(LIGHT_ENVIRONMENT)) ? NONE : head.y;
    return found;
}

// ---- MIS weights of what BSDF sampling finds (previous_pdf: the density with which the
// path's last vertex chose its direction, 0 when that vertex sampled no light)

// A path that hit the emissive world primitive hit.primitive at p (geometric normal n),
// coming from vertex, where light sampling left choice_memo (choose_light_at):
// light sampling could have found it too.
float emitter_mis_weight(Hit hit, float previous_pdf, vec2 choice_memo, vec3 vertex, vec3 p, vec3 n)
{
    uint light = previous_pdf > 0.0 && hit.instance == NONE ? area_light_of(hit.primitive) : NONE;
    if (light == NONE || light >= light_count)
        return 1.0;
    float light_pdf = light_choice_probability(light, vertex, choice_memo) * light_direction_pdf(light, vertex, p, n);
    return power_heuristic(previous_pdf, light_pdf);
}

// A path that left the scene along direction from vertex (choice_memo as above): light
// sampling could have picked that direction of an environment sky too (the environment is
// the last light).
float environment_mis_weight(float previous_pdf, vec2 choice_memo, vec3 vertex, vec3 direction)
{
    if (HAS_ENVIRONMENT_LIGHT && previous_pdf > 0.0 && sky_kind() == SKY_ENVIRONMENT && light_count > 0u) {
        uint last = light_count - 1u;
        if (packed_texel(light_offset + last * uint(PACKED_LIGHT_STRIDE)).x == uint(LIGHT_ENVIRONMENT))
            return power_heuristic(previous_pdf,
                                   light_choice_probability(last, vertex, choice_memo) * environment_pdf(last, direction));
    }
    return 1.0;
}
