/* scene_assets.c: see scene_assets.h. */
#include "scene_assets.h"

#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "image_io.h"
#include "obj_load.h"
#include "ply_load.h"

/* The largest Kd component of a material that counts as dark, and the smallest largest-Ks
 * component that counts as bright, for the metal rule. */
#define DARK_DIFFUSE 0.1f
#define BRIGHT_SPECULAR 0.5f
#define DEFAULT_INDEX_OF_REFRACTION 1.5f

/* Returns the reason in a message "TAG: cannot read 'PATH': REASON" of obj_load() or
 * image_io, or the whole message when it has another form. */
static const char *reason_of(const char *message, const char *tag, const char *path)
{
    size_t tag_length = strlen(tag), path_length = strlen(path);
    const char *p = message;
    if (strncmp(p, tag, tag_length) != 0)
        return message;
    p += tag_length;
    if (strncmp(p, ": cannot read '", 15) != 0)
        return message;
    p += 15;
    if (strncmp(p, path, path_length) != 0 || strncmp(p + path_length, "': ", 3) != 0)
        return message;
    return p + path_length + 3;
}

/* Returns the last component of path. */
static const char *file_name_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash != NULL ? slash + 1 : path;
}

static float clamp01(float x)
{
    return x > 1.0f ? 1.0f : x > 0.0f ? x : 0.0f;
}

/* Returns the scene material an MTL material becomes (see scene_assets.h), named name. */
static scene_material material_from_mtl(const obj_material *m, const char *name)
{
    scene_material out = scene_material_defaults();
    snprintf(out.name, sizeof out.name, "%.*s", SCENE_NAME_MAX - 1, name);
    if (glm_vec3_max((float *)m->emission) > 0.0f) {
        out.type = MATERIAL_EMISSIVE;
        for (int c = 0; c < 3; c++)
            out.emission[c] = m->emission[c] > 0.0f ? m->emission[c] : 0.0f;
    } else if (m->dissolve < 1.0f) {
        out.type = MATERIAL_DIELECTRIC;
        float ior = m->index_of_refraction;
        out.index_of_refraction = ior > 0.0f && ior != 1.0f ? ior : DEFAULT_INDEX_OF_REFRACTION;
    } else if (glm_vec3_max((float *)m->specular) > BRIGHT_SPECULAR && glm_vec3_max((float *)m->diffuse) <= DARK_DIFFUSE) {
        out.type = MATERIAL_METAL;
        for (int c = 0; c < 3; c++)
            out.albedo[c] = clamp01(m->specular[c]);
        float shininess = m->shininess > 0.0f ? m->shininess : 0.0f;
        out.fuzz = clamp01(sqrtf(2.0f / (shininess + 2.0f)));
    } else {
        out.type = MATERIAL_LAMBERTIAN;
        for (int c = 0; c < 3; c++)
            out.albedo[c] = clamp01(m->diffuse[c]);
    }
    return out;
}

/* Returns the index of the material called name among the first count, or -1. */
static int find_material_among(const scene *s, int count, const char *name)
{
    for (int i = 0; i < count; i++)
        if (strncmp(s->materials[i].name, name, SCENE_NAME_MAX) == 0)
            return i;
    return -1;
}

/* Whether path's last component ends in extension (".ply"; any case). */
static bool has_extension(const char *path, const char *extension)
{
    size_t length = strlen(path), wanted = strlen(extension);
    return length > wanted && strcasecmp(path + length - wanted, extension) == 0 &&
           strchr(path + length - wanted, '/') == NULL;
}

/* Loads the PLY mesh index into the scene (see scene_assets.h): its vertex colours are
 * decoded from sRGB, every triangle gets the mesh's default material. */
