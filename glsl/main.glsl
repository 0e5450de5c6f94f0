// main.glsl: one pass of the tracer: one invocation per pixel reads the pixel's state
// from the previous pass, lets the integrator continue it, and writes it for the next
// (core/gpu_tracer.c ping-pongs two sets of state textures, glsl/pass_state.glsl).

// Pixels with samples left, and samples finished in this pass (read by core/gpu_tracer.c).
layout(binding = TRACER_COUNTER_BINDING, offset = 0) uniform atomic_uint unfinished_pixels;
layout(binding = TRACER_COUNTER_BINDING, offset = 4) uniform atomic_uint samples_finished;

// The state at pixel (a pixel, or a compact slot), or in a compacted pass the state of a
// run that has not begun when the slot was last written in another round (the texel's
// counters.w against the pixel map's round, core/tracer_interface.h): no path in flight
// and sums of zero, which is how compacted runs start without a clear of their textures.
PixelState read_state(ivec2 pixel, uint round)
{
    PixelState s;
    vec4 origin = texelFetch(state_origin, pixel, 0);
    vec4 throughput = texelFetch(state_throughput, pixel, 0);
    uvec4 counters = texelFetch(state_counters, pixel, 0);
    s.origin = origin.xyz;
    s.since_vertex = origin.w;
    vec4 direction = texelFetch(state_direction, pixel, 0);
    s.direction = direction.xyz;
    vec4 radiance = texelFetch(state_radiance, pixel, 0);
    s.choice_memo = vec2(direction.w, radiance.w);
    s.throughput = throughput.rgb;
    s.previous_pdf = throughput.w;
    s.radiance = radiance.rgb;
    s.samples_started = counters.x;
    s.bounce = counters.y;
    s.media = counters.z;
    s.accumulated = texelFetch(state_accumulated, pixel, 0);
    s.statistics = texelFetch(state_statistics, pixel, 0);
    s.squares = HAS_SQUARES ? texelFetch(state_squares, pixel, 0) : vec4(0.0);
    s.finished_here = 0u;
    if (round != 0u && counters.w != round) {
        s.choice_memo = vec2(0.0);
        s.previous_pdf = 0.0;
        s.samples_started = 0u;
        s.bounce = 0u;
        s.accumulated = vec4(0.0);
        s.statistics = vec4(0.0);
        s.squares = vec4(0.0);
    }
    return s;
}

void write_state(PixelState s, uint round)
{
    out_origin = vec4(s.origin, s.since_vertex);
    out_direction = vec4(s.direction, s.choice_memo.x);
    out_throughput = vec4(s.throughput, s.previous_pdf);
    out_radiance = vec4(s.radiance, s.choice_memo.y);
    out_counters = uvec4(s.samples_started, s.bounce, s.media, round);
    out_accumulated = s.accumulated;
    out_statistics = s.statistics;
    if (HAS_SQUARES)   // else the state has no such texture (core/gpu.h GPU_OMIT_SQUARES)
        out_squares = s.squares;
}

// Early fragment tests: a pixel that gpu_tracer_cull_finished marked (core/gpu.h) fails
// the depth test of full passes before any of this runs, image stores and counters included.
layout(early_fragment_tests) in;

void main()
{
    read_parameters();
    // The state lives where this invocation draws: the pixel itself, or its compact slot.
    // A compact slot traces a run of its pixel's samples (core/tracer_interface.h), and its
    // samples_started counts from the run's first.
    ivec2 slot = ivec2(gl_FragCoord.xy);
    frame_pixel = slot;
    first_sample = sample_start;
    uint round = 0u;
    if (compact_pixels != 0u) {
        uvec4 run = texelFetch(pixel_map, slot, 0);
        round = run.w;
        frame_pixel = mapped_pixel(run.x);
        if (frame_pixel.x < 0)
            discard;
        first_sample = sample_start + run.y;
        sample_limit = run.z - run.y;
    } else {
        sample_limit = min(samples_per_pixel, texelFetch(sample_limits, frame_pixel, 0).x);
    }
    PixelState s = read_state(slot, round);
    read_header();
    begin_pixel();
    rng_sample = first_sample + s.samples_started - 1u;   // the sample of the path in flight
    work = 0;
    overflow = false;
    // Sums beside the pass state, held in registers through the pass.
    load_light_groups();
    load_direct_emission();
    integrate(s);
    store_light_groups();
    store_direct_emission();
    if (overflow) {
        s.statistics.y += 1.0;
        s.bounce = 0u;     // drop the broken path; the host reports the overflow as an error
    }
    if (s.samples_started < sample_limit || s.bounce != 0u)
        atomicCounterIncrement(unfinished_pixels);
    for (uint i = 0u; i < s.finished_here; i++)
        atomicCounterIncrement(samples_finished);
    write_state(s, round);
}
