/* packed_traverse.c: see packed_traverse.h. The traversal follows the tracer's
 * (glsl/intersect.glsl, glsl/traverse.glsl: intersection, BVH walk, instances) operation
 * for operation, so that CPU and shader
 * agree on what a ray hits. */
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
    t_near /= length;
    t_far /= length;
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
    glm_vec3_div(GLM_VEC3_ONE, direction, ray->inverse_direction);
}

/* glsl/intersect.glsl intersect_box, the slab test: where the ray enters node's box within
 * (0, t_max), or INFINITY when it misses. */
static float intersect_box(const packed_scene *packed, uint32_t node, const moving_ray *ray, float t_max)
{
    uint32_t base = packed->node_offset + node * PACKED_NODE_STRIDE;
    float enter = 0, leave = t_max;
    for (int axis = 0; axis < 3; axis++) {
        float t0 = (packed_float(packed, base, axis) - ray->origin[axis]) * ray->inverse_direction[axis];
        float t1 = (packed_float(packed, base + 1, axis) - ray->origin[axis]) * ray->inverse_direction[axis];
        enter = fmaxf(enter, fminf(t0, t1));
        leave = fminf(leave, fmaxf(t0, t1));
    }
    return enter <= leave ? enter : INFINITY;
}

bool packed_intersect_nearest(const packed_scene *packed, const float origin[3], const float direction[3], float time,
                              float t_max, packed_hit *hit)
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
    if (intersect_box(packed, 0, &ray, INFINITY) == INFINITY)
        return false;
    enum { STACK = 2 * BVH_MAX_DEPTH + 2 * BVH_MAX_LEAF_SIZE };
    uint32_t stack_node[STACK];
    float stack_entry[STACK];
    int stack_size = 0;
    uint32_t node = 0, current_instance = PACKED_NONE;
    float node_entry = 0;
    for (;;) {
        if (node == PACKED_NONE) {
            /* Leaving an instance: back to the world ray. */
            ray_set(&ray, world_origin, world_direction);
            current_instance = PACKED_NONE;
        } else if (node_entry < hit->t) {
            uint32_t base = packed->node_offset + node * PACKED_NODE_STRIDE;
            uint32_t first = packed_uint(packed, base, 3), count = packed_uint(packed, base + 1, 3);
            if (count > 0) {
                for (uint32_t slot = first; slot < first + count; slot++) {
                    packed_primitive primitive = packed_primitive_at(packed, slot);
                    float t = INFINITY;
                    if (primitive.type == PRIMITIVE_INSTANCE) {
                        /* Visited after this leaf: a marker that restores the world ray,
                         * under an entry that moves the ray into the instance. */
                        if (stack_size + 2 > STACK)
                            continue;
                        stack_node[stack_size] = PACKED_NONE;
                        stack_entry[stack_size] = -INFINITY;
                        stack_size++;
                        stack_node[stack_size] = primitive.instance | 0x80000000u;
                        stack_entry[stack_size] = -INFINITY;
                        stack_size++;
                        continue;
                    }
                    if (primitive.type == PRIMITIVE_SPHERE)
                        t = intersect_sphere(primitive.data[0], primitive.data[0][3], ray.origin, ray.direction, hit->t);
                    else if (primitive.type == PRIMITIVE_MOVING_SPHERE) {
                        vec3 motion, center;
                        glm_vec3_sub(primitive.data[1], primitive.data[0], motion);
                        glm_vec3_scale(motion, time, motion);
                        glm_vec3_add(primitive.data[0], motion, center);
                        t = intersect_sphere(center, primitive.data[0][3], ray.origin, ray.direction, hit->t);
                    } else
                        t = intersect_flat(&primitive, ray.origin, ray.direction, hit->t);
                    if (t < hit->t) {
                        hit->t = t;
                        hit->primitive = slot;
                        hit->instance = current_instance;
                    }
                }
            } else {
                float left = intersect_box(packed, first, &ray, hit->t);
                float right = intersect_box(packed, first + 1, &ray, hit->t);
                uint32_t near_node = right < left ? first + 1 : first;
                float near_entry = fminf(left, right), far_entry = fmaxf(left, right);
                if (near_entry < INFINITY) {
                    if (far_entry < INFINITY && stack_size < STACK) {
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
        if (node != PACKED_NONE && (node & 0x80000000u)) {
            /* Entering an instance: move the ray into its object's coordinates. The
             * direction is not renormalised, so t stays the world ray's parameter. */
            uint32_t instance = node & 0x7fffffffu;
            uint32_t instance_base = packed->instance_offset + instance * PACKED_INSTANCE_STRIDE;
            node = packed_uint(packed, instance_base, 0);
            vec3 object_origin, object_direction;
            for (int r = 0; r < 3; r++) {
                vec4 row;
                for (int c = 0; c < 4; c++)
                    row[c] = packed_float(packed, instance_base + 1 + r, c);
                object_origin[r] = glm_vec3_dot(row, world_origin) + row[3];
                object_direction[r] = glm_vec3_dot(row, world_direction);
            }
            ray_set(&ray, object_origin, object_direction);
            current_instance = instance;
            node_entry = intersect_box(packed, node, &ray, hit->t);
        }
    }
    return hit->primitive != PACKED_NONE;
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
