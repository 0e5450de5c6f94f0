/* pack_geometry.c: the packer's geometry sections (pack_internal.h): primitive records,
 * their info and shape records, the BVH nodes, the vertices and uvs, the instances. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pack_internal.h"

rt_status pack_order_vertices(packer *p, uint32_t *vertex_count, rt_error *error)
{
    /* Vertices are stored in the order the triangles, in leaf order, first use them: a
     * leaf's triangles then read neighbouring vertex texels (docs/performance.md, the log:
     * vertices renumbered). Unused ones are dropped. */
    const scene *s = p->scene;
    p->vertex_order = malloc(((size_t)p->vertices.count + 1) * sizeof *p->vertex_order);
    if (p->vertex_order == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    for (uint32_t v = 0; v < p->vertices.count; v++)
        p->vertex_order[v] = UINT32_MAX;
    uint32_t count = 0;
    for (int o = -1; o < s->object_count; o++) {
        const built_tree *built = o < 0 ? &p->top : &p->objects[o];
        if (o >= 0 && !p->object_needed[o])
            continue;
        for (uint32_t slot = 0; slot < built->primitives.count; slot++) {
            const pending_primitive *item = &built->primitives.items[built->tree.primitive_indices[slot]];
            if (item->type != PRIMITIVE_TRIANGLE)
                continue;
            for (int k = 0; k < 3; k++)
                if (p->vertex_order[item->vertices[k]] == UINT32_MAX)
                    p->vertex_order[item->vertices[k]] = count++;
        }
    }
    *vertex_count = count;
    return RT_OK;
}

/* Writes the record and the info of the primitive in global_slot; a moving sphere's or a
 * quad's shape record goes to *next_shape, which moves past it. */
static void write_primitive(packer *p, const pending_primitive *item, uint64_t global_slot, uint64_t *next_shape)
{
    uint32_t *texels = p->texels;
    uint64_t base = p->layout.primitive_offset + global_slot * PACKED_PRIMITIVE_STRIDE;
    const float (*d)[4] = item->data;
    switch (item->type) {
    case PRIMITIVE_SPHERE:
        put_texel(texels, base, float_bits(d[0][0]), float_bits(d[0][1]), float_bits(d[0][2]), float_bits(d[0][3]));
        break;
    case PRIMITIVE_TRIANGLE:
        put_texel(texels, base, p->vertex_order[item->vertices[0]], p->vertex_order[item->vertices[1]],
                  p->vertex_order[item->vertices[2]], PRIMITIVE_RECORD_TAG + PRIMITIVE_TRIANGLE);
        break;
    case PRIMITIVE_INSTANCE:
        put_texel(texels, base, item->instance, 0, 0, PRIMITIVE_RECORD_TAG + PRIMITIVE_INSTANCE);
        break;
    default: { /* moving sphere, quad: the record points at its shape texels */
        int count = item->type == PRIMITIVE_QUAD ? PACKED_QUAD_TEXELS : PACKED_MOVING_SPHERE_TEXELS;
        put_texel(texels, base, (uint32_t)*next_shape, 0, 0, PRIMITIVE_RECORD_TAG + item->type);
        for (int k = 0; k < count; k++)
            put_texel(texels, *next_shape + k, float_bits(d[k][0]), float_bits(d[k][1]), float_bits(d[k][2]),
                      float_bits(d[k][3]));
        *next_shape += count;
    }
    }
    uint32_t material = item->material == PACKED_NONE ? PRIMITIVE_NO_MATERIAL : item->material;
    texels[4 * (p->layout.info_offset + global_slot / 4) + global_slot % 4] =
        item->type << PRIMITIVE_INFO_TYPE_SHIFT | (item->has_uvs ? PRIMITIVE_INFO_HAS_UVS : 0) | material;
    p->out->triangle_count += item->type == PRIMITIVE_TRIANGLE;
    p->out->summary.primitive_types |= 1u << item->type;
}

/* The packed first of a node of one BVH: its child or leaf index moved to where the BVH
 * landed. */
static uint32_t packed_first(const built_tree *built, const bvh_node *node)
{
    return node->count ? node->first + built->primitive_base : node->first + built->node_base;
}

