/* fuzz_obj_load.c: libFuzzer harness for the OBJ loading path a render runs: OBJ (and
 * MTL) text -> obj_load() through tinyobjloader -> scene_load_assets() (usemtl names to
 * scene materials, MTL-derived materials) -> pack_scene() (the mesh's BVH, the top-level
 * BVH, packing) -> a few CPU rays through the packed BVH.
 *
 * Input format (so that plain OBJ files are good seeds as they are):
 *   - The input up to a line "#mtl" is the OBJ text, written to mesh.obj in a private
 *     temporary directory. What follows that line is written to m.mtl beside it; without
 *     the line there is no m.mtl, so a `mtllib m.mtl` is a missing MTL file.
 *
 * The scene that places the mesh is fixed: two materials (one called "red", which a
 * `usemtl red` picks over any MTL definition), the mesh placed twice (once as is, once
 * through a scaled and rotated group) and a camera looking at the origin.
 *
 * Besides crashes and sanitizer reports, the harness aborts when obj_load()'s documented
 * contract breaks: a failure must leave the mesh zeroed with an "OBJ: " message; a success
 * must give at least one vertex and triangle, indices below the vertex count, material
 * indices in [-1, material_count), finite positions, unit or zero normals; a packed ray
 * must never hit a primitive slot that does not exist.
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
#include "obj_load.h"
#include "scene_assets.h"
#include "scene_parse.h"

static char directory[256];
static char obj_path[300];
static char mtl_path[300];
static char scene_path[300];

static const char scene_text[] =
    "material red lambertian 0.8 0.1 0.1\n"
    "material grey metal 0.7 0.7 0.7 fuzz 0.2\n"
    "camera from 0 0.5 4 at 0 0 0 up 0 1 0 fov 40\n"
    "render size 16 16 spp 1\n"
    "mesh \"mesh.obj\" grey\n"
    "group {\n"
    "    translate 1 0 0\n"
    "    rotate 0 1 0 30\n"
    "    scale 0.5\n"
    "    mesh \"mesh.obj\"\n"
    "}\n";

/* Removes the fixtures at exit, so repeated runs do not litter the temporary directory. */
static void remove_fixtures(void)
{
    unlink(obj_path);
    unlink(mtl_path);
    unlink(scene_path);
    rmdir(directory);
}

/* libFuzzer calls this once before the first input: makes the directory and scene file. */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_make_directory("rtspheres-fuzz-obj", directory, sizeof directory);
    snprintf(obj_path, sizeof obj_path, "%s/mesh.obj", directory);
    snprintf(mtl_path, sizeof mtl_path, "%s/m.mtl", directory);
    snprintf(scene_path, sizeof scene_path, "%s/scene.txt", directory);
    atexit(remove_fixtures);
    fuzz_write_file(scene_path, scene_text, sizeof scene_text - 1);
    return 0;
}

/* Checks obj_load()'s contract on one result. */
static void check_mesh(rt_status status, const obj_mesh *mesh, const rt_error *error)
{
    if (status != RT_OK) {
        static const obj_mesh zero;
        if (status != RT_ERROR_INPUT && status != RT_ERROR_RUNTIME)
            abort();
        if (strncmp(error->message, "OBJ: ", 5) != 0 || memchr(error->message, '\0', sizeof error->message) == NULL)
            abort();
        if (memcmp(mesh, &zero, sizeof zero) != 0)
            abort();
        return;
    }
    if (mesh->vertex_count < 1 || mesh->triangle_count < 1 || mesh->positions == NULL || mesh->indices == NULL)
        abort();
    for (int i = 0; i < 3 * mesh->triangle_count; i++)
        if (mesh->indices[i] >= (uint32_t)mesh->vertex_count)
            abort();
    for (int t = 0; t < mesh->triangle_count; t++)
        if (mesh->triangle_materials[t] < -1 || mesh->triangle_materials[t] >= mesh->material_count)
            abort();
    for (int i = 0; i < 3 * mesh->vertex_count; i++)
        if (!isfinite(mesh->positions[i]))
            abort();
    if (mesh->normals != NULL)
        for (int v = 0; v < mesh->vertex_count; v++) {
            const float *n = mesh->normals + 3 * v;
            float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (!(length == 0.0f || fabsf(length - 1.0f) < 1e-3f))
                abort();
        }
}

/* Loads the fixed scene around the mesh, packs it and traces a few rays. */
static void load_pack_and_trace(void)
{
    scene_parse_options options = scene_parse_options_defaults();
    scene s;
    rt_error error = {{0}};
    if (scene_load_file(scene_path, &options, &s, &error) != RT_OK)
        abort(); /* the scene text is fixed and valid */
    if (scene_load_assets(&s, &error) != RT_OK) {
        if (error.message[0] == '\0')
            abort();
        scene_free(&s);
        return;
    }
    fuzz_pack_and_trace(&s);
    scene_free(&s);
}

/* Finds the "#mtl" separator line; returns its offset or size when there is none. */
static size_t find_separator(const uint8_t *data, size_t size, size_t *after)
{
    static const char line[] = "#mtl\n";
    size_t length = sizeof line - 1;
    for (size_t i = 0; i + length <= size; i++)
        if ((i == 0 || data[i - 1] == '\n') && memcmp(data + i, line, length) == 0) {
            *after = i + length;
            return i;
        }
    *after = size;
    return size;
}

/* libFuzzer's entry point: one OBJ (and maybe MTL) file, loaded alone and in a scene. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t after;
    size_t obj_size = find_separator(data, size, &after);
    fuzz_write_file(obj_path, data, obj_size);
    if (after < size || obj_size < size)
        fuzz_write_file(mtl_path, data + after, size - after);
    else
        unlink(mtl_path);

    obj_mesh mesh;
    rt_error error = {{0}};
    rt_status status = obj_load(obj_path, &mesh, &error);
    check_mesh(status, &mesh, &error);
    obj_mesh_free(&mesh);
    if (status == RT_OK)
        load_pack_and_trace();
    return 0;
}
