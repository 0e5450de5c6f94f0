// material.glsl: what a material is to the tracer, and the interface every material
// implements.
//
// The interface. A material NAME (type tag MATERIAL_NAME of core/packed_layout.h) lives in
// glsl/material_NAME.glsl and defines:
//   BsdfSample NAME_sample(Material m, ShadingFrame frame, vec3 direction, vec4 u)
//       where a path arriving along direction goes on, from four uniform numbers u
//   vec3 NAME_evaluate(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
//       f * cos for light from to_light seen towards view: what next-event estimation
//       adds per unit of incident radiance (0 for a specular material, which sampling
//       alone handles)
//   float NAME_pdf(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
//       the solid-angle density with which NAME_sample picks to_light (for MIS)
//   vec3 NAME_guide_albedo(Material m)
//       the colour the denoiser's albedo guide shows (glsl/aov.glsl)
// and, for a material that emits, vec3 NAME_emitted(Material m, vec3 p, vec2 uv). A
// material that emits and scatters (pbr with an emission) samples on like any other; one
// that only emits absorbs in NAME_sample.
// glsl/material_table.glsl calls them by type. Light sampling happens only where
// NAME_sample says (BsdfSample.light_sampled), and only for light above the surface
// (glsl/direct_light.glsl), so a material that sets it reflects and does not transmit.
// The Whitted integrator shades with its own model, glsl/material_phong.glsl.
//
// Adding a material, the GLSL side:
//   1. its tag MATERIAL_NAME in core/packed_layout.h (MATERIAL_TYPE_COUNT one more);
//   2. glsl/material_NAME.glsl with the functions above;
//   3. one line in the module table of core/shader_sources.S, among the materials;
//   4. one line in each function of glsl/material_table.glsl (and in material_emits /
//      material_emitted if it emits);
//   5. glsl/material_phong.glsl: whether Whitted shades it with Phong (phong_shades).
// The parser (core/scene_statements_appearance.c) and the packer (core/pack_materials.c) then
// make and pack it; tests/unit/test_material_pbr.c shows how to test its sampling on the
// device (gpu.h gpu_material_test).

// A material record (packed_layout.h "materials") as shading reads it.
struct Material {
    uint index;       // in the material section
    uint type;        // MATERIAL_*
    uint flags;       // MATERIAL_FLAG_*
    vec3 albedo;      // texel 0's colour, times the albedo texture at the hit (pbr: and the
                      // vertex colour)
    uvec4 texel1;     // (emission.rgb, fuzz)
    uvec4 texel2;     // (index of refraction, albedo texture, emission texture, normal map)
    vec4 pbr;         // pbr: (metallic, roughness, transmission, 0) at the hit; else 0
};

// A surface point as a material sees it: normals on the side the ray arrived from.
struct ShadingFrame {
    vec3 normal;      // geometric, unit
    vec3 shading;     // shading (interpolated or mapped), unit
    bool front_face;  // the ray arrived on the side the primitive faces (dielectric: entering)
};

// What a material's sample function returns.
struct BsdfSample {
    vec3 direction;      // where the path goes on (unit)
    vec3 weight;         // the throughput's factor: f * cos / pdf
    float pdf;           // density of direction, for MIS (0: a specular choice, never weighted)
    bool absorbed;       // the path ends here
    bool light_sampled;  // gather direct light here (next-event estimation)
};

// A material's record (by index), its albedo untextured.
Material material_record(uint index)
{
    Material m;
    m.index = index;
    uint base = material_offset + index * uint(PACKED_MATERIAL_STRIDE);
    uvec4 texel0 = packed_texel(base);
    m.texel1 = packed_texel(base + 1u);
    m.texel2 = packed_texel(base + 2u);
    m.type = texel0.x & uint(MATERIAL_TYPE_MASK);
    m.flags = texel0.x & ~uint(MATERIAL_TYPE_MASK);
    m.albedo = uintBitsToFloat(texel0.yzw);
    m.pbr = vec4(0.0);
    return m;
}

// A material that is none (what a query that shades nothing carries).
Material no_material()
{
    Material m;
    m.index = 0u;
    m.type = uint(MATERIAL_LAMBERTIAN);
    m.flags = 0u;
    m.albedo = vec3(0.0);
    m.texel1 = uvec4(0u);
    m.texel2 = uvec4(0u);
    m.pbr = vec4(0.0);
    return m;
}

// The material (by index) at a surface point p with texture coordinates uv: the albedo
// texture, and pbr's parameters with its metallic-roughness image (G: roughness, B:
// metallic, as glTF packs them).
Material material_at(uint index, vec3 p, vec2 uv)
{
    Material m = material_record(index);
    if (HAS_TEXTURES && m.texel2.y != NONE)
        m.albedo *= texture_value(m.texel2.y, p, uv);
    if (HAS_PBR && m.type == uint(MATERIAL_PBR)) {
        uvec4 texel4 = packed_texel(material_offset + index * uint(PACKED_MATERIAL_STRIDE) + 4u);
        m.pbr = vec4(uintBitsToFloat(texel4.xyz), 0.0);
        if (HAS_TEXTURES && texel4.w != NONE) {
            vec3 packed_values = image_lookup(texel4.w, uv);
            m.pbr.x *= packed_values.b;
            m.pbr.y *= packed_values.g;
        }
    }
    return m;
}

// The material of a surface as the ray along direction meets it (frame: shading_frame's):
// material_at, the vertex colour for a pbr material that asks for it, and no emission
// from the back of a one-sided emitter (MATERIAL_FLAG_ONE_SIDED: the front is the side the
// geometric normal points to).
Material surface_material(Surface surface, ShadingFrame frame)
{
    Material m = material_at(surface.material, surface.position, surface.uv);
    if (HAS_VERTEX_COLORS && (m.flags & uint(MATERIAL_FLAG_VERTEX_COLORS)) != 0u)
        m.albedo *= surface.color;
    if (HAS_EMITTERS && !frame.front_face && (m.flags & uint(MATERIAL_FLAG_ONE_SIDED)) != 0u) {
        m.texel1.xyz = floatBitsToUint(vec3(0.0));
        m.texel2.z = NONE;
    }
    return m;
}

// The shading frame of a surface hit by a ray along direction.
ShadingFrame shading_frame(Surface surface, vec3 direction)
{
    ShadingFrame frame;
    frame.front_face = dot(direction, surface.geometric) < 0.0;
    frame.normal = frame.front_face ? surface.geometric : -surface.geometric;
    frame.shading = frame.front_face ? surface.shading : -surface.shading;
    return frame;
}

// A sample that ends the path.
BsdfSample absorbed_sample(vec3 direction)
{
    BsdfSample s;
    s.direction = direction;
    s.weight = vec3(0.0);
    s.pdf = 0.0;
    s.absorbed = true;
    s.light_sampled = false;
    return s;
}
