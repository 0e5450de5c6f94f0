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

// With at most TRACER_LIGHT_GROUP_REGISTERS_MAX groups (core/tracer_interface.h), the
// pixel's layers are held in registers through the pass: loaded before the segment loop
// (load_light_groups), added to there, stored after it (store_light_groups): llvmpipe runs
// an image load and store in the loop in every iteration, and on a GPU each is a trip to
// memory; a select per group is a few instructions (lights.txt's segment loop 8,284 ->
// 8,173 instructions, docs/performance.md, the log). The sums receive the same additions
// in the same order either way, and a float keeps its bits through the image, so the
// layers are bit for bit those of the image's way. More groups keep the image's way
// (LIGHT_GROUP_REGISTERS 0). Each layer is written out for every k below, not as a loop:
// NIR keeps a loop over the layers a loop, and an array indexed by a loop's counter in
// memory, which llvmpipe reads and writes lane by lane.
const uint LIGHT_GROUP_REGISTERS = uint(RTSPHERES_LIGHT_GROUP_REGISTERS);
vec3 held_layers[TRACER_LIGHT_GROUP_REGISTERS_MAX];
#define RTSPHERES_FOR_EACH_HELD_LAYER(step) \
    step(0) step(1) step(2) step(3) step(4) step(5) step(6) step(7)
#if TRACER_LIGHT_GROUP_REGISTERS_MAX != 8
#error "RTSPHERES_FOR_EACH_HELD_LAYER names TRACER_LIGHT_GROUP_REGISTERS_MAX layers"
#endif

// Adds value to group's layer at this pixel.
void add_to_layer(uint group, vec3 value)
{
    if (LIGHT_GROUP_REGISTERS > 0u) {
        uint layer = min(group, LIGHT_GROUP_REGISTERS - 1u);
#define RTSPHERES_ADD_TO_HELD_LAYER(k) \
        if (uint(k) < LIGHT_GROUP_REGISTERS) \
            held_layers[k] = layer == uint(k) ? held_layers[k] + value : held_layers[k];
        RTSPHERES_FOR_EACH_HELD_LAYER(RTSPHERES_ADD_TO_HELD_LAYER)
    } else {
        ivec3 at = ivec3(frame_pixel, int(min(group, light_group_count - 1u)));
        imageStore(light_group_sums, at, imageLoad(light_group_sums, at) + vec4(value, 0.0));
    }
}

// Before the pass's segment loop: the pixel's layers into the registers that hold them.
void load_light_groups()
{
    if (!collects_light_groups())
        return;
#define RTSPHERES_LOAD_HELD_LAYER(k) \
    if (uint(k) < LIGHT_GROUP_REGISTERS) \
        held_layers[k] = imageLoad(light_group_sums, ivec3(frame_pixel, k)).rgb;
    RTSPHERES_FOR_EACH_HELD_LAYER(RTSPHERES_LOAD_HELD_LAYER)
}

// After the pass's segment loop: the held layers back into the image (a unused, 0).
void store_light_groups()
{
    if (!collects_light_groups())
        return;
#define RTSPHERES_STORE_HELD_LAYER(k) \
    if (uint(k) < LIGHT_GROUP_REGISTERS) \
        imageStore(light_group_sums, ivec3(frame_pixel, k), vec4(held_layers[k], 0.0));
    RTSPHERES_FOR_EACH_HELD_LAYER(RTSPHERES_STORE_HELD_LAYER)
}

// Adds value (radiance the path gathered, throughput included) to group's layer at this
// pixel at once. For contributions gathered outside the segment loop's top level (Whitted's
// shadow rays walked in place, its ambient term); the segment loop's own go through the
// two slots below.
void add_to_light_group(uint group, vec3 value)
{
    if (collects_light_groups())
        add_to_layer(group, value);
}

// The segment loop's contributions of one iteration (glsl/integrators.glsl): the light its
// shadow ray brought, and what its path segment found (the sky, or an emitter; never
// both). They are set where they arise and added to their layers by flush_light_groups at
// the loop's top level, whether or not a lane has anything to add: an image store inside
// a condition is, on llvmpipe, a branch per lane on the lane's mask, which goes either way
// at random when the condition does, and every store in the loop costs in every iteration
// (docs/performance.md, the log).
//
// Where a segment's light always ends its path with no shadow ray left (no volumes, whose
// boundaries hold shadow rays back, and no pbr emitter, which scatters on and samples a
// light), the next iteration starts a new sample and brings no shadow light: so the
// segment's light waits for that iteration and goes through the one store the shadow light
// uses, and the layers receive the same additions in the same order with one store an
// iteration instead of two. flush_light_groups_at_end adds what still waits when the loop
// ends. Not for Whitted, whose ambient term and lights go to the layers at once
// (add_to_light_group) in the iteration a deferred light would wait for: the order of the
// additions, and so the sums' rounding, would change.
const bool SEGMENT_LIGHT_ENDS_PATH = !HAS_VOLUMES && !(HAS_PBR && HAS_EMITTERS);
bool segment_light_waits() { return SEGMENT_LIGHT_ENDS_PATH && tracer_integrator() != INTEGRATOR_WHITTED; }
uint shadow_light_group = 0u;
vec3 shadow_light = vec3(0.0);
uint segment_light_group = 0u;
vec3 segment_light = vec3(0.0);
uint waiting_light_group = 0u;   // segment_light_waits(): the segment light of the iteration before
vec3 waiting_light = vec3(0.0);

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

// Adds this iteration's contributions to their layers (zero when there was none), the
// shadow ray's before the segment's, as the segment loop gathers them, and clears them.
void flush_light_groups()
{
    if (!collects_light_groups())
        return;
    if (segment_light_waits()) {
        // A light still waiting means a sample began this iteration: no shadow light.
        bool waiting = any(notEqual(waiting_light, vec3(0.0)));
        add_to_layer(waiting ? waiting_light_group : shadow_light_group, waiting ? waiting_light : shadow_light);
        waiting_light_group = segment_light_group;
        waiting_light = segment_light;
    } else {
        add_to_layer(shadow_light_group, shadow_light);
        add_to_layer(segment_light_group, segment_light);
    }
    shadow_light = vec3(0.0);
    segment_light = vec3(0.0);
}

// After the segment loop: adds the segment light still waiting (segment_light_waits()).
void flush_light_groups_at_end()
{
    if (collects_light_groups() && segment_light_waits())
        add_to_layer(waiting_light_group, waiting_light);
}

// The light group of light (texel 4 of its record, core/packed_layout.h).
uint light_group_of(uint light)
{
    return packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE) + 4u).x;
}

// The light group of an emissive material (texel 1 .w of its record).
uint emitter_light_group(Material material) { return material.texel1.w; }
