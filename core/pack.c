/* pack.c: see pack.h. */
#include "pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "array.h"
#include "clock.h"

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

static float dot3(const float a[3], const float b[3]);
static void cross3(const float a[3], const float b[3], float out[3]);

/* ---- primitives before packing ------------------------------------------------------- */

/* One primitive on its way into a BVH: what to write and its bounding box. */
typedef struct pending_primitive {
    uint32_t type;
    uint32_t material;           /* PACKED_NONE: the instance's */
    uint32_t instance;           /* PRIMITIVE_INSTANCE */
    uint32_t vertices[3];        /* triangles: indices into the packer's vertex list */
    bool has_uvs;                /* triangles: the vertices carry uvs */
    float data[3][4];
    bvh_box box;
} pending_primitive;

typedef struct primitive_list {
    pending_primitive *items;
    uint32_t count;
    size_t capacity;
} primitive_list;

/* A triangle vertex on its way into the vertex section. */
typedef struct pending_vertex {
    float position[3];
    float normal[3];
    bool has_normal;
    float uv[2];
} pending_vertex;

typedef struct vertex_list {
    pending_vertex *items;
    uint32_t count;
    size_t capacity;
} vertex_list;

/* Lists stop well short of 32-bit indices, which the packed records use. */
#define PACK_LIST_LIMIT (UINT32_MAX / 4)

/* Appends a zeroed vertex; returns its index, or UINT32_MAX when memory runs out or the
 * list would pass 32-bit indices. */
static uint32_t vertex_push(vertex_list *list)
{
    if (list->count >= PACK_LIST_LIMIT
        || !array_reserve((void **)&list->items, &list->capacity, (size_t)list->count + 1, sizeof *list->items))
        return UINT32_MAX;
    memset(&list->items[list->count], 0, sizeof list->items[0]);
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
        for (int axis = 0; axis < 3; axis++) {
            item->data[1][axis] = p[1][axis] - p[0][axis];
            item->data[2][axis] = p[2][axis] - p[0][axis];
        }
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
    float q[3];
    for (int r = 0; r < 3; r++)
        q[r] = m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + (translate ? m[r][3] : 0.0f);
    memcpy(out, q, sizeof q);
}

/* Writes to out the normal n moved by the transpose of inverse (the inverse of a
 * placement), as the shader moves an instance's normals; not renormalised, so that moved
 * normals interpolate to the moved interpolation. */
static void move_normal(const float inverse[3][4], const float n[3], float out[3])
{
    float q[3];
    for (int c = 0; c < 3; c++)
        q[c] = inverse[0][c] * n[0] + inverse[1][c] * n[1] + inverse[2][c] * n[2];
    memcpy(out, q, sizeof q);
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

/* Inverts the affine 3x4 matrix m into inverse. Returns false when it is singular. */
static bool invert_affine(const float m[3][4], float inverse[3][4])
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

/* A built BVH over a primitive list, kept until everything is placed. */
typedef struct built_tree {
    primitive_list primitives;
    bvh tree;
    uint32_t node_base, primitive_base;   /* where it lands in the packed arrays */
} built_tree;

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

static void put_texel(uint32_t *texels, uint64_t index, uint32_t x, uint32_t y, uint32_t z, uint32_t w)
{
    texels[4 * index + 0] = x;
    texels[4 * index + 1] = y;
    texels[4 * index + 2] = z;
    texels[4 * index + 3] = w;
}

/* ---- the whole scene ----------------------------------------------------------------- */

typedef struct packer {
    const scene *scene;
    const pack_options *options;
    built_tree top;
    built_tree *objects;         /* per scene object: its BVH when an instance needs one */
    bool *object_needed;
    uint32_t *instance_of_scene; /* scene instance -> packed instance index or PACKED_NONE */
    uint32_t packed_instances;
    vertex_list vertices;        /* every triangle's vertices, in the order they are stored */
    uint32_t *mesh_first_vertex; /* per mesh: where its untransformed vertices start, or
                                  * UINT32_MAX before a triangle needs them */
    uint32_t *vertex_order;      /* vertex list index -> stored index (UINT32_MAX: unused) */
    packed_scene *out;
} packer;

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
            vertex->has_normal = dot3(vertex->normal, vertex->normal) > 0;
        }
        if (mesh->uvs != NULL)
            memcpy(vertex->uv, mesh->uvs + 2 * (size_t)v, sizeof vertex->uv);
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
            vertex->has_normal = dot3(vertex->normal, vertex->normal) > 0;
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
    if (transform != NULL && !invert_affine(transform, inverse))
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