static rt_status load_ply_mesh(scene *s, int index, rt_error *error)
{
    scene_mesh *mesh = &s->meshes[index];
    ply_mesh ply;
    rt_error inner;
    rt_status status = ply_load(mesh->path, &ply, &inner);
    if (status != RT_OK)
        return rt_error_set(error, status, "%s: cannot read mesh '%s': %s", mesh->position, mesh->path,
                            reason_of(inner.message, "PLY", mesh->path));
    int *triangle_materials = malloc((size_t)ply.triangle_count * sizeof *triangle_materials);
    if (triangle_materials == NULL) {
        ply_mesh_free(&ply);
        return rt_error_set(error, RT_ERROR_RUNTIME, "%s: out of memory loading mesh '%s'", mesh->position,
                            mesh->path);
    }
    for (int t = 0; t < ply.triangle_count; t++)
        triangle_materials[t] = mesh->default_material;
    for (int i = 0; ply.colors != NULL && i < 3 * ply.vertex_count; i++)
        ply.colors[i] = image_srgb_decode(ply.colors[i]);
    /* The scene takes the arrays over. */
    mesh->positions = ply.positions;
    mesh->normals = ply.normals;
    mesh->uvs = ply.uvs;
    mesh->colors = ply.colors;
    mesh->indices = ply.indices;
    mesh->triangle_materials = triangle_materials;
    mesh->vertex_count = ply.vertex_count;
    mesh->triangle_count = ply.triangle_count;
    return RT_OK;
}

/* Loads mesh index into the scene, by its file's extension: .ply, else OBJ;
 * scene_materials is the count of the scene's own materials (those usemtl names are
 * matched against). */
static rt_status load_mesh(scene *s, int index, int scene_materials, rt_error *error)
{
    scene_mesh *mesh = &s->meshes[index];
    if (mesh->default_material < -1 || mesh->default_material >= s->material_count)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "%s: mesh '%s' has default material %d, which is not a material "
                            "of the scene (%d)", mesh->position, mesh->path,
                            mesh->default_material, s->material_count);
    if (has_extension(mesh->path, ".ply"))
        return load_ply_mesh(s, index, error);
    obj_mesh obj;
    rt_error inner;
    rt_status status = obj_load(mesh->path, &obj, &inner);
    if (status != RT_OK)
        return rt_error_set(error, status, "%s: cannot read mesh '%s': %s", mesh->position,
                            mesh->path, reason_of(inner.message, "OBJ", mesh->path));

    /* scene_index[k]: the scene material of obj material k; -2 until it is needed. */
    int *scene_index = malloc((size_t)(obj.material_count > 0 ? obj.material_count : 1) * sizeof *scene_index);
    int *triangle_materials = malloc((size_t)obj.triangle_count * sizeof *triangle_materials);
    if (scene_index == NULL || triangle_materials == NULL) {
        status = rt_error_set(error, RT_ERROR_RUNTIME, "%s: out of memory loading mesh '%s'",
                              mesh->position, mesh->path);
        goto done;
    }
    for (int k = 0; k < obj.material_count; k++)
        scene_index[k] = -2;
    for (int t = 0; t < obj.triangle_count; t++) {
        int k = obj.triangle_materials[t];
        if (k < 0 || k >= obj.material_count) {
            triangle_materials[t] = mesh->default_material;
            continue;
        }
        if (scene_index[k] == -2) {
            const obj_material *m = &obj.materials[k];
            int found = find_material_among(s, scene_materials, m->name);
            if (found < 0 && m->defined) {
                char name[sizeof mesh->path + OBJ_NAME_MAX + 2];
                snprintf(name, sizeof name, "%.1023s:%.255s", file_name_of(mesh->path), m->name);
                scene_material derived = material_from_mtl(m, name);
                found = scene_add_material(s, &derived);
                mesh = &s->meshes[index];
                if (found < 0) {
                    status = rt_error_set(error, RT_ERROR_RUNTIME,
                                          "%s: out of memory loading mesh '%s'", mesh->position,
                                          mesh->path);
                    goto done;
                }
            }
            scene_index[k] = found;
        }
        triangle_materials[t] = scene_index[k] >= 0 ? scene_index[k] : mesh->default_material;
    }

    /* Warnings become the scene's, prefixed like errors; see scene_assets.h. */
    for (int w = 0; w < obj.warning_count && w < OBJ_MAX_WARNINGS; w++) {
        if (scene_add_warning(s, "%s: mesh '%s': %s", mesh->position, mesh->path, obj.warnings[w]) < 0) {
            status = rt_error_set(error, RT_ERROR_RUNTIME, "%s: out of memory loading mesh '%s'",
                                  mesh->position, mesh->path);
            goto done;
        }
    }
    if (obj.warning_count > OBJ_MAX_WARNINGS &&
        scene_add_warning(s, "%s: mesh '%s': %d more warnings left out", mesh->position, mesh->path,
                          obj.warning_count - OBJ_MAX_WARNINGS) < 0) {
        status = rt_error_set(error, RT_ERROR_RUNTIME, "%s: out of memory loading mesh '%s'", mesh->position,
                              mesh->path);
        goto done;
    }

    /* The scene takes the arrays over. */
    mesh->positions = obj.positions;
    mesh->normals = obj.normals;
    mesh->uvs = obj.uvs;
    mesh->indices = obj.indices;
    mesh->triangle_materials = triangle_materials;
    mesh->vertex_count = obj.vertex_count;
    mesh->triangle_count = obj.triangle_count;
    obj.positions = NULL;
    obj.normals = NULL;
    obj.uvs = NULL;
    obj.indices = NULL;
    triangle_materials = NULL;
    status = RT_OK;
