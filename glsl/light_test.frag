// light_test.frag: the light choice test's main (core/gpu.h gpu_light_choice_test): for
// each query (one per pixel, row by row), the light choose_light_at picks for a point and
// a surface normal from one uniform number, the chance it reports and the memo it leaves,
// and the chance light_choice_probability finds again from that memo, for the light
// picked and for the query's own light (glsl/lights.glsl), on the device that renders.
// For tests of the light choice against its probabilities (tests/unit/test_light_choice.c).
//
// A query's texels: (point.xyz, u), (normal.xyz (0: a point in a medium), light index).
layout(binding = LIGHT_TEST_QUERY_UNIT) uniform samplerBuffer light_queries;
uniform int query_first;     // the first query of this draw
uniform int query_count;     // queries in this draw
uniform int query_width;     // queries per row

layout(location = 0) out vec4 out_choice;   // light picked, its chance, the memo (x, y)
layout(location = 1) out vec4 out_again;    // light_choice_probability of the light picked, of the query's light

void main()
{
    read_parameters();
    read_header();
    work = 0;
    int query = int(gl_FragCoord.y) * query_width + int(gl_FragCoord.x);
    if (query >= query_count) {
        out_choice = out_again = vec4(0.0);
        return;
    }
    int base = (query_first + query) * LIGHT_TEST_QUERY_TEXELS;
    vec4 t0 = texelFetch(light_queries, base), t1 = texelFetch(light_queries, base + 1);
    float chance;
    vec2 memo;
    uint picked = choose_light_at(t0.w, t0.xyz, t1.xyz, chance, memo);
    out_choice = vec4(float(picked), chance, memo);
    out_again = vec4(light_choice_probability(picked, t0.xyz, memo), light_choice_probability(uint(t1.w), t0.xyz, memo),
                     0.0, 0.0);
}
