// aov.glsl: the AOV pass, the main of its own program: first-hit albedo, normal and
// depth, averaged over aov_samples jittered camera rays (the render's first samples' camera
// rays), to guide the denoiser (core/postprocess.h).

layout(location = TRACER_AOV_ALBEDO_DEPTH) out vec4 out_albedo_depth;  // rgb: albedo, a: distance to
                                                                        // the first hit (0: none)
layout(location = TRACER_AOV_NORMAL) out vec4 out_normal;  // xyz: world shading normal, w: share of rays that hit

void main()
{
    read_parameters();
    read_header();
    light_count = 0u;
    frame_pixel = ivec2(gl_FragCoord.xy);
    begin_pixel();
    vec3 albedo_sum = vec3(0.0), normal_sum = vec3(0.0);
    float depth_sum = 0.0, hits = 0.0, taken = 0.0;
    work = 0;
    overflow = false;
    // One invocation does all the AOV samples, so they share the work bound: a pixel
    // stops taking samples while a whole one still fits (half the cap), and averages
    // those it took.
    for (int k = 0; k < aov_samples && work < work_cap / 2; k++) {
        work += SEGMENT_WORK;
        taken += 1.0;
        rng_sample = sample_start + uint(k);
        vec3 origin, direction;
        camera_ray(origin, direction);
        float time = ray_time();
        Hit hit;
        if (!trace(origin, direction, time, INFINITY, hit)) {
            albedo_sum += clamp(sky_radiance(direction), 0.0, 1.0);
            continue;
        }
        Surface surface = surface_at(hit, origin, direction, time);
        albedo_sum += material_guide_albedo(surface_material(surface, shading_frame(surface, direction)));
        normal_sum += dot(direction, surface.shading) < 0.0 ? surface.shading : -surface.shading;
        depth_sum += hit.t;
        hits += 1.0;
    }
    float n = max(taken, 1.0);
    out_albedo_depth = vec4(albedo_sum / n, hits > 0.0 ? depth_sum / hits : 0.0);
    vec3 normal = hits > 0.0 ? normal_sum / hits : vec3(0.0);
    out_normal = vec4(dot(normal, normal) > 0.0 ? normalize(normal) : vec3(0.0), hits / n);
}
