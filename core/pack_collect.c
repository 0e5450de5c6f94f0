/* pack_collect.c: the packer's first step (pack_internal.h): the scene's primitives into
 * BVH-ready lists, placements copied into the world, baked into it or kept as instances,
 * and the BVHs built over them. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cglm/cglm.h>

#include "array.h"
#include "clock.h"
#include "pack_internal.h"

/* ---- primitives before packing ------------------------------------------------------- */

/* Appends a zeroed vertex (its colour white); returns its index, or UINT32_MAX when memory
 * runs out or the list would pass 32-bit indices. */
static uint32_t vertex_push(vertex_list *list)
{
    if (list->count >= PACK_LIST_LIMIT
        || !array_reserve((void **)&list->items, &list->capacity, (size_t)list->count + 1, sizeof *list->items))
        return UINT32_MAX;
    pending_vertex *vertex = &list->items[list->count];
    memset(vertex, 0, sizeof *vertex);
    vertex->color[0] = vertex->color[1] = vertex->color[2] = 1;
    return list->count++;
}

/* Appends an item; returns a pointer to it, or NULL when memory runs out. */
static pending_primitive *list_push(primitive_list *list)
{
    if (list->count >= PACK_LIST_LIMIT
        || !array_reserve((void **)&list->items, &list->capacity, (size_t)list->count + 1, sizeof *list->items))
        return NULL;
    pending_primitive *item = &list->items[list->count++];
    memset(item, 0, sizeof *item);
    item->material = PACKED_NONE;
    item->instance = PACKED_NONE;
    return item;
}

/* Pads a box by a few float steps: corners computed in float round, and a box that cuts
 * off a sliver of its primitive would make grazing rays miss it. */
static void box_pad(bvh_box *box)
{
    for (int axis = 0; axis < 3; axis++) {
        float pad = 1e-6f * (fabsf(box->min[axis]) + fabsf(box->max[axis])) + 1e-7f;
        box->min[axis] -= pad;
        box->max[axis] += pad;
    }
}

static void sphere_box(bvh_box *box, const float center[3], float radius)
{
    for (int axis = 0; axis < 3; axis++) {
        box->min[axis] = fminf(box->min[axis], center[axis] - radius);
        box->max[axis] = fmaxf(box->max[axis], center[axis] + radius);
    }
}

/* Fills item from a scene shape (material already resolved) and computes its box. */
static void pending_from_shape(pending_primitive *item, const scene_shape *shape, uint32_t material)
{
    item->material = material;
    item->box = bvh_box_empty();
    const float (*p)[3] = shape->points;
    switch (shape->type) {
    case SHAPE_SPHERE:
        item->type = PRIMITIVE_SPHERE;
        memcpy(item->data[0], p[0], 3 * sizeof(float));
        item->data[0][3] = shape->radius;
        sphere_box(&item->box, p[0], shape->radius);
        break;
    case SHAPE_MOVING_SPHERE:
        item->type = PRIMITIVE_MOVING_SPHERE;
        memcpy(item->data[0], p[0], 3 * sizeof(float));
        item->data[0][3] = shape->radius;
        memcpy(item->data[1], p[1], 3 * sizeof(float));
        sphere_box(&item->box, p[0], shape->radius);
        sphere_box(&item->box, p[1], shape->radius);
        break;
    case SHAPE_TRIANGLE:
        item->type = PRIMITIVE_TRIANGLE;
        memcpy(item->data[0], p[0], 3 * sizeof(float));
        glm_vec3_sub((float *)p[1], (float *)p[0], item->data[1]);
        glm_vec3_sub((float *)p[2], (float *)p[0], item->data[2]);
        for (int k = 0; k < 3; k++)
            bvh_box_add_point(&item->box, p[k]);
        break;
    case SHAPE_QUAD:
        item->type = PRIMITIVE_QUAD;
        for (int k = 0; k < 3; k++)
            memcpy(item->data[k], p[k], 3 * sizeof(float));
        for (int corner = 0; corner < 4; corner++) {
            float q[3];
            for (int axis = 0; axis < 3; axis++)
                q[axis] = p[0][axis] + ((corner & 1) ? p[1][axis] : 0) + ((corner & 2) ? p[2][axis] : 0);
            bvh_box_add_point(&item->box, q);
        }
        break;
    }
    box_pad(&item->box);
}

/* Writes m p to out for the affine m (rows x, y, z); with translate false, only m's
 * linear part (for an edge or other direction). */
