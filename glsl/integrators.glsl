// integrators.glsl: the table of integrators, and the loop that runs the one this render
// uses (INTEGRATOR_* of core/tracer_interface.h) over a pixel's paths for one pass.
//
// Every integrator traces paths segment by segment through the same loop (below): one
// traversal per segment, scattering in media, crossing volume boundaries, emitters adding
// their light, and direct light gathered once per segment. An integrator makes four choices
// in it, one function each in glsl/integrator_NAME.glsl:
//   bool NAME_samples_lights()    whether it gathers direct light from the lights
//   float NAME_sky_weight(PixelState s)
//                                 the weight of the sky a path sees when it leaves the scene
//   BsdfSample NAME_shade(inout PixelState s, Material material, ShadingFrame frame, vec3 p,
//                         BsdfSample sampled, inout LightQuery query)
//                                 at a surface: where the path goes on (sampled is the
//                                 material's own choice) and where direct light is gathered
//   bool NAME_survives(inout PixelState s)
//                                 after the path went on (from a surface or through a
//                                 volume boundary): whether it lives
// One loop rather than one per integrator: the whole tracer (--full-tracer) has every
// integrator, and llvmpipe runs all of a shader's code, so one traversal and one
// direct-light call serve them all (docs/performance.md). Variants compile the integrator
// in as a constant (tracer_integrator()), and only its choices are left in the program.
//
// Adding an integrator:
//   1. its id INTEGRATOR_NAME in core/tracer_interface.h (INTEGRATOR_COUNT one more;
//      core/gpu_tracer.c variant_key keeps two bits for it);
//   2. glsl/integrator_NAME.glsl with the four functions above;
//   3. one line in the module table of core/shader_sources.S, before this file;
//   4. one line in each of the four functions below;
//   5. its name for --integrator in cli/command_render.c, and what core/render.c
//      omitted_features keeps for it.

bool integrator_samples_lights()
{
    int id = tracer_integrator();
    if (id == INTEGRATOR_WHITTED) return whitted_samples_lights();
    return path_samples_lights();
}

float integrator_sky_weight(PixelState s)
{
    int id = tracer_integrator();
    if (id == INTEGRATOR_WHITTED) return whitted_sky_weight(s);
    return path_sky_weight(s);
}

BsdfSample integrator_shade(inout PixelState s, Material material, ShadingFrame frame, vec3 p, BsdfSample sampled,
                            inout LightQuery query)
{
    int id = tracer_integrator();
    if (id == INTEGRATOR_WHITTED) return whitted_shade(s, material, frame, p, sampled, query);
    return path_shade(s, material, frame, p, sampled, query);
}

bool integrator_survives(inout PixelState s)
{
    int id = tracer_integrator();
    if (id == INTEGRATOR_WHITTED) return whitted_survives(s);
    return path_survives(s);
}

// Runs the pixel's paths for one pass: segment after segment while the work budget
// lasts, starting new samples as paths end.
void integrate(inout PixelState s)
{
    if (!HAS_DIRECT_LIGHT || !integrator_samples_lights())
        light_count = 0u;       // nothing to sample
    for (;;) {
        if (!begin_segment(s))
            break;
        float time = ray_time();
        Hit hit;
        bool hit_something = trace(s.origin, s.direction, time, INFINITY, hit);
        s.statistics.x += 1.0;
        bool path_done = false;
        vec4 u = random4(s.bounce, 1u);
        uint segment_bounce = s.bounce;     // the steps below may move bounce and direction on
        vec3 incoming = s.direction;
        // Direct light is gathered once per segment, after the steps below decide where
        // (one call site: glsl/direct_light.glsl).
        LightQuery query = no_light_query();

        if (scatter_in_medium(s, hit.t, u, query, path_done)) {
            // scattered before the surface: done there
        } else if (!hit_something) {
            vec3 sky = s.throughput * sky_radiance(s.direction) * integrator_sky_weight(s);
            s.radiance += sky;
            add_to_light_group(sky_light_group, sky);
            path_done = true;
        } else {
            Surface surface = surface_at(hit, s.origin, s.direction, time);
            ShadingFrame frame = shading_frame(surface, s.direction);
            vec3 next_direction = s.direction;
            if (surface.volume_boundary) {
                cross_volume_boundary(s, surface, frame.front_face, hit.t);
            } else {
                s.since_vertex = 0.0;
                Material material = surface_material(surface, frame);
                // An emitter's light joins the path's; an emissive material then absorbs
                // (its sample ends the path), a pbr one scatters on.
                if (material_emits(material))
                    hit_emitter(s, hit, surface, material);
                BsdfSample sampled = material_sample(material, frame, s.direction, u);
                BsdfSample bsdf = integrator_shade(s, material, frame, surface.position, sampled, query);
                next_direction = bsdf.direction;
                s.throughput *= bsdf.weight;
                path_done = bsdf.absorbed;
            }
            if (!path_done) {
                if (!leave_surface(s, surface.position, frame.normal, next_direction))
                    path_done = true;
                else if (!integrator_survives(s))
                    path_done = true;
            }
        }
        if (HAS_DIRECT_LIGHT && query.wanted)
            s.radiance += query.weight * direct_light(query, -incoming, s.media, time, segment_bounce, s.light_total);
        if (path_done)
            finish_sample(s);
        if (overflow)
            break;
    }
}
