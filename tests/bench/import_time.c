/* import_time.c: times what the importers' performance target counts (issue 14: a
 * 1M-triangle glTF or PLY loads and packs in under 3 s, at most 100 packed bytes per
 * triangle): reading the scene (a glTF file by itself, or a scene file whose meshes are
 * read by the asset loader), its assets, and packing it, each on the one clock
 * (core/clock.h). No GPU. A tool of `make bench` (tests/bench/run.sh), linked with
 * build/librtspheres.a.
 *
 *   usage: import_time SCENE
 * prints one line:
 *   import: SCENE: load S s, pack S s, together S s (CPU S s); T triangles, B bytes (P per
 *   triangle)
 * (the CPU seconds of the process: on a busy machine less moved by other work than the
 * wall seconds; the loader and the packer use one thread) and exits 1 (with the message) when the scene cannot be loaded or packed. */
#include <stdio.h>
#include <time.h>

#include "clock.h"
#include "pack.h"
#include "scene_assets.h"
#include "scene_gltf.h"
#include "scene_parse.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: import_time SCENE\n");
        return 2;
    }
    const char *path = argv[1];
    scene s;
    rt_error error = {{0}};
    double start = clock_seconds();
    clock_t cpu_start = clock();
    rt_status status = scene_gltf_is_model_path(path) ? scene_gltf_load_file(path, NULL, &s, &error)
                                                       : scene_load_file(path, NULL, &s, &error);
    if (status == RT_OK && (status = scene_load_assets(&s, &error)) != RT_OK)
        scene_free(&s);
    if (status != RT_OK) {
        fprintf(stderr, "import_time: %s\n", error.message);
        return 1;
    }
    double loaded = clock_seconds();
    packed_scene packed;
    status = pack_scene(&s, NULL, &packed, &error);
    double done = clock_seconds();
    double cpu = (double)(clock() - cpu_start) / CLOCKS_PER_SEC;
    if (status != RT_OK) {
        fprintf(stderr, "import_time: %s\n", error.message);
        scene_free(&s);
        return 1;
    }
    double bytes = 16.0 * packed.texel_count;
    printf("import: %s: load %.3f s, pack %.3f s, together %.3f s (CPU %.3f s); %u triangles, %.0f bytes (%.1f per "
           "triangle)\n", path, loaded - start, done - loaded, done - start, cpu, packed.triangle_count, bytes,
           packed.triangle_count > 0 ? bytes / packed.triangle_count : 0.0);
    packed_scene_free(&packed);
    scene_free(&s);
    return 0;
}