static void move_point(const float m[3][4], const float p[3], bool translate, float out[3])
{
    vec3 q;
    for (int r = 0; r < 3; r++)
        q[r] = glm_vec3_dot((float *)m[r], (float *)p) + (translate ? m[r][3] : 0.0f);
    glm_vec3_copy(q, out);
}

/* Writes to out the normal n moved by the transpose of inverse (the inverse of a
 * placement), as the shader moves an instance's normals; not renormalised, so that moved
 * normals interpolate to the moved interpolation. */
static void move_normal(const float inverse[3][4], const float n[3], float out[3])
{
    vec3 q;
    for (int c = 0; c < 3; c++) {
        vec3 column = {inverse[0][c], inverse[1][c], inverse[2][c]};
        q[c] = glm_vec3_dot(column, (float *)n);
    }
    glm_vec3_copy(q, out);
}

/* Moves a shape by the affine m (rows x, y, z) whose inverse is inverse: points by m, a
 * quad's edges by its linear part, corner normals by the inverse transpose, a sphere's
 * radius by scale (the caller bakes spheres only under a uniform scale). */
static void transform_shape(scene_shape *shape, const float m[3][4], const float inverse[3][4], float scale)
{
    int points = shape->type == SHAPE_MOVING_SPHERE ? 2 : shape->type == SHAPE_SPHERE ? 1 : 3;
    for (int k = 0; k < points; k++)
        move_point(m, shape->points[k], !(shape->type == SHAPE_QUAD && k > 0), shape->points[k]);
    for (int corner = 0; corner < 3 && shape->has_normals; corner++)
        move_normal(inverse, shape->normals[corner], shape->normals[corner]);
    shape->radius *= scale;
}

/* ---- transforms ---------------------------------------------------------------------- */

/* In double (cglm's inverse is float), so that each entry of the inverse is rounded to
 * float once. */
