/* pack_lights.c: the packer's light section (pack_internal.h): the emissive world
 * primitives (area lights), the scene's point, spot and sun lights and the environment
 * map, each with its power, which the cdf of choosing a light follows; the environment's
 * sampling distribution; and, with more than LIGHT_LOCAL_CHOICE_MAX lights, the light tree
 * (core/light_tree.h) over each light's bounds. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cglm/cglm.h>

#include "light_tree.h"
#include "luminance.h"
#include "pack_internal.h"

/* Whether a world primitive is an area light: a sphere, quad or triangle whose material
 * (concrete at the top level) emits. Moving spheres are left to BSDF sampling. */
static bool is_area_light(const scene *s, const pending_primitive *item)
{
    if (item->type != PRIMITIVE_SPHERE && item->type != PRIMITIVE_QUAD && item->type != PRIMITIVE_TRIANGLE)
        return false;
    return pack_is_emissive(s, item->material);
}

uint32_t pack_count_area_lights(const packer *p)
{
    uint32_t count = 0;
    for (uint32_t k = 0; k < p->top.primitives.count; k++)
        count += is_area_light(p->scene, &p->top.primitives.items[k]);
    return count;
}

/* Writes the area lights, in primitive slot order, from light 0 on; their powers go to
 * power[]: emission luminance x area (x pi for the cosine lobe); their bounds for the light
 * tree to bounds[]: the estimate glsl/lights.glsl light_importance makes of one light, as
 * an intensity over the squared distance (luminance x area; a sphere's projected area is a
 * quarter of its area) with a flat light's normal as the axis of its facing. */
static void write_area_lights(packer *p, double *power, light_bounds *bounds)
{
    const scene *s = p->scene;
    uint32_t light = 0;
    for (uint32_t slot = 0; slot < p->top.primitives.count; slot++) {
        const pending_primitive *item = &p->top.primitives.items[p->top.tree.primitive_indices[slot]];
        if (!is_area_light(s, item))
            continue;
        const float *e = s->materials[item->material].emission;
        double luminance = luminance_double(e[0], e[1], e[2]);
        double area;
        uint32_t type;
        vec3 centre, normal = {0, 0, 0};
        if (item->type == PRIMITIVE_SPHERE) {
            area = 4 * M_PI * item->data[0][3] * item->data[0][3];
            type = LIGHT_SPHERE;
            glm_vec3_copy((float *)item->data[0], centre);
        } else {
            glm_vec3_cross((float *)item->data[1], (float *)item->data[2], normal);
            area = sqrt((double)glm_vec3_norm2(normal)) * (item->type == PRIMITIVE_QUAD ? 1.0 : 0.5);
            glm_vec3_normalize(normal);
            type = item->type == PRIMITIVE_QUAD ? LIGHT_QUAD : LIGHT_TRIANGLE;
            /* The centre: of the parallelogram Q + (u + v) / 2, of the triangle v0 + (e1 + e2) / 3. */
            float share = item->type == PRIMITIVE_QUAD ? 0.5f : 1.0f / 3.0f;
            for (int axis = 0; axis < 3; axis++)
                centre[axis] = item->data[0][axis] + share * (item->data[1][axis] + item->data[2][axis]);
        }
        /* A light of no power is still listed (for MIS weights) but never chosen. */
        power[light] = luminance * area * M_PI;
        light_bounds *b = &bounds[light];
        b->box = bvh_box_empty();
        if (item->type == PRIMITIVE_SPHERE) {
            float radius = fabsf(item->data[0][3]);
            for (int axis = 0; axis < 3; axis++) {
                b->box.min[axis] = centre[axis] - radius;
                b->box.max[axis] = centre[axis] + radius;
            }
            b->cos_spread = -1;
            b->intensity = (float)(luminance * area * 0.25);
        } else {
            vec3 corner;
            bvh_box_add_point(&b->box, item->data[0]);
            glm_vec3_add((float *)item->data[0], (float *)item->data[1], corner);
            bvh_box_add_point(&b->box, corner);
            glm_vec3_add((float *)item->data[0], (float *)item->data[2], corner);
            bvh_box_add_point(&b->box, corner);
            if (item->type == PRIMITIVE_QUAD) {
                glm_vec3_add(corner, (float *)item->data[1], corner);
                bvh_box_add_point(&b->box, corner);
            }
            glm_vec3_copy(normal, b->axis);
            b->cos_spread = 1;
            b->intensity = (float)(luminance * area);
        }
        /* Slots ascend with light: the shader finds a primitive's light by a binary
         * search of the first area_light_count lights. */
        uint64_t base = p->layout.light_offset + (uint64_t)light * PACKED_LIGHT_STRIDE;
        put_texel(p->texels, base, type, slot, 0, 0);
        /* What the shader's estimate of this light's irradiance at a point reads
         * (glsl/lights.glsl, light_importance); texel 1's w is the cdf, written last. */
        put_texel(p->texels, base + 1, float_bits(centre[0]), float_bits(centre[1]), float_bits(centre[2]), 0);
        put_texel(p->texels, base + 2, float_bits(normal[0]), float_bits(normal[1]), float_bits(normal[2]),
                  float_bits((float)(luminance * area)));
        put_texel(p->texels, base + 3, float_bits((float)area), 0, 0, 0);
        put_texel(p->texels, base + 4, (uint32_t)s->materials[item->material].light_group, 0, 0, 0);
        p->out->summary.light_types |= 1u << type;
        light++;
    }
}

