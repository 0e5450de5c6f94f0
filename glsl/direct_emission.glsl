// direct_emission.glsl: the emission camera rays see at once (--denoise, --aovs): what a sample's
// first segment gathers from an emitter it hits or from the sky it escapes to, summed per
// pixel into one rgba32f image (rgb; a unused). core/render.c divides the sums by the
// pixel's samples, and the denoiser (core/postprocess.h) filters the image less this
// part and adds it back: it has no noise but the pixel's coverage, and a pixel that a
// bright light covers in part must not be averaged with the surface around the light.
// Added with an image load and store, as glsl/light_groups.glsl adds its layers (the pass
// state uses every draw buffer); renders without --denoise or --aovs leave this code out.

layout(binding = TRACER_DIRECT_EMISSION_IMAGE_UNIT, rgba32f) uniform image2D direct_emission_sums;

// The direct emission this iteration of the segment loop found (glsl/integrators.glsl),
// added by flush_direct_emission at the loop's top level, as glsl/light_groups.glsl does
// with its slots (a conditional image store costs a branch per lane on llvmpipe).
vec3 direct_emission_now = vec3(0.0);

// Takes value as this pixel's direct emission when the segment that gathered it was the
// sample's first (segment 1: the camera ray up to the first surface it meets; a volume
// boundary counts as one, so a light seen through a volume is filtered with the rest).
void add_direct_emission(uint segment, vec3 value)
{
    if (segment == 1u)
        direct_emission_now = value;
}

// Adds this iteration's direct emission (zero when there was none) to the pixel's sum.
void flush_direct_emission()
{
    if (!HAS_DIRECT_EMISSION || direct_emission == 0u)
        return;
    imageStore(direct_emission_sums, frame_pixel,
               imageLoad(direct_emission_sums, frame_pixel) + vec4(direct_emission_now, 0.0));
    direct_emission_now = vec3(0.0);
}
