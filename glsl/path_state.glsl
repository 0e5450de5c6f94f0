// path_state.glsl: a pixel's state between passes (glsl/main.glsl reads and writes it),
// and the steps of a path that the loop of glsl/integrators.glsl takes for every
// integrator: starting a sample, counting a segment, scattering in a medium, crossing a
// volume boundary, hitting an emitter, leaving a surface, finishing a sample.

struct PixelState {
    vec3 origin;            // ray origin of the path in flight
    float since_vertex;     // how far the ray went straight on (through volume boundaries)
                            // since its last scattering vertex
    vec3 direction;         // ray direction (unit)
    vec3 throughput;        // path throughput so far
    float previous_pdf;     // the BSDF density of the direction the path left its last
                            // vertex by, when that vertex also sampled a light (then an
                            // emitter hit is weighted by MIS); 0 otherwise
    vec2 choice_memo;       // what the light choice at the vertex that last sampled a
                            // light left (glsl/lights.glsl, choose_light_at): with
                            // previous_pdf, what MIS needs at the next emitter hit
    vec3 radiance;          // gathered by the path in flight
    uint samples_started;
    uint bounce;            // segments of the path in flight; 0: no path in flight
    uint media;             // the media the path is in (glsl/media.glsl)
    vec4 accumulated;       // rgb: sum over finished samples, a: finished samples
    vec4 statistics;        // x: path segments traced, y: traversal overflows,
                            // z: sum of squared luminance of finished samples
    vec4 squares;           // rgb: sum of squared radiance of finished samples, per channel
    uint finished_here;     // samples finished in this pass
};

// The samples this pixel may start in this pass at most (glsl/main.glsl sets it:
// samples_per_pixel, or less where adaptive sampling holds the pixel back), and the
// absolute index of the sample samples_started counts from (sample_start, or a compact
// slot's run's first).
uint sample_limit;
uint first_sample;

// Prepares the next iteration of the segment loop: starts a sample (its camera ray) when
// no path is in flight and may_start, and counts the iteration's work. trace_path is set
// when the path's next segment is to be traced now. False when the pixel stops for this
// pass: no samples left or its work budget spent, and nothing busy (a shadow ray still
// to trace, a hit to shade) that must end in this pass, since the pass state keeps
// neither.
bool begin_segment(inout PixelState s, bool busy, bool may_start, out bool trace_path)
{
    bool budget_left = work < pass_work_budget;
    trace_path = false;
    if (!busy && !budget_left)
        return false;
    if (s.bounce == 0u && may_start && budget_left && s.samples_started < sample_limit) {
        rng_sample = first_sample + s.samples_started;
        s.samples_started++;
        camera_ray(s.origin, s.direction);
        s.throughput = vec3(1.0);
        s.radiance = vec3(0.0);
        s.media = camera_media;
        s.previous_pdf = 0.0;
        s.since_vertex = 0.0;
        s.bounce = 1u;
    }
    if (s.bounce == 0u && !busy)
        return false;
    trace_path = s.bounce != 0u && budget_left;
    work += SEGMENT_WORK;
    return true;
}

// Ends a sample: its radiance joins the pixel's sums.
void finish_sample(inout PixelState s, vec3 radiance)
{
    s.accumulated += vec4(radiance, 1.0);
    float luminance = dot(radiance, vec3(LUMINANCE_R, LUMINANCE_G, LUMINANCE_B));
    s.statistics.z += luminance * luminance;
    s.squares.rgb += radiance * radiance;
    s.finished_here++;
}

// Sends the path on from surface point p (normal facing the incoming ray) along
// next_direction, from just off the surface on the side it goes to. False when that
// would be more than max_depth segments: the path ends.
bool leave_surface(inout PixelState s, vec3 p, vec3 normal, vec3 next_direction)
{
    float side = dot(next_direction, normal) > 0.0 ? 1.0 : -1.0;
    s.origin = p + side * ray_offset(p) * normal;
    s.direction = next_direction;
    s.bounce++;
    return s.bounce <= max_depth;
}

// In a medium the ray may scatter before the surface at hit_distance (glsl/media.glsl):
// then the path moves to that point and goes on in a direction drawn from the phase
// function (u), and query asks for the light there. Returns whether it scattered;
// path_done is set when that was the last segment allowed.
bool scatter_in_medium(inout PixelState s, float hit_distance, vec4 u, inout LightQuery query, inout bool path_done)
{
    float distance;
    vec3 albedo;
    if (!medium_scatters(s.media, hit_distance, s.bounce, distance, albedo))
        return false;
    s.origin += distance * s.direction;
    s.throughput *= albedo;
    s.since_vertex = 0.0;
    query = no_light_query();
    query.wanted = light_count > 0u;
    query.in_medium = true;
    query.position = s.origin;
    query.material.albedo = vec3(1.0);
    query.weight = s.throughput;
    s.direction = sample_phase(u.xy);
    s.previous_pdf = light_count > 0u ? PHASE_PDF : 0.0;
    s.bounce++;
    if (s.bounce > max_depth)
        path_done = true;
    return true;
}

// At a volume boundary the ray goes on unchanged, entering or leaving the medium.
void cross_volume_boundary(inout PixelState s, Surface surface, bool front_face, float hit_distance)
{
    s.media = front_face ? media_enter(s.media, surface.instance) : media_leave(s.media, surface.instance);
    s.since_vertex += hit_distance;
}

// The path hit an emitter (surface): its radiance joins the path's, weighted by MIS when
// light sampling could have found it too. The material's sample then ends the path or,
// for a pbr emitter, sends it on. Returns the radiance added.
vec3 hit_emitter(inout PixelState s, Hit hit, Surface surface, Material material)
{
    // MIS wants the path's last scattering vertex, where light sampling chose: the ray
    // went straight on from it through any volume boundaries since.
    vec3 vertex = s.origin - s.since_vertex * s.direction;
    float weight = emitter_mis_weight(hit, s.previous_pdf, s.choice_memo, vertex, surface.position, surface.geometric);
    vec3 emitted = s.throughput * material_emitted(material, surface.position, surface.uv) * weight;
    s.radiance += emitted;
    set_segment_light(emitter_light_group(material), emitted);
    return emitted;
}
