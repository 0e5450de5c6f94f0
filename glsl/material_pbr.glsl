// material_pbr.glsl: glTF 2.0's metallic-roughness material (MATERIAL_PBR), the material
// interface of glsl/material.glsl, as the glTF specification's appendix B combines it:
//
//   f = mix(dielectric, metal, metallic)
//   metal      = F_metal(v.h) * specular,     F_metal = base + (1 - base) (1 - v.h)^5
//   dielectric = F(v.h) * specular + (1 - F(v.h)) * mix(base / pi, base * btdf, transmission)
//
// specular is GGX with Smith's height-correlated masking-shadowing, D G2 / (4 |n.v| |n.l|)
// (glsl/microfacet.glsl), alpha = roughness^2; btdf is the rough dielectric of Walter et al.
// ("Microfacet Models for Refraction through Rough Surfaces", EGSR 2007) through the same
// microfacets; F is the dielectric material's Fresnel term (Schlick's, on the cosine of
// the side the ray is on, with f0 = ((ior - 1) / (ior + 1))^2, 0.04 at glTF's default 1.5;
// 1 under total internal reflection), so that the specular colour is Schlick's on
// F0 = mix(f0, base, metallic). Transmitted radiance is not scaled by the squared ratio of
// the indices, as the dielectric material's is not either (a body that is entered and left
// changes nothing by it).
//
// Below PBR_SMOOTH_ALPHA the specular and transmission lobes are their delta limits, the
// dielectric material's mirror and refraction (glsl/material_dielectric.glsl) and the
// fuzz-0 metal's mirror, with F at the shading normal: roughness 0 renders as those do.
//
// Sampling: one lobe, chosen by u.w with probabilities that depend on the view alone
// (pbr_view: the specular reflectance at the normal, and the diffuse and transmission
// shares of the rest, by the base colour's mean), then the specular lobe by visible
// normals, the diffuse lobe by the cosine, the transmission lobe by visible normals
// refracted. pbr_pdf is the density of that whole choice (the probability-weighted sum of
// the lobes' densities), and a sample's weight is f cos / pdf of every lobe at the sampled
// direction, so MIS and sampling agree (tests/unit/test_material_pbr.c checks both by a
// chi-square test on the device). Directions that end on the wrong side of the surface
// (a reflection below it, a refraction above it) are absorbed. Light sampling gathers
// light above the surface only (glsl/direct_light.glsl), so a transmitted sample carries
// pdf 0: what it finds through the surface is BSDF sampling's alone.

const float PBR_SMOOTH_ALPHA = 1e-3;

// What sampling and evaluation share for one material and view direction.
struct PbrView {
    vec3 normal;           // the shading normal used (world): frame.shading, or the
                           // geometric normal when the view is not above the shading one
    vec3 tangent, bitangent;
    vec3 view;             // the view direction in (tangent, bitangent, normal)
    vec3 base;             // base colour
    float metallic;
    float transmission;
    float alpha;           // GGX width: roughness^2
    float eta_ratio;       // index of refraction on the view's side / the other side's
    bool smooth_surface;   // alpha < PBR_SMOOTH_ALPHA: specular and transmission are delta
    float p_specular;      // the lobe choice: specular, diffuse, and the rest transmission
    float p_diffuse;
};

// The dielectric Fresnel reflectance for cosine (>= 0) on the side whose index over the
// other's is eta_ratio: 1 under total internal reflection, else Schlick's (as
// glsl/material_dielectric.glsl decides it).
float pbr_dielectric_fresnel(float cosine, float eta_ratio)
{
    float sine = sqrt(max(0.0, 1.0 - cosine * cosine));
    return eta_ratio * sine > 1.0 ? 1.0 : schlick_reflectance(cosine, eta_ratio);
}

float colour_mean(vec3 c) { return (c.r + c.g + c.b) / 3.0; }

