/* pack.c: see pack.h. */
#include "pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

pack_options pack_options_defaults(void)
{
    return (pack_options){0};
}

static uint32_t float_bits(float value)
{
    uint32_t bits;
    memcpy(&bits, &value, sizeof bits);
    return bits;
}

static float bits_float(uint32_t bits)
{
    float value;
    memcpy(&value, &bits, sizeof value);
    return value;
}

static void put_texel(uint32_t *texels, uint32_t index, uint32_t x, uint32_t y, uint32_t z, uint32_t w)
{
    texels[4 * (size_t)index + 0] = x;
    texels[4 * (size_t)index + 1] = y;
    texels[4 * (size_t)index + 2] = z;
    texels[4 * (size_t)index + 3] = w;
}

static double seconds_now(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return now.tv_sec + now.tv_nsec * 1e-9;
}

rt_status pack_scene(const scene *s, const pack_options *options, packed_scene *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    pack_options defaults = pack_options_defaults();
    if (options == NULL)
        options = &defaults;

    uint32_t primitive_count = (uint32_t)s->sphere_count;
    bvh_box *boxes = malloc((primitive_count ? primitive_count : 1) * sizeof *boxes);
    if (boxes == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    for (uint32_t i = 0; i < primitive_count; i++) {
        const scene_sphere *sphere = &s->spheres[i];
        for (int axis = 0; axis < 3; axis++) {
            /* Padded by a few float steps: centre +- radius rounds, and a box that
             * cuts off a sliver of its sphere would make grazing rays miss it. */
            float pad = 1e-6f * (fabsf(sphere->center[axis]) + sphere->radius);
            boxes[i].min[axis] = sphere->center[axis] - sphere->radius - pad;
            boxes[i].max[axis] = sphere->center[axis] + sphere->radius + pad;
        }
    }
    bvh tree;
    double build_start = seconds_now();
    rt_status status = bvh_build(boxes, primitive_count, options->bvh_config, &tree, error);
    free(boxes);
    if (status != RT_OK)
        return status;
    out->bvh_build_seconds = seconds_now() - build_start;
    out->bvh_depth = tree.depth;

    uint64_t node_count = primitive_count ? tree.node_count : 0;
    uint64_t material_offset = PACKED_HEADER_TEXELS;
    uint64_t primitive_offset = material_offset + (uint64_t)s->material_count * PACKED_MATERIAL_STRIDE;
    uint64_t node_offset = primitive_offset + (uint64_t)primitive_count * PACKED_PRIMITIVE_STRIDE;
    uint64_t texel_count = node_offset + node_count * PACKED_NODE_STRIDE;
    if (texel_count > UINT32_MAX / 4) {
        bvh_free(&tree);
        return rt_error_set(error, RT_ERROR_INPUT, "PACK: the scene needs %llu texels, more than 32-bit indices reach",
                            (unsigned long long)texel_count);
    }
    uint32_t *texels = calloc(texel_count, 4 * sizeof(uint32_t));
    if (texels == NULL) {
        bvh_free(&tree);
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory for %llu texels",
                            (unsigned long long)texel_count);
    }

    put_texel(texels, 0, PACKED_MAGIC, PACKED_LAYOUT_VERSION, (uint32_t)material_offset, (uint32_t)s->material_count);
    put_texel(texels, 1, (uint32_t)primitive_offset, primitive_count, (uint32_t)node_offset, (uint32_t)node_count);

    for (int i = 0; i < s->material_count; i++) {
        const scene_material *m = &s->materials[i];
        uint32_t base = (uint32_t)material_offset + (uint32_t)i * PACKED_MATERIAL_STRIDE;
        put_texel(texels, base + 0, (uint32_t)m->type, float_bits(m->albedo[0]), float_bits(m->albedo[1]),
                  float_bits(m->albedo[2]));
        put_texel(texels, base + 1, float_bits(m->emission[0]), float_bits(m->emission[1]),
                  float_bits(m->emission[2]), float_bits(m->fuzz));
        put_texel(texels, base + 2, float_bits(m->index_of_refraction), 0, 0, 0);
    }

    for (uint32_t slot = 0; slot < primitive_count; slot++) {
        const scene_sphere *sphere = &s->spheres[tree.primitive_indices[slot]];
        uint32_t base = (uint32_t)primitive_offset + slot * PACKED_PRIMITIVE_STRIDE;
        put_texel(texels, base + 0, PRIMITIVE_SPHERE, (uint32_t)sphere->material, 0, 0);
        put_texel(texels, base + 1, float_bits(sphere->center[0]), float_bits(sphere->center[1]),
                  float_bits(sphere->center[2]), float_bits(sphere->radius));
    }

    for (uint32_t n = 0; n < node_count; n++) {
        const bvh_node *node = &tree.nodes[n];
        uint32_t base = (uint32_t)node_offset + n * PACKED_NODE_STRIDE;
        put_texel(texels, base + 0, float_bits(node->box.min[0]), float_bits(node->box.min[1]),
                  float_bits(node->box.min[2]), node->first);
        put_texel(texels, base + 1, float_bits(node->box.max[0]), float_bits(node->box.max[1]),
                  float_bits(node->box.max[2]), node->count);
    }
    bvh_free(&tree);

    out->texels = texels;
    out->texel_count = (uint32_t)texel_count;
    out->material_offset = (uint32_t)material_offset;
    out->material_count = (uint32_t)s->material_count;
    out->primitive_offset = (uint32_t)primitive_offset;
    out->primitive_count = primitive_count;
    out->node_offset = (uint32_t)node_offset;
    out->node_count = (uint32_t)node_count;
    return RT_OK;
}

