// material_table.glsl: the table of materials: each function calls the material
// interface (glsl/material.glsl) of the record's type. A new material adds one line to
// each (glsl/material.glsl lists the other steps). llvmpipe runs every line for every
// pixel (docs/performance.md), so a material costs its code here whether a scene has it
// or not; the HAS_ constants of the kinds (glsl/variant.glsl) leave out each kind no
// material of the scene has.

BsdfSample material_sample(Material m, ShadingFrame frame, vec3 direction, vec4 u)
{
    if (HAS_LAMBERTIAN && m.type == uint(MATERIAL_LAMBERTIAN)) return lambertian_sample(m, frame, direction, u);
    if (HAS_METAL && m.type == uint(MATERIAL_METAL)) return metal_sample(m, frame, direction, u);
    if (HAS_DIELECTRIC && m.type == uint(MATERIAL_DIELECTRIC)) return dielectric_sample(m, frame, direction, u);
    if (HAS_EMITTERS && m.type == uint(MATERIAL_EMISSIVE)) return emissive_sample(m, frame, direction, u);
    if (HAS_PBR && m.type == uint(MATERIAL_PBR)) return pbr_sample(m, frame, direction, u);
    return absorbed_sample(direction);
}

vec3 material_evaluate(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
{
    if (HAS_LAMBERTIAN && m.type == uint(MATERIAL_LAMBERTIAN)) return lambertian_evaluate(m, frame, view, to_light);
    if (HAS_METAL && m.type == uint(MATERIAL_METAL)) return metal_evaluate(m, frame, view, to_light);
    if (HAS_DIELECTRIC && m.type == uint(MATERIAL_DIELECTRIC)) return dielectric_evaluate(m, frame, view, to_light);
    if (HAS_EMITTERS && m.type == uint(MATERIAL_EMISSIVE)) return emissive_evaluate(m, frame, view, to_light);
    if (HAS_PBR && m.type == uint(MATERIAL_PBR)) return pbr_evaluate(m, frame, view, to_light);
    return vec3(0.0);
}

float material_pdf(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
{
    if (HAS_LAMBERTIAN && m.type == uint(MATERIAL_LAMBERTIAN)) return lambertian_pdf(m, frame, view, to_light);
    if (HAS_METAL && m.type == uint(MATERIAL_METAL)) return metal_pdf(m, frame, view, to_light);
    if (HAS_DIELECTRIC && m.type == uint(MATERIAL_DIELECTRIC)) return dielectric_pdf(m, frame, view, to_light);
    if (HAS_EMITTERS && m.type == uint(MATERIAL_EMISSIVE)) return emissive_pdf(m, frame, view, to_light);
    if (HAS_PBR && m.type == uint(MATERIAL_PBR)) return pbr_pdf(m, frame, view, to_light);
    return 0.0;
}

vec3 material_guide_albedo(Material m)
{
    if (HAS_LAMBERTIAN && m.type == uint(MATERIAL_LAMBERTIAN)) return lambertian_guide_albedo(m);
    if (HAS_METAL && m.type == uint(MATERIAL_METAL)) return metal_guide_albedo(m);
    if (HAS_DIELECTRIC && m.type == uint(MATERIAL_DIELECTRIC)) return dielectric_guide_albedo(m);
    if (HAS_EMITTERS && m.type == uint(MATERIAL_EMISSIVE)) return emissive_guide_albedo(m);
    if (HAS_PBR && m.type == uint(MATERIAL_PBR)) return pbr_guide_albedo(m);
    return m.albedo;
}

// Emitters: whether the material emits (glsl/integrators.glsl adds its light; an emissive
// material then absorbs, a pbr one scatters on), and its radiance at p. pbr emits what
// emissive does: colour x strength times the emission texture (texel 1, texel 2's z).
bool material_emits(Material m)
{
    bool pbr_emission = HAS_PBR && m.type == uint(MATERIAL_PBR) && any(greaterThan(uintBitsToFloat(m.texel1.xyz),
                                                                                    vec3(0.0)));
    return HAS_EMITTERS && (m.type == uint(MATERIAL_EMISSIVE) || pbr_emission);
}

vec3 material_emitted(Material m, vec3 p, vec2 uv)
{
    if (HAS_EMITTERS && (m.type == uint(MATERIAL_EMISSIVE) || (HAS_PBR && m.type == uint(MATERIAL_PBR))))
        return emissive_emitted(m, p, uv);
    return vec3(0.0);
}
