// material_phong.glsl: the Whitted integrator's shading model (glsl/integrator_whitted.glsl):
// ambient + Lambert diffuse + normalised-Phong specular from the lights, for the materials
// it shades, with the exponent and specular colour of the material's texel 3
// (core/packed_layout.h "materials"). Dielectrics and emitters keep their own behaviour.
//
// pbr is a Phong-like stand-in for its GGX lobes: diffuse (1 - metallic)(1 - transmission)
// x base colour, a highlight of colour F0 = mix(f0, base, metallic) and an exponent of
// about GGX's width (glsl/material_pbr.glsl), and a mirror reflection of weight
// F0 (1 - roughness)^2, which fades out as the surface gets rough. A pbr material that
// mostly transmits (transmission >= 0.5) goes on as it samples, like a dielectric.

// Whether Whitted shades the material with this model (lambertian, metal, pbr that does
// not mostly transmit).
bool phong_shades(Material m)
{
    bool transmits = HAS_PBR && m.type == uint(MATERIAL_PBR) && m.pbr.z >= 0.5;
    return m.type != uint(MATERIAL_EMISSIVE) && m.type != uint(MATERIAL_DIELECTRIC) && !transmits;
}

// (Phong exponent, specular colour.rgb) of the material.
vec4 phong_parameters(Material m)
{
    if (HAS_PBR && m.type == uint(MATERIAL_PBR))
        return vec4(pbr_phong_exponent(m), pbr_specular_colour(m));
    return packed_vec4(material_offset + m.index * uint(PACKED_MATERIAL_STRIDE) + 3u);
}

// Where Whitted goes on from a shaded point: metals reflect as perfect mirrors, pbr as a
// mirror of its fading weight (a direction below the surface ends the path), diffuse
// surfaces end it; all gather the lights.
BsdfSample phong_sample(Material m, ShadingFrame frame, vec3 direction)
{
    bool pbr = HAS_PBR && m.type == uint(MATERIAL_PBR);
    BsdfSample s;
    s.direction = reflect(direction, frame.shading);
    s.weight = pbr ? pbr_specular_colour(m) * (1.0 - m.pbr.y) * (1.0 - m.pbr.y) : m.albedo;
    s.pdf = 0.0;
    s.absorbed = (m.type != uint(MATERIAL_METAL) && !pbr) || dot(s.direction, frame.normal) <= 0.0;
    s.light_sampled = true;
    return s;
}

// f * cos for light from to_light seen towards view: the Lambertian term of the material's
// (diffuse) colour plus the normalised Phong lobe about the mirror direction of the light.
vec3 phong_evaluate(Material m, vec4 phong, ShadingFrame frame, vec3 view, vec3 to_light)
{
    float cosine = dot(frame.shading, to_light);
    vec3 reflected = reflect(-to_light, frame.shading);
    float highlight = pow(max(dot(reflected, view), 0.0), phong.x) * (phong.x + 2.0) / (2.0 * PI);
    vec3 diffuse = HAS_PBR && m.type == uint(MATERIAL_PBR) ? pbr_diffuse_colour(m) : m.albedo;
    return diffuse * (cosine / PI) + phong.yzw * highlight * cosine;
}
