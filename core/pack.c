/* pack.c: see pack.h. pack_scene plans the layout and calls one writer per section; the
 * steps live in core/pack_collect.c, pack_geometry.c, pack_lights.c and pack_materials.c
 * (pack_internal.h says which does what). */
#include "pack.h"

#include <stdlib.h>
#include <string.h>

#include "hash.h"
#include "light_tree.h"
#include "pack_internal.h"
#include "tracer_interface.h"

/* The shader's traversal stack keeps a leaf's primitive count in the 32 - PACKED_FIRST_BITS
 * top bits of a word, beside the counts 6 and 7 that mark instances (glsl/traverse.glsl). */
_Static_assert(BVH_MAX_LEAF_SIZE < 6 && 32 - PACKED_FIRST_BITS >= 3, "a leaf's count must fit below the instance marks");

pack_options pack_options_defaults(void)
{
    return (pack_options){0};
}

/* Places the BVHs one after another, the top level first (root: node 0), then each
 * object's: sets each tree's node and primitive base and the layout's node, primitive and
 * shape counts. */
static void place_trees(packer *p)
{
    pack_layout *layout = &p->layout;
    uint64_t node_count = p->top.primitives.count ? p->top.tree.node_count : 0;
    uint64_t primitive_count = p->top.primitives.count;
    uint64_t shape_texels = 0;
    for (int o = -1; o < p->scene->object_count; o++) {
        built_tree *built = o < 0 ? &p->top : &p->objects[o];
        if (o >= 0 && !p->object_needed[o])
            continue;
        if (o >= 0) {
            /* Every BVH's root at an even node, so that sibling pairs (at odd nodes) start
             * on a 64-byte boundary (see plan_layout). */
            node_count += node_count % 2;
            built->node_base = (uint32_t)node_count;
            built->primitive_base = (uint32_t)primitive_count;
            node_count += built->tree.node_count;
            primitive_count += built->primitives.count;
        }
        for (uint32_t k = 0; k < built->primitives.count; k++) {
            uint32_t type = built->primitives.items[k].type;
            shape_texels += type == PRIMITIVE_MOVING_SPHERE ? PACKED_MOVING_SPHERE_TEXELS
                            : type == PRIMITIVE_QUAD        ? PACKED_QUAD_TEXELS
                                                            : 0;
        }
    }
    layout->node_count = node_count;
    layout->primitive_count = primitive_count;
    layout->shape_texels = shape_texels;
}

/* Plans where every section of packed_layout.h starts, in its order, and how large the
 * whole is. A scene that 32-bit indices (or the tracer's PACKED_FIRST_BITS) cannot reach
 * is RT_ERROR_INPUT. */
