/* packed_traverse.c: see packed_traverse.h. The traversal follows the shader's
 * (glsl/intersect.glsl, glsl/traverse.glsl: intersection, BVH walk, instances, shadow
 * rays) operation for operation, so that CPU and shader agree on what a ray hits. */
#include "packed_traverse.h"

#include <math.h>
#include <string.h>

#include <cglm/cglm.h>

#include "packed_layout.h"

/* ---- records ------------------------------------------------------------------------- */

uint32_t packed_uint(const packed_scene *packed, uint32_t texel, int component)
{
    return packed->texels[4 * (size_t)texel + component];
}

float packed_float(const packed_scene *packed, uint32_t texel, int component)
{
    uint32_t bits = packed_uint(packed, texel, component);
    float value;
    memcpy(&value, &bits, sizeof value);
    return value;
}

void packed_decode_normal(uint32_t bits, float normal[3])
{
    /* As GLSL's unpackSnorm2x16, then the octahedron unfolded. */
    float x = fmaxf(-1.0f, (float)(int16_t)(bits & 0xffffu) / 32767.0f);
    float y = fmaxf(-1.0f, (float)(int16_t)(bits >> 16) / 32767.0f);
    float z = 1 - fabsf(x) - fabsf(y);
    float t = fmaxf(-z, 0.0f);
    x += x >= 0 ? -t : t;
    y += y >= 0 ? -t : t;
    vec3 unfolded = {x, y, z};
    glm_vec3_divs(unfolded, glm_vec3_norm(unfolded), normal);
}

void packed_vertex_position(const packed_scene *packed, uint32_t vertex, float position[3])
{
    for (int i = 0; i < 3; i++)
        position[i] = packed_float(packed, packed->vertex_offset + vertex, i);
}

bool packed_vertex_normal(const packed_scene *packed, uint32_t vertex, float normal[3])
{
    uint32_t bits = packed_uint(packed, packed->vertex_offset + vertex, 3);
    if (bits == VERTEX_NO_NORMAL)
        return false;
    packed_decode_normal(bits, normal);
    return true;
}

uint32_t packed_primitive_type(const packed_scene *packed, uint32_t slot)
{
    return packed_uint(packed, packed->info_offset + slot / 4, (int)(slot % 4)) >> PRIMITIVE_INFO_TYPE_SHIFT;
}

packed_primitive packed_primitive_at(const packed_scene *packed, uint32_t slot)
{
    uint32_t base = packed->primitive_offset + slot * PACKED_PRIMITIVE_STRIDE;
    uint32_t info = packed_uint(packed, packed->info_offset + slot / 4, (int)(slot % 4));
    uint32_t material = info & PRIMITIVE_INFO_MATERIAL_MASK;
    packed_primitive primitive = {
        .type = info >> PRIMITIVE_INFO_TYPE_SHIFT,
        .material = material == PRIMITIVE_NO_MATERIAL ? PACKED_NONE : material,
        .has_uvs = (info & PRIMITIVE_INFO_HAS_UVS) != 0,
        .instance = PACKED_NONE,
        .vertices = {PACKED_NONE, PACKED_NONE, PACKED_NONE},
    };
    switch (primitive.type) {
    case PRIMITIVE_SPHERE:
        for (int i = 0; i < 4; i++)
            primitive.data[0][i] = packed_float(packed, base, i);
        break;
    case PRIMITIVE_TRIANGLE: {
        vec3 v[3];
        for (int k = 0; k < 3; k++) {
            primitive.vertices[k] = packed_uint(packed, base, k);
            packed_vertex_position(packed, primitive.vertices[k], v[k]);
        }
        glm_vec3_copy(v[0], primitive.data[0]);
        glm_vec3_sub(v[1], v[0], primitive.data[1]);
        glm_vec3_sub(v[2], v[0], primitive.data[2]);
        break;
    }
    case PRIMITIVE_INSTANCE:
        primitive.instance = packed_uint(packed, base, 0);
        break;
    default: {
        uint32_t shape = packed_uint(packed, base, 0);
        int count = primitive.type == PRIMITIVE_QUAD ? PACKED_QUAD_TEXELS : PACKED_MOVING_SPHERE_TEXELS;
        for (int k = 0; k < count; k++)
            for (int i = 0; i < 4; i++)
                primitive.data[k][i] = packed_float(packed, shape + k, i);
    }
    }
    return primitive;
}

