/* fuzz_gltf_load.c: libFuzzer harness for the glTF loading paths a render runs: glTF
 * bytes (JSON or GLB) -> gltf_load() through tinygltf -> the file as a scene by itself
 * (scene_gltf_load_file) and named by a scene file's gltf statement, placed twice through
 * groups -> scene_load_assets() (embedded images decoded) -> pack_scene() -> a few CPU
 * rays through the packed BVH.
 *
 * Input: a glTF file as it is (written to model.glb when it starts with "glTF", else to
 * model.gltf, in a private temporary directory), so every .gltf and .glb is a good seed.
 * An external buffer or image it names is looked up beside it, where there is none.
 *
 * Besides crashes and sanitizer reports, the harness aborts when gltf_load.h's contract
 * breaks: a failure must leave the model zeroed with a message starting with the path; a
 * success must give meshes whose indices are below their vertex counts, finite positions,
 * unit or zero normals, triangle materials in range, placements of meshes with triangles
 * and finite matrices, images with bytes; a packed ray must never hit a primitive slot
 * that does not exist.
 *
 * Built by `make fuzz` (see the Makefile); run by tests/fuzz/run.sh. */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fuzz_support.h"
#include "gltf_load.h"
#include "scene_assets.h"
#include "scene_gltf.h"
#include "scene_parse.h"

/* OpenImageIO 2.4's PNG reader leaks its error message (a std::string it builds before
 * libpng longjmps past it) for a PNG that ends early when it reads through an IOProxy, as
 * embedded images are read (image_read_memory). That leak is OpenImageIO's to fix; it is
 * the one leak this harness lets pass
 * (tests/fuzz/regressions/fuzz_gltf_load/png-cut-short-in-a-data-uri.gltf). */
const char *__asan_default_options(void);
const char *__lsan_default_suppressions(void);

/* OpenImageIO has no frame pointers: the fast unwinder would stop in libstdc++ before the
 * function the suppression names (the unit tests use the slow one for OpenImageIO too). */
const char *__asan_default_options(void)
{
    return "fast_unwind_on_malloc=0";
}

const char *__lsan_default_suppressions(void)
{
    return "leak:OpenImageIO_v2_4::PNGInput::PngReadCallback\n";
}

static char directory[256];
static char gltf_path[300], glb_path[300];
static char scene_gltf_path[300], scene_glb_path[300];

static const char scene_format[] =
    "camera from 0 0.5 4 at 0 0 0 up 0 1 0 fov 40\n"
    "render size 16 16 spp 1\n"
    "gltf \"%s\"\n"
    "group {\n"
    "    translate 1 0 0\n"
    "    rotate 0 1 0 30\n"
    "    gltf \"%s\"\n"
    "}\n";

static void remove_fixtures(void)
{
    unlink(gltf_path);
    unlink(glb_path);
    unlink(scene_gltf_path);
    unlink(scene_glb_path);
    rmdir(directory);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_make_directory("rtspheres-fuzz-gltf", directory, sizeof directory);
    snprintf(gltf_path, sizeof gltf_path, "%s/model.gltf", directory);
    snprintf(glb_path, sizeof glb_path, "%s/model.glb", directory);
    snprintf(scene_gltf_path, sizeof scene_gltf_path, "%s/gltf.txt", directory);
    snprintf(scene_glb_path, sizeof scene_glb_path, "%s/glb.txt", directory);
    atexit(remove_fixtures);
    char text[1024];
    int n = snprintf(text, sizeof text, scene_format, "model.gltf", "model.gltf");
    fuzz_write_file(scene_gltf_path, text, (size_t)n);
    n = snprintf(text, sizeof text, scene_format, "model.glb", "model.glb");
    fuzz_write_file(scene_glb_path, text, (size_t)n);
    return 0;
}

/* Checks gltf_load.h's contract on one result. */
static void check_model(rt_status status, const gltf_model *m, const rt_error *error, const char *path)
{
    if (status != RT_OK) {
        static const gltf_model zero;
        if (status != RT_ERROR_INPUT && status != RT_ERROR_RUNTIME)
            abort();
        if (strncmp(error->message, path, strlen(path)) != 0 || memchr(error->message, '\0', sizeof error->message) == NULL)
            abort();
        if (memcmp(m, &zero, sizeof zero) != 0)
            abort();
        return;
    }
    for (int i = 0; i < m->mesh_count; i++) {
        const gltf_mesh *mesh = &m->meshes[i];
        for (size_t k = 0; k < 3 * (size_t)mesh->triangle_count; k++)
            if (mesh->indices[k] >= (uint32_t)mesh->vertex_count)
                abort();
        for (int t = 0; t < mesh->triangle_count; t++)
            if (mesh->triangle_materials[t] < -1 || mesh->triangle_materials[t] >= m->material_count)
                abort();
        for (size_t k = 0; k < 3 * (size_t)mesh->vertex_count; k++)
            if (!isfinite(mesh->positions[k]))
                abort();
        for (int v = 0; mesh->normals != NULL && v < mesh->vertex_count; v++) {
            const float *n = mesh->normals + 3 * v;
            float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (!(length == 0.0f || fabsf(length - 1.0f) < 1e-3f))
                abort();
        }
    }
    for (int p = 0; p < m->placement_count; p++) {
        const gltf_placement *placement = &m->placements[p];
        if (placement->mesh < 0 || placement->mesh >= m->mesh_count || m->meshes[placement->mesh].triangle_count < 1)
            abort();
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 4; k++)
                if (!isfinite(placement->object_to_world[r][k]))
                    abort();
    }
    for (int i = 0; i < m->image_count; i++)
        if (m->images[i].bytes == NULL || m->images[i].size == 0)
            abort();
}

/* Loads the file as a scene by itself and through the scene file, packs and traces each. */
static void load_pack_and_trace(const char *path, const char *scene_path)
{
    scene s;
    rt_error error = {{0}};
    if (scene_gltf_load_file(path, NULL, &s, &error) == RT_OK) {
        if (scene_load_assets(&s, &error) == RT_OK)
            fuzz_pack_and_trace(&s);
        else if (error.message[0] == '\0')
            abort();
        scene_free(&s);
    } else if (error.message[0] == '\0') {
        abort();
    }
    /* gltf_load accepted the file, but placed through the groups a transform may still
     * leave the float range: a refusal with a message is allowed. */
    if (scene_load_file(scene_path, NULL, &s, &error) != RT_OK) {
        if (error.message[0] == '\0')
            abort();
        return;
    }
    if (scene_load_assets(&s, &error) == RT_OK)
        fuzz_pack_and_trace(&s);
    else if (error.message[0] == '\0')
        abort();
    scene_free(&s);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bool binary = size >= 4 && memcmp(data, "glTF", 4) == 0;
    const char *path = binary ? glb_path : gltf_path;
    fuzz_write_file(path, data, size);
    gltf_model model;
    rt_error error = {{0}};
    rt_status status = gltf_load(path, &model, &error);
    check_model(status, &model, &error, path);
    gltf_model_free(&model);
    if (status == RT_OK)
        load_pack_and_trace(path, binary ? scene_glb_path : scene_gltf_path);
    unlink(path);
    return 0;
}