static rt_status plan_layout(packer *p, rt_error *error)
{
    const scene *s = p->scene;
    pack_layout *layout = &p->layout;
    place_trees(p);
    if (layout->node_count >= (1ull << PACKED_FIRST_BITS) || layout->primitive_count >= (1ull << PACKED_FIRST_BITS))
        return rt_error_set(error, RT_ERROR_INPUT,
                            "PACK: %llu BVH nodes and %llu primitives, more than the %llu the tracer can name",
                            (unsigned long long)layout->node_count, (unsigned long long)layout->primitive_count,
                            (unsigned long long)(1ull << PACKED_FIRST_BITS) - 1);
    uint32_t vertex_count = 0;
    rt_status status = pack_order_vertices(p, &vertex_count, error);
    if (status != RT_OK)
        return status;
    layout->vertex_count = vertex_count;
    layout->material_count = (uint64_t)s->material_count + 1;
    if (layout->material_count >= PRIMITIVE_NO_MATERIAL)
        return rt_error_set(error, RT_ERROR_INPUT, "PACK: %d materials, more than the %d a primitive can name",
                            s->material_count, PRIMITIVE_NO_MATERIAL - 1);
    layout->material_offset = PACKED_HEADER_TEXELS;
    layout->primitive_offset = layout->material_offset + layout->material_count * PACKED_MATERIAL_STRIDE;
    layout->info_offset = layout->primitive_offset + layout->primitive_count * PACKED_PRIMITIVE_STRIDE;
    layout->shape_offset = layout->info_offset + (layout->primitive_count + 3) / 4;
    layout->vertex_offset = layout->shape_offset + layout->shape_texels;
    layout->uv_offset = layout->vertex_offset + vertex_count;
    uint64_t after_uvs = layout->uv_offset + (vertex_count + 1) / 2;
    layout->color_offset = PACKED_NONE;
    if (pack_needs_vertex_colors(s)) {
        layout->color_offset = after_uvs;
        after_uvs += (vertex_count + 1) / 2;
    }
    /* A node is 32 bytes and an interior node reads its two children, first and first + 1,
     * which are contiguous: with node_offset 2 mod 4 texels and every pair at an odd node,
     * each pair is one 64-byte cache line instead of straddling two (the buffer itself
     * is 64-byte aligned). */
    layout->node_offset = after_uvs;
    layout->node_offset += (6 - layout->node_offset % 4) % 4;
    layout->instance_offset = layout->node_offset + layout->node_count * PACKED_NODE_STRIDE;
    layout->texture_offset = layout->instance_offset + (uint64_t)p->packed_instances * PACKED_INSTANCE_STRIDE;
    layout->image_offset = layout->texture_offset + (uint64_t)s->texture_count * PACKED_TEXTURE_STRIDE;
    /* Lights: the emissive world primitives, the scene's lights, and an equirectangular
     * environment, importance-sampled by luminance. */
    layout->area_light_count = pack_count_area_lights(p);
    layout->light_count = layout->area_light_count + (uint64_t)s->light_count;
    if (s->sky.type == SKY_ENVIRONMENT && s->sky.environment >= 0 && s->sky.environment < s->image_count
        && s->images[s->sky.environment].pixels != NULL)
        p->environment = &s->images[s->sky.environment];
    if (p->environment != NULL) {
        layout->light_count++;
        layout->environment_texels = (uint64_t)p->environment->height * (1 + (uint64_t)p->environment->width);
    }
    layout->light_offset = layout->image_offset + (uint64_t)s->image_count * PACKED_IMAGE_STRIDE;
    layout->environment_offset = layout->light_offset + layout->light_count * PACKED_LIGHT_STRIDE;
    /* More lights than the tracer weighs one by one: a light tree (core/light_tree.h). */
    layout->light_tree_offset = PACKED_NONE;
    layout->light_tree_nodes = 0;
    uint64_t after_lights = layout->environment_offset + layout->environment_texels;
    if (layout->light_count > LIGHT_TREE_MAX_LIGHTS)
        return rt_error_set(error, RT_ERROR_INPUT, "PACK: %llu lights, more than the %u the light tree takes",
                            (unsigned long long)layout->light_count, LIGHT_TREE_MAX_LIGHTS);
    if (layout->light_count > LIGHT_LOCAL_CHOICE_MAX) {
        layout->light_tree_offset = after_lights;
        layout->light_tree_nodes = 2 * layout->light_count - 1;
        after_lights += layout->light_tree_nodes * PACKED_LIGHT_TREE_NODE_STRIDE;
    }
    layout->threaded_items = pack_threaded_items(p);
    layout->threaded_stride = pack_threaded_stride(p);
    layout->threaded_offset = layout->threaded_items ? after_lights : 0;
    after_lights += layout->threaded_items * PACKED_THREADED_ORDERS * layout->threaded_stride;
    layout->pixel_offset = after_lights;
    uint64_t image_pixels = 0;
    for (int i = 0; i < s->image_count; i++)
        image_pixels += (uint64_t)s->images[i].width * s->images[i].height;
    layout->texel_count = layout->pixel_offset + image_pixels;
    if (layout->texel_count > UINT32_MAX / 4)
        return rt_error_set(error, RT_ERROR_INPUT, "PACK: the scene needs %llu texels, more than 32-bit indices reach",
                            (unsigned long long)layout->texel_count);
    return RT_OK;
}

