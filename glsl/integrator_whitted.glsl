// integrator_whitted.glsl: Whitted recursive ray tracing (INTEGRATOR_WHITTED): Phong
// shading from every light at diffuse and metal surfaces (glsl/material_phong.glsl),
// mirror reflection off metals, reflection or refraction through dielectrics; fast and
// nearly noise-free. Volumes scatter and gather light as in path tracing. Its choices at
// the steps of the loop of glsl/integrators.glsl:

// The lights always shine (and the ambient term with them).
bool whitted_samples_lights() { return true; }

// The sky as it is: there is no BSDF sampling to weigh it against.
float whitted_sky_weight(PixelState s) { return 1.0; }

// Diffuse and metal surfaces are shaded locally with the Phong model: diffuse ones end the
// path, metals reflect as mirrors. Other materials (dielectrics) go on as they sample.
BsdfSample whitted_shade(inout PixelState s, Material material, ShadingFrame frame, vec3 p, BsdfSample sampled,
                         inout LightQuery query)
{
    if (!phong_shades(material)) {
        s.previous_pdf = 0.0;
        return sampled;
    }
    query = surface_light_query(true, DIRECT_PHONG, p, frame, material, s.throughput);
    return phong_sample(material, frame, s.direction);
}

// No Russian roulette: paths end at max_depth.
bool whitted_survives(inout PixelState s) { return true; }
