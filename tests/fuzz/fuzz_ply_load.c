/* fuzz_ply_load.c: libFuzzer harness for the PLY loading path a render runs: PLY bytes ->
 * ply_load_memory() -> (written to mesh.ply) scene_load_assets() (colours decoded, the
 * mesh's material) -> pack_scene() (the mesh's BVH, placed twice) -> a few CPU rays
 * through the packed BVH.
 *
 * Input: a PLY file as it is (so every PLY file is a good seed).
 *
 * Besides crashes and sanitizer reports, the harness aborts when ply_load.h's contract
 * breaks: a failure must leave the mesh zeroed with a "PLY: cannot read '" message; a
 * success must give at least one vertex and triangle, indices below the vertex count,
 * finite positions, unit or zero normals, colours in [0, 1]; and the file on disk must
 * load to the same mesh; a packed ray must never hit a primitive slot that does not
 * exist.
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
#include "ply_load.h"
#include "scene_assets.h"
#include "scene_parse.h"

static char directory[256];
static char ply_path[300];
static char scene_path[300];

static const char scene_text[] =
    "material grey metal 0.7 0.7 0.7 fuzz 0.2\n"
    "camera from 0 0.5 4 at 0 0 0 up 0 1 0 fov 40\n"
    "render size 16 16 spp 1\n"
    "mesh \"mesh.ply\" grey\n"
    "group {\n"
    "    translate 1 0 0\n"
    "    rotate 0 1 0 30\n"
    "    mesh \"mesh.ply\" grey\n"
    "}\n";

/* Removes the fixtures at exit. */
static void remove_fixtures(void)
{
    unlink(ply_path);
    unlink(scene_path);
    rmdir(directory);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_make_directory("rtspheres-fuzz-ply", directory, sizeof directory);
    snprintf(ply_path, sizeof ply_path, "%s/mesh.ply", directory);
    snprintf(scene_path, sizeof scene_path, "%s/scene.txt", directory);
    atexit(remove_fixtures);
    fuzz_write_file(scene_path, scene_text, sizeof scene_text - 1);
    return 0;
}

/* Checks ply_load.h's contract on one result. */
static void check_mesh(rt_status status, const ply_mesh *mesh, const rt_error *error)
{
    if (status != RT_OK) {
        static const ply_mesh zero;
        if (status != RT_ERROR_INPUT && status != RT_ERROR_RUNTIME)
            abort();
        if (strncmp(error->message, "PLY: cannot read '", 18) != 0 || memchr(error->message, '\0', sizeof error->message) == NULL)
            abort();
        if (memcmp(mesh, &zero, sizeof zero) != 0)
            abort();
        return;
    }
    if (mesh->vertex_count < 1 || mesh->triangle_count < 1 || mesh->positions == NULL || mesh->indices == NULL)
        abort();
    for (size_t i = 0; i < 3 * (size_t)mesh->triangle_count; i++)
        if (mesh->indices[i] >= (uint32_t)mesh->vertex_count)
            abort();
    for (size_t i = 0; i < 3 * (size_t)mesh->vertex_count; i++) {
        if (!isfinite(mesh->positions[i]))
            abort();
        if (mesh->colors != NULL && !(mesh->colors[i] >= 0.0f && mesh->colors[i] <= 1.0f))
            abort();
    }
    for (int v = 0; mesh->normals != NULL && v < mesh->vertex_count; v++) {
        const float *n = mesh->normals + 3 * v;
        float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(length == 0.0f || fabsf(length - 1.0f) < 1e-3f))
            abort();
    }
}

/* Loads the fixed scene around the mesh, packs it and traces a few rays. */
static void load_pack_and_trace(void)
{
    scene s;
    rt_error error = {{0}};
    if (scene_load_file(scene_path, NULL, &s, &error) != RT_OK)
        abort(); /* the scene text is fixed and valid */
    if (scene_load_assets(&s, &error) != RT_OK)
        abort(); /* ply_load_memory accepted these very bytes */
    fuzz_pack_and_trace(&s);
    scene_free(&s);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ply_mesh mesh;
    rt_error error = {{0}};
    rt_status status = ply_load_memory(data, size, "mesh.ply", &mesh, &error);
    check_mesh(status, &mesh, &error);
    if (status == RT_OK) {
        /* The file on disk reads the same. */
        fuzz_write_file(ply_path, data, size);
        ply_mesh again;
        if (ply_load(ply_path, &again, &error) != RT_OK || again.vertex_count != mesh.vertex_count ||
            again.triangle_count != mesh.triangle_count ||
            memcmp(again.indices, mesh.indices, 3 * (size_t)mesh.triangle_count * sizeof *mesh.indices) != 0)
            abort();
        ply_mesh_free(&again);
        load_pack_and_trace();
    }
    ply_mesh_free(&mesh);
    return 0;
}
