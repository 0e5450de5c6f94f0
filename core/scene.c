/* scene.c: see scene.h. */
#include "scene.h"

#include <stdlib.h>
#include <string.h>

void scene_defaults(scene *s)
{
    memset(s, 0, sizeof *s);
    s->camera = (scene_camera){
        .look_from = {0, 0, 1}, .look_at = {0, 0, 0}, .up = {0, 1, 0},
        .vertical_fov_degrees = 40, .aperture = 0, .focus_distance = 0,
    };
    s->render = (scene_render_settings){
        .width = 640, .height = 360, .samples_per_pixel = 64, .max_depth = 16, .seed = 1,
    };
    s->sky = (scene_sky){.type = SKY_GRADIENT, .bottom = {1, 1, 1}, .top = {0.5f, 0.7f, 1.0f}};
}

void scene_free(scene *s)
{
    free(s->materials);
    free(s->spheres);
    scene_defaults(s);
}

/* Grows *array (of element_size bytes each) so that one more element fits.
 * Returns 0 on success, -1 when memory runs out (the array is then unchanged). */
static int grow(void **array, int count, int *capacity, size_t element_size)
{
    if (count < *capacity)
        return 0;
    int new_capacity = *capacity ? *capacity * 2 : 16;
    void *grown = realloc(*array, (size_t)new_capacity * element_size);
    if (grown == NULL)
        return -1;
    *array = grown;
    *capacity = new_capacity;
    return 0;
}

int scene_add_material(scene *s, const scene_material *material)
{
    if (grow((void **)&s->materials, s->material_count, &s->material_capacity, sizeof *material))
        return -1;
    s->materials[s->material_count] = *material;
    return s->material_count++;
}

int scene_add_sphere(scene *s, const scene_sphere *sphere)
{
    if (grow((void **)&s->spheres, s->sphere_count, &s->sphere_capacity, sizeof *sphere))
        return -1;
    s->spheres[s->sphere_count] = *sphere;
    return s->sphere_count++;
}

int scene_find_material(const scene *s, const char *name)
{
    for (int i = 0; i < s->material_count; i++)
        if (strcmp(s->materials[i].name, name) == 0)
            return i;
    return -1;
}