// The shared part of a pbr material seen from view (unit, on the side frame's normals
// face).
PbrView pbr_view(Material m, ShadingFrame frame, vec3 view)
{
    PbrView p;
    p.normal = dot(view, frame.shading) > 1e-4 ? frame.shading : frame.normal;
    basis_around(p.normal, p.tangent, p.bitangent);
    p.view = vec3(dot(view, p.tangent), dot(view, p.bitangent), dot(view, p.normal));
    p.base = m.albedo;
    p.metallic = clamp(m.pbr.x, 0.0, 1.0);
    p.alpha = m.pbr.y * m.pbr.y;
    p.transmission = clamp(m.pbr.z, 0.0, 1.0);
    p.smooth_surface = p.alpha < PBR_SMOOTH_ALPHA;
    // An opaque surface has no inside: both of its sides face the outer medium.
    float ior = uintBitsToFloat(m.texel2.x);
    p.eta_ratio = frame.front_face || p.transmission <= 0.0 ? 1.0 / ior : ior;
    float cosine = clamp(p.view.z, 0.0, 1.0);
    // Lobe weights: smooth lobes know their Fresnel term exactly; rough ones take
    // Schlick's without total internal reflection, which some microfacets escape.
    float dielectric = p.smooth_surface ? pbr_dielectric_fresnel(cosine, p.eta_ratio)
                                        : schlick_reflectance(cosine, p.eta_ratio);
    vec3 metal = p.base + (1.0 - p.base) * pow(1.0 - cosine, 5.0);
    float specular = mix(dielectric, colour_mean(metal), p.metallic);
    float rest = (1.0 - p.metallic) * (1.0 - dielectric) * colour_mean(p.base);
    // Never 0 while the specular lobe can reflect something (ior 1, black metals).
    specular = max(specular, 0.01);
    float diffuse = rest * (1.0 - p.transmission);
    float total = specular + rest;
    p.p_specular = specular / total;
    p.p_diffuse = diffuse / total;
    return p;
}

// f cos (per unit of light from l, world) and, in pdf, the density with which pbr_sample
// picks l: every lobe that is not a delta, on the side of the surface l is on.
vec3 pbr_evaluate_pdf(PbrView p, vec3 to_light, out float pdf)
{
    vec3 v = p.view;
    vec3 l = vec3(dot(to_light, p.tangent), dot(to_light, p.bitangent), dot(to_light, p.normal));
    pdf = 0.0;
    if (v.z <= 0.0)
        return vec3(0.0);
    float lambda_v = ggx_lambda(v, p.alpha), lambda_l = ggx_lambda(l, p.alpha);
    vec3 value = vec3(0.0);
    if (l.z > 0.0) {
        vec3 h = normalize(v + l);
        // Clamped: v.h may round above 1, and pow of a negative base is undefined.
        float vh = clamp(dot(v, h), 0.0, 1.0);
        float dielectric = pbr_dielectric_fresnel(vh, p.eta_ratio);
        value = (1.0 - p.metallic) * (1.0 - p.transmission) * (1.0 - dielectric) * p.base * (l.z / PI);
        pdf = p.p_diffuse * l.z / PI;
        if (!p.smooth_surface) {
            float d = ggx_distribution(h, p.alpha);
            vec3 fresnel = mix(vec3(dielectric), p.base + (1.0 - p.base) * pow(1.0 - vh, 5.0), p.metallic);
            value += fresnel * (d / (4.0 * v.z * (1.0 + lambda_v + lambda_l)));
            pdf += p.p_specular * d / (4.0 * v.z * (1.0 + lambda_v));
        }
    } else if (l.z < 0.0 && !p.smooth_surface && p.transmission > 0.0 && p.metallic < 1.0) {
        // The microfacet that refracts v into l: h along -(eta_v v + eta_l l), on the
        // normal's side; v on its front, l behind it.
        vec3 h = normalize(p.eta_ratio * v + l);
        h = h.z < 0.0 ? -h : h;
        float vh = dot(v, h), lh = dot(l, h);
        if (vh > 0.0 && lh < 0.0) {
            float denominator = p.eta_ratio * vh + lh;
            float jacobian = abs(lh) / (denominator * denominator);   // d(omega_h) / d(omega_l)
            float d = ggx_distribution(h, p.alpha);
            float transmitted = 1.0 - pbr_dielectric_fresnel(min(vh, 1.0), p.eta_ratio);
            value = (1.0 - p.metallic) * p.transmission * transmitted * p.base
                    * (d * vh * jacobian / (v.z * (1.0 + lambda_v + lambda_l)));
            pdf = (1.0 - p.p_specular - p.p_diffuse) * d * vh * jacobian / (v.z * (1.0 + lambda_v));
        }
    }
    return value;
}

