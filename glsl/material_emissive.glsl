// material_emissive.glsl: a light source surface (MATERIAL_EMISSIVE): it emits and
// scatters nothing; the material interface of glsl/material.glsl. Emissive world
// primitives are also area lights that light sampling picks (glsl/lights.glsl), as are
// those of pbr materials with an emission, which emit as this one does.

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

// The share of an emitter's radiance sent along direction from a point of it with
// geometric normal n: all of it, but none from the back (dot(direction, n) >= 0 seen from
// the receiver: direction points from it to the emitter) of a one-sided emitter
// (MATERIAL_FLAG_ONE_SIDED). By default emitters emit on both sides, as Cycles' mesh
// lights do.
float emitted_side(Material m, vec3 direction, vec3 n)
{
    return (m.flags & uint(MATERIAL_FLAG_ONE_SIDED)) != 0u && dot(direction, n) >= 0.0 ? 0.0 : 1.0;
}

// The emission, untextured and clamped to a colour.
vec3 emissive_guide_albedo(Material m) { return clamp(uintBitsToFloat(m.texel1.xyz), 0.0, 1.0); }
