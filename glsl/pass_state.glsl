// pass_state.glsl: the pass state as a tracer pass (glsl/main.glsl) sees it: the state
// textures of the previous pass (TRACER_STATE_* of core/tracer_interface.h, one unit
// each), the outputs of this one (the same numbers as locations), and the tables a pass
// looks its pixel up in.

layout(binding = TRACER_STATE_ORIGIN) uniform sampler2D state_origin;
layout(binding = TRACER_STATE_DIRECTION) uniform sampler2D state_direction;
layout(binding = TRACER_STATE_THROUGHPUT) uniform sampler2D state_throughput;
layout(binding = TRACER_STATE_RADIANCE) uniform sampler2D state_radiance;
layout(binding = TRACER_STATE_COUNTERS) uniform usampler2D state_counters;
layout(binding = TRACER_STATE_ACCUMULATED) uniform sampler2D state_accumulated;
layout(binding = TRACER_STATE_STATISTICS) uniform sampler2D state_statistics;
layout(binding = TRACER_STATE_SQUARES) uniform sampler2D state_squares;
// The pixel's sample limit (core/adaptive.h; all at most samples_per_pixel without it).
layout(binding = TRACER_SAMPLE_LIMITS_UNIT) uniform usampler2D sample_limits;
// Compacted passes: the pixel of each compact slot (core/tracer_interface.h).
layout(binding = TRACER_PIXEL_MAP_UNIT) uniform usampler2D pixel_map;

layout(location = TRACER_STATE_ORIGIN) out vec4 out_origin;            // xyz: origin, w: since_vertex
layout(location = TRACER_STATE_DIRECTION) out vec4 out_direction;      // xyz: direction, w: choice_memo.x
layout(location = TRACER_STATE_THROUGHPUT) out vec4 out_throughput;    // rgb: throughput, a: previous_pdf
layout(location = TRACER_STATE_RADIANCE) out vec4 out_radiance;        // rgb: radiance, w: choice_memo.y
layout(location = TRACER_STATE_COUNTERS) out uvec4 out_counters;       // samples_started, bounce, media
layout(location = TRACER_STATE_ACCUMULATED) out vec4 out_accumulated;
layout(location = TRACER_STATE_STATISTICS) out vec4 out_statistics;
layout(location = TRACER_STATE_SQUARES) out vec4 out_squares;          // rgb: sums of squared radiance

// The framebuffer pixel (row 0 at the bottom) of a pixel map entry's code, or (-1, -1) for
// TRACER_NO_PIXEL.
ivec2 mapped_pixel(uint code)
{
    if (code == TRACER_NO_PIXEL)
        return ivec2(-1);
    return ivec2(code & ((1u << TRACER_PIXEL_MAP_SHIFT) - 1u), code >> TRACER_PIXEL_MAP_SHIFT);
}
