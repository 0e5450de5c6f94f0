/* scene_gltf.c: see scene_gltf.h. */
#include "scene_gltf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "bvh.h"

/* The wrap-mode pairs a glTF image can be sampled with, and its two uses (colour, data):
 * each combination is one scene image. */
#define WRAP_PAIRS 9
#define IMAGE_VARIANTS (2 * WRAP_PAIRS)

/* The sky and image height of a glTF file rendered by itself (scene_gltf.h). */
#define NEUTRAL_SKY 0.5f
#define DEFAULT_HEIGHT 360
#define DEFAULT_FOV_DEGREES 40.0

/* One model being added: the scene images and textures made for its images so far. */
typedef struct import {
    scene *scene;
    gltf_model *model;
    const char *path, *position;
    int *image_variants;         /* model image i, variant v: scene image, or -1 */
    int *texture_variants;       /* the same for colour images: scene texture, or -1 */
    int default_material;        /* glTF's default material, -1 until needed */
    rt_error *error;
} import;

/* Returns the last component of path. */
static const char *file_name_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash != NULL ? slash + 1 : path;
}

/* Reports that memory ran out; returns RT_ERROR_RUNTIME. */
static rt_status out_of_memory(import *im)
{
    return rt_error_set(im->error, RT_ERROR_RUNTIME, "%s: out of memory importing glTF '%s'",
                        im->position != NULL ? im->position : im->path, im->path);
}

/* What the messages about the model's images and meshes start with. */
static const char *where_of(const import *im)
{
    return im->position != NULL ? im->position : im->path;
}

/* Sets *index to the scene image of texture ref used as data or colour, adding it (with a
 * copy of the model image's bytes, or the bytes themselves for its first use). */
static rt_status image_for(import *im, const gltf_texture_ref *ref, bool data, int *index)
{
    int variant = (data ? WRAP_PAIRS : 0) + ref->wrap_u * 3 + ref->wrap_v;
    int *slot = &im->image_variants[(size_t)ref->image * IMAGE_VARIANTS + (size_t)variant];
    if (*slot >= 0) {
        *index = *slot;
        return RT_OK;
    }
    gltf_image *source = &im->model->images[ref->image];
    scene_image image;
    memset(&image, 0, sizeof image);
    snprintf(image.path, sizeof image.path, "images[%d]%s%.64s%s", ref->image, source->name[0] != '\0' ? " (" : "",
             source->name, source->name[0] != '\0' ? ")" : "");
    if (im->position != NULL)
        snprintf(image.position, sizeof image.position, "%s: glTF '%s'", im->position, im->path);
    else
        snprintf(image.position, sizeof image.position, "%s", im->path);
    image.data = data;
    image.wrap[0] = ref->wrap_u;
    image.wrap[1] = ref->wrap_v;
    image.encoded_size = source->size;
    if (source->bytes != NULL) {
        /* The first use takes the bytes over; a later one (another sampler or use) copies. */
        image.encoded = source->bytes;
        source->bytes = NULL;
    } else {
        image.encoded = malloc(source->size);
        int first = -1;
        for (int v = 0; v < IMAGE_VARIANTS && first < 0; v++)
            first = im->image_variants[(size_t)ref->image * IMAGE_VARIANTS + (size_t)v];
        if (image.encoded == NULL || first < 0)
            return free(image.encoded), out_of_memory(im);
        memcpy(image.encoded, im->scene->images[first].encoded, source->size);
    }
    *index = scene_add_image(im->scene, &image);
    if (*index < 0)
        return free(image.encoded), out_of_memory(im);
    *slot = *index;
    return RT_OK;
}

/* Sets *texture to the image texture of a colour texture ref (-1 when it has no image). */
static rt_status texture_for(import *im, const gltf_texture_ref *ref, int *texture)
{
    *texture = -1;
    if (ref->image < 0)
        return RT_OK;
    int variant = ref->wrap_u * 3 + ref->wrap_v;
    int *slot = &im->texture_variants[(size_t)ref->image * WRAP_PAIRS + (size_t)variant];
    if (*slot < 0) {
        scene_texture made = {.type = TEXTURE_IMAGE, .even = -1, .odd = -1};
        rt_status status = image_for(im, ref, false, &made.image);
        if (status != RT_OK)
            return status;
        *slot = scene_add_texture(im->scene, &made);
        if (*slot < 0)
            return out_of_memory(im);
    }
    *texture = *slot;
    return RT_OK;
}