// The lobe that u picks (the first two numbers warp it, u.w chooses it).
BsdfSample pbr_sample(Material m, ShadingFrame frame, vec3 direction, vec4 u)
{
    PbrView p = pbr_view(m, frame, -direction);
    BsdfSample s = absorbed_sample(direction);
    s.light_sampled = !p.smooth_surface || p.p_diffuse > 0.0;
    if (p.view.z <= 0.0)
        return s;
    bool specular = u.w < p.p_specular;
    bool diffuse = !specular && u.w < p.p_specular + p.p_diffuse;
    vec3 next;
    if (diffuse) {
        vec2 disk = random_in_unit_disk(u.xy);
        vec3 local = vec3(disk, sqrt(max(0.0, 1.0 - dot(disk, disk))));
        next = local.x * p.tangent + local.y * p.bitangent + local.z * p.normal;
    } else if (p.smooth_surface) {
        next = specular ? reflect(direction, p.normal) : refract(direction, p.normal, p.eta_ratio);
    } else {
        vec3 h = ggx_sample_visible_normal(p.view, p.alpha, u.xy);
        vec3 world_h = h.x * p.tangent + h.y * p.bitangent + h.z * p.normal;
        next = specular ? reflect(direction, world_h) : refract(direction, world_h, p.eta_ratio);
    }
    // refract gives 0 under total internal reflection: that facet sends nothing through.
    bool transmitted = !specular && !diffuse;
    float side = transmitted ? -1.0 : 1.0;
    if (dot(next, next) < 0.5 || side * dot(next, p.normal) <= 0.0 || side * dot(next, frame.normal) <= 0.0)
        return s;
    s.direction = normalize(next);
    if (p.smooth_surface && !diffuse) {
        // A delta lobe: its weight is its Fresnel share over its probability.
        float cosine = min(p.view.z, 1.0);
        float dielectric = pbr_dielectric_fresnel(cosine, p.eta_ratio);
        vec3 metal = p.base + (1.0 - p.base) * pow(1.0 - cosine, 5.0);
        s.weight = specular ? mix(vec3(dielectric), metal, p.metallic) / p.p_specular
                            : (1.0 - p.metallic) * p.transmission * (1.0 - dielectric) * p.base
                              / (1.0 - p.p_specular - p.p_diffuse);
        s.absorbed = false;
        return s;
    }
    float pdf;
    vec3 value = pbr_evaluate_pdf(p, s.direction, pdf);
    if (!(pdf > 0.0))
        return s;
    s.weight = value / pdf;
    s.pdf = transmitted ? 0.0 : pdf;
    s.absorbed = false;
    return s;
}

vec3 pbr_evaluate(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
{
    float pdf;
    return pbr_evaluate_pdf(pbr_view(m, frame, view), to_light, pdf);
}

float pbr_pdf(Material m, ShadingFrame frame, vec3 view, vec3 to_light)
{
    float pdf;
    pbr_evaluate_pdf(pbr_view(m, frame, view), to_light, pdf);
    return pdf;
}

vec3 pbr_guide_albedo(Material m) { return m.albedo; }

// Whitted's stand-in (glsl/material_phong.glsl): the diffuse colour, the specular colour
// F0 = mix(f0, base, metallic), and a Phong exponent of about GGX's width (the Blinn-Phong
// exponent 2 / alpha^2 - 2, a quarter of it for Phong's reflected-vector lobe).
vec3 pbr_diffuse_colour(Material m) { return (1.0 - m.pbr.x) * (1.0 - m.pbr.z) * m.albedo; }

vec3 pbr_specular_colour(Material m)
{
    return mix(vec3(schlick_reflectance(1.0, 1.0 / uintBitsToFloat(m.texel2.x))), m.albedo, m.pbr.x);
}

float pbr_phong_exponent(Material m)
{
    float alpha = m.pbr.y * m.pbr.y;
    return clamp((2.0 / max(alpha * alpha, 1e-8) - 2.0) / 4.0, 1.0, 10000.0);
}
