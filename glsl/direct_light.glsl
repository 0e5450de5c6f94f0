// direct_light.glsl: the light that reaches a scattering point straight from the lights
// (next-event estimation), with ONE shadow-ray call site: GLSL inlines every call, and
// each extra copy of the BVH traversal costs llvmpipe dearly (docs/performance.md).

// How the light is gathered (LightQuery.model):
//   DIRECT_MIS (path tracing): one light chosen by power, one point on it, weighted
//     against BSDF sampling (material_pdf, or the phase function's density in a medium)
//     by the power heuristic; delta lights (point, spot, sun) unweighted.
//   DIRECT_PHONG (Whitted): ambient plus, for every light (one chosen by power when there
//     are more than WHITTED_ALL_LIGHTS), the Phong model of glsl/material_phong.glsl; area
//     lights are lit from a random point each sample, which averages to soft shadows.
const int DIRECT_MIS = 0;
const int DIRECT_PHONG = 1;
const uint WHITTED_ALL_LIGHTS = 16u;

// Where and how an integrator asks for direct light after a segment.
struct LightQuery {
    bool wanted;
    int model;           // DIRECT_MIS or DIRECT_PHONG
    bool in_medium;      // a scattering event in a volume: the isotropic phase function
    vec3 position;
    ShadingFrame frame;  // surfaces: the normals facing the incoming ray
    Material material;   // surfaces: what scatters (in a medium only albedo is read: 1)
    vec3 weight;         // the path's throughput at the point
};

// No direct light this segment.
LightQuery no_light_query()
{
    LightQuery q;
    q.wanted = false;
    q.model = DIRECT_MIS;
    q.in_medium = false;
    q.position = vec3(0.0);
    q.frame.normal = vec3(0.0);
    q.frame.shading = vec3(0.0);
    q.frame.front_face = true;
    q.material = no_material();
    q.weight = vec3(0.0);
    return q;
}

// The query for a surface point p shaded by material with the given model.
LightQuery surface_light_query(bool wanted, int model, vec3 p, ShadingFrame frame, Material material, vec3 weight)
{
    LightQuery q = no_light_query();
    q.wanted = wanted;
    q.model = model;
    q.position = p;
    q.frame = frame;
    q.material = material;
    q.weight = weight;
    return q;
}

// The light the query's point sends towards view (the reverse of the incoming ray),
// per unit of the path's throughput: the caller multiplies by query.weight. media and
// time are the path's, bounce picks the random numbers; light_total receives what MIS at
// the path's next emitter hit needs of the light choice here (glsl/lights.glsl). Each
// light's share (times query.weight) also goes to its light group (glsl/light_groups.glsl);
// Whitted's ambient term to the sky's.
vec3 direct_light(LightQuery query, vec3 view, uint media, float time, uint bounce, inout float light_total)
{
    bool phong_model = query.model == DIRECT_PHONG;
    vec3 result = phong_model ? ambient * query.material.albedo : vec3(0.0);
    if (phong_model)
        add_to_light_group(sky_light_group, query.weight * result);
    if (light_count == 0u)
        return result;
    vec4 phong = phong_model ? phong_parameters(query.material) : vec4(0.0);
    bool choose = !phong_model || light_count > WHITTED_ALL_LIGHTS;
    uint count = choose ? 1u : light_count;
    for (uint k = 0u; k < count; k++) {
        work++;
        vec4 u = !phong_model ? random4(bounce, 5u)
                              : fract(random4(bounce, 6u + (k & 1u)) + float(k >> 1u) * 0.6180339887);
        float choice = 1.0;
        uint light = k;
        if (!phong_model)
            light = choose_light_at(u.x, query.position, choice, light_total);
        else if (choose) {
            light = choose_light(u.x);
            choice = light_power_probability(light);
        }
        if (choice <= 0.0)
            continue;
        LightSample light_sample;
        // u.x chooses the light; the point on it is the stratified pair (z, w).
        if (!sample_light_from(light, query.position, u.zw, light_sample))
            continue;
        vec3 to_light = light_sample.direction;
        vec3 value;
        float bsdf_pdf;
        vec3 origin = query.position;
        if (query.in_medium) {
            bsdf_pdf = PHASE_PDF;
            value = query.material.albedo * bsdf_pdf;
        } else {
            // Materials that sample lights reflect: light from below the surface is none.
            if (dot(query.frame.shading, to_light) <= 0.0 || dot(query.frame.normal, to_light) <= 0.0)
                continue;
            bsdf_pdf = material_pdf(query.material, query.frame, view, to_light);
            value = phong_model ? phong_evaluate(query.material, phong, query.frame, view, to_light)
                                : material_evaluate(query.material, query.frame, view, to_light);
            origin = query.position + ray_offset(query.position) * query.frame.normal;
        }
        float weight;
        if (light_sample.delta)
            weight = 1.0 / choice;
        else if (phong_model)
            weight = 1.0 / (choice * light_sample.pdf);
        else
            weight = power_heuristic(choice * light_sample.pdf, bsdf_pdf) / (choice * light_sample.pdf);
        vec3 transmittance = shadow_transmittance(origin, to_light, light_sample.distance, light_sample.slot, media,
                                                  time);
        vec3 contribution = transmittance * value * light_sample.emitted * weight;
        result += contribution;
        add_to_light_group(light_group_of(light), query.weight * contribution);
    }
    return result;
}