/* Writes the nodes of one BVH. */
static void write_nodes(packer *p, const built_tree *built)
{
    for (uint32_t n = 0; n < built->tree.node_count; n++) {
        const bvh_node *node = &built->tree.nodes[n];
        uint64_t base = p->layout.node_offset + ((uint64_t)built->node_base + n) * PACKED_NODE_STRIDE;
        uint32_t first = packed_first(built, node);
        put_texel(p->texels, base + 0, float_bits(node->box.min[0]), float_bits(node->box.min[1]),
                  float_bits(node->box.min[2]), first);
        put_texel(p->texels, base + 1, float_bits(node->box.max[0]), float_bits(node->box.max[1]),
                  float_bits(node->box.max[2]), node->count);
    }
}

void pack_write_primitives(packer *p)
{
    uint64_t next_shape = p->layout.shape_offset;
    for (int o = -1; o < p->scene->object_count; o++) {
        const built_tree *built = o < 0 ? &p->top : &p->objects[o];
        if (o >= 0 && !p->object_needed[o])
            continue;
        if (built->primitives.count == 0)
            continue;
        for (uint32_t slot = 0; slot < built->primitives.count; slot++)
            write_primitive(p, &built->primitives.items[built->tree.primitive_indices[slot]],
                            (uint64_t)built->primitive_base + slot, &next_shape);
        write_nodes(p, built);
    }
}

uint64_t pack_threaded_items(const packer *p)
{
    const built_tree *top = &p->top;
    if (p->options->no_threaded_walk || p->packed_instances > 0 || top->primitives.count == 0)
        return 0;
    for (uint32_t i = 0; i < top->primitives.count; i++)
        if (top->primitives.items[i].type != PRIMITIVE_SPHERE && top->primitives.items[i].type != PRIMITIVE_QUAD)
            return 0;
    uint64_t interior = 0;
    for (uint32_t n = 0; n < top->tree.node_count; n++)
        interior += top->tree.nodes[n].count == 0;
    /* Every interior node's box but the root's (packed_layout.h), and every primitive. */
    uint64_t items = interior - (interior > 0) + top->primitives.count;
    return items * PACKED_THREADED_ORDERS * pack_threaded_stride(p) <= PACKED_THREADED_MAX_TEXELS ? items : 0;
}

uint32_t pack_threaded_stride(const packer *p)
{
    for (uint32_t i = 0; i < p->top.primitives.count; i++)
        if (p->top.primitives.items[i].type == PRIMITIVE_QUAD)
            return PACKED_THREADED_QUAD_ITEM_STRIDE;
    return PACKED_THREADED_ITEM_STRIDE;
}

/* Whether a ray of octant (packed_layout.h "threaded walk") meets an interior node's right
 * child first: along the axis on which the children's centres lie farthest apart, the
 * child on the ray's side of the other comes second. */
static bool right_child_first(const bvh_node *left, const bvh_node *right, int octant)
{
    int axis = 0;
    float widest = -1;
    for (int a = 0; a < 3; a++) {
        float apart = fabsf((right->box.min[a] + right->box.max[a]) - (left->box.min[a] + left->box.max[a]));
        if (apart > widest) {
            widest = apart;
            axis = a;
        }
    }
    bool right_above = right->box.min[axis] + right->box.max[axis] > left->box.min[axis] + left->box.max[axis];
    bool negative = (octant >> axis) & 1;
    return right_above == negative;
}

static uint32_t write_threaded_subtree(packer *p, uint32_t n, int octant, uint64_t list, uint32_t item);

/* Writes the subtrees of interior node's two children into octant's list at list from
 * item on, in the order the octant's rays meet them; returns the item after them. */
static uint32_t write_threaded_children(packer *p, const bvh_node *node, int octant, uint64_t list, uint32_t item)
{
    const bvh_node *nodes = p->top.tree.nodes;
    bool right_first = right_child_first(&nodes[node->first], &nodes[node->first + 1], octant);
    item = write_threaded_subtree(p, node->first + right_first, octant, list, item);
    return write_threaded_subtree(p, node->first + !right_first, octant, list, item);
}

