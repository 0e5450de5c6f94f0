// microfacet.glsl: the GGX (Trowbridge-Reitz) microfacet distribution, Smith's
// height-correlated masking-shadowing, and sampling by visible normals (Heitz, "Sampling
// the GGX Distribution of Visible Normals", JCGT 2018), for glsl/material_pbr.glsl.
//
// Directions are in a local frame whose +Z is the (shading) normal, so that cos theta is
// z and sin^2 theta is x^2 + y^2, which keeps D accurate for small alpha near the normal.
// Isotropic: alpha is the distribution's width (glTF's perceptual roughness squared).

// Two unit vectors t, b with (t, b, n) right-handed and orthonormal, for a unit n (the
// branchless construction of Duff et al., "Building an Orthonormal Basis, Revisited",
// JCGT 2017).
void basis_around(vec3 n, out vec3 t, out vec3 b)
{
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// D(h): the density of microfacet normals h (local, unit) per solid angle, normalised so
// that its integral with cos theta_h over the hemisphere is 1.
float ggx_distribution(vec3 h, float alpha)
{
    if (h.z <= 0.0)
        return 0.0;
    float a2 = alpha * alpha;
    float d = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
    return 1.0 / (PI * a2 * d * d);
}

// Smith's Lambda of GGX for a direction w (local, unit): G1 = 1 / (1 + Lambda).
float ggx_lambda(vec3 w, float alpha)
{
    float z2 = max(w.z * w.z, 1e-12);
    return 0.5 * (sqrt(1.0 + alpha * alpha * (w.x * w.x + w.y * w.y) / z2) - 1.0);
}

// A microfacet normal drawn from the distribution of normals visible from v (local, v.z >
// 0), D_v(h) = G1(v) max(0, v.h) D(h) / v.z, from two uniform numbers: the hemisphere
// stretched to alpha 1, a point on the projected disc warped onto its visible half, and
// back.
vec3 ggx_sample_visible_normal(vec3 v, float alpha, vec2 u)
{
    vec3 stretched = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    float length_squared = stretched.x * stretched.x + stretched.y * stretched.y;
    vec3 t1 = length_squared > 0.0 ? vec3(-stretched.y, stretched.x, 0.0) * inversesqrt(length_squared)
                                   : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(stretched, t1);
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + stretched.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 n = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * stretched;
    return normalize(vec3(alpha * n.x, alpha * n.y, max(n.z, 1e-7)));
}

// The density D_v(h) with which ggx_sample_visible_normal draws h (per solid angle of h).
float ggx_visible_normal_pdf(vec3 v, vec3 h, float alpha)
{
    return ggx_distribution(h, alpha) * max(dot(v, h), 0.0) / ((1.0 + ggx_lambda(v, alpha)) * v.z);
}
