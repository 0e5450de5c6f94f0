// material_phong.glsl: the Whitted integrator's shading model (glsl/integrator_whitted.glsl):
// ambient + Lambert diffuse + normalised-Phong specular from the lights, for the materials
// it shades, with the exponent and specular colour of the material's texel 3
// (core/packed_layout.h "materials"). Dielectrics and emitters keep their own behaviour.

// Whether Whitted shades the material with this model (lambertian and metal).
bool phong_shades(Material m)
{
    return m.type != uint(MATERIAL_EMISSIVE) && m.type != uint(MATERIAL_DIELECTRIC);
}

// (Phong exponent, specular colour.rgb) of the material.
vec4 phong_parameters(Material m)
{
    return packed_vec4(material_offset + m.index * uint(PACKED_MATERIAL_STRIDE) + 3u);
}

// Where Whitted goes on from a shaded point: metals reflect as perfect mirrors (a
// direction below the surface ends the path), diffuse surfaces end it; both gather the
// lights.
BsdfSample phong_sample(Material m, ShadingFrame frame, vec3 direction)
{
    BsdfSample s;
    s.direction = reflect(direction, frame.shading);
    s.weight = m.albedo;
    s.pdf = 0.0;
    s.absorbed = m.type != uint(MATERIAL_METAL) || dot(s.direction, frame.normal) <= 0.0;
    s.light_sampled = true;
    return s;
}

// f * cos for light from to_light seen towards view: the Lambertian term of the material's
// albedo plus the normalised Phong lobe about the mirror direction of the light.
vec3 phong_evaluate(Material m, vec4 phong, ShadingFrame frame, vec3 view, vec3 to_light)
{
    float cosine = dot(frame.shading, to_light);
    vec3 reflected = reflect(-to_light, frame.shading);
    float highlight = pow(max(dot(reflected, view), 0.0), phong.x) * (phong.x + 2.0) / (2.0 * PI);
    return lambertian_evaluate(m, frame, view, to_light) + phong.yzw * highlight * cosine;
}
