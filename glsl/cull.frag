// cull.frag: marks in the depth buffer the pixels that full passes no longer change, so
// that the next full passes skip them before shading (glsl/main.glsl runs with early
// fragment tests; core/gpu_tracer.c gpu_tracer_cull_finished). A pixel is marked when both
// sets of pass state (the latest pass's and the one before's) say it has started all its
// samples and has no path in flight: a pass leaves such a pixel's state as it is, so both
// sets already hold what a pass would write. Others are left as they are (discard).

layout(binding = 0) uniform usampler2D counters_latest;
layout(binding = 1) uniform usampler2D counters_before;
layout(binding = TRACER_SAMPLE_LIMITS_UNIT) uniform usampler2D cull_sample_limits;

void main()
{
    read_parameters();
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    uint limit = min(samples_per_pixel, texelFetch(cull_sample_limits, pixel, 0).x);
    uvec4 latest = texelFetch(counters_latest, pixel, 0), before = texelFetch(counters_before, pixel, 0);
    if (latest.x < limit || latest.y != 0u || before.x < limit || before.y != 0u)
        discard;
    gl_FragDepth = 0.0;   // the tracer's triangle is at 0.5 and passes where the depth is greater
}
