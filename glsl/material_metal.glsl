// material_metal.glsl: a mirror roughened by fuzz (MATERIAL_METAL), as the Ray Tracing
// books have it; the material interface of glsl/material.glsl.

// The mirror direction moved by fuzz times a point in the unit ball; a direction below
// the surface is absorbed.
BsdfSample metal_sample(Material m, ShadingFrame frame, vec3 direction, vec4 u)
{
    float fuzz = uintBitsToFloat(m.texel1.w);
    vec3 reflected = reflect(direction, frame.shading);
    BsdfSample s;
    s.direction = normalize(reflected + fuzz * random_in_unit_sphere(u.xyz));
    s.weight = m.albedo;
    s.pdf = 0.0;
    s.absorbed = dot(s.direction, frame.normal) <= 0.0;
    s.light_sampled = false;
    return s;
}

// Treated as specular: light reaches it by sampling only.
vec3 metal_evaluate(Material m, ShadingFrame frame, vec3 view, vec3 to_light) { return vec3(0.0); }
float metal_pdf(Material m, ShadingFrame frame, vec3 view, vec3 to_light) { return 0.0; }

vec3 metal_guide_albedo(Material m) { return m.albedo; }