bool pack_invert_affine(const float m[3][4], float inverse[3][4])
{
    double a[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            a[r][c] = m[r][c];
    double cofactor[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cofactor[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
        }
    double determinant = a[0][0] * cofactor[0][0] + a[0][1] * cofactor[0][1] + a[0][2] * cofactor[0][2];
    if (!(fabs(determinant) > 1e-30))
        return false;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            inverse[r][c] = (float)(cofactor[c][r] / determinant);
    for (int r = 0; r < 3; r++)
        inverse[r][3] = -(inverse[r][0] * m[0][3] + inverse[r][1] * m[1][3] + inverse[r][2] * m[2][3]);
    return true;
}

static bool is_identity(const float m[3][4])
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            if (m[r][c] != (r == c ? 1.0f : 0.0f))
                return false;
    return true;
}

/* The factor s when m's linear part is s times the identity (a uniform scale without
 * rotation, s > 0), else 0. */
static float uniform_scale(const float m[3][4])
{
    float scale = m[0][0];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            if (m[r][c] != (r == c ? scale : 0.0f))
                return 0.0f;
    return scale > 0 ? scale : 0.0f;
}

/* The determinant of m's linear part, in double. */
static double linear_determinant(const float m[3][4])
{
    return (double)m[0][0] * ((double)m[1][1] * m[2][2] - (double)m[1][2] * m[2][1])
           - (double)m[0][1] * ((double)m[1][0] * m[2][2] - (double)m[1][2] * m[2][0])
           + (double)m[0][2] * ((double)m[1][0] * m[2][1] - (double)m[1][1] * m[2][0]);
}

/* Tolerance of similarity_scale: each product of two columns of m's linear part may be
 * this far (relative to the scale squared) from that of a rotation. Transforms are
 * composed in double and stored as float (docs/scene-format.md), which leaves a rotation's
 * column products within about 2e-7 of it; a sphere taken as one under a map this far
 * from a similarity is off by about 5e-7 of its radius, float rounding again. */
#define SIMILARITY_TOLERANCE 1e-6

/* The factor s when m's linear part is s times a rotation (a similarity: uniform scale,
 * rotation, no mirror, s > 0), within SIMILARITY_TOLERANCE; else 0. s is the exact
 * factor when there is no rotation (uniform_scale), else the cube root of the
 * determinant. */
static float similarity_scale(const float m[3][4])
{
    float exact = uniform_scale(m);
    if (exact > 0)
        return exact;
    double gram[3][3];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            gram[a][b] = (double)m[0][a] * m[0][b] + (double)m[1][a] * m[1][b] + (double)m[2][a] * m[2][b];
    double determinant = linear_determinant(m);
    if (!(determinant > 0) || !isfinite(determinant))
        return 0.0f;
    double scale = cbrt(determinant);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            if (!(fabs(gram[a][b] - (a == b ? scale * scale : 0.0)) <= SIMILARITY_TOLERANCE * scale * scale))
                return 0.0f;
    return (float)scale;
}

/* The world box of an object box under object_to_world (its 8 corners transformed). */
static bvh_box transform_box(const bvh_box *box, const float m[3][4])
{
    bvh_box world = bvh_box_empty();
    for (int corner = 0; corner < 8; corner++) {
        float p[3] = {(corner & 1) ? box->max[0] : box->min[0], (corner & 2) ? box->max[1] : box->min[1],
                      (corner & 4) ? box->max[2] : box->min[2]};
        float q[3];
        move_point(m, p, true, q);
        bvh_box_add_point(&world, q);
    }
    box_pad(&world);
    return world;
}

/* ---- BVHs ---------------------------------------------------------------------------- */

/* One tree of a BVH cache (pack.h): the boxes and config it was built from, and it. */
typedef struct cached_tree {
    bvh_box *boxes;
    uint32_t count;
    bvh_build_config config;
    bvh tree;
} cached_tree;

struct pack_bvh_cache {
    cached_tree *kept;           /* the trees of the last finished pack; boxes NULL: taken */
    int kept_count;
    cached_tree *made;           /* the trees of the pack under way */
    int made_count;
    size_t made_capacity;
};

rt_status pack_bvh_cache_create(pack_bvh_cache **out, rt_error *error)
{
    *out = calloc(1, sizeof **out);
    return *out != NULL ? RT_OK : rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory for the BVH cache");
}

/* Frees count trees of a cache's list and the list. */
static void free_cached_trees(cached_tree *trees, int count)
{
    for (int i = 0; i < count; i++) {
        free(trees[i].boxes);
        bvh_free(&trees[i].tree);
    }
    free(trees);
}

void pack_bvh_cache_free(pack_bvh_cache *cache)
{
    if (cache == NULL)
        return;
    free_cached_trees(cache->kept, cache->kept_count);
    free_cached_trees(cache->made, cache->made_count);
    free(cache);
}

void pack_bvh_cache_finish(pack_bvh_cache *cache, bool succeeded)
{
    if (cache == NULL)
        return;
    if (succeeded) {
        free_cached_trees(cache->kept, cache->kept_count);
        cache->kept = cache->made;
        cache->kept_count = cache->made_count;
    } else {
        free_cached_trees(cache->made, cache->made_count);
    }
    cache->made = NULL;
    cache->made_count = 0;
    cache->made_capacity = 0;
}

/* True when a and b build the same tree: the same fields (zero meaning default in both). */
static bool same_config(const bvh_build_config *a, const bvh_build_config *b)
{
    return a->max_leaf_size == b->max_leaf_size && a->bin_count == b->bin_count && a->max_depth == b->max_depth
           && a->traversal_cost == b->traversal_cost && a->intersection_cost == b->intersection_cost;
}

/* Copies tree into *copy (allocated; the caller frees it with bvh_free()). */
static rt_status copy_tree(const bvh *tree, bvh *copy, rt_error *error)
{
    *copy = *tree;
    copy->nodes = malloc(((size_t)tree->node_count + 1) * sizeof *copy->nodes);
    copy->primitive_indices = malloc(((size_t)tree->primitive_count + 1) * sizeof *copy->primitive_indices);
    if (copy->nodes == NULL || copy->primitive_indices == NULL) {
        bvh_free(copy);
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    }
    memcpy(copy->nodes, tree->nodes, (size_t)tree->node_count * sizeof *copy->nodes);
    memcpy(copy->primitive_indices, tree->primitive_indices, (size_t)tree->primitive_count * sizeof *copy->primitive_indices);
    return RT_OK;
}

/* Looks for a tree over exactly these boxes and config in the cache: the last pack's
 * (moved into this pack's list, so that the next pack finds it too) or this pack's.
 * Returns it, or NULL. */
static const cached_tree *find_cached_tree(pack_bvh_cache *cache, const bvh_box *boxes, uint32_t count,
                                           const bvh_build_config *config)
{
    for (int i = 0; i < cache->made_count; i++) {
        const cached_tree *made = &cache->made[i];
        if (made->count == count && same_config(&made->config, config)
            && memcmp(made->boxes, boxes, (size_t)count * sizeof *boxes) == 0)
            return made;
    }
    for (int i = 0; i < cache->kept_count; i++) {
        cached_tree *kept = &cache->kept[i];
        if (kept->boxes == NULL || kept->count != count || !same_config(&kept->config, config)
            || memcmp(kept->boxes, boxes, (size_t)count * sizeof *boxes) != 0)
            continue;
        if (!array_reserve((void **)&cache->made, &cache->made_capacity, (size_t)cache->made_count + 1,
                           sizeof *cache->made))
            return NULL;
        cache->made[cache->made_count] = *kept;
        memset(kept, 0, sizeof *kept);
        return &cache->made[cache->made_count++];
    }
    return NULL;
}

/* Keeps a tree just built in the cache's list of this pack: boxes (taken over; *boxes
 * becomes NULL) and a copy of tree. Running out of memory only leaves it out. */
static void cache_tree(pack_bvh_cache *cache, bvh_box **boxes, uint32_t count, const bvh_build_config *config,
                       const bvh *tree)
{
    cached_tree entry = {.boxes = *boxes, .count = count, .config = *config};
    if (!array_reserve((void **)&cache->made, &cache->made_capacity, (size_t)cache->made_count + 1,
                       sizeof *cache->made)
        || copy_tree(tree, &entry.tree, NULL) != RT_OK)
        return;
    cache->made[cache->made_count++] = entry;
    *boxes = NULL;
}

/* Builds the BVH of list (the list stays in caller order; tree.primitive_indices orders
 * it), or copies the cache's tree over the same boxes; counts which in p->out. */
static rt_status build_tree(packer *p, built_tree *built, rt_error *error)
{
    uint32_t count = built->primitives.count;
    bvh_box *boxes = malloc((count ? count : 1) * sizeof *boxes);
    if (boxes == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    for (uint32_t i = 0; i < count; i++)
        boxes[i] = built->primitives.items[i].box;
    pack_bvh_cache *cache = p->options->bvh_cache;
    bvh_build_config config = p->options->bvh_config != NULL ? *p->options->bvh_config : (bvh_build_config){0};
    const cached_tree *cached = cache != NULL ? find_cached_tree(cache, boxes, count, &config) : NULL;
    rt_status status;
    if (cached != NULL) {
        status = copy_tree(&cached->tree, &built->tree, error);
        p->out->bvh_reused++;
    } else {
        double start = clock_seconds();
        status = bvh_build(boxes, count, p->options->bvh_config, &built->tree, error);
        p->out->bvh_build_seconds += clock_seconds() - start;
        p->out->bvh_built++;
        if (status == RT_OK && cache != NULL)
            cache_tree(cache, &boxes, count, &config, &built->tree);
    }
    free(boxes);
    return status;
}

/* ---- objects and placements ---------------------------------------------------------- */

/* Appends the vertices of a mesh to the packer's list, moved by transform when it is not
 * NULL (normals by the inverse transpose, inverse being transform's inverse). Returns the
 * index of the first one in *first, or an error. */
static rt_status add_mesh_vertices(packer *p, const scene_mesh *mesh, const float (*transform)[4],
                                   const float (*inverse)[4], uint32_t *first, rt_error *error)
{
    *first = p->vertices.count;
    for (int v = 0; v < mesh->vertex_count; v++) {
        uint32_t index = vertex_push(&p->vertices);
        if (index == UINT32_MAX)
            return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory for the vertices of '%s'", mesh->path);
        pending_vertex *vertex = &p->vertices.items[index];
        memcpy(vertex->position, mesh->positions + 3 * (size_t)v, sizeof vertex->position);
        if (transform != NULL)
            move_point(transform, vertex->position, true, vertex->position);
        if (mesh->normals != NULL) {
            memcpy(vertex->normal, mesh->normals + 3 * (size_t)v, sizeof vertex->normal);
            if (transform != NULL)
                move_normal(inverse, vertex->normal, vertex->normal);
            vertex->has_normal = glm_vec3_norm2(vertex->normal) > 0;
        }
        if (mesh->uvs != NULL)
            memcpy(vertex->uv, mesh->uvs + 2 * (size_t)v, sizeof vertex->uv);
        if (mesh->colors != NULL)
            memcpy(vertex->color, mesh->colors + 3 * (size_t)v, sizeof vertex->color);
    }
    return RT_OK;
}

/* Fills item from triangle t of a loaded mesh whose vertices start at first_vertex in
 * the packer's list (moved there already when the placement is baked). */
static void pending_from_triangle(packer *p, pending_primitive *item, const scene_mesh *mesh, int t,
                                  uint32_t first_vertex)
{
    scene_shape shape = {.type = SHAPE_TRIANGLE};
    for (int k = 0; k < 3; k++) {
        item->vertices[k] = first_vertex + mesh->indices[3 * (size_t)t + k];
        memcpy(shape.points[k], p->vertices.items[item->vertices[k]].position, 3 * sizeof(float));
    }
    int material = mesh->triangle_materials ? mesh->triangle_materials[t] : -1;
    uint32_t vertices[3];
    memcpy(vertices, item->vertices, sizeof vertices);
    pending_from_shape(item, &shape, material >= 0 ? (uint32_t)material : PACKED_NONE);
    memcpy(item->vertices, vertices, sizeof vertices);
    item->has_uvs = mesh->uvs != NULL;
}

/* Gives a triangle shape (not of a mesh) its three vertices in the packer's list, with
 * its corner normals and uvs when it has them. */
static rt_status add_shape_vertices(packer *p, pending_primitive *item, const scene_shape *shape, rt_error *error)
{
    for (int k = 0; k < 3; k++) {
        uint32_t index = vertex_push(&p->vertices);
        if (index == UINT32_MAX)
            return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory for triangle vertices");
        pending_vertex *vertex = &p->vertices.items[index];
        memcpy(vertex->position, shape->points[k], 3 * sizeof(float));
        if (shape->has_normals) {
            memcpy(vertex->normal, shape->normals[k], 3 * sizeof(float));
            vertex->has_normal = glm_vec3_norm2(vertex->normal) > 0;
        }
        if (shape->has_uvs)
            memcpy(vertex->uv, shape->uvs[k], 2 * sizeof(float));
        item->vertices[k] = index;
    }
    item->has_uvs = shape->has_uvs;
    return RT_OK;
}

/* Resolves a shape's material against an instance override: the shape's own, else the
 * override, else PACKED_NONE (the shader then uses the instance's or the default). */
static uint32_t resolve_material(int own, int override)
{
    if (own >= 0)
        return (uint32_t)own;
    if (override >= 0)
        return (uint32_t)override;
    return PACKED_NONE;
}

/* Adds the primitives of scene object index to list; materials resolved with override
 * (for objects copied into the top level) or left to the instance (override = -2).
 * baked_instance >= 0: the copies are moved into the world by that scene instance's
 * transform (spheres under it must be a similarity: see placement_of). */
static rt_status add_object_primitives(packer *p, int index, int override, primitive_list *list, int baked_instance,
                                       rt_error *error)
{
    const scene *s = p->scene;
    const scene_object *object = &s->objects[index];
    const float (*transform)[4] = baked_instance >= 0 ? s->instances[baked_instance].object_to_world : NULL;
    float scale = transform != NULL ? similarity_scale(transform) : 1.0f;
    float inverse[3][4];
    if (transform != NULL && !pack_invert_affine(transform, inverse))
        return rt_error_set(error, RT_ERROR_INPUT, "PACK: instance %d has a transform that cannot be inverted",
                            baked_instance);
    if (object->mesh >= 0) {
        const scene_mesh *mesh = &s->meshes[object->mesh];
        if (mesh->positions == NULL && mesh->triangle_count > 0)
            return rt_error_set(error, RT_ERROR_INPUT, "PACK: mesh '%s' was not loaded", mesh->path);
        /* Untransformed vertices are shared by every use of the mesh; a baked placement
         * gets its own, moved. */
        uint32_t first = 0;
        if (transform == NULL && p->mesh_first_vertex[object->mesh] != UINT32_MAX) {
            first = p->mesh_first_vertex[object->mesh];
        } else {
            rt_status status = add_mesh_vertices(p, mesh, transform, (const float (*)[4])inverse, &first, error);
            if (status != RT_OK)
                return status;
            if (transform == NULL)
                p->mesh_first_vertex[object->mesh] = first;
        }
        for (int t = 0; t < mesh->triangle_count; t++) {
            pending_primitive *item = list_push(list);
            if (item == NULL)
                return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
            pending_from_triangle(p, item, mesh, t, first);
            if (item->material == PACKED_NONE && override >= 0)
                item->material = (uint32_t)override;
        }
        return RT_OK;
    }
    for (int k = 0; k < object->shape_count; k++) {
        scene_shape shape = s->shapes[object->first_shape + k];
        if (transform != NULL)
            transform_shape(&shape, transform, (const float (*)[4])inverse, scale);
        pending_primitive *item = list_push(list);
        if (item == NULL)
            return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
        pending_from_shape(item, &shape, resolve_material(shape.material, override));
        if (shape.type == SHAPE_TRIANGLE) {
            rt_status status = add_shape_vertices(p, item, &shape, error);
            if (status != RT_OK)
                return status;
        }
    }
    return RT_OK;
}

/* Whether the material (resolved: an index, or PACKED_NONE for the default grey) is of
 * the type (MATERIAL_* of packed_layout.h). */
static bool material_is(const scene *s, uint32_t material, int type)
{
    return material != PACKED_NONE && material < (uint32_t)s->material_count && s->materials[material].type == type;
}

bool pack_is_emissive(const scene *s, uint32_t material)
{
    if (!material_is(s, material, MATERIAL_PBR))
        return material_is(s, material, MATERIAL_EMISSIVE);
    const scene_material *m = &s->materials[material];
    bool emission = m->emission[0] > 0 || m->emission[1] > 0 || m->emission[2] > 0;
    /* An alpha-masked emitter is no light: light sampling would pick points in its holes. */
    return emission && m->alpha_mode != SCENE_ALPHA_MASK;
}

/* ---- which placements bake ----------------------------------------------------------
 *
 * A placement with a transform other than the identity is baked (its object's shapes
 * copied into the top level, moved by the transform) or kept as an instance (the object's
 * own BVH, entered by moving each ray into object coordinates). Baking is the faster of
 * the two: no second BVH level, and when no instance is left the tracer variant leaves
 * the instance code out (pack_summary, core/render.c), which llvmpipe pays for on every
 * traversal step whether a ray enters an instance or not (docs/performance.md). It costs
 * memory: n baked placements store n copies where an instance stores one. The rule:
 *
 *   - Emitters bake whenever their shapes survive the transform (below), however often
 *     they are placed: only world primitives are lights (light sampling works in world
 *     space), as before this rule.
 *   - Others bake when the shapes stay what they are, exactly (below), and the copies
 *     beyond the first, (placements - 1) x primitives of the object, fit the budget
 *     (pack_options.bake_budget, 262,144 primitives by default). An object placed once
 *     always bakes: one copy either way. Baking was faster in every case measured (1.3x
 *     to 1.8x in time per sample, up to 64 copies of a 5,120-triangle mesh); what it
 *     costs is about 70 packed bytes, 80 bytes of peak memory and 0.7 us of BVH build per
 *     extra triangle, which the budget bounds at about 18 MB and 0.2 s
 *     (docs/performance.md, "Placements baked into the world"). A mesh of 1M triangles
 *     placed 3 times stays instanced, one of 82k placed 3 times bakes; so do the Cornell
 *     box's blocks (six quads, placed once each) and the orchard of
 *     scenes/instancing.txt (two objects of 8 and 80 primitives, 25 placements each).
 *
 * What survives a transform exactly: triangles and quads under any affine map that keeps
 * orientation (a parallelogram stays one, barycentric and quad uvs are the same); a mirror
 * would turn their geometric normal (a cross product of moved edges) inside out, which
 * dielectrics and vertex normals notice, so mirrored placements stay instanced. Spheres
 * stay spheres under similarities only (uniform scale, rotation), and a turned sphere's
 * uv (its object-space longitude and latitude) and tangent turn with it: a sphere whose
 * material reads uv (an image texture) or has a normal map bakes only without rotation.
 * Vertex normals and normal maps are interpolated and applied in object space by an
 * instance and in the world when baked, which agree under similarities only. Solid
 * textures (checker, noise) read the world position either way. Volumes never bake: a
 * path's media are instance numbers (glsl/tracer.frag, media_enter).
 * Glass bakes like anything else: a path through it carries the float rounding of the
 * baked arithmetic to wherever it lands, which matters only where the colour there
 * hangs on rounding, as it did on a checker's cell boundary before the checker's cells
 * were offset (glsl/textures.glsl). */

/* What a placement's object holds under it, as far as baking is concerned. */
typedef struct placement_needs {
    bool emits;           /* a primitive (not a moving sphere) emits: baked, it becomes a light */
    bool spheres;         /* spheres or moving spheres: a similarity is needed */
    bool spheres_oriented;/* one of them reads uv or has a normal map: no rotation either */
    bool shading_frame;   /* vertex normals or a normal map on a triangle or quad: a similarity */
} placement_needs;

/* Whether texture (an index of s->textures, or -1) reads the surface's uv: an image, or
 * a checker with an image cell (the shader evaluates a checker's cells as flat textures,
 * one level deep). */
static bool texture_reads_uv(const scene *s, int texture)
{
    if (texture < 0 || texture >= s->texture_count)
        return false;
    const scene_texture *t = &s->textures[texture];
    if (t->type == TEXTURE_IMAGE)
        return true;
    if (t->type != TEXTURE_CHECKER)
        return false;
    for (int k = 0; k < 2; k++) {
        int cell = k == 0 ? t->even : t->odd;
        if (cell >= 0 && cell < s->texture_count && s->textures[cell].type == TEXTURE_IMAGE)
            return true;
    }
    return false;
}

/* Whether the material (resolved: an index, or PACKED_NONE for the default grey) reads
 * uv (*reads_uv) and has a normal map (returned). */
static bool material_normal_map(const scene *s, uint32_t material, bool *reads_uv)
{
    *reads_uv = false;
    if (material == PACKED_NONE || material >= (uint32_t)s->material_count)
        return false;
    const scene_material *m = &s->materials[material];
    *reads_uv = texture_reads_uv(s, m->albedo_texture) || texture_reads_uv(s, m->emission_texture)
                || (m->type == MATERIAL_PBR && m->metallic_roughness_texture >= 0);
    return m->normal_map >= 0;
}

/* Collects what the object placed by instance holds under the instance's material. */
static placement_needs placement_needs_of(const scene *s, const scene_instance *instance)
{
    placement_needs needs = {0};
    const scene_object *object = &s->objects[instance->object];
    bool reads_uv;
    if (object->mesh >= 0) {
        const scene_mesh *mesh = &s->meshes[object->mesh];
        needs.shading_frame = mesh->normals != NULL;
        for (int t = 0; t < mesh->triangle_count && !(needs.emits && needs.shading_frame); t++) {
            int own = mesh->triangle_materials ? mesh->triangle_materials[t] : -1;
            uint32_t material = resolve_material(own, instance->material);
            needs.emits |= pack_is_emissive(s, material);
            needs.shading_frame |= material_normal_map(s, material, &reads_uv);
        }
        return needs;
    }
    for (int k = 0; k < object->shape_count; k++) {
        const scene_shape *shape = &s->shapes[object->first_shape + k];
        uint32_t material = resolve_material(shape->material, instance->material);
        bool normal_map = material_normal_map(s, material, &reads_uv);
        if (shape->type == SHAPE_SPHERE || shape->type == SHAPE_MOVING_SPHERE) {
            needs.spheres = true;
            needs.spheres_oriented |= reads_uv || normal_map;
        } else {
            needs.shading_frame |= normal_map || shape->has_normals;
        }
        if (shape->type != SHAPE_MOVING_SPHERE)
            needs.emits |= pack_is_emissive(s, material);
    }
    return needs;
}

/* Whether the spheres of a placement (if any) stay the same spheres under m. */
static bool spheres_survive(const placement_needs *needs, const float m[3][4])
{
    if (!needs->spheres)
        return true;
    return needs->spheres_oriented ? uniform_scale(m) > 0 : similarity_scale(m) > 0;
}

/* How pack_collect places one scene instance. */
typedef enum placement {
    PLACEMENT_INSTANCE,   /* an instance of the object's own BVH */
    PLACEMENT_COPY,       /* the identity: copied into the top level as it is */
    PLACEMENT_BAKE,       /* copied into the top level, moved by its transform */
    PLACEMENT_MAY_BAKE,   /* baked if the object's placements fit the budget, else an instance */
} placement;

/* The first choice for one placement (before the budget): see the rule above. */
static placement placement_of(const scene *s, const scene_instance *instance)
{
    if (instance->volume)
        return PLACEMENT_INSTANCE;
    if (is_identity(instance->object_to_world))
        return PLACEMENT_COPY;
    const float (*m)[4] = instance->object_to_world;
    placement_needs needs = placement_needs_of(s, instance);
    if (!spheres_survive(&needs, m))
        return PLACEMENT_INSTANCE;
    if (needs.emits)
        return PLACEMENT_BAKE;
    if (!(linear_determinant(m) > 0) || (needs.shading_frame && !(similarity_scale(m) > 0)))
        return PLACEMENT_INSTANCE;
    return PLACEMENT_MAY_BAKE;
}

/* The primitives of the object an instance places. */
static uint64_t object_primitives(const scene *s, int object)
{
    const scene_object *o = &s->objects[object];
    return o->mesh >= 0 ? (uint64_t)s->meshes[o->mesh].triangle_count : (uint64_t)o->shape_count;
}

/* Chooses how each instance is placed (placements[i]): the first choice of placement_of,
 * then the budget for the placements that may bake. Returns an error for an instance
 * naming no object. */
static rt_status choose_placements(const packer *p, placement *placements, rt_error *error)
{
    const scene *s = p->scene;
    uint32_t *may_bake = calloc((size_t)s->object_count + 1, sizeof *may_bake);
    if (may_bake == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    for (int i = 0; i < s->instance_count; i++) {
        const scene_instance *instance = &s->instances[i];
        if (instance->object < 0 || instance->object >= s->object_count) {
            free(may_bake);
            return rt_error_set(error, RT_ERROR_INPUT, "PACK: instance %d names object %d of %d", i, instance->object,
                                s->object_count);
        }
        placements[i] = placement_of(s, instance);
        may_bake[instance->object] += placements[i] == PLACEMENT_MAY_BAKE;
    }
    uint64_t budget = p->options->bake_budget ? p->options->bake_budget : PACK_DEFAULT_BAKE_BUDGET;
    for (int i = 0; i < s->instance_count; i++) {
        if (placements[i] != PLACEMENT_MAY_BAKE)
            continue;
        int object = s->instances[i].object;
        uint64_t extra = (uint64_t)(may_bake[object] - 1) * object_primitives(s, object);
        placements[i] = !p->options->keep_instances && extra <= budget ? PLACEMENT_BAKE : PLACEMENT_INSTANCE;
    }
    free(may_bake);
    return RT_OK;
}

rt_status pack_collect(packer *p, rt_error *error)
{
    const scene *s = p->scene;
    for (int i = 0; i < s->sphere_count; i++) {
        pending_primitive *item = list_push(&p->top.primitives);
        if (item == NULL)
            return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
        scene_shape shape = {.type = SHAPE_SPHERE, .radius = s->spheres[i].radius};
        memcpy(shape.points[0], s->spheres[i].center, sizeof shape.points[0]);
        pending_from_shape(item, &shape, (uint32_t)s->spheres[i].material);
    }
    placement *placements = malloc(((size_t)s->instance_count + 1) * sizeof *placements);
    if (placements == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    rt_status status = choose_placements(p, placements, error);
    for (int i = 0; i < s->instance_count && status == RT_OK; i++) {
        const scene_instance *instance = &s->instances[i];
        p->instance_of_scene[i] = PACKED_NONE;
        if (placements[i] != PLACEMENT_INSTANCE) {
            status = add_object_primitives(p, instance->object, instance->material, &p->top.primitives,
                                           placements[i] == PLACEMENT_BAKE ? i : -1, error);
            continue;
        }
        p->object_needed[instance->object] = true;
        /* The shader keeps a path's media as 16-bit instance numbers. */
        if (instance->volume && p->packed_instances >= 65534)
            status = rt_error_set(error, RT_ERROR_INPUT, "PACK: more than 65533 instances come before volume %d", i);
        else
            p->instance_of_scene[i] = p->packed_instances++;
    }
    free(placements);
    return status;
}

rt_status pack_build_trees(packer *p, rt_error *error)
{
    const scene *s = p->scene;
    packed_scene *out = p->out;
    rt_status status = RT_OK;
    /* Bottom-level BVHs, one per object an instance needs. */
    for (int o = 0; o < s->object_count && status == RT_OK; o++) {
        if (!p->object_needed[o])
            continue;
        status = add_object_primitives(p, o, -2, &p->objects[o].primitives, -1, error);
        if (status == RT_OK && p->objects[o].primitives.count == 0)
            status = rt_error_set(error, RT_ERROR_INPUT, "PACK: object %d placed by an instance is empty", o);
        if (status == RT_OK)
            status = build_tree(p, &p->objects[o], error);
        if (status == RT_OK && p->objects[o].tree.depth > out->bvh_depth)
            out->bvh_depth = p->objects[o].tree.depth;
    }
    /* One top-level item per instance, boxed by its object's root box in the world. */
    for (int i = 0; i < s->instance_count && status == RT_OK; i++) {
        if (p->instance_of_scene[i] == PACKED_NONE)
            continue;
        const scene_instance *instance = &s->instances[i];
        pending_primitive *item = list_push(&p->top.primitives);
        if (item == NULL)
            return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
        item->type = PRIMITIVE_INSTANCE;
        item->instance = p->instance_of_scene[i];
        item->box = transform_box(&p->objects[instance->object].tree.nodes[0].box, instance->object_to_world);
    }
    if (status == RT_OK)
        status = build_tree(p, &p->top, error);
    if (status == RT_OK && p->top.tree.depth > out->bvh_depth)
        out->bvh_depth = p->top.tree.depth;
    return status;
}