/* ---- the shader's traversal, in C ---------------------------------------------------- */

/* glsl/intersect.glsl intersect_sphere: nearest root in (0, t_max) for any direction length. */
static float intersect_sphere(vec3 center, float radius, vec3 origin, vec3 direction, float t_max)
{
    float length = glm_vec3_norm(direction);
    vec3 unit, to_origin, along, closest;
    glm_vec3_divs(direction, length, unit);
    glm_vec3_sub(origin, center, to_origin);
    float b = glm_vec3_dot(to_origin, unit);
    glm_vec3_scale(unit, b, along);
    glm_vec3_sub(to_origin, along, closest);
    float discriminant = radius * radius - glm_vec3_norm2(closest);
    if (discriminant < 0)
        return INFINITY;
    float root = sqrtf(discriminant);
    float c = glm_vec3_norm2(to_origin) - radius * radius;
    float q = -b - (b >= 0 ? root : -root);
    float t_near = c / q, t_far = q;
    if (t_near > t_far) {
        float swap = t_near;
        t_near = t_far;
        t_far = swap;
    }
    float inverse_length = 1 / length;   /* as the shader: one division, then products */
    t_near *= inverse_length;
    t_far *= inverse_length;
    if (t_near > 0 && t_near < t_max)
        return t_near;
    if (t_far > 0 && t_far < t_max)
        return t_far;
    return INFINITY;
}

/* glsl/intersect.glsl intersect_flat: Moller-Trumbore for triangles, quads by their plane. */
static float intersect_flat(packed_primitive *primitive, vec3 origin, vec3 direction, float t_max)
{
    float *corner = primitive->data[0], *edge1 = primitive->data[1], *edge2 = primitive->data[2];
    vec3 p, s, q;
    glm_vec3_cross(direction, edge2, p);
    float determinant = glm_vec3_dot(edge1, p);
    if (fabsf(determinant) < 1e-20f)
        return INFINITY;
    float inverse = 1.0f / determinant;
    glm_vec3_sub(origin, corner, s);
    float u = glm_vec3_dot(s, p) * inverse;
    glm_vec3_cross(s, edge1, q);
    float v = glm_vec3_dot(direction, q) * inverse;
    bool inside = primitive->type == PRIMITIVE_QUAD ? (u >= 0 && u <= 1 && v >= 0 && v <= 1)
                                                     : (u >= 0 && v >= 0 && u + v <= 1);
    if (!inside)
        return INFINITY;
    float t = glm_vec3_dot(edge2, q) * inverse;
    return t > 0 && t < t_max ? t : INFINITY;
}

/* A ray in the coordinates of the BVH being walked (the world's or an instance's object's),
 * with the reciprocals of its direction for the box tests. */
typedef struct moving_ray {
    vec3 origin, direction, inverse_direction;
} moving_ray;

static void ray_set(moving_ray *ray, vec3 origin, vec3 direction)
{
    glm_vec3_copy(origin, ray->origin);
    glm_vec3_copy(direction, ray->direction);
    /* As glsl/intersect.glsl traversal_ray: no infinities (packed_layout.h
     * TRAVERSAL_SMALLEST_DIRECTION). */
    const float smallest = (float)TRAVERSAL_SMALLEST_DIRECTION;
    for (int axis = 0; axis < 3; axis++) {
        float component = fabsf(direction[axis]) < smallest ? (direction[axis] < 0 ? -smallest : smallest)
                                                            : direction[axis];
        ray->inverse_direction[axis] = 1.0f / component;
    }
}

/* A float's bits as a signed integer (glsl floatBitsToInt). */
static int32_t float_order(float value)
{
    int32_t bits;
    memcpy(&bits, &value, sizeof bits);
    return bits;
}

/* glsl/intersect.glsl intersect_ordered_box: where the ray enters the box with corners
 * near and far in the order it meets them, within (0, t_max), or INFINITY when it misses;
 * its minima and maxima taken of the distances' bits as the shader takes them. */