/* Writes the header (packed_layout.h) and copies the plan into *out. */
static void write_header(packer *p)
{
    const pack_layout *l = &p->layout;
    packed_scene *out = p->out;
    out->texel_count = (uint32_t)l->texel_count;
    out->material_offset = (uint32_t)l->material_offset;
    out->material_count = (uint32_t)l->material_count;
    out->default_material = (uint32_t)p->scene->material_count;
    out->primitive_offset = (uint32_t)l->primitive_offset;
    out->primitive_count = (uint32_t)l->primitive_count;
    out->info_offset = (uint32_t)l->info_offset;
    out->shape_offset = (uint32_t)l->shape_offset;
    out->shape_texels = (uint32_t)l->shape_texels;
    out->vertex_offset = (uint32_t)l->vertex_offset;
    out->vertex_count = (uint32_t)l->vertex_count;
    out->uv_offset = (uint32_t)l->uv_offset;
    out->color_offset = (uint32_t)l->color_offset;
    out->node_offset = (uint32_t)l->node_offset;
    out->node_count = (uint32_t)l->node_count;
    out->instance_offset = (uint32_t)l->instance_offset;
    out->instance_count = p->packed_instances;
    out->texture_offset = (uint32_t)l->texture_offset;
    out->texture_count = (uint32_t)p->scene->texture_count;
    out->image_offset = (uint32_t)l->image_offset;
    out->image_count = (uint32_t)p->scene->image_count;
    out->light_offset = (uint32_t)l->light_offset;
    out->light_count = (uint32_t)l->light_count;
    out->area_light_count = (uint32_t)l->area_light_count;
    out->light_tree_offset = (uint32_t)l->light_tree_offset;
    out->threaded_offset = (uint32_t)l->threaded_offset;
    out->threaded_items = (uint32_t)l->threaded_items;
    uint32_t environment_offset = (uint32_t)l->environment_offset;
    put_texel(p->texels, 0, PACKED_MAGIC, PACKED_LAYOUT_VERSION, out->material_offset, out->material_count);
    put_texel(p->texels, 1, out->primitive_offset, out->primitive_count, out->node_offset, out->node_count);
    put_texel(p->texels, 2, out->instance_offset, out->instance_count, out->info_offset, out->default_material);
    put_texel(p->texels, 3, out->texture_offset, out->texture_count, out->image_offset, out->image_count);
    put_texel(p->texels, 4, out->light_offset, out->light_count, environment_offset, out->area_light_count);
    put_texel(p->texels, 5, out->shape_offset, out->vertex_offset, out->uv_offset, out->vertex_count);
    put_texel(p->texels, 6, out->color_offset, out->light_tree_offset, out->threaded_offset, out->threaded_items);
}

/* Allocates the packer's per-object, per-instance and per-mesh arrays. */
static rt_status start_packer(packer *p, rt_error *error)
{
    const scene *s = p->scene;
    p->objects = calloc((size_t)s->object_count + 1, sizeof *p->objects);
    p->object_needed = calloc((size_t)s->object_count + 1, sizeof *p->object_needed);
    p->instance_of_scene = calloc((size_t)s->instance_count + 1, sizeof *p->instance_of_scene);
    p->mesh_first_vertex = malloc(((size_t)s->mesh_count + 1) * sizeof *p->mesh_first_vertex);
    if (p->objects == NULL || p->object_needed == NULL || p->instance_of_scene == NULL || p->mesh_first_vertex == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    for (int m = 0; m < s->mesh_count; m++)
        p->mesh_first_vertex[m] = UINT32_MAX;
    return RT_OK;
}

/* Frees what the packer holds (not the texels it handed out). */
static void finish_packer(packer *p)
{
    free(p->texels);
    free(p->top.primitives.items);
    bvh_free(&p->top.tree);
    if (p->objects != NULL)
        for (int o = 0; o < p->scene->object_count; o++) {
            free(p->objects[o].primitives.items);
            bvh_free(&p->objects[o].tree);
        }
    free(p->objects);
    free(p->object_needed);
    free(p->instance_of_scene);
    free(p->mesh_first_vertex);
    free(p->vertex_order);
    free(p->vertices.items);
}

rt_status pack_scene(const scene *s, const pack_options *options, packed_scene *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    pack_options defaults = pack_options_defaults();
    packer p = {.scene = s, .options = options != NULL ? options : &defaults, .out = out};
    rt_status status = start_packer(&p, error);
    if (status == RT_OK)
        status = pack_collect(&p, error);
    if (status == RT_OK)
        status = pack_build_trees(&p, error);
    if (status == RT_OK)
        status = plan_layout(&p, error);
    if (status == RT_OK) {
        p.texels = calloc(p.layout.texel_count, 4 * sizeof(uint32_t));
        if (p.texels == NULL)
            status = rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory for %llu texels",
                                  (unsigned long long)p.layout.texel_count);
    }
    if (status == RT_OK) {
        write_header(&p);
        pack_write_materials(&p);
        pack_write_primitives(&p);
        pack_write_threaded(&p);
        pack_write_vertices(&p);
        status = pack_write_lights(&p, error);
    }
    if (status == RT_OK)
        status = pack_write_instances(&p, error);
    if (status == RT_OK) {
        pack_write_textures(&p);
        out->texels = p.texels;
        out->texel_hash = hash_bytes(HASH_START, p.texels, (size_t)out->texel_count * 16u);
        p.texels = NULL;
    }
    finish_packer(&p);
    pack_bvh_cache_finish(p.options->bvh_cache, status == RT_OK);
    if (status != RT_OK) {
        double seconds = out->bvh_build_seconds;
        memset(out, 0, sizeof *out);
        out->bvh_build_seconds = seconds;
    }
    return status;
}

void packed_scene_free(packed_scene *packed)
{
    free(packed->texels);
    memset(packed, 0, sizeof *packed);
}