/* Whether the material index resolves to an emissive material. */
static bool is_emissive(const scene *s, uint32_t material)
{
    return material != PACKED_NONE && material < (uint32_t)s->material_count
           && s->materials[material].type == MATERIAL_EMISSIVE;
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
            emits = is_emissive(s, resolve_material(own, instance->material));
        }
    }
    for (int k = 0; object->mesh < 0 && k < object->shape_count; k++) {
        const scene_shape *shape = &s->shapes[object->first_shape + k];
        spheres |= shape->type == SHAPE_SPHERE || shape->type == SHAPE_MOVING_SPHERE;
        if (shape->type != SHAPE_MOVING_SPHERE)
            emits |= is_emissive(s, resolve_material(shape->material, instance->material));
    }
    return emits && (!spheres || uniform_scale(instance->object_to_world) > 0);
}

/* Collects the top level: world spheres, identity placements copied in, instances. */
static rt_status collect(packer *p, rt_error *error)
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

rt_status pack_scene(const scene *s, const pack_options *options, packed_scene *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    pack_options defaults = pack_options_defaults();
    if (options == NULL)
        options = &defaults;
    packer p = {.scene = s, .options = options, .out = out};
    rt_status status = RT_OK;
    uint32_t *texels = NULL;
    p.objects = calloc((size_t)s->object_count + 1, sizeof *p.objects);
    p.object_needed = calloc((size_t)s->object_count + 1, sizeof *p.object_needed);
    p.instance_of_scene = calloc((size_t)s->instance_count + 1, sizeof *p.instance_of_scene);
    p.mesh_first_vertex = malloc(((size_t)s->mesh_count + 1) * sizeof *p.mesh_first_vertex);
    if (p.mesh_first_vertex != NULL)
        for (int m = 0; m < s->mesh_count; m++)
            p.mesh_first_vertex[m] = UINT32_MAX;
    if (p.objects == NULL || p.object_needed == NULL || p.instance_of_scene == NULL || p.mesh_first_vertex == NULL) {
        status = rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
        goto done;
    }
    status = collect(&p, error);

    /* Bottom-level BVHs, one per object an instance needs. */
    for (int o = 0; o < s->object_count && status == RT_OK; o++) {
        if (!p.object_needed[o])
            continue;
        status = add_object_primitives(&p, o, -2, &p.objects[o].primitives, -1, error);
        if (status == RT_OK && p.objects[o].primitives.count == 0)
            status = rt_error_set(error, RT_ERROR_INPUT, "PACK: object %d placed by an instance is empty", o);
        if (status == RT_OK)
            status = build_tree(&p.objects[o], options, &out->bvh_build_seconds, error);
        if (status == RT_OK && p.objects[o].tree.depth > out->bvh_depth)
            out->bvh_depth = p.objects[o].tree.depth;
    }
    /* One top-level item per instance, boxed by its object's root box in the world. */
    for (int i = 0; i < s->instance_count && status == RT_OK; i++) {
        if (p.instance_of_scene[i] == PACKED_NONE)
            continue;
        const scene_instance *instance = &s->instances[i];
        pending_primitive *item = list_push(&p.top.primitives);
        if (item == NULL) {
            status = rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
            break;
        }
        item->type = PRIMITIVE_INSTANCE;
        item->instance = p.instance_of_scene[i];
        item->box = transform_box(&p.objects[instance->object].tree.nodes[0].box, instance->object_to_world);
    }
    if (status == RT_OK)
        status = build_tree(&p.top, options, &out->bvh_build_seconds, error);
    if (status != RT_OK)
        goto done;
    if (p.top.tree.depth > out->bvh_depth)
        out->bvh_depth = p.top.tree.depth;

    /* Where everything goes: top level first (root node 0), then each object's BVH. */
    uint64_t node_count = p.top.primitives.count ? p.top.tree.node_count : 0;
    uint64_t primitive_count = p.top.primitives.count;
    uint64_t shape_texels = 0;
    for (int o = -1; o < s->object_count; o++) {
        built_tree *built = o < 0 ? &p.top : &p.objects[o];
        if (o >= 0 && !p.object_needed[o])
            continue;
        if (o >= 0) {
            /* Every BVH's root at an even node, so that sibling pairs (at odd nodes) start
             * on a 64-byte boundary (see node_offset). */
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
    /* Vertices are stored in the order the triangles, in leaf order, first use them: a
     * leaf's triangles then read neighbouring vertex texels (the 1.3M-triangle mesh
     * traced about 1.3x slower with the loader's vertex order). Unused ones are dropped. */
    p.vertex_order = malloc(((size_t)p.vertices.count + 1) * sizeof *p.vertex_order);
    if (p.vertex_order == NULL) {
        status = rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
        goto done;
    }
    for (uint32_t v = 0; v < p.vertices.count; v++)
        p.vertex_order[v] = UINT32_MAX;
    uint32_t vertex_count = 0;
    for (int o = -1; o < s->object_count; o++) {
        built_tree *built = o < 0 ? &p.top : &p.objects[o];
        if (o >= 0 && !p.object_needed[o])
            continue;
        for (uint32_t slot = 0; slot < built->primitives.count; slot++) {
            const pending_primitive *item = &built->primitives.items[built->tree.primitive_indices[slot]];
            if (item->type != PRIMITIVE_TRIANGLE)
                continue;
            for (int k = 0; k < 3; k++)
                if (p.vertex_order[item->vertices[k]] == UINT32_MAX)
                    p.vertex_order[item->vertices[k]] = vertex_count++;
        }
    }
    uint64_t image_pixels = 0;
    for (int i = 0; i < s->image_count; i++)
        image_pixels += (uint64_t)s->images[i].width * s->images[i].height;

    uint64_t material_count = (uint64_t)s->material_count + 1;
    if (material_count >= PRIMITIVE_NO_MATERIAL) {
        status = rt_error_set(error, RT_ERROR_INPUT, "PACK: %d materials, more than the %d a primitive can name",
                              s->material_count, PRIMITIVE_NO_MATERIAL - 1);
        goto done;
    }
    uint64_t material_offset = PACKED_HEADER_TEXELS;
    uint64_t primitive_offset = material_offset + material_count * PACKED_MATERIAL_STRIDE;
    uint64_t info_offset = primitive_offset + primitive_count * PACKED_PRIMITIVE_STRIDE;
    uint64_t shape_offset = info_offset + (primitive_count + 3) / 4;
    uint64_t vertex_offset = shape_offset + shape_texels;
    uint64_t uv_offset = vertex_offset + vertex_count;
    /* A node is 32 bytes and an interior node reads its two children, first and first + 1,
     * which are contiguous: with node_offset 2 mod 4 texels and every pair at an odd node,
     * each pair is one 64-byte cache line instead of straddling two (the buffer itself
     * is 64-byte aligned). */
    uint64_t node_offset = uv_offset + (vertex_count + 1) / 2;
    node_offset += (6 - node_offset % 4) % 4;
    uint64_t instance_offset = node_offset + node_count * PACKED_NODE_STRIDE;
    uint64_t texture_offset = instance_offset + (uint64_t)p.packed_instances * PACKED_INSTANCE_STRIDE;
    uint64_t image_offset = texture_offset + (uint64_t)s->texture_count * PACKED_TEXTURE_STRIDE;
    /* Lights: every emissive world-level sphere, quad and triangle (their material is
     * concrete at the top level). Moving spheres are left to BSDF sampling. */
    uint32_t light_count = 0;
    for (uint32_t k = 0; k < p.top.primitives.count; k++) {
        const pending_primitive *item = &p.top.primitives.items[k];
        uint32_t material = item->material;
        if (item->type != PRIMITIVE_SPHERE && item->type != PRIMITIVE_QUAD && item->type != PRIMITIVE_TRIANGLE)
            continue;
        if (material != PACKED_NONE && material < (uint32_t)s->material_count
            && s->materials[material].type == MATERIAL_EMISSIVE)
            light_count++;
    }
    uint32_t area_light_count = light_count;
    light_count += (uint32_t)s->light_count;
    /* An equirectangular environment is a light too, importance-sampled by luminance. */
    const scene_image *environment = NULL;
    if (s->sky.type == SKY_ENVIRONMENT && s->sky.environment >= 0 && s->sky.environment < s->image_count
        && s->images[s->sky.environment].pixels != NULL)
        environment = &s->images[s->sky.environment];
    uint64_t environment_texels = 0;
    if (environment != NULL) {
        light_count++;
        environment_texels = (uint64_t)environment->height * (1 + (uint64_t)environment->width);
    }
    uint64_t light_offset = image_offset + (uint64_t)s->image_count * PACKED_IMAGE_STRIDE;
    uint64_t environment_offset = light_offset + (uint64_t)light_count * PACKED_LIGHT_STRIDE;
    uint64_t pixel_offset = environment_offset + environment_texels;
    uint64_t texel_count = pixel_offset + image_pixels;
    if (texel_count > UINT32_MAX / 4) {
        status = rt_error_set(error, RT_ERROR_INPUT, "PACK: the scene needs %llu texels, more than 32-bit indices reach",
                              (unsigned long long)texel_count);
        goto done;
    }
    texels = calloc(texel_count, 4 * sizeof(uint32_t));
    if (texels == NULL) {
        status = rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory for %llu texels",
                              (unsigned long long)texel_count);
        goto done;
    }
    uint32_t default_material = (uint32_t)s->material_count;
    put_texel(texels, 0, PACKED_MAGIC, PACKED_LAYOUT_VERSION, (uint32_t)material_offset, (uint32_t)material_count);
    put_texel(texels, 1, (uint32_t)primitive_offset, (uint32_t)primitive_count, (uint32_t)node_offset,
              (uint32_t)node_count);
    put_texel(texels, 2, (uint32_t)instance_offset, p.packed_instances, (uint32_t)info_offset, default_material);
    put_texel(texels, 3, (uint32_t)texture_offset, (uint32_t)s->texture_count, (uint32_t)image_offset,
              (uint32_t)s->image_count);
    put_texel(texels, 4, (uint32_t)light_offset, light_count, (uint32_t)environment_offset, area_light_count);
    put_texel(texels, 5, (uint32_t)shape_offset, (uint32_t)vertex_offset, (uint32_t)uv_offset, (uint32_t)vertex_count);

    /* Materials, and the default grey one last. */
    for (uint64_t i = 0; i < material_count; i++) {
        scene_material m = scene_material_defaults();
        if (i < (uint64_t)s->material_count)
            m = s->materials[i];
        else {
            m.type = MATERIAL_LAMBERTIAN;
            m.albedo[0] = m.albedo[1] = m.albedo[2] = 0.5f;
        }
        uint64_t base = material_offset + i * PACKED_MATERIAL_STRIDE;
        put_texel(texels, base + 0, (uint32_t)m.type, float_bits(m.albedo[0]), float_bits(m.albedo[1]),
                  float_bits(m.albedo[2]));
        put_texel(texels, base + 1, float_bits(m.emission[0]), float_bits(m.emission[1]), float_bits(m.emission[2]),
                  float_bits(m.fuzz));
        put_texel(texels, base + 2, float_bits(m.index_of_refraction),
                  m.albedo_texture >= 0 ? (uint32_t)m.albedo_texture : PACKED_NONE,
                  m.emission_texture >= 0 ? (uint32_t)m.emission_texture : PACKED_NONE,
                  m.normal_map >= 0 ? (uint32_t)m.normal_map : PACKED_NONE);
        /* Phong terms of the Whitted integrator: a dim white highlight on diffuse
         * surfaces and the metal's own colour on metals, unless the scene says. */
        float specular[3] = {0.04f, 0.04f, 0.04f};
        if (m.specular_set)
            memcpy(specular, m.specular, sizeof specular);
        else if (m.type == MATERIAL_METAL)
            memcpy(specular, m.albedo, sizeof specular);
        put_texel(texels, base + 3, float_bits(m.phong_exponent > 0 ? m.phong_exponent : 32.0f),
                  float_bits(specular[0]), float_bits(specular[1]), float_bits(specular[2]));
    }

    /* Primitives (record and info), their shape records, and the nodes of every BVH. */
    uint64_t next_shape = shape_offset;
    built_tree *trees[1] = {&p.top};
    for (int o = -1; o < s->object_count; o++) {
        built_tree *built = o < 0 ? trees[0] : &p.objects[o];
        if (o >= 0 && !p.object_needed[o])
            continue;
        if (built->primitives.count == 0)
            continue;
        for (uint32_t slot = 0; slot < built->primitives.count; slot++) {
            const pending_primitive *item = &built->primitives.items[built->tree.primitive_indices[slot]];
            uint64_t global_slot = (uint64_t)built->primitive_base + slot;
            uint64_t base = primitive_offset + global_slot * PACKED_PRIMITIVE_STRIDE;
            const float (*d)[4] = item->data;
            switch (item->type) {
            case PRIMITIVE_SPHERE:
                put_texel(texels, base, float_bits(d[0][0]), float_bits(d[0][1]), float_bits(d[0][2]),
                          float_bits(d[0][3]));
                break;
            case PRIMITIVE_TRIANGLE:
                put_texel(texels, base, p.vertex_order[item->vertices[0]], p.vertex_order[item->vertices[1]],
                          p.vertex_order[item->vertices[2]], PRIMITIVE_RECORD_TAG + PRIMITIVE_TRIANGLE);
                break;
            case PRIMITIVE_INSTANCE:
                put_texel(texels, base, item->instance, 0, 0, PRIMITIVE_RECORD_TAG + PRIMITIVE_INSTANCE);
                break;
            default: { /* moving sphere, quad: the record points at its shape texels */
                int count = item->type == PRIMITIVE_QUAD ? PACKED_QUAD_TEXELS : PACKED_MOVING_SPHERE_TEXELS;
                put_texel(texels, base, (uint32_t)next_shape, 0, 0, PRIMITIVE_RECORD_TAG + item->type);
                for (int k = 0; k < count; k++)
                    put_texel(texels, next_shape + k, float_bits(d[k][0]), float_bits(d[k][1]), float_bits(d[k][2]),
                              float_bits(d[k][3]));
                next_shape += count;
            }
            }
            uint32_t material = item->material == PACKED_NONE ? PRIMITIVE_NO_MATERIAL : item->material;
            texels[4 * (info_offset + global_slot / 4) + global_slot % 4] =
                item->type << PRIMITIVE_INFO_TYPE_SHIFT | (item->has_uvs ? PRIMITIVE_INFO_HAS_UVS : 0) | material;
            out->triangle_count += item->type == PRIMITIVE_TRIANGLE;
        }
        for (uint32_t n = 0; n < built->tree.node_count; n++) {
            const bvh_node *node = &built->tree.nodes[n];
            uint64_t base = node_offset + ((uint64_t)built->node_base + n) * PACKED_NODE_STRIDE;
            uint32_t first = node->count ? node->first + built->primitive_base : node->first + built->node_base;
            put_texel(texels, base + 0, float_bits(node->box.min[0]), float_bits(node->box.min[1]),
                      float_bits(node->box.min[2]), first);
            put_texel(texels, base + 1, float_bits(node->box.max[0]), float_bits(node->box.max[1]),
                      float_bits(node->box.max[2]), node->count);
        }
    }

    /* Vertices: position and octahedron-encoded normal; uvs two to a texel. */
    for (uint32_t old = 0; old < p.vertices.count; old++) {
        uint32_t v = p.vertex_order[old];
        if (v == UINT32_MAX)
            continue;
        const pending_vertex *vertex = &p.vertices.items[old];
        put_texel(texels, vertex_offset + v, float_bits(vertex->position[0]), float_bits(vertex->position[1]),
                  float_bits(vertex->position[2]),
                  vertex->has_normal ? packed_encode_normal(vertex->normal) : VERTEX_NO_NORMAL);
        texels[4 * (uv_offset + v / 2) + 2 * (v % 2)] = float_bits(vertex->uv[0]);
        texels[4 * (uv_offset + v / 2) + 2 * (v % 2) + 1] = float_bits(vertex->uv[1]);
    }

    /* Lights, chosen by power: emission luminance x area (x pi for the cosine lobe). */
    if (light_count > 0) {
        double *power = malloc(light_count * sizeof *power);
        if (power == NULL) {
            status = rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
            goto done;
        }
        double total = 0;
        uint32_t light = 0;
        for (uint32_t slot = 0; slot < p.top.primitives.count; slot++) {
            const pending_primitive *item = &p.top.primitives.items[p.top.tree.primitive_indices[slot]];
            if (item->type != PRIMITIVE_SPHERE && item->type != PRIMITIVE_QUAD && item->type != PRIMITIVE_TRIANGLE)
                continue;
            if (item->material == PACKED_NONE || item->material >= (uint32_t)s->material_count
                || s->materials[item->material].type != MATERIAL_EMISSIVE)
                continue;
            const float *e = s->materials[item->material].emission;
            double luminance = 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2];
            double area;
            uint32_t type;
            if (item->type == PRIMITIVE_SPHERE) {
                area = 4 * M_PI * item->data[0][3] * item->data[0][3];
                type = LIGHT_SPHERE;
            } else {
                float c[3];
                cross3(item->data[1], item->data[2], c);
                area = sqrt((double)dot3(c, c)) * (item->type == PRIMITIVE_QUAD ? 1.0 : 0.5);
                type = item->type == PRIMITIVE_QUAD ? LIGHT_QUAD : LIGHT_TRIANGLE;
            }
            power[light] = luminance * area * M_PI;
            /* A light of no power is still listed (for MIS weights) but never chosen. */
            total += power[light];
            uint64_t base = light_offset + (uint64_t)light * PACKED_LIGHT_STRIDE;
            /* Slots ascend with light: the shader finds a primitive's light by a binary
             * search of the first area_light_count lights. */
            put_texel(texels, base, type, (uint32_t)slot, 0, 0);
            light++;
        }
        /* Point, spot and sun lights after the area lights. A sun's power is its
         * irradiance over the scene's cross-section (the top-level box). */
        double scene_radius = 1;
        if (p.top.primitives.count > 0) {
            const bvh_box *box = &p.top.tree.nodes[0].box;
            double extent[3] = {box->max[0] - box->min[0], box->max[1] - box->min[1], box->max[2] - box->min[2]};
            scene_radius = 0.5 * sqrt(extent[0] * extent[0] + extent[1] * extent[1] + extent[2] * extent[2]);
            if (!(scene_radius > 0) || !isfinite(scene_radius))
                scene_radius = 1;
        }
        for (int k = 0; k < s->light_count; k++, light++) {
            const scene_light *source = &s->lights[k];
            const float *c = source->color;
            double luminance = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            uint32_t type = source->type == SCENE_LIGHT_POINT ? LIGHT_POINT
                            : source->type == SCENE_LIGHT_SPOT ? LIGHT_SPOT : LIGHT_SUN;
            double cos_outer = cos(source->spot_outer_degrees * M_PI / 180);
            double cos_inner = cos(source->spot_inner_degrees * M_PI / 180);
            double cos_sun = cos(0.5 * source->sun_angle_degrees * M_PI / 180);
            if (type == LIGHT_POINT)
                power[light] = 4 * M_PI * luminance;
            else if (type == LIGHT_SPOT)
                power[light] = 2 * M_PI * (1 - 0.5 * (cos_outer + cos_inner)) * luminance;
            else
                power[light] = M_PI * scene_radius * scene_radius * luminance;
            total += power[light];
            bool polynomial = source->falloff == FALLOFF_POLYNOMIAL;
            uint64_t base = light_offset + (uint64_t)light * PACKED_LIGHT_STRIDE;
            put_texel(texels, base, type, polynomial ? float_bits(source->attenuation[0]) : 0,
                      polynomial ? float_bits(source->attenuation[1]) : 0,
                      polynomial ? float_bits(source->attenuation[2]) : 0);
            /* The sun is stored as the direction towards it. */
            float where[3];
            for (int i = 0; i < 3; i++)
                where[i] = type == LIGHT_SUN ? -source->direction[i] : source->position[i];
            put_texel(texels, base + 1, float_bits(where[0]), float_bits(where[1]), float_bits(where[2]), 0);
            put_texel(texels, base + 2, float_bits(c[0]), float_bits(c[1]), float_bits(c[2]),
                      float_bits((float)(type == LIGHT_SUN ? cos_sun : cos_outer)));
            put_texel(texels, base + 3, float_bits(source->direction[0]), float_bits(source->direction[1]),
                      float_bits(source->direction[2]), float_bits((float)cos_inner));
        }
        if (environment != NULL) {
            /* Rows, then pixels in each row, weighted by luminance x sin(latitude) (the
             * solid angle a pixel covers); a small floor keeps every pixel reachable. */
            int width = environment->width, height = environment->height;
            double *row_sums = calloc((size_t)height, sizeof *row_sums);
            if (row_sums == NULL) {
                free(power);
                status = rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
                goto done;
            }
            double mean = 0;
            for (size_t i = 0; i < (size_t)width * height; i++) {
                const float *c = environment->pixels + 4 * i;
                mean += 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            }
            mean /= (double)width * height;
            double floor_weight = 1e-3 * mean + 1e-12, total_weight = 0;
            for (int y = 0; y < height; y++) {
                double sine = sin(M_PI * (y + 0.5) / height), row = 0;
                uint64_t row_base = environment_offset + height + (uint64_t)y * width;
                for (int x = 0; x < width; x++) {
                    const float *c = environment->pixels + 4 * ((size_t)y * width + x);
                    row += (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2] + floor_weight) * sine;
                    put_texel(texels, row_base + x, float_bits((float)row), 0, 0, 0);
                }
                for (int x = 0; x < width; x++) {
                    uint64_t at = row_base + x;
                    float value = x + 1 == width ? 1.0f : bits_float(texels[4 * at]) / (float)row;
                    texels[4 * at] = float_bits(value);
                }
                row_sums[y] = row;
                total_weight += row;
            }
            double cumulative_rows = 0;
            for (int y = 0; y < height; y++) {
                cumulative_rows += row_sums[y];
                put_texel(texels, environment_offset + y,
                          float_bits(y + 1 == height ? 1.0f : (float)(cumulative_rows / total_weight)), 0, 0, 0);
            }
            free(row_sums);
            /* Its power: the mean radiance on the scene's cross-section from all around. */
            power[light] = 4 * M_PI * scene_radius * scene_radius * mean * s->sky.intensity;
            total += power[light];
            put_texel(texels, light_offset + (uint64_t)light * PACKED_LIGHT_STRIDE, LIGHT_ENVIRONMENT, (uint32_t)width,
                      (uint32_t)height, 0);
            light++;
        }
        double cumulative = 0;
        for (uint32_t l = 0; l < light_count; l++) {
            cumulative += total > 0 ? power[l] / total : 1.0 / light_count;
            uint64_t base = light_offset + (uint64_t)l * PACKED_LIGHT_STRIDE;
            texels[4 * (base + 1) + 3] = float_bits(l + 1 == light_count ? 1.0f : (float)cumulative);
        }
        free(power);
    }

    /* Instances: the object's root, material, world-to-object matrix, volume. */
    for (int i = 0; i < s->instance_count; i++) {
        uint32_t packed_index = p.instance_of_scene[i];
        if (packed_index == PACKED_NONE)
            continue;
        const scene_instance *instance = &s->instances[i];
        float world_to_object[3][4];
        if (!invert_affine(instance->object_to_world, world_to_object)) {
            status = rt_error_set(error, RT_ERROR_INPUT, "PACK: instance %d has a transform that cannot be inverted", i);
            goto done;
        }
        uint64_t base = instance_offset + (uint64_t)packed_index * PACKED_INSTANCE_STRIDE;
        put_texel(texels, base, p.objects[instance->object].node_base,
                  instance->material >= 0 ? (uint32_t)instance->material : PACKED_NONE,
                  instance->volume ? INSTANCE_VOLUME : 0, 0);
        for (int r = 0; r < 3; r++)
            put_texel(texels, base + 1 + r, float_bits(world_to_object[r][0]), float_bits(world_to_object[r][1]),
                      float_bits(world_to_object[r][2]), float_bits(world_to_object[r][3]));
        put_texel(texels, base + 4, float_bits(instance->density), float_bits(instance->volume_albedo[0]),
                  float_bits(instance->volume_albedo[1]), float_bits(instance->volume_albedo[2]));
    }

    /* Textures and images. */
    for (int i = 0; i < s->texture_count; i++) {
        const scene_texture *t = &s->textures[i];
        uint64_t base = texture_offset + (uint64_t)i * PACKED_TEXTURE_STRIDE;
        put_texel(texels, base, (uint32_t)t->type, (uint32_t)t->even, (uint32_t)t->odd, (uint32_t)t->image);
        put_texel(texels, base + 1, float_bits(t->color[0]), float_bits(t->color[1]), float_bits(t->color[2]),
                  float_bits(t->scale));
    }
    uint64_t next_pixel = pixel_offset;
    for (int i = 0; i < s->image_count; i++) {
        const scene_image *image = &s->images[i];
        put_texel(texels, image_offset + (uint64_t)i * PACKED_IMAGE_STRIDE, (uint32_t)next_pixel, (uint32_t)image->width,
                  (uint32_t)image->height, 0);
        uint64_t pixels = (uint64_t)image->width * image->height;
        if (image->pixels != NULL)
            for (uint64_t k = 0; k < 4 * pixels; k++)
                texels[4 * next_pixel + k] = float_bits(image->pixels[k]);
        next_pixel += pixels;
    }

    out->texels = texels;
    texels = NULL;
    out->texel_count = (uint32_t)texel_count;
    out->material_offset = (uint32_t)material_offset;
    out->material_count = (uint32_t)material_count;
    out->default_material = default_material;
    out->primitive_offset = (uint32_t)primitive_offset;
    out->primitive_count = (uint32_t)primitive_count;
    out->info_offset = (uint32_t)info_offset;
    out->shape_offset = (uint32_t)shape_offset;
    out->shape_texels = (uint32_t)shape_texels;
    out->vertex_offset = (uint32_t)vertex_offset;
    out->vertex_count = (uint32_t)vertex_count;
    out->uv_offset = (uint32_t)uv_offset;
    out->area_light_count = area_light_count;
    out->node_offset = (uint32_t)node_offset;
    out->node_count = (uint32_t)node_count;
    out->instance_offset = (uint32_t)instance_offset;
    out->instance_count = p.packed_instances;
    out->texture_offset = (uint32_t)texture_offset;
    out->texture_count = (uint32_t)s->texture_count;
    out->image_offset = (uint32_t)image_offset;
    out->image_count = (uint32_t)s->image_count;
    out->light_offset = (uint32_t)light_offset;
    out->light_count = light_count;

done:
    free(texels);
    free(p.top.primitives.items);
    bvh_free(&p.top.tree);
    if (p.objects != NULL)
        for (int o = 0; o < s->object_count; o++) {
            free(p.objects[o].primitives.items);
            bvh_free(&p.objects[o].tree);
        }
    free(p.objects);
    free(p.object_needed);
    free(p.instance_of_scene);
    free(p.mesh_first_vertex);
    free(p.vertex_order);
    free(p.vertices.items);
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

/* ---- vector helpers ------------------------------------------------------------------ */

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
