// material_lambertian.glsl: the ideal diffuse reflector (MATERIAL_LAMBERTIAN), the
// material interface of glsl/material.glsl.

// Cosine-distributed about the shading normal: the normal plus a uniform unit vector.
BsdfSample lambertian_sample(Material m, ShadingFrame frame, vec3 direction, vec4 u)
{
    vec3 next = frame.shading + random_unit_vector(u.xy);
    float length_squared = dot(next, next);
    next = length_squared > 1e-12 ? next * inversesqrt(length_squared) : frame.shading;
    if (dot(next, frame.normal) <= 0.0)
        next = reflect(next, frame.normal);
    BsdfSample s;
    s.direction = next;
    s.weight = m.albedo;
    s.pdf = max(dot(frame.shading, next), 0.0) / PI;
    s.absorbed = false;
    s.light_sampled = true;
    return s;
}

vec3 lambertian_evaluate(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
{
    return m.albedo * (dot(frame.shading, to_light) / PI);
}

float lambertian_pdf(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
{
    return dot(frame.shading, to_light) / PI;
}

vec3 lambertian_guide_albedo(Material m) { return m.albedo; }
