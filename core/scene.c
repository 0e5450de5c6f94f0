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


int scene_add_material(scene *s, const scene_material *material)
{
    if (!array_reserve((void **)&s->materials, &s->material_capacity, (size_t)s->material_count + 1, sizeof *material))
        return -1;
    s->materials[s->material_count] = *material;
    return s->material_count++;
}

int scene_add_sphere(scene *s, const scene_sphere *sphere)
{
    if (!array_reserve((void **)&s->spheres, &s->sphere_capacity, (size_t)s->sphere_count + 1, sizeof *sphere))
        return -1;
    s->spheres[s->sphere_count] = *sphere;
    return s->sphere_count++;
}

int scene_add_shape(scene *s, const scene_shape *shape)
{
    if (!array_reserve((void **)&s->shapes, &s->shape_capacity, (size_t)s->shape_count + 1, sizeof *shape))
        return -1;
    s->shapes[s->shape_count] = *shape;
    return s->shape_count++;
}

int scene_add_object(scene *s, const scene_object *object)
{
    if (!array_reserve((void **)&s->objects, &s->object_capacity, (size_t)s->object_count + 1, sizeof *object))
        return -1;
    s->objects[s->object_count] = *object;
    return s->object_count++;
}

int scene_add_instance(scene *s, const scene_instance *instance)
{
    if (!array_reserve((void **)&s->instances, &s->instance_capacity, (size_t)s->instance_count + 1, sizeof *instance))
        return -1;
    s->instances[s->instance_count] = *instance;
    return s->instance_count++;
}

int scene_add_mesh(scene *s, const scene_mesh *mesh)
{
    if (!array_reserve((void **)&s->meshes, &s->mesh_capacity, (size_t)s->mesh_count + 1, sizeof *mesh))
        return -1;
    s->meshes[s->mesh_count] = *mesh;
    return s->mesh_count++;
}

int scene_add_texture(scene *s, const scene_texture *texture)
{
    if (!array_reserve((void **)&s->textures, &s->texture_capacity, (size_t)s->texture_count + 1, sizeof *texture))
        return -1;
    s->textures[s->texture_count] = *texture;
    return s->texture_count++;
}

int scene_add_image(scene *s, const scene_image *image)
{
    if (!array_reserve((void **)&s->images, &s->image_capacity, (size_t)s->image_count + 1, sizeof *image))
        return -1;
    s->images[s->image_count] = *image;
    return s->image_count++;
}

int scene_add_light(scene *s, const scene_light *light)
{
    if (!array_reserve((void **)&s->lights, &s->light_capacity, (size_t)s->light_count + 1, sizeof *light))
        return -1;
    s->lights[s->light_count] = *light;
    return s->light_count++;
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