/* Writes node n's subtree of the top BVH into octant's list at list (its first texel) from
 * item on, depth first; returns the item after it. Recursion is as deep as the BVH
 * (BVH_MAX_DEPTH). */
static uint32_t write_threaded_subtree(packer *p, uint32_t n, int octant, uint64_t list, uint32_t item)
{
    const built_tree *top = &p->top;
    const bvh_node *node = &top->tree.nodes[n];
    uint32_t stride = (uint32_t)p->layout.threaded_stride;
    if (node->count > 0) {
        for (uint32_t k = 0; k < node->count; k++, item++) {
            uint32_t slot = top->primitive_base + node->first + k;
            const uint32_t *record = &p->texels[4 * (p->layout.primitive_offset + slot)];
            uint64_t base = list + (uint64_t)item * stride;
            if (record[3] == PRIMITIVE_RECORD_TAG + PRIMITIVE_QUAD) {
                const uint32_t *shape = &p->texels[4 * (uint64_t)record[0]];   /* Q, u, v */
                put_texel(p->texels, base, shape[0], shape[1], shape[2], item + 1);
                put_texel(p->texels, base + 1, shape[4], shape[5], shape[6], THREADED_QUAD | slot);
                put_texel(p->texels, base + 2, shape[8], shape[9], shape[10], 0);
            } else {
                put_texel(p->texels, base, record[0], record[1], record[2], item + 1);   /* (centre, radius) */
                put_texel(p->texels, base + 1, record[3], 0, 0, THREADED_SPHERE | slot);
            }
        }
        return item;
    }
    uint32_t own = item++;
    item = write_threaded_children(p, node, octant, list, item);
    /* The corners in the order the octant's rays meet them (packed_layout.h): the shader's
     * slab test then takes no minimum and maximum per axis, which llvmpipe compiles to three
     * instructions each (docs/performance.md, the log). */
    float near[3], far[3];
    for (int axis = 0; axis < 3; axis++) {
        bool negative = (octant >> axis) & 1;
        near[axis] = negative ? node->box.max[axis] : node->box.min[axis];
        far[axis] = negative ? node->box.min[axis] : node->box.max[axis];
    }
    uint64_t base = list + (uint64_t)own * stride;
    put_texel(p->texels, base, float_bits(near[0]), float_bits(near[1]), float_bits(near[2]), item);
    put_texel(p->texels, base + 1, float_bits(far[0]), float_bits(far[1]), float_bits(far[2]), 0);
    return item;
}

void pack_write_threaded(packer *p)
{
    const pack_layout *layout = &p->layout;
    const bvh_node *root = &p->top.tree.nodes[0];
    for (int octant = 0; octant < PACKED_THREADED_ORDERS && layout->threaded_items > 0; octant++) {
        uint64_t list = layout->threaded_offset + (uint64_t)octant * layout->threaded_items * layout->threaded_stride;
        /* No item for the root's box: nearly every ray starts inside it (the scene's
         * bounds), so its test is an iteration of every walk that culls nothing; a ray
         * that misses it misses its children's boxes as well. */
        if (root->count == 0)
            write_threaded_children(p, root, octant, list, 0);
        else
            write_threaded_subtree(p, 0, octant, list, 0);
    }
}

uint32_t packed_encode_normal(const float normal[3])
{
    float sum = fabsf(normal[0]) + fabsf(normal[1]) + fabsf(normal[2]);
    float x = sum > 0 ? normal[0] / sum : 0, y = sum > 0 ? normal[1] / sum : 0;
    if (sum > 0 && normal[2] < 0) {
        float folded_x = (1 - fabsf(y)) * (x >= 0 ? 1.0f : -1.0f);
        y = (1 - fabsf(x)) * (y >= 0 ? 1.0f : -1.0f);
        x = folded_x;
    }
    int16_t qx = (int16_t)lrintf(fmaxf(-1.0f, fminf(1.0f, x)) * 32767.0f);
    int16_t qy = (int16_t)lrintf(fmaxf(-1.0f, fminf(1.0f, y)) * 32767.0f);
    return (uint32_t)(uint16_t)qx | (uint32_t)(uint16_t)qy << 16;
}