/* Sets *image to the data image of ref (-1 when it has none). */
static rt_status data_image_for(import *im, const gltf_texture_ref *ref, int *image)
{
    *image = -1;
    return ref->image < 0 ? RT_OK : image_for(im, ref, true, image);
}

/* Adds glTF material index (-1: glTF's default material) as a pbr material. */
static rt_status add_material(import *im, int index, int *added)
{
    gltf_material defaults = {
        .base_color = {1, 1, 1, 1}, .metallic = 1, .roughness = 1, .alpha_cutoff = 0.5f, .ior = 1.5f,
        .base_color_texture = {-1, 0, 0}, .metallic_roughness_texture = {-1, 0, 0}, .normal_texture = {-1, 0, 0},
        .emissive_texture = {-1, 0, 0},
    };
    const gltf_material *g = index >= 0 ? &im->model->materials[index] : &defaults;
    scene_material m = scene_material_defaults();
    char name[GLTF_NAME_MAX + 16];
    if (index < 0)
        snprintf(name, sizeof name, "default");
    else if (g->name[0] != '\0')
        snprintf(name, sizeof name, "%s", g->name);
    else
        snprintf(name, sizeof name, "materials[%d]", index);
    char full[sizeof im->scene->meshes->path + sizeof name + 2];
    snprintf(full, sizeof full, "%.1023s:%s", file_name_of(im->path), name);
    snprintf(m.name, sizeof m.name, "%.*s", SCENE_NAME_MAX - 1, full);
    m.type = MATERIAL_PBR;
    memcpy(m.albedo, g->base_color, sizeof m.albedo);
    m.alpha = g->base_color[3];
    m.metallic = g->metallic;
    m.roughness = g->roughness;
    memcpy(m.emission, g->emissive, sizeof m.emission);
    m.one_sided = true;
    m.alpha_mode = g->alpha_mode == GLTF_ALPHA_OPAQUE ? SCENE_ALPHA_OPAQUE : SCENE_ALPHA_MASK;
    m.alpha_cutoff = g->alpha_cutoff;
    m.transmission = g->transmission;
    m.index_of_refraction = g->ior;
    rt_status status = texture_for(im, &g->base_color_texture, &m.albedo_texture);
    if (status == RT_OK)
        status = texture_for(im, &g->emissive_texture, &m.emission_texture);
    if (status == RT_OK)
        status = data_image_for(im, &g->metallic_roughness_texture, &m.metallic_roughness_texture);
    if (status == RT_OK)
        status = data_image_for(im, &g->normal_texture, &m.normal_map);
    if (status != RT_OK)
        return status;
    *added = scene_add_material(im->scene, &m);
    return *added >= 0 ? RT_OK : out_of_memory(im);
}

/* Adds mesh index (its arrays taken from the model) and its object; *object is -1 for a
 * mesh without triangles. first_material is the scene index of the model's material 0. */
static rt_status add_mesh(import *im, int index, int first_material, int *object)
{
    gltf_mesh *g = &im->model->meshes[index];
    *object = -1;
    if (g->triangle_count == 0)
        return RT_OK;
    scene *s = im->scene;
    for (int t = 0; t < g->triangle_count; t++) {
        int own = g->triangle_materials[t];
        if (own < 0 && im->default_material < 0) {
            rt_status status = add_material(im, -1, &im->default_material);
            if (status != RT_OK)
                return status;
        }
        g->triangle_materials[t] = own >= 0 ? first_material + own : im->default_material;
        if (g->colors != NULL)
            s->materials[g->triangle_materials[t]].vertex_colors = true;
    }
    scene_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    snprintf(mesh.path, sizeof mesh.path, "%.900s: meshes[%d]", im->path, index);
    snprintf(mesh.position, sizeof mesh.position, "%s", where_of(im));
    mesh.default_material = -1;
    mesh.positions = g->positions;
    mesh.normals = g->normals;
    mesh.uvs = g->uvs;
    mesh.colors = g->colors;
    mesh.indices = g->indices;
    mesh.triangle_materials = g->triangle_materials;
    mesh.vertex_count = g->vertex_count;
    mesh.triangle_count = g->triangle_count;
    int mesh_index = scene_add_mesh(s, &mesh);
    if (mesh_index < 0)
        return out_of_memory(im);
    /* The scene owns the arrays now. */
    g->positions = g->normals = g->uvs = g->colors = NULL;
    g->indices = NULL;
    g->triangle_materials = NULL;
    scene_object made = {.first_shape = 0, .shape_count = 0, .mesh = mesh_index};
    *object = scene_add_object(s, &made);
    return *object >= 0 ? RT_OK : out_of_memory(im);
}