done:
    free(scene_index);
    free(triangle_materials);
    obj_mesh_free(&obj);
    return status;
}

static const char *const face_names[SKY_FACE_COUNT] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};

/* A volume's boundary must be closed, and no closed surface has fewer than 4 triangles: a
 * mesh of 1 to 3 placed as (part of) a volume's boundary is an open surface for certain.
 * (Whether a larger mesh is closed is not checked; see docs/scene-format.md.) */
static rt_status check_volume_mesh(const scene *s, int index, rt_error *error)
{
    const scene_mesh *mesh = &s->meshes[index];
    if (mesh->positions == NULL || mesh->triangle_count >= 4)
        return RT_OK;
    for (int i = 0; i < s->instance_count; i++) {
        const scene_instance *instance = &s->instances[i];
        if (!instance->volume || instance->object < 0 || instance->object >= s->object_count ||
            s->objects[instance->object].mesh != index)
            continue;
        return rt_error_set(error, RT_ERROR_INPUT,
                            "%s: mesh '%s' is (part of) a volume's boundary, which must be closed, but it "
                            "has only %d triangle%s: fewer than 4 enclose nothing", mesh->position,
                            mesh->path, mesh->triangle_count, mesh->triangle_count == 1 ? "" : "s");
    }
    return RT_OK;
}

/* Returns the index of the channel of image called name (case-insensitive), or -1. */
static int channel_named(const rt_image *image, const char *name)
{
    for (int c = 0; c < image->channels; c++)
        if (strcasecmp(image->channel_names[c], name) == 0)
            return c;
    return -1;
}

/* Loads image index into the scene as linear RGBA. role says what the image is in messages:
 * prefix ("" or "sky box: ") goes after the position, noun ("image" or "the +X face
 * image") names it. */
