// direct_light.glsl: the light that reaches a scattering point straight from the lights
// (next-event estimation), one shadow ray at a time: this file samples a light and makes
// the shadow ray, and for path tracing the segment loop (glsl/integrators.glsl) traces it
// in the same traversal loop as its next path ray (glsl/traverse.glsl): GLSL inlines
// every call, and each extra copy of the BVH traversal costs llvmpipe dearly
// (docs/performance.md). Whitted walks its shadow rays here (gathers_in_place).

// How the light is gathered (LightQuery.model):
//   DIRECT_MIS (path tracing): one light chosen for the point (glsl/lights.glsl: by its
//     estimated irradiance there, by the light tree, or by power), one point on it,
//     weighted against BSDF sampling (material_pdf, or the phase function's density in a
//     medium) by the power heuristic; delta lights (point, spot, sun) unweighted.
//   DIRECT_PHONG (Whitted): ambient plus, for every light (one chosen when there are more
//     than WHITTED_ALL_LIGHTS: by the light tree, else by power), the Phong model of
//     glsl/material_phong.glsl; area lights are lit from a random point each sample, which
//     averages to soft shadows.
const int DIRECT_MIS = 0;
const int DIRECT_PHONG = 1;
const uint WHITTED_ALL_LIGHTS = uint(LIGHT_WHITTED_ALL_MAX);

// Where and how an integrator asks for direct light after a segment, and, once the
// segment loop has begun gathering it (begin_direct_light), which lights are left.
struct LightQuery {
    bool wanted;
    int model;           // DIRECT_MIS or DIRECT_PHONG
    bool in_medium;      // a scattering event in a volume: the isotropic phase function
    vec3 position;
    ShadingFrame frame;  // surfaces: the normals facing the incoming ray
    Material material;   // surfaces: what scatters (in a medium only albedo is read: 1)
    vec3 weight;         // the path's throughput at the point
    // Set by begin_direct_light:
    uint next_light;     // the next of the light_samples samples to take
    uint light_samples;
    vec3 view;           // the reverse of the incoming ray
    uint bounce;         // the segment's bounce (its random numbers)
    float time;          // the path's
    uint media;          // the path's at the point
};

