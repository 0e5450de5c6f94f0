// material_test.frag: the material test's main (core/gpu.h gpu_material_test): for each
// query (one per pixel, row by row), the material's sample for four uniform numbers, and
// its evaluate and pdf at a given direction and at the sampled one, as the tracer calls
// them (glsl/material_table.glsl), on the device that renders. For tests of a material's
// sampling against its density (tests/unit/test_material_pbr.c).
//
// A query's texels: (incoming direction.xyz, material index), (geometric normal.xyz facing
// the ray, front face 1 or 0), (shading normal.xyz, 0), (u), (to_light.xyz, 0).
layout(binding = MATERIAL_TEST_QUERY_UNIT) uniform samplerBuffer material_queries;
uniform int query_first;     // the first query of this draw
uniform int query_count;     // queries in this draw
uniform int query_width;     // queries per row

layout(location = 0) out vec4 out_sample;         // sampled direction.xyz, BsdfSample.pdf
layout(location = 1) out vec4 out_weight;         // weight.rgb, absorbed + 2 light_sampled
layout(location = 2) out vec4 out_at_light;       // evaluate.rgb, pdf at to_light
layout(location = 3) out vec4 out_at_sample;      // evaluate.rgb, pdf at the sampled direction

void main()
{
    read_parameters();
    read_header();
    work = 0;
    int query = int(gl_FragCoord.y) * query_width + int(gl_FragCoord.x);
    if (query >= query_count) {
        out_sample = out_weight = out_at_light = out_at_sample = vec4(0.0);
        return;
    }
    int base = (query_first + query) * MATERIAL_TEST_QUERY_TEXELS;
    vec4 t0 = texelFetch(material_queries, base), t1 = texelFetch(material_queries, base + 1);
    vec4 t2 = texelFetch(material_queries, base + 2), u = texelFetch(material_queries, base + 3);
    vec3 to_light = texelFetch(material_queries, base + 4).xyz;
    ShadingFrame frame;
    frame.normal = t1.xyz;
    frame.shading = t2.xyz;
    frame.front_face = t1.w > 0.5;
    Material m = material_at(uint(t0.w), vec3(0.0), vec2(0.5));
    vec3 direction = t0.xyz, view = -t0.xyz;
    BsdfSample s = material_sample(m, frame, direction, u);
    out_sample = vec4(s.direction, s.pdf);
    out_weight = vec4(s.weight, (s.absorbed ? 1.0 : 0.0) + (s.light_sampled ? 2.0 : 0.0));
    out_at_light = vec4(material_evaluate(m, frame, view, to_light), material_pdf(m, frame, view, to_light));
    out_at_sample = vec4(material_evaluate(m, frame, view, s.direction), material_pdf(m, frame, view, s.direction));
}