static float ordered_box_entry(const float near[3], const float far[3], const moving_ray *ray, float t_max)
{
    int32_t enter = 0, leave = float_order(t_max);
    for (int axis = 0; axis < 3; axis++) {
        int32_t t_near = float_order((near[axis] - ray->origin[axis]) * ray->inverse_direction[axis]);
        int32_t t_far = float_order((far[axis] - ray->origin[axis]) * ray->inverse_direction[axis]);
        enter = t_near > enter ? t_near : enter;
        leave = t_far < leave ? t_far : leave;
    }
    float entry;
    memcpy(&entry, &enter, sizeof entry);
    return enter <= leave ? entry : INFINITY;
}

/* The slab test of a box of packed at texels lo and hi: as they are (ordered true: a
 * threaded walk's near and far corners), or ordered by the signs of the ray's inverse
 * direction as glsl/intersect.glsl intersect_box orders them (lo: the minimum). */
static float intersect_box(const packed_scene *packed, uint32_t lo, uint32_t hi, bool ordered, const moving_ray *ray,
                           float t_max)
{
    float near[3], far[3];
    for (int axis = 0; axis < 3; axis++) {
        bool down = !ordered && ray->inverse_direction[axis] < 0;
        near[axis] = packed_float(packed, down ? hi : lo, axis);
        far[axis] = packed_float(packed, down ? lo : hi, axis);
    }
    return ordered_box_entry(near, far, ray, t_max);
}

/* The shader's stack entries (glsl/traverse.glsl): a node record's (first, count) pair, or
 * an instance marker. */
enum { STACK = 2 * BVH_MAX_DEPTH + 2 * BVH_MAX_LEAF_SIZE, ENTER_INSTANCE = 6, LEAVE_INSTANCE = 7 };

typedef struct walk_item {
    uint32_t first, count;
    float entry;
} walk_item;

/* Tests one primitive of the level being walked; on a hit nearer than hit->t, updates
 * *hit and returns true. */
static bool test_primitive(const packed_scene *packed, const packed_primitive *primitive, uint32_t slot,
                           const moving_ray *ray, float time, uint32_t instance, packed_hit *hit)
{
    float t = INFINITY;
    if (primitive->type == PRIMITIVE_SPHERE)
        t = intersect_sphere((float *)primitive->data[0], primitive->data[0][3], (float *)ray->origin,
                             (float *)ray->direction, hit->t);
    else if (primitive->type == PRIMITIVE_MOVING_SPHERE) {
        vec3 motion, center;
        glm_vec3_sub((float *)primitive->data[1], (float *)primitive->data[0], motion);
        glm_vec3_scale(motion, time, motion);
        glm_vec3_add((float *)primitive->data[0], motion, center);
        t = intersect_sphere(center, primitive->data[0][3], (float *)ray->origin, (float *)ray->direction, hit->t);
    } else
        t = intersect_flat((packed_primitive *)primitive, (float *)ray->origin, (float *)ray->direction, hit->t);
    (void)packed;
    if (!(t < hit->t))
        return false;
    hit->t = t;
    hit->primitive = slot;
    hit->instance = instance;
    return true;
}

/* The walk of glsl/traverse.glsl trace_rays for one ray, step for step: the current item
 * is a node record's (first, count) pair (the root's box is not tested, its children's
 * are), nearer child first, instances entered through markers on the stack, the object's
 * root pair read from the instance record. shadow: the shader's shadow ray, which stops
 * at the first hit that is not light_slot (a world primitive) nor, when volumes, on the
 * boundary of a volume instance; returns whether it stopped so (blocked). Otherwise
 * returns false; *hit holds the nearest hit (or, for a shadow ray, the nearest of those
 * that do not block), t = t_max when none. */
