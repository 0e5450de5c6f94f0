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
//      core/gpu_program.c gpu_variant_key keeps two bits for it);
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
//
// Each iteration makes ONE traversal (glsl/traverse.glsl trace_rays) for two rays: the
// path's next segment and the shadow ray that the previous segment's direct light left
// pending (both start at the same vertex); the shadow ray's light is added when it
// returns. So a path's shadow rays ride along with its segments, and the last one of a
// sample with the next sample's camera ray. When the shadow ray is not done after one
// trace (it stopped at a volume boundary, glsl/media.glsl), the path's hit is held and
// shaded in a later iteration; a sample whose path ended is finished when its shadow ray
// returns. None of that is kept between passes: a pass ends only when nothing is
// pending, and once the budget is spent no new segment is traced. Whitted, which samples
// every light at a point, gathers its direct light in place instead
// (glsl/direct_light.glsl gathers_in_place).
void integrate(inout PixelState s)
{
    if (!HAS_DIRECT_LIGHT || !integrator_samples_lights())
        light_count = 0u;       // nothing to sample
    PendingShadow shadow = no_pending_shadow();
    LightQuery query = no_light_query();
    Hit held_hit = no_hit(INFINITY);
    bool holding = false;                  // held_hit is a segment still to be shaded
    bool finishing = false;                // a sample whose path ended waits for its shadow ray
    vec3 finishing_radiance = vec3(0.0);
    for (;;) {
        bool busy = shadow.pending || holding;
        bool trace_path;
        if (!begin_segment(s, busy, !holding, trace_path))
            break;
        trace_path = trace_path && !holding;
        float time = ray_time();
        bool blocked;
        Hit shadow_hit, path_hit;
        trace_rays(HAS_DIRECT_LIGHT && !gathers_in_place() && shadow.pending, shadow.ray, trace_path, s.origin,
                   s.direction, time, INFINITY, blocked, shadow_hit, path_hit);
        if (trace_path)
            s.statistics.x += 1.0;
        if (holding)
            path_hit = held_hit;

        // The shadow ray: its light arrives, or it goes on through a volume boundary.
        bool crossing = false;
        if (HAS_DIRECT_LIGHT && shadow.pending) {
            crossing = shadow_at_boundary(shadow.ray, blocked, shadow_hit);
            if (!crossing) {
                vec3 light = shadow_arrived(shadow.transit, shadow.ray, blocked, shadow_hit) * shadow.contribution;
                set_shadow_light(shadow.light_group, light);
                shadow.pending = false;
                if (finishing) {
                    finish_sample(s, finishing_radiance + light);
                    finishing = false;
                } else {
                    s.radiance += light;
                }
            }
        }

        // The path's segment, once nothing of its last vertex is pending.
        bool shade = (trace_path || holding) && !shadow.pending;
        holding = (trace_path || holding) && !shade;
        held_hit = path_hit;
        bool path_done = false;
        bool at_surface = false;
        vec4 u = random4(s.bounce, 1u);
        uint segment_bounce = s.bounce;     // the steps below may move bounce and direction on
        vec3 incoming = s.direction;
        if (shade) {
            // Direct light is gathered after the steps below decide where.
            query = no_light_query();
            if (scatter_in_medium(s, path_hit.t, u, query, path_done)) {
                // scattered before the surface: done there
            } else if (path_hit.t == INFINITY) {
                vec3 sky = s.throughput * sky_radiance(s.direction) * integrator_sky_weight(s);
                s.radiance += sky;
                set_segment_light(sky_light_group, sky);
                add_direct_emission(segment_bounce, sky);
                path_done = true;
            } else {
                at_surface = true;
            }
        }
        if (crossing || at_surface) {
            // One surface_at for both: the shadow ray's volume boundary, or the path's hit.
            Hit hit = crossing ? shadow_hit : path_hit;
            vec3 from = crossing ? shadow.ray.origin : s.origin, along = crossing ? shadow.ray.direction : s.direction;
            Surface surface = surface_at(hit, from, along, crossing ? shadow.ray.time : time);
            if (crossing) {
                shadow.pending = shadow_cross(shadow.ray, shadow.transit, hit, surface);
            } else {
                ShadingFrame frame = shading_frame(surface, s.direction);
                vec3 next_direction = s.direction;
                if (surface.volume_boundary) {
                    cross_volume_boundary(s, surface, frame.front_face, hit.t);
                } else {
                    Material material = surface_material(surface, frame);
                    // An emitter's light joins the path's; an emissive material then absorbs
                    // (its sample ends the path), a pbr one scatters on. Its MIS weight
                    // wants since_vertex up to here: this hit is the next vertex.
                    if (material_emits(material))
                        add_direct_emission(segment_bounce, hit_emitter(s, hit, surface, material));
                    s.since_vertex = 0.0;
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
        }
        if (HAS_DIRECT_LIGHT && shade && query.wanted) {
            begin_direct_light(query, -incoming, s.media, time, segment_bounce, s.radiance);
            if (gathers_in_place())
                direct_light_in_place(query, s.choice_memo, s.radiance);
            else if (direct_light_pending(query))   // one light sample: the shadow ray for the next iteration
                shadow = next_shadow_ray(query, s.choice_memo);
        }
        if (path_done) {
            s.bounce = 0u;
            if (HAS_DIRECT_LIGHT && shadow.pending) {
                finishing = true;
                finishing_radiance = s.radiance;
            } else {
                finish_sample(s, s.radiance);
            }
        }
        // The ended path's shadow ray passed one volume boundary too many: nothing comes.
        if (finishing && !shadow.pending) {
            finish_sample(s, finishing_radiance);
            finishing = false;
        }
        flush_light_groups();
        flush_direct_emission();
        if (overflow)
            break;
    }
    flush_light_groups_at_end();
}