/* Half the diagonal of the top-level box (1 when there is none): what a sun or the
 * environment lights is taken to be this large. */
static double scene_radius(const packer *p)
{
    double radius = 1;
    if (p->top.primitives.count > 0) {
        const bvh_box *box = &p->top.tree.nodes[0].box;
        double extent[3] = {box->max[0] - box->min[0], box->max[1] - box->min[1], box->max[2] - box->min[2]};
        radius = 0.5 * sqrt(extent[0] * extent[0] + extent[1] * extent[1] + extent[2] * extent[2]);
        if (!(radius > 0) || !isfinite(radius))
            radius = 1;
    }
    return radius;
}

/* Writes the scene's point, spot and sun lights from light first on, with their powers
 * and their bounds for the light tree (a point or spot: its intensity's luminance at a
 * point, a spot's within its outer cone only; a sun: its irradiance's, from within its
 * angular radius of the way towards it). A sun's power is its irradiance over the scene's
 * cross-section. */
static void write_scene_lights(packer *p, uint32_t first, double radius, double *power, light_bounds *bounds)
{
    const scene *s = p->scene;
    uint32_t light = first;
    for (int k = 0; k < s->light_count; k++, light++) {
        const scene_light *source = &s->lights[k];
        const float *c = source->color;
        double luminance = luminance_double(c[0], c[1], c[2]);
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
            power[light] = M_PI * radius * radius * luminance;
        light_bounds *b = &bounds[light];
        b->box = bvh_box_empty();
        b->cos_spread = -1;
        if (type == LIGHT_SPOT) {
            glm_vec3_copy((float *)source->direction, b->axis);
            b->cos_spread = (float)cos_outer;
            b->one_sided = true;
        }
        if (type == LIGHT_SUN) {
            b->infinite = true;
            b->irradiance = (float)luminance;
            /* It comes from within its angular radius of the way towards it. */
            glm_vec3_negate_to((float *)source->direction, b->axis);
            b->cos_spread = (float)cos_sun;
        } else {
            bvh_box_add_point(&b->box, source->position);
            b->intensity = (float)luminance;
        }
        bool polynomial = source->falloff == FALLOFF_POLYNOMIAL;
        uint64_t base = p->layout.light_offset + (uint64_t)light * PACKED_LIGHT_STRIDE;
        put_texel(p->texels, base, type, polynomial ? float_bits(source->attenuation[0]) : 0,
                  polynomial ? float_bits(source->attenuation[1]) : 0,
                  polynomial ? float_bits(source->attenuation[2]) : 0);
        /* The sun is stored as the direction towards it. */
        vec3 where;
        if (type == LIGHT_SUN)
            glm_vec3_negate_to((float *)source->direction, where);
        else
            glm_vec3_copy((float *)source->position, where);
        put_texel(p->texels, base + 1, float_bits(where[0]), float_bits(where[1]), float_bits(where[2]), 0);
        put_texel(p->texels, base + 2, float_bits(c[0]), float_bits(c[1]), float_bits(c[2]),
                  float_bits((float)(type == LIGHT_SUN ? cos_sun : cos_outer)));
        put_texel(p->texels, base + 3, float_bits(source->direction[0]), float_bits(source->direction[1]),
                  float_bits(source->direction[2]), float_bits((float)cos_inner));
        put_texel(p->texels, base + 4, (uint32_t)source->light_group, 0, 0, 0);
        p->out->summary.light_types |= 1u << type;
    }
}

/* Writes the environment's sampling distribution (packed_layout.h, lights) and its light
 * record as light number light; returns its power: the mean radiance on the scene's
 * cross-section from all around. Rows, then pixels in each row, are weighted by
 * luminance x sin(latitude) (the solid angle a pixel covers); a small floor keeps every
 * pixel reachable. */