static rt_status load_image(scene *s, int index, const char *prefix, const char *noun, rt_error *error)
{
    scene_image *target = &s->images[index];
    rt_image image;
    rt_error inner;
    /* A normal map stores vectors, not colours: its values are used as they are. An image
     * of a glTF model is decoded from its bytes. */
    rt_status status = target->encoded != NULL
                           ? image_read_memory(target->encoded, target->encoded_size, target->path,
                                               SCENE_IMAGE_MAX_SIDE, !target->data, &image, &inner)
                       : target->data ? image_read(target->path, &image, &inner)
                                      : image_read_linear(target->path, SCENE_IMAGE_MAX_SIDE, &image, &inner);
    if (status == RT_OK && target->data && (image.width > SCENE_IMAGE_MAX_SIDE || image.height > SCENE_IMAGE_MAX_SIDE)) {
        image_free(&image);
        return rt_error_set(error, RT_ERROR_INPUT, "%s: %s%s '%s' is larger than %d pixels on a side",
                            target->position, prefix, noun, target->path, SCENE_IMAGE_MAX_SIDE);
    }
    if (status != RT_OK)
        return rt_error_set(error, status, "%s: %scannot read %s '%s': %s", target->position, prefix, noun,
                            target->path, reason_of(inner.message, "IMAGE", target->path));

    /* Where R, G, B and A come from (-1 for A: 1). */
    int source[4] = {-1, -1, -1, -1};
    int red = channel_named(&image, "R"), green = channel_named(&image, "G"),
        blue = channel_named(&image, "B");
    if (red >= 0 && green >= 0 && blue >= 0) {
        source[0] = red;
        source[1] = green;
        source[2] = blue;
        source[3] = channel_named(&image, "A");
    } else if (image.channels <= 2) {
        source[0] = source[1] = source[2] = 0;
        source[3] = image.channels == 2 ? 1 : -1;
    } else {
        for (int c = 0; c < 4; c++)
            source[c] = c < image.channels ? c : -1;
    }

    size_t count = (size_t)image.width * (size_t)image.height;
    float *pixels = malloc(count * 4 * sizeof *pixels);
    if (pixels == NULL) {
        image_free(&image);
        return rt_error_set(error, RT_ERROR_RUNTIME, "%s: %sout of memory for %s '%s' (%dx%d)",
                            target->position, prefix, noun, target->path, image.width, image.height);
    }
    for (size_t i = 0; i < count; i++) {
        const float *in = &image.pixels[i * (size_t)image.channels];
        for (int c = 0; c < 4; c++) {
            float value = source[c] >= 0 ? in[source[c]] : 1.0f;
            if (!isfinite(value)) {
                int x = (int)(i % (size_t)image.width), y = (int)(i / (size_t)image.width);
                free(pixels);
                image_free(&image);
                return rt_error_set(error, RT_ERROR_INPUT,
                                    "%s: %s%s '%s' has a pixel that is not a finite number "
                                    "(NaN or infinite) at x %d, y %d", target->position, prefix,
                                    noun, target->path, x, y);
            }
            pixels[i * 4 + (size_t)c] = value;
        }
    }
    target->width = image.width;
    target->height = image.height;
    target->pixels = pixels;
    free(target->encoded);
    target->encoded = NULL;
    target->encoded_size = 0;
    image_free(&image);
    return RT_OK;
}


/* Checks that the six faces of a sky box are loaded, square and of one size. */
static rt_status check_sky_box(const scene *s, rt_error *error)
{
    const scene_image *first = NULL;
    for (int f = 0; f < SKY_FACE_COUNT; f++) {
        int index = s->sky.faces[f];
        if (index < 0 || index >= s->image_count || s->images[index].pixels == NULL)
            return rt_error_set(error, RT_ERROR_INPUT, "sky box: the %s face has no image",
                                face_names[f]);
        const scene_image *face = &s->images[index];
        if (face->width != face->height)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "%s: sky box: the %s face '%s' is %dx%d; the faces must be square",
                                face->position, face_names[f], face->path, face->width,
                                face->height);
        if (first == NULL)
            first = face;
        else if (face->width != first->width)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "%s: sky box: the %s face '%s' is %dx%d, the %s face is %dx%d",
                                face->position, face_names[f], face->path, face->width,
                                face->height, face_names[0], first->width, first->height);
    }
    return RT_OK;
}

rt_status scene_load_assets(scene *s, rt_error *error)
{
    const int scene_materials = s->material_count;
    for (int i = 0; i < s->mesh_count; i++) {
        if (s->meshes[i].positions != NULL)
            continue;
        rt_status status = load_mesh(s, i, scene_materials, error);
        if (status != RT_OK)
            return status;
    }
    for (int i = 0; i < s->mesh_count; i++) {
        rt_status status = check_volume_mesh(s, i, error);
        if (status != RT_OK)
            return status;
    }
    for (int i = 0; i < s->image_count; i++) {
        if (s->images[i].pixels != NULL)
            continue;
        /* A sky box face is named as one, like the size checks name it: "the -Y face image"
         * (faces sharing one file: "the +X/-X face image"). */
        char faces[64] = "", noun[96] = "image";
        for (int f = 0; s->sky.type == SKY_BOX && f < SKY_FACE_COUNT; f++) {
            if (s->sky.faces[f] != i)
                continue;
            size_t used = strlen(faces);
            snprintf(faces + used, sizeof faces - used, "%s%s", used > 0 ? "/" : "", face_names[f]);
        }
        if (faces[0] != '\0')
            snprintf(noun, sizeof noun, "the %s face image", faces);
        rt_status status = load_image(s, i, faces[0] != '\0' ? "sky box: " : "", noun, error);
        if (status != RT_OK)
            return status;
    }
    if (s->sky.type == SKY_BOX)
        return check_sky_box(s, error);
    return RT_OK;
}