// A shadow ray waiting for the segment loop to trace it, and what it brings when it gets
// through (in the variants with volumes it may step through their boundaries on the way:
// glsl/media.glsl).
struct PendingShadow {
    bool pending;
    ShadowRay ray;
    vec3 contribution;      // added to the path's radiance times the transmittance
    uint light_group;       // the light's group (glsl/light_groups.glsl), which it goes to too
    ShadowTransit transit;  // through volumes
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
    q.next_light = 0u;
    q.light_samples = 0u;
    q.view = vec3(0.0);
    q.bounce = 0u;
    q.time = 0.0;
    q.media = 0u;
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

// No shadow ray.
PendingShadow no_pending_shadow()
{
    PendingShadow shadow;
    shadow.pending = false;
    shadow.ray.origin = vec3(0.0);
    shadow.ray.direction = vec3(0.0, 1.0, 0.0);
    shadow.ray.t_max = 0.0;
    shadow.ray.light_slot = NONE;
    shadow.ray.time = 0.0;
    shadow.contribution = vec3(0.0);
    shadow.light_group = 0u;
    shadow.transit = shadow_transit(0.0, 0u);
    return shadow;
}

// Whether the query has lights left to sample.
bool direct_light_pending(LightQuery query) { return query.next_light < query.light_samples; }

// Starts gathering the light the query's point sends towards view (the reverse of the
// incoming ray): Whitted's ambient term goes to radiance at once, and the lights to
// sample are counted. media and time are the path's, bounce picks the random numbers.
void begin_direct_light(inout LightQuery query, vec3 view, uint media, float time, uint bounce, inout vec3 radiance)
{
    bool phong_model = query.model == DIRECT_PHONG;
    if (phong_model) {
        radiance += query.weight * (ambient * query.material.albedo);
        add_to_light_group(sky_light_group, query.weight * (ambient * query.material.albedo));
    }
    bool choose = !phong_model || light_count > WHITTED_ALL_LIGHTS;
    query.next_light = 0u;
    query.light_samples = light_count == 0u ? 0u : choose ? 1u : light_count;
    query.view = view;
    query.media = media;
    query.time = time;
    query.bounce = bounce;
}

// Samples the query's next light: the shadow ray towards it and what it adds to the
// path's radiance if nothing is in the way (pending false when the light gives nothing:
// chosen with probability 0, out of reach, or below the surface). choice_memo receives
// what MIS at the path's next emitter hit needs of the light choice here
// (glsl/lights.glsl).
PendingShadow next_shadow_ray(inout LightQuery query, inout vec2 choice_memo)
{
    PendingShadow shadow = no_pending_shadow();
    uint k = query.next_light;
    query.next_light++;
    bool phong_model = query.model == DIRECT_PHONG;
    bool choose = !phong_model || light_count > WHITTED_ALL_LIGHTS;
    vec4 u = !phong_model ? random4(query.bounce, 5u)
                          : fract(random4(query.bounce, 6u + (k & 1u)) + float(k >> 1u) * 0.6180339887);
    float choice = 1.0;
    uint light = k;
    if (!phong_model || (choose && chooses_by_tree()))
        light = choose_light_at(u.x, query.position, query.in_medium ? vec3(0.0) : query.frame.normal, choice,
                                choice_memo);
    else if (choose) {
        light = choose_light(u.x);
        choice = light_power_probability(light);
    }
    if (choice <= 0.0)
        return shadow;
    LightSample light_sample;
    // u.x chooses the light; the point on it is the stratified pair (z, w).
    if (!sample_light_from(light, query.position, u.zw, light_sample))
        return shadow;
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
            return shadow;
        bsdf_pdf = material_pdf(query.material, query.frame, query.view, to_light);
        value = phong_model ? phong_evaluate(query.material, phong_parameters(query.material), query.frame, query.view,
                                             to_light)
                            : material_evaluate(query.material, query.frame, query.view, to_light);
        origin = query.position + ray_offset(query.position) * query.frame.normal;
    }
    float weight;
    if (light_sample.delta)
        weight = 1.0 / choice;
    else if (phong_model)
        weight = 1.0 / (choice * light_sample.pdf);
    else
        weight = power_heuristic(choice * light_sample.pdf, bsdf_pdf) / (choice * light_sample.pdf);
    shadow.pending = true;
    shadow.ray.origin = origin;
    shadow.ray.direction = to_light;
    // Hits within 1e-4 of the light's distance are the light itself (or beyond it): the
    // traversal need not look that far.
    shadow.ray.t_max = light_sample.distance * (1.0 - 1e-4);
    shadow.ray.light_slot = light_sample.slot;
    shadow.ray.time = query.time;
    shadow.contribution = query.weight * (value * light_sample.emitted * weight);
    shadow.light_group = light_group_of(light);
    shadow.transit = shadow_transit(light_sample.distance, query.media);
    return shadow;
}

// Whether the segment loop gathers a point's direct light in place, each shadow ray
// walked at once by a traversal of its own (direct_light_in_place), instead of in the
// next iteration's walk with the path's next segment (glsl/integrators.glsl). Whitted
// samples up to WHITTED_ALL_LIGHTS lights at a point: an iteration of the segment loop
// per light (and per volume boundary its shadow ray crosses) runs the loop's whole body
// each time (docs/performance.md), which costs more than a light loop of its own, and
// since the pass state keeps no pending shadow ray, all of them would have to fit in what
// a pass may run past its budget (glsl/work.glsl): 16 lights behind a few boundaries did
// not. So Whitted variants keep the second traversal; path tracing takes one light sample
// a point and has none.
bool gathers_in_place() { return tracer_integrator() == INTEGRATOR_WHITTED; }

// Takes all the query's light samples (begin_direct_light counted them), walking each
// shadow ray to its light through the volume boundaries on its way, and adds what gets
// through to radiance.
void direct_light_in_place(inout LightQuery query, inout vec2 choice_memo, inout vec3 radiance)
{
    while (direct_light_pending(query)) {
        work++;
        PendingShadow shadow = next_shadow_ray(query, choice_memo);
        while (shadow.pending) {
            work++;
            bool blocked;
            Hit hit, no_path_hit;
            trace_rays(true, shadow.ray, false, shadow.ray.origin, shadow.ray.direction, shadow.ray.time, 0.0, blocked,
                       hit, no_path_hit);
            if (shadow_at_boundary(shadow.ray, blocked, hit)) {
                Surface surface = surface_at(hit, shadow.ray.origin, shadow.ray.direction, shadow.ray.time);
                shadow.pending = shadow_cross(shadow.ray, shadow.transit, hit, surface);
            } else {
                vec3 light = shadow_arrived(shadow.transit, shadow.ray, blocked, hit) * shadow.contribution;
                radiance += light;
                add_to_light_group(shadow.light_group, light);
                shadow.pending = false;
            }
        }
    }
}