static bool walk(const packed_scene *packed, const float origin[3], const float direction[3], float time, float t_max,
                 bool shadow, uint32_t light_slot, bool volumes, packed_hit *hit)
{
    hit->t = t_max;
    hit->primitive = PACKED_NONE;
    hit->instance = PACKED_NONE;
    if (packed->node_count == 0)
        return false;
    vec3 world_origin, world_direction;
    glm_vec3_copy((float *)origin, world_origin);
    glm_vec3_copy((float *)direction, world_direction);
    moving_ray ray;
    ray_set(&ray, world_origin, world_direction);
    walk_item stack[STACK];
    int stack_size = 0;
    walk_item item = {packed_uint(packed, packed->node_offset, 3), packed_uint(packed, packed->node_offset + 1, 3),
                      -INFINITY};
    uint32_t instance = PACKED_NONE;
    bool volume_instance = false;
    for (;;) {
        if (item.count == LEAVE_INSTANCE) {
            ray_set(&ray, world_origin, world_direction);
            instance = PACKED_NONE;
            volume_instance = false;
        } else if (item.count == ENTER_INSTANCE) {
            /* Into the object's coordinates: the direction is not renormalised, so t stays
             * the world ray's parameter. */
            instance = item.first;
            uint32_t base = packed->instance_offset + instance * PACKED_INSTANCE_STRIDE;
            volume_instance = (packed_uint(packed, base, 2) & INSTANCE_VOLUME) != 0;
            vec3 object_origin, object_direction;
            for (int r = 0; r < 3; r++) {
                vec4 row;
                for (int c = 0; c < 4; c++)
                    row[c] = packed_float(packed, base + 1 + r, c);
                object_origin[r] = glm_vec3_dot(row, world_origin) + row[3];
                object_direction[r] = glm_vec3_dot(row, world_direction);
            }
            ray_set(&ray, object_origin, object_direction);
            item = (walk_item){packed_uint(packed, base, 0), packed_uint(packed, base, 3), -INFINITY};
            continue;
        } else if (item.entry < hit->t) {
            if (item.count > 0) {
                for (uint32_t slot = item.first; slot < item.first + item.count; slot++) {
                    packed_primitive primitive = packed_primitive_at(packed, slot);
                    if (primitive.type == PRIMITIVE_INSTANCE) {
                        /* Visited after this leaf: a marker that restores the world ray,
                         * under one that moves the ray into the instance. */
                        if (stack_size + 2 > STACK)
                            continue;
                        stack[stack_size++] = (walk_item){0, LEAVE_INSTANCE, -INFINITY};
                        stack[stack_size++] = (walk_item){primitive.instance, ENTER_INSTANCE, -INFINITY};
                        continue;
                    }
                    if (!test_primitive(packed, &primitive, slot, &ray, time, instance, hit) || !shadow)
                        continue;
                    bool passable = instance == PACKED_NONE ? slot == light_slot : volumes && volume_instance;
                    if (!passable)
                        return true;
                }
            } else {
                uint32_t base = packed->node_offset + item.first * PACKED_NODE_STRIDE;
                float left = intersect_box(packed, base, base + 1, false, &ray, hit->t);
                float right = intersect_box(packed, base + 2, base + 3, false, &ray, hit->t);
                bool right_nearer = right < left;
                walk_item near = {packed_uint(packed, base + (right_nearer ? 2 : 0), 3),
                                  packed_uint(packed, base + (right_nearer ? 3 : 1), 3), fminf(left, right)};
                walk_item far = {packed_uint(packed, base + (right_nearer ? 0 : 2), 3),
                                 packed_uint(packed, base + (right_nearer ? 1 : 3), 3), fmaxf(left, right)};
                if (near.entry < INFINITY) {
                    if (far.entry < INFINITY && stack_size < STACK)
                        stack[stack_size++] = far;
                    item = near;
                    continue;
                }
            }
        }
        if (stack_size == 0)
            return false;
        item = stack[--stack_size];
    }
}

bool packed_intersect_nearest(const packed_scene *packed, const float origin[3], const float direction[3], float time,
                              float t_max, packed_hit *hit)
{
    walk(packed, origin, direction, time, t_max, false, PACKED_NONE, false, hit);
    return hit->primitive != PACKED_NONE;
}

bool packed_shadow_blocked(const packed_scene *packed, const float origin[3], const float direction[3], float time,
                           float t_max, uint32_t light_slot, bool volumes, packed_hit *hit)
{
    return walk(packed, origin, direction, time, t_max, true, light_slot, volumes, hit);
}

uint32_t packed_threaded_stride(const packed_scene *packed)
{
    return packed->summary.primitive_types & 1u << PRIMITIVE_QUAD ? PACKED_THREADED_QUAD_ITEM_STRIDE
                                                                  : PACKED_THREADED_ITEM_STRIDE;
}

