// material_dielectric.glsl: clear glass and the like (MATERIAL_DIELECTRIC): reflection or
// refraction, chosen by Schlick's approximation of the Fresnel reflectance; the material
// interface of glsl/material.glsl.

float schlick_reflectance(float cosine, float eta_ratio)
{
    float r0 = (1.0 - eta_ratio) / (1.0 + eta_ratio);
    r0 = r0 * r0;
    float m = 1.0 - cosine, m2 = m * m;
    return r0 + (1.0 - r0) * (m2 * m2 * m);
}

// Reflects when refraction is impossible (total internal reflection) or with the Fresnel
// probability (u.w), refracts otherwise; nothing is absorbed.
BsdfSample dielectric_sample(Material m, ShadingFrame frame, vec3 direction, vec4 u)
{
    float ior = uintBitsToFloat(m.texel2.x);
    float eta_ratio = frame.front_face ? 1.0 / ior : ior;
    float cosine = min(dot(-direction, frame.shading), 1.0);
    float sine = sqrt(max(0.0, 1.0 - cosine * cosine));
    BsdfSample s;
    if (eta_ratio * sine > 1.0 || schlick_reflectance(cosine, eta_ratio) > u.w)
        s.direction = reflect(direction, frame.shading);
    else
        s.direction = refract(direction, frame.shading, eta_ratio);
    s.weight = vec3(1.0);
    s.pdf = 0.0;
    s.absorbed = false;
    s.light_sampled = false;
    return s;
}

// Specular: light reaches it by sampling only.
vec3 dielectric_evaluate(Material m, ShadingFrame frame, vec3 view, vec3 to_light) { return vec3(0.0); }
float dielectric_pdf(Material m, ShadingFrame frame, vec3 view, vec3 to_light) { return 0.0; }

// Glass shows what is behind it; the guide says "white" rather than a colour of its own.
vec3 dielectric_guide_albedo(Material m) { return vec3(1.0); }
