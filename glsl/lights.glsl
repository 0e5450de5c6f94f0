// lights.glsl: light sampling: choosing a light by power, a direction towards it and its
// density, and the multiple importance sampling (MIS) weights that combine light sampling
// with BSDF sampling (the light records are core/packed_layout.h "lights").

// The probability that choose_light() picks light.
float light_probability(uint light)
{
    float cdf = packed_vec4(light_offset + light * uint(PACKED_LIGHT_STRIDE) + 1u).w;
    float before = light > 0u ? packed_vec4(light_offset + (light - 1u) * uint(PACKED_LIGHT_STRIDE) + 1u).w : 0.0;
    return cdf - before;
}

// Picks a light by power: binary search of the cumulative probabilities.
uint choose_light(float u)
{
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

// Solid-angle density, seen from p, of the direction light sampling would pick towards
// point x on area light (normal n there), given its record head and geometry. Spheres
// are sampled by their visible cone.
float area_light_pdf(uvec4 head, vec4 a, vec4 edge1, vec4 edge2, vec3 p, vec3 x, vec3 n)
{
    if (head.x == uint(LIGHT_SPHERE)) {
        float distance_squared = dot(a.xyz - p, a.xyz - p);
        if (distance_squared <= a.w * a.w)
            return 0.0;
        float cos_max = sqrt(max(0.0, 1.0 - a.w * a.w / distance_squared));
        return 1.0 / (2.0 * PI * max(1.0 - cos_max, 1e-12));
    }
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
    if (head.x == uint(LIGHT_SPHERE)) {
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
    } else {
        if (head.x == uint(LIGHT_TRIANGLE) && u.x + u.y > 1.0)
            uv = vec2(1.0) - u;   // fold the square onto the triangle: still uniform
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
    if (head.x == uint(LIGHT_ENVIRONMENT)) {
        found = sample_environment(light, u, s.direction, s.emitted, s.pdf);
        s.distance = INFINITY;
    } else if (head.x >= uint(LIGHT_POINT)) {
        found = sample_delta_light(light, p, u, s.direction, s.distance, s.emitted);
        s.delta = true;
    } else {
        found = sample_light(light, p, u, s.direction, s.distance, s.emitted, s.pdf) && !(s.pdf <= 0.0);
    }
    s.slot = s.delta || head.x == uint(LIGHT_ENVIRONMENT) ? NONE : head.y;
    return found;
}

// ---- MIS weights of what BSDF sampling finds (previous_pdf: the density with which the
// path's last vertex chose its direction, 0 when that vertex sampled no light)

// A path that hit the emissive world primitive hit.primitive at p (geometric normal n),
// coming from vertex: light sampling could have found it too.
float emitter_mis_weight(Hit hit, float previous_pdf, vec3 vertex, vec3 p, vec3 n)
{
    uint light = previous_pdf > 0.0 && hit.instance == NONE ? area_light_of(hit.primitive) : NONE;
    if (light == NONE || light >= light_count)
        return 1.0;
    float light_pdf = light_probability(light) * light_direction_pdf(light, vertex, p, n);
    return power_heuristic(previous_pdf, light_pdf);
}

// A path that left the scene along direction: light sampling could have picked that
// direction of an environment sky too (the environment is the last light).
float environment_mis_weight(float previous_pdf, vec3 direction)
{
    if (previous_pdf > 0.0 && sky_kind() == SKY_ENVIRONMENT && light_count > 0u) {
        uint last = light_count - 1u;
        if (packed_texel(light_offset + last * uint(PACKED_LIGHT_STRIDE)).x == uint(LIGHT_ENVIRONMENT))
            return power_heuristic(previous_pdf, light_probability(last) * environment_pdf(last, direction));
    }
    return 1.0;
}
