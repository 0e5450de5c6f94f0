// integrator_path.glsl: the path tracer (INTEGRATOR_PATH): unbiased, with light sampling
// (next-event estimation with MIS) where the material allows it and in volumes, and
// Russian roulette. Its choices at the steps of the loop of glsl/integrators.glsl:

// Light sampling is the render's choice (--light-sampling): off leaves BSDF sampling
// alone, the same image with more noise.
bool path_samples_lights() { return light_sampling != 0; }

// A path that leaves the scene sees the sky, weighted by MIS against light sampling of
// an environment sky.
float path_sky_weight(PixelState s)
{
    return environment_mis_weight(s.previous_pdf, s.choice_memo, s.origin - s.since_vertex * s.direction, s.direction);
}

// At a surface the path goes on as the material samples it, and gathers direct light
// where the material says (weighted by MIS: previous_pdf keeps the sample's density).
BsdfSample path_shade(inout PixelState s, Material material, ShadingFrame frame, vec3 p, BsdfSample sampled,
                      inout LightQuery query)
{
    if (sampled.light_sampled)
        query = surface_light_query(light_count > 0u, DIRECT_MIS, p, frame, material, s.throughput);
    s.previous_pdf = light_count > 0u ? sampled.pdf : 0.0;
    return sampled;
}

// After russian_roulette_depth segments a path ends at random, more likely the less it
// carries; unbiased, since survivors carry the weight of the paths that ended.
bool path_survives(inout PixelState s)
{
    if (s.bounce <= russian_roulette_depth)
        return true;
    float survival = clamp(max(s.throughput.r, max(s.throughput.g, s.throughput.b)), 0.05, 1.0);
    if (random4(s.bounce, 2u).x >= survival)
        return false;
    s.throughput /= survival;
    return true;
}