bool pack_needs_vertex_colors(const scene *s)
{
    bool asked = false, given = false;
    for (int i = 0; i < s->material_count; i++)
        asked |= s->materials[i].type == MATERIAL_PBR && s->materials[i].vertex_colors;
    for (int i = 0; i < s->mesh_count; i++)
        given |= s->meshes[i].colors != NULL;
    return asked && given;
}

/* Two values from 0 to 1 as unsigned 16-bit fractions in one word, a low (GLSL's
 * unpackUnorm2x16). */
static uint32_t unorm16_pair(float a, float b)
{
    float values[2] = {a, b};
    uint32_t word = 0;
    for (int k = 0; k < 2; k++) {
        float clamped = values[k] > 0 ? (values[k] < 1 ? values[k] : 1) : 0;   /* NaN: 0 */
        word |= (uint32_t)lrintf(clamped * 65535.0f) << (16 * k);
    }
    return word;
}

void pack_write_vertices(packer *p)
{
    const pack_layout *layout = &p->layout;
    for (uint32_t old = 0; old < p->vertices.count; old++) {
        uint32_t v = p->vertex_order[old];
        if (v == UINT32_MAX)
            continue;
        const pending_vertex *vertex = &p->vertices.items[old];
        put_texel(p->texels, layout->vertex_offset + v, float_bits(vertex->position[0]), float_bits(vertex->position[1]),
                  float_bits(vertex->position[2]),
                  vertex->has_normal ? packed_encode_normal(vertex->normal) : VERTEX_NO_NORMAL);
        p->texels[4 * (layout->uv_offset + v / 2) + 2 * (v % 2)] = float_bits(vertex->uv[0]);
        p->texels[4 * (layout->uv_offset + v / 2) + 2 * (v % 2) + 1] = float_bits(vertex->uv[1]);
        if (layout->color_offset != PACKED_NONE) {
            p->texels[4 * (layout->color_offset + v / 2) + 2 * (v % 2)] =
                unorm16_pair(vertex->color[0], vertex->color[1]);
            p->texels[4 * (layout->color_offset + v / 2) + 2 * (v % 2) + 1] =
                unorm16_pair(vertex->color[2], 1);
        }
    }
    p->out->summary.vertex_colors = layout->color_offset != PACKED_NONE;
}

rt_status pack_write_instances(packer *p, rt_error *error)
{
    /* Each: the (first, count) of the object's root node, material, world-to-object
     * matrix, volume. */
    const scene *s = p->scene;
    for (int i = 0; i < s->instance_count; i++) {
        uint32_t packed_index = p->instance_of_scene[i];
        if (packed_index == PACKED_NONE)
            continue;
        const scene_instance *instance = &s->instances[i];
        float world_to_object[3][4];
        if (!pack_invert_affine(instance->object_to_world, world_to_object))
            return rt_error_set(error, RT_ERROR_INPUT, "PACK: instance %d has a transform that cannot be inverted", i);
        uint64_t base = p->layout.instance_offset + (uint64_t)packed_index * PACKED_INSTANCE_STRIDE;
        const built_tree *object = &p->objects[instance->object];
        const bvh_node *root = &object->tree.nodes[0];
        put_texel(p->texels, base, packed_first(object, root),
                  instance->material >= 0 ? (uint32_t)instance->material : PACKED_NONE,
                  instance->volume ? INSTANCE_VOLUME : 0, root->count);
        for (int r = 0; r < 3; r++)
            put_texel(p->texels, base + 1 + r, float_bits(world_to_object[r][0]), float_bits(world_to_object[r][1]),
                      float_bits(world_to_object[r][2]), float_bits(world_to_object[r][3]));
        put_texel(p->texels, base + 4, float_bits(instance->density), float_bits(instance->volume_albedo[0]),
                  float_bits(instance->volume_albedo[1]), float_bits(instance->volume_albedo[2]));
        p->out->summary.volumes |= instance->volume;
    }
    return RT_OK;
}