/* Adds the model's warnings to the scene, prefixed with where they come from. */
static rt_status add_warnings(import *im)
{
    const gltf_model *model = im->model;
    /* "POSITION: glTF 'PATH': " in a scene file, "PATH: " for the file by itself. */
    char prefix[1400];
    if (im->position != NULL)
        snprintf(prefix, sizeof prefix, "%s: glTF '%s'", im->position, im->path);
    else
        snprintf(prefix, sizeof prefix, "%s", im->path);
    for (int w = 0; w < model->warning_count && w < GLTF_MAX_WARNINGS; w++)
        if (scene_add_warning(im->scene, "%s: %s", prefix, model->warnings[w]) < 0)
            return out_of_memory(im);
    if (model->warning_count > GLTF_MAX_WARNINGS &&
        scene_add_warning(im->scene, "%s: %d more warnings left out", prefix,
                          model->warning_count - GLTF_MAX_WARNINGS) < 0)
        return out_of_memory(im);
    return RT_OK;
}

/* Adds everything but the placements (see scene_gltf_add); object_of_mesh[i] is set to
 * mesh i's object. */
static rt_status add_contents(import *im, int *object_of_mesh)
{
    scene *s = im->scene;
    const int first_material = s->material_count;
    for (int i = 0; i < im->model->material_count; i++) {
        int added = -1;
        rt_status status = add_material(im, i, &added);
        if (status != RT_OK)
            return status;
    }
    for (int i = 0; i < im->model->mesh_count; i++) {
        rt_status status = add_mesh(im, i, first_material, &object_of_mesh[i]);
        if (status != RT_OK)
            return status;
    }
    return add_warnings(im);
}

rt_status scene_gltf_add(scene *s, gltf_model *model, const char *path, const char *position,
                         scene_gltf_contents *out, rt_error *error)
{
    memset(out, 0, sizeof *out);
    out->first_material = s->material_count;
    out->first_texture = s->texture_count;
    out->first_mesh = s->mesh_count;
    import im = {.scene = s, .model = model, .path = path, .position = position, .default_material = -1,
                 .error = error};
    size_t images = (size_t)model->image_count;
    im.image_variants = malloc((images > 0 ? images : 1) * IMAGE_VARIANTS * sizeof *im.image_variants);
    im.texture_variants = malloc((images > 0 ? images : 1) * WRAP_PAIRS * sizeof *im.texture_variants);
    int *object_of_mesh = malloc((size_t)(model->mesh_count > 0 ? model->mesh_count : 1) * sizeof *object_of_mesh);
    out->placements = malloc((size_t)(model->placement_count > 0 ? model->placement_count : 1) *
                             sizeof *out->placements);
    rt_status status = RT_OK;
    if (im.image_variants == NULL || im.texture_variants == NULL || object_of_mesh == NULL || out->placements == NULL)
        status = out_of_memory(&im);
    if (status == RT_OK) {
        for (size_t i = 0; i < images * IMAGE_VARIANTS; i++)
            im.image_variants[i] = -1;
        for (size_t i = 0; i < images * WRAP_PAIRS; i++)
            im.texture_variants[i] = -1;
        status = add_contents(&im, object_of_mesh);
    }
    for (int p = 0; status == RT_OK && p < model->placement_count; p++) {
        const gltf_placement *placement = &model->placements[p];
        scene_gltf_placement *placed = &out->placements[out->placement_count++];
        placed->object = object_of_mesh[placement->mesh];
        memcpy(placed->object_to_world, placement->object_to_world, sizeof placed->object_to_world);
    }
    free(im.image_variants);
    free(im.texture_variants);
    free(object_of_mesh);
    if (status != RT_OK)
        scene_gltf_contents_free(out);
    return status;
}