bool packed_threaded_walk(const packed_scene *packed, const float origin[3], const float direction[3], float t_max,
                          bool shadow, uint32_t light_slot, packed_hit *hit, uint32_t *items_visited)
{
    hit->t = t_max;
    hit->primitive = PACKED_NONE;
    hit->instance = PACKED_NONE;
    if (items_visited != NULL)
        *items_visited = 0;
    uint32_t items = packed->threaded_items, stride = packed_threaded_stride(packed);
    if (items == 0)
        return false;
    moving_ray ray;
    ray_set(&ray, (float *)origin, (float *)direction);
    uint32_t octant = (ray.inverse_direction[0] < 0) | (ray.inverse_direction[1] < 0) << 1
                      | (ray.inverse_direction[2] < 0) << 2;
    uint32_t list = packed->threaded_offset + octant * items * stride;
    for (uint32_t item = 0; item < items;) {
        uint32_t base = list + item * stride;
        if (items_visited != NULL)
            ++*items_visited;
        uint32_t tag = packed_uint(packed, base + 1, 3);
        if (!(tag & (THREADED_SPHERE | THREADED_QUAD))) {
            item = intersect_box(packed, base, base + 1, true, &ray, hit->t) < INFINITY ? item + 1
                                                                                     : packed_uint(packed, base, 3);
            continue;
        }
        packed_primitive primitive = {.type = tag & THREADED_QUAD ? PRIMITIVE_QUAD : PRIMITIVE_SPHERE};
        for (int k = 0; k < (tag & THREADED_QUAD ? 3 : 2); k++)
            for (int c = 0; c < 4; c++)
                primitive.data[k][c] = packed_float(packed, base + k, c);
        if (primitive.type == PRIMITIVE_SPHERE)
            primitive.data[0][3] = primitive.data[1][0];   /* (centre, radius) */
        if (test_primitive(packed, &primitive, tag & THREADED_SLOT_MASK, &ray, 0, PACKED_NONE, hit) && shadow
            && hit->primitive != light_slot)
            return true;
        item++;
    }
    return false;
}

uint32_t packed_media_at(const packed_scene *packed, const float point[3])
{
    /* Parity along one ray: a closed boundary that the ray from the point crosses an odd
     * number of times contains the point. Of those, the one crossed first is innermost.
     * The direction is skewed so the walk does not run along edges of axis-aligned boxes. */
    vec3 direction = {0.5773503f, 0.5896503f, 0.5452503f};
    enum { TRACKED = 256 };
    uint32_t volume[TRACKED];
    int crossings[TRACKED];
    float first_crossing[TRACKED];
    int tracked = 0;
    vec3 origin;
    glm_vec3_copy((float *)point, origin);
    float travelled = 0;
    for (int step = 0; step < 100000; step++) {
        packed_hit hit;
        if (!packed_intersect_nearest(packed, origin, direction, 0, INFINITY, &hit))
            break;
        travelled += hit.t;
        if (hit.instance != PACKED_NONE
            && (packed_uint(packed, packed->instance_offset + hit.instance * PACKED_INSTANCE_STRIDE, 2)
                & INSTANCE_VOLUME)) {
            int k = 0;
            while (k < tracked && volume[k] != hit.instance)
                k++;
            if (k == tracked && tracked < TRACKED) {
                volume[tracked] = hit.instance;
                crossings[tracked] = 0;
                first_crossing[tracked] = travelled;
                tracked++;
            }
            if (k < TRACKED)
                crossings[k]++;
        }
        float step_length = hit.t + 1e-4f * (1.0f + fmaxf(fabsf(origin[0]), fmaxf(fabsf(origin[1]), fabsf(origin[2]))));
        glm_vec3_muladds(direction, step_length, origin);
    }
    uint32_t inner = 0, outer = 0;
    float inner_distance = INFINITY, outer_distance = INFINITY;
    for (int k = 0; k < tracked; k++) {
        if (crossings[k] % 2 == 0)
            continue;
        if (first_crossing[k] < inner_distance) {
            outer = inner;
            outer_distance = inner_distance;
            inner = volume[k] + 1;
            inner_distance = first_crossing[k];
        } else if (first_crossing[k] < outer_distance) {
            outer = volume[k] + 1;
            outer_distance = first_crossing[k];
        }
    }
    return (inner & 0xffffu) | ((outer & 0xffffu) << 16);
}
