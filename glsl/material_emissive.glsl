// material_emissive.glsl: a light source surface (MATERIAL_EMISSIVE): it emits and
// scatters nothing; the material interface of glsl/material.glsl. Emissive world
// primitives are also area lights that light sampling picks (glsl/lights.glsl).

BsdfSample emissive_sample(Material m, ShadingFrame frame, vec3 direction, vec4 u)
{
    return absorbed_sample(direction);
}

vec3 emissive_evaluate(Material m, ShadingFrame frame, vec3 view, vec3 to_light) { return vec3(0.0); }
float emissive_pdf(Material m, ShadingFrame frame, vec3 view, vec3 to_light) { return 0.0; }

// Radiance leaving p: colour x strength, times the emission texture.
vec3 emissive_emitted(Material m, vec3 p, vec2 uv)
{
    vec3 emission = uintBitsToFloat(m.texel1.xyz);
    if (HAS_TEXTURES && m.texel2.z != NONE)
        emission *= texture_value(m.texel2.z, p, uv);
    return emission;
}

// The emission, untextured and clamped to a colour.
vec3 emissive_guide_albedo(Material m) { return clamp(uintBitsToFloat(m.texel1.xyz), 0.0, 1.0); }