void scene_gltf_contents_free(scene_gltf_contents *contents)
{
    free(contents->placements);
    memset(contents, 0, sizeof *contents);
}

bool scene_gltf_is_model_path(const char *path)
{
    size_t length = path != NULL ? strlen(path) : 0;
    return (length > 5 && strcasecmp(path + length - 5, ".gltf") == 0) ||
           (length > 4 && strcasecmp(path + length - 4, ".glb") == 0);
}

/* ------------------------------------------------------------------ a file by itself */

/* Returns the unit vector of v (or false when it has no length). */
static bool unit(const double v[3], float out[3])
{
    double length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(length > 0) || !isfinite(length))
        return false;
    for (int k = 0; k < 3; k++)
        out[k] = (float)(v[k] / length);
    return true;
}

/* Sets out to column k of m (k = 3: the translation; else a direction, negated by sign). */
static void column(const gltf_matrix m, int k, double sign, double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = sign * m[r][k];
}

/* Sets the scene's camera and size from the model's camera called name (NULL or "": the
 * first). */
static rt_status use_camera(scene *s, const gltf_model *model, const char *path, const char *name, rt_error *error)
{
    const gltf_camera *chosen = NULL;
    for (int i = 0; i < model->camera_count && chosen == NULL; i++)
        if (name == NULL || name[0] == '\0' || strcmp(model->cameras[i].name, name) == 0 ||
            strcmp(model->cameras[i].node_name, name) == 0)
            chosen = &model->cameras[i];
    if (chosen == NULL) {
        char names[512] = "";
        for (int i = 0; i < model->camera_count; i++) {
            size_t used = strlen(names);
            const gltf_camera *c = &model->cameras[i];
            snprintf(names + used, sizeof names - used, "%s'%s'", i > 0 ? ", " : "",
                     c->name[0] != '\0' ? c->name : c->node_name);
        }
        return rt_error_set(error, RT_ERROR_INPUT, "%s: no camera called '%s' (%s%s)", path, name,
                            model->camera_count > 0 ? "its scene places " : "its scene places no camera",
                            names);
    }
    if (chosen->orthographic)
        return rt_error_set(error, RT_ERROR_INPUT, "%s: cameras[%d]%s%s%s is orthographic, which rtspheres does not "
                            "render (only perspective cameras; choose another with --camera NAME)", path,
                            chosen->index, chosen->name[0] != '\0' ? " ('" : "", chosen->name,
                            chosen->name[0] != '\0' ? "')" : "");
    double from[3], forward[3], up[3];
    column(chosen->camera_to_world, 3, 1, from);
    column(chosen->camera_to_world, 2, -1, forward);
    column(chosen->camera_to_world, 1, 1, up);
    float forward_unit[3], up_unit[3];
    if (!unit(forward, forward_unit) || !unit(up, up_unit))
        return rt_error_set(error, RT_ERROR_INPUT, "%s: cameras[%d]: its node's transform squashes it flat (a zero "
                            "scale), so it has no view direction", path, chosen->index);
    for (int k = 0; k < 3; k++) {
        s->camera.look_from[k] = (float)from[k];
        s->camera.look_at[k] = (float)(from[k] + forward_unit[k]);
        s->camera.up[k] = up_unit[k];
    }
    s->camera.vertical_fov_degrees = (float)(chosen->yfov * 180.0 / M_PI);
    s->camera.focus_distance = 0;
    s->render.height = DEFAULT_HEIGHT;
    if (chosen->aspect_ratio > 0) {
        double width = round(DEFAULT_HEIGHT * chosen->aspect_ratio);
        s->render.width = width < 1 ? 1 : width > 16384 ? 16384 : (int)width;
    }
    return RT_OK;
}

/* Points the default camera at the placed meshes (scene_gltf.h); leaves it as it is when
 * nothing is placed. */
