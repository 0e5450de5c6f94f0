// compact_scatter.vert: the scatter program's vertex shader (core/gpu_compact.c): point
// gl_VertexID is compact slot (gl_VertexID mod width, gl_VertexID / width) of the pixel
// map, placed on the centre of the slot's pixel in a frame of frame_size pixels; a slot
// with no pixel is placed outside the viewport, so it draws nothing.
layout(binding = TRACER_PIXEL_MAP_UNIT) uniform usampler2D pixel_map;
uniform vec2 frame_size;
flat out ivec2 slot;

void main()
{
    int width = textureSize(pixel_map, 0).x;
    slot = ivec2(gl_VertexID % width, gl_VertexID / width);
    uint code = texelFetch(pixel_map, slot, 0).x;
    vec2 pixel = vec2(code & ((1u << TRACER_PIXEL_MAP_SHIFT) - 1u), code >> TRACER_PIXEL_MAP_SHIFT);
    gl_Position = code == TRACER_NO_PIXEL ? vec4(2.0, 2.0, 0.0, 1.0)
                                          : vec4((pixel + 0.5) / frame_size * 2.0 - 1.0, 0.0, 1.0);
}
