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

/* Builds the BVH of list (the list stays in caller order; tree.primitive_indices orders it). */
static rt_status build_tree(built_tree *built, const pack_options *options, double *seconds, rt_error *error)
{
    uint32_t count = built->primitives.count;
    bvh_box *boxes = malloc((count ? count : 1) * sizeof *boxes);
    if (boxes == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    for (uint32_t i = 0; i < count; i++)
        boxes[i] = built->primitives.items[i].box;
    double start = clock_seconds();
    rt_status status = bvh_build(boxes, count, options->bvh_config, &built->tree, error);
    *seconds += clock_seconds() - start;
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
 * transform (spheres under it must be a uniform scale: see instance_bakes). */
static rt_status add_object_primitives(packer *p, int index, int override, primitive_list *list, int baked_instance,
                                       rt_error *error)
{
    const scene *s = p->scene;
    const scene_object *object = &s->objects[index];
    const float (*transform)[4] = baked_instance >= 0 ? s->instances[baked_instance].object_to_world : NULL;
    float scale = transform != NULL ? uniform_scale(transform) : 1.0f;
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

bool pack_is_emissive(const scene *s, uint32_t material)
{
    if (material == PACKED_NONE || material >= (uint32_t)s->material_count)
        return false;
    const scene_material *m = &s->materials[material];
    bool emission = m->emission[0] > 0 || m->emission[1] > 0 || m->emission[2] > 0;
    /* An alpha-masked emitter is no light: light sampling would pick points in its holes. */
    return m->type == MATERIAL_EMISSIVE || (m->type == MATERIAL_PBR && emission && m->alpha_mode != SCENE_ALPHA_MASK);
}

/* Whether a placement bakes its object into the world (copies moved by its transform)
 * instead of instancing it: when something of the object emits under this placement, so
 * that it becomes a light, which only world primitives can be (light sampling works in
 * world space). Not for volumes, and not when the object has spheres and the transform
 * is more than a uniform scale, rotation free (a rotated sphere's texture would turn
 * with the world, a stretched one is no sphere): those emitters stay instanced and are
 * found by BSDF sampling only. Moving spheres never become lights. */
static bool instance_bakes(const scene *s, const scene_instance *instance)
{
    if (instance->volume)
        return false;
    const scene_object *object = &s->objects[instance->object];
    bool emits = false, spheres = false;
    if (object->mesh >= 0) {
        const scene_mesh *mesh = &s->meshes[object->mesh];
        for (int t = 0; t < mesh->triangle_count && !emits; t++) {
            int own = mesh->triangle_materials ? mesh->triangle_materials[t] : -1;
            emits = pack_is_emissive(s, resolve_material(own, instance->material));
        }
    }
    for (int k = 0; object->mesh < 0 && k < object->shape_count; k++) {
        const scene_shape *shape = &s->shapes[object->first_shape + k];
        spheres |= shape->type == SHAPE_SPHERE || shape->type == SHAPE_MOVING_SPHERE;
        if (shape->type != SHAPE_MOVING_SPHERE)
            emits |= pack_is_emissive(s, resolve_material(shape->material, instance->material));
    }
    return emits && (!spheres || uniform_scale(instance->object_to_world) > 0);
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
    for (int i = 0; i < s->instance_count; i++) {
        const scene_instance *instance = &s->instances[i];
        if (instance->object < 0 || instance->object >= s->object_count)
            return rt_error_set(error, RT_ERROR_INPUT, "PACK: instance %d names object %d of %d", i, instance->object,
                                s->object_count);
        /* Identity placements join the top level, meshes too, and so do placements of
         * emitting objects, moved into the world: their emitters then become lights. */
        bool copy_in = !instance->volume && is_identity(instance->object_to_world);
        bool bake = !copy_in && instance_bakes(s, instance);
        p->instance_of_scene[i] = PACKED_NONE;
        if (copy_in || bake) {
            rt_status status = add_object_primitives(p, instance->object, instance->material, &p->top.primitives,
                                                     bake ? i : -1, error);
            if (status != RT_OK)
                return status;
            continue;
        }
        p->object_needed[instance->object] = true;
        /* The shader keeps a path's media as 16-bit instance numbers. */
        if (instance->volume && p->packed_instances >= 65534)
            return rt_error_set(error, RT_ERROR_INPUT, "PACK: more than 65533 instances come before volume %d", i);
        p->instance_of_scene[i] = p->packed_instances++;
    }
    return RT_OK;
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
            status = build_tree(&p->objects[o], p->options, &out->bvh_build_seconds, error);
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
        status = build_tree(&p->top, p->options, &out->bvh_build_seconds, error);
    if (status == RT_OK && p->top.tree.depth > out->bvh_depth)
        out->bvh_depth = p->top.tree.depth;
    return status;
}
