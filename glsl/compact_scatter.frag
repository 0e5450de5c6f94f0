// compact_scatter.frag: the main of the scatter program (core/gpu_compact.c): one point per
// compact slot, drawn at its pixel of the full state textures (glsl/compact_scatter.vert),
// writes the slot's state back there.
flat in ivec2 slot;

void main()
{
    copy_state(slot);
}
