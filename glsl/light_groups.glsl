// light_groups.glsl: light groups (--light-groups): every contribution a path gathers is
// also added to the layer of the light group it came from (scene.h light_groups), so that
// each layer is the image of its group alone and the layers sum to the beauty image.
//
// The layers are one rgba32f image2DArray (layer = group, a unused), read and written with
// image load/store rather than colour attachments: the pass state already uses the draw
// buffers. Each pixel is one invocation of the pass (a full-screen triangle), so a
// load followed by a store to its own texel is race-free. The sums are of contributions as
// they are gathered, so a path still in flight when a render is interrupted has added part
// of its light; finished renders have no path in flight. core/gpu_tracer.c reads the
// layers; core/render.c divides them by the pixel's finished samples, as it does the
// beauty sum. Renders without groups leave this code out (HAS_LIGHT_GROUPS).
//
// Per group the estimator stays unbiased: a light sample gives f / (p_choice x pdf) to the
// group of the light it chose, whose expectation over the choice is the sum of that
// group's lights' f; the MIS weights of a light's two strategies sum to one per light.

layout(binding = TRACER_LIGHT_GROUP_IMAGE_UNIT, rgba32f) uniform image2DArray light_group_sums;

// Whether this pass collects light groups: the variant has the code and the render asked.
bool collects_light_groups() { return HAS_LIGHT_GROUPS && light_group_count > 0u; }

// Adds value (radiance the path gathered, throughput included) to group's layer at this
// pixel at once. For contributions gathered outside the segment loop's top level (Whitted's
// shadow rays walked in place, its ambient term); the segment loop's own go through the
// two slots below.
void add_to_light_group(uint group, vec3 value)
{
    if (!collects_light_groups())
        return;
    ivec3 at = ivec3(frame_pixel, int(min(group, light_group_count - 1u)));
    imageStore(light_group_sums, at, imageLoad(light_group_sums, at) + vec4(value, 0.0));
}

// The segment loop's contributions of one iteration (glsl/integrators.glsl): the light its
// shadow ray brought, and what its path segment found (the sky, or an emitter; never
// both). They are set where they arise and added to their layers by flush_light_groups,
// once per iteration at the loop's top level, whether or not a lane has anything to add.
// An image store inside a condition is, on llvmpipe, a branch per lane on the lane's
// mask, which goes either way at random when the condition does; at the top level every
// lane still in the loop stores, and three such sites in conditions became two that
// always store (docs/performance.md, the log: lights.txt --light-groups about 4% faster).
uint shadow_light_group = 0u;
vec3 shadow_light = vec3(0.0);
uint segment_light_group = 0u;
vec3 segment_light = vec3(0.0);

// The light this iteration's shadow ray brought, for group.
void set_shadow_light(uint group, vec3 value)
{
    shadow_light_group = group;
    shadow_light = value;
}

// The light this iteration's path segment found (sky or emitter), for group.
void set_segment_light(uint group, vec3 value)
{
    segment_light_group = group;
    segment_light = value;
}

// Adds this iteration's two contributions to their layers (zero when there was none) and
// clears them: the shadow ray's first, as the segment loop gathered them before.
void flush_light_groups()
{
    if (!collects_light_groups())
        return;
    ivec3 at = ivec3(frame_pixel, int(min(shadow_light_group, light_group_count - 1u)));
    imageStore(light_group_sums, at, imageLoad(light_group_sums, at) + vec4(shadow_light, 0.0));
    at = ivec3(frame_pixel, int(min(segment_light_group, light_group_count - 1u)));
    imageStore(light_group_sums, at, imageLoad(light_group_sums, at) + vec4(segment_light, 0.0));
    shadow_light = vec3(0.0);
    segment_light = vec3(0.0);
}

// The light group of light (texel 4 of its record, core/packed_layout.h).
uint light_group_of(uint light)
{
    return packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE) + 4u).x;
}

// The light group of an emissive material (texel 1 .w of its record).
uint emitter_light_group(Material material) { return material.texel1.w; }