void packed_scene_free(packed_scene *packed)
{
    free(packed->texels);
    memset(packed, 0, sizeof *packed);
}

uint32_t packed_uint(const packed_scene *packed, uint32_t texel, int component)
{
    return packed->texels[4 * (size_t)texel + component];
}

float packed_float(const packed_scene *packed, uint32_t texel, int component)
{
    return bits_float(packed_uint(packed, texel, component));
}

packed_primitive packed_primitive_at(const packed_scene *packed, uint32_t slot)
{
    uint32_t base = packed->primitive_offset + slot * PACKED_PRIMITIVE_STRIDE;
    packed_primitive primitive = {
        .type = packed_uint(packed, base, 0),
        .material = packed_uint(packed, base, 1),
    };
    for (int i = 0; i < 4; i++)
        primitive.sphere[i] = packed_float(packed, base + 1, i);
    return primitive;
}

/* The shader's sphere test (tracer.frag, intersect_sphere), in C. */
static float intersect_sphere(const float sphere[4], const float origin[3], const float direction[3], float t_max)
{
    float to_origin[3], closest[3];
    for (int i = 0; i < 3; i++)
        to_origin[i] = origin[i] - sphere[i];
    float b = to_origin[0] * direction[0] + to_origin[1] * direction[1] + to_origin[2] * direction[2];
    for (int i = 0; i < 3; i++)
        closest[i] = to_origin[i] - b * direction[i];
    float radius_squared = sphere[3] * sphere[3];
    float discriminant = radius_squared - (closest[0] * closest[0] + closest[1] * closest[1] + closest[2] * closest[2]);
    if (discriminant < 0)
        return INFINITY;
    float root = sqrtf(discriminant);
    float c = to_origin[0] * to_origin[0] + to_origin[1] * to_origin[1] + to_origin[2] * to_origin[2] - radius_squared;
    float q = -b - (b >= 0 ? root : -root);
    float t_near = c / q, t_far = q;
    if (t_near > t_far) {
        float swap = t_near;
        t_near = t_far;
        t_far = swap;
    }
    if (t_near > 0 && t_near < t_max)
        return t_near;
    if (t_far > 0 && t_far < t_max)
        return t_far;
    return INFINITY;
}

/* The shader's slab test (tracer.frag, intersect_box), in C. */
static float intersect_box(const packed_scene *packed, uint32_t node, const float origin[3],
                           const float inverse_direction[3], float t_max)
{
    uint32_t base = packed->node_offset + node * PACKED_NODE_STRIDE;
    float enter = 0, leave = t_max;
    for (int axis = 0; axis < 3; axis++) {
        float t0 = (packed_float(packed, base, axis) - origin[axis]) * inverse_direction[axis];
        float t1 = (packed_float(packed, base + 1, axis) - origin[axis]) * inverse_direction[axis];
        enter = fmaxf(enter, fminf(t0, t1));
        leave = fminf(leave, fmaxf(t0, t1));
    }
    return enter <= leave ? enter : INFINITY;
}

uint32_t packed_intersect_nearest(const packed_scene *packed, const float origin[3], const float direction[3],
                                  float t_max, float *t_hit)
{
    float nearest = t_max;
    uint32_t nearest_slot = UINT32_MAX;
    *t_hit = INFINITY;
    if (packed->node_count == 0)
        return UINT32_MAX;
    float inverse_direction[3];
    for (int i = 0; i < 3; i++)
        inverse_direction[i] = 1.0f / direction[i];
    if (intersect_box(packed, 0, origin, inverse_direction, INFINITY) == INFINITY)
        return UINT32_MAX;
    uint32_t stack_node[BVH_MAX_DEPTH + 1];
    float stack_entry[BVH_MAX_DEPTH + 1];
    int stack_size = 0;
    uint32_t node = 0;
    float node_entry = 0;
    for (;;) {
        if (node_entry < nearest) {
            uint32_t base = packed->node_offset + node * PACKED_NODE_STRIDE;
            uint32_t first = packed_uint(packed, base, 3), count = packed_uint(packed, base + 1, 3);
            if (count > 0) {
                for (uint32_t slot = first; slot < first + count; slot++) {
                    packed_primitive primitive = packed_primitive_at(packed, slot);
                    float t = intersect_sphere(primitive.sphere, origin, direction, nearest);
                    if (t < nearest) {
                        nearest = t;
                        nearest_slot = slot;
                    }
                }
            } else {
                float left = intersect_box(packed, first, origin, inverse_direction, nearest);
                float right = intersect_box(packed, first + 1, origin, inverse_direction, nearest);
                uint32_t near_node = right < left ? first + 1 : first;
                float near_entry = fminf(left, right), far_entry = fmaxf(left, right);
                if (near_entry < INFINITY) {
                    if (far_entry < INFINITY && stack_size <= BVH_MAX_DEPTH) {
                        stack_node[stack_size] = near_node == first ? first + 1 : first;
                        stack_entry[stack_size] = far_entry;
                        stack_size++;
                    }
                    node = near_node;
                    node_entry = near_entry;
                    continue;
                }
            }
        }
        if (stack_size == 0)
            break;
        stack_size--;
        node = stack_node[stack_size];
        node_entry = stack_entry[stack_size];
    }
    if (nearest_slot != UINT32_MAX)
        *t_hit = nearest;
    return nearest_slot;
}
