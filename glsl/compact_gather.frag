// compact_gather.frag: the main of the gather program (core/gpu_compact.c): drawn over the
// compact state textures, each slot takes the state of its pixel (the pixel map) from the
// full ones, where the last pass left it.
void main()
{
    ivec2 pixel = mapped_pixel(texelFetch(pixel_map, ivec2(gl_FragCoord.xy), 0).x);
    if (pixel.x < 0)
        discard;
    copy_state(pixel);
}