static rt_status write_environment(packer *p, uint32_t light, double radius, double *power, light_bounds *bounds,
                                   rt_error *error)
{
    const scene_image *environment = p->environment;
    uint32_t *texels = p->texels;
    uint64_t offset = p->layout.environment_offset;
    int width = environment->width, height = environment->height;
    double *row_sums = calloc((size_t)height, sizeof *row_sums);
    if (row_sums == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    double mean = 0;
    for (size_t i = 0; i < (size_t)width * height; i++) {
        const float *c = environment->pixels + 4 * i;
        mean += luminance_double(c[0], c[1], c[2]);
    }
    mean /= (double)width * height;
    double floor_weight = 1e-3 * mean + 1e-12, total_weight = 0;
    for (int y = 0; y < height; y++) {
        double sine = sin(M_PI * (y + 0.5) / height), row = 0;
        uint64_t row_base = offset + height + (uint64_t)y * width;
        for (int x = 0; x < width; x++) {
            const float *c = environment->pixels + 4 * ((size_t)y * width + x);
            row += (luminance_double(c[0], c[1], c[2]) + floor_weight) * sine;
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
        put_texel(texels, offset + y, float_bits(y + 1 == height ? 1.0f : (float)(cumulative_rows / total_weight)), 0,
                  0, 0);
    }
    free(row_sums);
    power[light] = 4 * M_PI * radius * radius * mean * p->scene->sky.intensity;
    uint64_t base = p->layout.light_offset + (uint64_t)light * PACKED_LIGHT_STRIDE;
    put_texel(texels, base, LIGHT_ENVIRONMENT, (uint32_t)width, (uint32_t)height, 0);
    /* The irradiance it gives a surface facing any way, about pi x its mean radiance. */
    put_texel(texels, base + 2, 0, 0, 0, float_bits((float)(M_PI * mean * p->scene->sky.intensity)));
    bounds[light].box = bvh_box_empty();
    bounds[light].cos_spread = -1;
    bounds[light].infinite = true;
    bounds[light].irradiance = (float)(M_PI * mean * p->scene->sky.intensity);
    put_texel(texels, base + 4, (uint32_t)p->scene->sky.light_group, 0, 0, 0);
    p->out->summary.light_types |= 1u << LIGHT_ENVIRONMENT;
    return RT_OK;
}

/* Writes the light tree over bounds[] (light_count lights) to its section and each light's
 * trail to texel 4 of its record (packed_layout.h, lights). */
static rt_status write_light_tree(packer *p, const light_bounds *bounds, uint32_t light_count, rt_error *error)
{
    light_tree tree = {0};
    rt_status status = light_tree_build(bounds, light_count, &tree, error);
    if (status != RT_OK)
        return status;
    for (uint32_t n = 0; n < tree.node_count; n++) {
        const light_tree_node *node = &tree.nodes[n];
        uint64_t base = p->layout.light_tree_offset + (uint64_t)n * PACKED_LIGHT_TREE_NODE_STRIDE;
        put_texel(p->texels, base, float_bits(node->box.min[0]), float_bits(node->box.min[1]),
                  float_bits(node->box.min[2]), float_bits(node->intensity));
        put_texel(p->texels, base + 1, float_bits(node->box.max[0]), float_bits(node->box.max[1]),
                  float_bits(node->box.max[2]), float_bits(node->irradiance));
        put_texel(p->texels, base + 2, packed_encode_normal(node->axis), float_bits(node->cos_spread),
                  node->leaf ? node->first | LIGHT_TREE_LEAF : node->first,
                  node->one_sided ? LIGHT_TREE_ONE_SIDED : 0);
    }
    for (uint32_t l = 0; l < light_count; l++) {
        uint64_t base = p->layout.light_offset + (uint64_t)l * PACKED_LIGHT_STRIDE;
        p->texels[4 * (base + 4) + 1] = tree.trails[l];
    }
    p->out->light_tree_depth = tree.depth;
    light_tree_free(&tree);
    return RT_OK;
}

rt_status pack_write_lights(packer *p, rt_error *error)
{
    uint32_t light_count = (uint32_t)p->layout.light_count;
    if (light_count == 0)
        return RT_OK;
    double *power = malloc(light_count * sizeof *power);
    light_bounds *bounds = calloc(light_count, sizeof *bounds);
    if (power == NULL || bounds == NULL) {
        free(power);
        free(bounds);
        return rt_error_set(error, RT_ERROR_RUNTIME, "PACK: out of memory");
    }
    uint32_t area_lights = (uint32_t)p->layout.area_light_count;
    double radius = scene_radius(p);
    write_area_lights(p, power, bounds);
    write_scene_lights(p, area_lights, radius, power, bounds);
    rt_status status = RT_OK;
    if (p->environment != NULL)
        status = write_environment(p, area_lights + (uint32_t)p->scene->light_count, radius, power, bounds, error);
    if (status == RT_OK && p->layout.light_tree_offset != PACKED_NONE)
        status = write_light_tree(p, bounds, light_count, error);
    free(bounds);
    if (status != RT_OK) {
        free(power);
        return status;
    }
    /* The cdf of choosing each light, by power (all alike when none has any). */
    double total = 0;
    for (uint32_t l = 0; l < light_count; l++)
        total += power[l];
    double cumulative = 0;
    for (uint32_t l = 0; l < light_count; l++) {
        cumulative += total > 0 ? power[l] / total : 1.0 / light_count;
        uint64_t base = p->layout.light_offset + (uint64_t)l * PACKED_LIGHT_STRIDE;
        p->texels[4 * (base + 1) + 3] = float_bits(l + 1 == light_count ? 1.0f : (float)cumulative);
    }
    free(power);
    return RT_OK;
}
