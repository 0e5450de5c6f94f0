/* scene.c: see scene.h. */
#include "scene.h"

#include "array.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void scene_defaults(scene *s)
{
    memset(s, 0, sizeof *s);
    s->camera = (scene_camera){
        .look_from = {0, 0, 1}, .look_at = {0, 0, 0}, .up = {0, 1, 0},
        .vertical_fov_degrees = 40, .aperture = 0, .focus_distance = 0,
        .shutter_open = 0, .shutter_close = 1,
    };
    s->render = (scene_render_settings){
        .width = 640, .height = 360, .samples_per_pixel = 64, .max_depth = 16, .seed = 1,
    };
    s->ambient[0] = s->ambient[1] = s->ambient[2] = 0.03f;
    snprintf(s->light_groups[0], SCENE_NAME_MAX, "%s", SCENE_DEFAULT_LIGHT_GROUP);
    s->light_group_count = 1;
    s->sky = (scene_sky){
        .type = SKY_GRADIENT, .bottom = {1, 1, 1}, .top = {0.5f, 0.7f, 1.0f},
        .faces = {-1, -1, -1, -1, -1, -1}, .environment = -1, .intensity = 1, .rotation_degrees = 0,
    };
}

void scene_free(scene *s)
{
    free(s->materials);
    free(s->spheres);
    free(s->shapes);
    free(s->objects);
    free(s->instances);
    for (int i = 0; i < s->mesh_count; i++) {
        free(s->meshes[i].positions);
        free(s->meshes[i].normals);
        free(s->meshes[i].uvs);
        free(s->meshes[i].colors);
        free(s->meshes[i].indices);
        free(s->meshes[i].triangle_materials);
    }
    free(s->meshes);
    free(s->textures);
    free(s->lights);
    for (int i = 0; i < s->image_count; i++) {
        free(s->images[i].pixels);
        free(s->images[i].encoded);
    }
    free(s->images);
    free(s->warnings);
    scene_defaults(s);
}

/* Appends the element_size bytes at item to the array *items of *count elements and room
 * for *capacity (grown with array_reserve); returns the new element's index, or -1 when
 * memory runs out (the array is then unchanged). Every scene_add_* but the warnings'. */
static int append_item(void **items, int *count, size_t *capacity, const void *item, size_t element_size)
{
    if (!array_reserve(items, capacity, (size_t)*count + 1, element_size))
        return -1;
    memcpy((char *)*items + (size_t)*count * element_size, item, element_size);
    return (*count)++;
}

int scene_add_material(scene *s, const scene_material *material)
{
    return append_item((void **)&s->materials, &s->material_count, &s->material_capacity, material, sizeof *material);
}

int scene_add_sphere(scene *s, const scene_sphere *sphere)
{
    return append_item((void **)&s->spheres, &s->sphere_count, &s->sphere_capacity, sphere, sizeof *sphere);
}

int scene_add_shape(scene *s, const scene_shape *shape)
{
    return append_item((void **)&s->shapes, &s->shape_count, &s->shape_capacity, shape, sizeof *shape);
}

int scene_add_object(scene *s, const scene_object *object)
{
    return append_item((void **)&s->objects, &s->object_count, &s->object_capacity, object, sizeof *object);
}

int scene_add_instance(scene *s, const scene_instance *instance)
{
    return append_item((void **)&s->instances, &s->instance_count, &s->instance_capacity, instance, sizeof *instance);
}

int scene_add_mesh(scene *s, const scene_mesh *mesh)
{
    return append_item((void **)&s->meshes, &s->mesh_count, &s->mesh_capacity, mesh, sizeof *mesh);
}

int scene_add_texture(scene *s, const scene_texture *texture)
{
    return append_item((void **)&s->textures, &s->texture_count, &s->texture_capacity, texture, sizeof *texture);
}

int scene_add_image(scene *s, const scene_image *image)
{
    return append_item((void **)&s->images, &s->image_count, &s->image_capacity, image, sizeof *image);
}

int scene_add_light(scene *s, const scene_light *light)
{
    return append_item((void **)&s->lights, &s->light_count, &s->light_capacity, light, sizeof *light);
}

int scene_add_warning(scene *s, const char *format, ...)
{
    if (!array_reserve((void **)&s->warnings, &s->warning_capacity, (size_t)s->warning_count + 1, sizeof *s->warnings))
        return -1;
    va_list arguments;
    va_start(arguments, format);
    vsnprintf(s->warnings[s->warning_count].message, sizeof s->warnings[s->warning_count].message, format,
              arguments);
    va_end(arguments);
    return s->warning_count++;
}

int scene_light_group(scene *s, const char *name)
{
    for (int i = 0; i < s->light_group_count; i++)
        if (strcmp(s->light_groups[i], name) == 0)
            return i;
    if (s->light_group_count == SCENE_LIGHT_GROUP_MAX)
        return -1;
    snprintf(s->light_groups[s->light_group_count], SCENE_NAME_MAX, "%s", name);
    return s->light_group_count++;
}

scene_light scene_light_defaults(scene_light_type type)
{
    scene_light light;
    memset(&light, 0, sizeof light);
    light.type = type;
    light.direction[1] = -1;
    light.color[0] = light.color[1] = light.color[2] = 1;
    light.spot_outer_degrees = 30;
    light.spot_inner_degrees = 25;
    light.sun_angle_degrees = 0.53f;
    light.falloff = FALLOFF_INVERSE_SQUARE;
    light.attenuation[0] = 1;
    return light;
}

scene_material scene_material_defaults(void)
{
    scene_material material;
    memset(&material, 0, sizeof material);
    material.albedo_texture = -1;
    material.emission_texture = -1;
    material.normal_map = -1;
    material.metallic_roughness_texture = -1;
    material.alpha = 1.0f;
    material.alpha_cutoff = 0.5f;
    return material;
}

void scene_identity_transform(float m[3][4])
{
    for (int row = 0; row < 3; row++)
        for (int column = 0; column < 4; column++)
            m[row][column] = row == column ? 1.0f : 0.0f;
}

int scene_find_material(const scene *s, const char *name)
{
    for (int i = 0; i < s->material_count; i++)
        if (strcmp(s->materials[i].name, name) == 0)
            return i;
    return -1;
}