static void frame_placements(scene *s)
{
    bvh_box box = bvh_box_empty();
    for (int i = 0; i < s->instance_count; i++) {
        const scene_instance *instance = &s->instances[i];
        const scene_mesh *mesh = &s->meshes[s->objects[instance->object].mesh];
        for (int v = 0; v < mesh->vertex_count; v++) {
            const float *p = mesh->positions + 3 * (size_t)v;
            float world[3];
            for (int r = 0; r < 3; r++)
                world[r] = instance->object_to_world[r][0] * p[0] + instance->object_to_world[r][1] * p[1] +
                           instance->object_to_world[r][2] * p[2] + instance->object_to_world[r][3];
            bvh_box_add_point(&box, world);
        }
    }
    if (!(box.min[0] <= box.max[0]))
        return;
    double radius = 0, centre[3];
    for (int k = 0; k < 3; k++) {
        centre[k] = 0.5 * ((double)box.min[k] + box.max[k]);
        radius += 0.25 * ((double)box.max[k] - box.min[k]) * ((double)box.max[k] - box.min[k]);
    }
    radius = sqrt(radius);
    double distance = (radius > 0 ? radius : 1) / sin(0.5 * DEFAULT_FOV_DEGREES * M_PI / 180.0);
    for (int k = 0; k < 3; k++) {
        s->camera.look_at[k] = (float)centre[k];
        s->camera.look_from[k] = (float)(centre[k] + (k == 2 ? distance : 0));
    }
    s->camera.vertical_fov_degrees = (float)DEFAULT_FOV_DEGREES;
}

/* Adds the model's KHR_lights_punctual lights as the scene's lights (scene_gltf.h). */
static rt_status add_lights(scene *s, const gltf_model *model, const char *path, rt_error *error)
{
    static const scene_light_type types[] = {SCENE_LIGHT_POINT, SCENE_LIGHT_SPOT, SCENE_LIGHT_SUN};
    for (int i = 0; i < model->light_count; i++) {
        const gltf_light *g = &model->lights[i];
        scene_light light = scene_light_defaults(types[g->type]);
        double position[3], direction[3];
        column(g->light_to_world, 3, 1, position);
        column(g->light_to_world, 2, -1, direction);
        for (int k = 0; k < 3; k++) {
            light.position[k] = (float)position[k];
            light.color[k] = g->color[k] * g->intensity;
        }
        if (g->type != GLTF_LIGHT_POINT && !unit(direction, light.direction))
            return rt_error_set(error, RT_ERROR_INPUT, "%s: the light '%s': its node's transform squashes it flat (a "
                                "zero scale), so it has no direction", path, g->name);
        light.spot_inner_degrees = (float)(g->inner_cone * 180.0 / M_PI);
        light.spot_outer_degrees = (float)(g->outer_cone * 180.0 / M_PI);
        light.sun_angle_degrees = 0;
        if (scene_add_light(s, &light) < 0)
            return rt_error_set(error, RT_ERROR_RUNTIME, "%s: out of memory for its lights", path);
    }
    return RT_OK;
}

/* Fills *out (already scene_defaults()) with the model (see scene_gltf.h). */
static rt_status build_file_scene(scene *out, gltf_model *model, const char *path, const char *camera_name,
                                  rt_error *error)
{
    out->sky.type = SKY_CONSTANT;
    for (int k = 0; k < 3; k++)
        out->sky.bottom[k] = out->sky.top[k] = NEUTRAL_SKY;
    scene_gltf_contents contents;
    rt_status status = scene_gltf_add(out, model, path, NULL, &contents, error);
    for (int p = 0; status == RT_OK && p < contents.placement_count; p++) {
        scene_instance instance = {.object = contents.placements[p].object, .material = -1};
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 4; k++)
                instance.object_to_world[r][k] = (float)contents.placements[p].object_to_world[r][k];
        if (scene_add_instance(out, &instance) < 0)
            status = rt_error_set(error, RT_ERROR_RUNTIME, "%s: out of memory for its placements", path);
    }
    scene_gltf_contents_free(&contents);
    if (status != RT_OK)
        return status;
    if (model->camera_count > 0 || (camera_name != NULL && camera_name[0] != '\0'))
        status = use_camera(out, model, path, camera_name, error);
    else
        frame_placements(out);
    return status == RT_OK ? add_lights(out, model, path, error) : status;
}

rt_status scene_gltf_load_file(const char *path, const char *camera_name, scene *out, rt_error *error)
{
    scene_defaults(out);
    if (path == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "GLTF: no glTF file given");
    gltf_model model;
    rt_status status = gltf_load(path, &model, error);
    if (status != RT_OK)
        return status;
    status = build_file_scene(out, &model, path, camera_name, error);
    gltf_model_free(&model);
    if (status != RT_OK)
        scene_free(out);
    return status;
}
