// direct_emission.glsl: the emission camera rays see at once (--denoise, --aovs): what a sample's
// first segment gathers from an emitter it hits or from the sky it escapes to, summed per
// pixel into one rgba32f image (rgb; a unused). core/render.c divides the sums by the
// pixel's samples, and the denoiser (core/postprocess.h) filters the image less this
// part and adds it back: it has no noise but the pixel's coverage, and a pixel that a
// bright light covers in part must not be averaged with the surface around the light.
// Held in a register through the pass, as glsl/light_groups.glsl holds its layers (the pass
// state uses every draw buffer, and an image load and store in the segment loop would run
// in every iteration): loaded before the segment loop, stored after it. Renders without
// --denoise or --aovs leave this code out.

layout(binding = TRACER_DIRECT_EMISSION_IMAGE_UNIT, rgba32f) uniform image2D direct_emission_sums;

// The direct emission this iteration of the segment loop found (glsl/integrators.glsl),
// added by flush_direct_emission at the loop's top level, and the pixel's sum so far.
vec3 direct_emission_now = vec3(0.0);
vec3 held_direct_emission = vec3(0.0);

// Whether this pass sums the direct emission: the variant has the code and the render asked.
bool sums_direct_emission() { return HAS_DIRECT_EMISSION && direct_emission != 0u; }

// Takes value as this pixel's direct emission when the segment that gathered it was the
// sample's first (segment 1: the camera ray up to the first surface it meets; a volume
// boundary counts as one, so a light seen through a volume is filtered with the rest).
void add_direct_emission(uint segment, vec3 value)
{
    if (segment == 1u)
        direct_emission_now = value;
}

// Before the pass's segment loop: the pixel's sum into the register that holds it.
void load_direct_emission()
{
    if (sums_direct_emission())
        held_direct_emission = imageLoad(direct_emission_sums, frame_pixel).rgb;
}

// Adds this iteration's direct emission (zero when there was none) to the pixel's sum.
void flush_direct_emission()
{
    if (!sums_direct_emission())
        return;
    held_direct_emission += direct_emission_now;
    direct_emission_now = vec3(0.0);
}

// After the pass's segment loop: the sum back into the image (a unused, 0).
void store_direct_emission()
{
    if (sums_direct_emission())
        imageStore(direct_emission_sums, frame_pixel, vec4(held_direct_emission, 0.0));
}
