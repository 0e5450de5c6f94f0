/* fuzz_support.h: what the loading harnesses share (fuzz_obj_load.c, fuzz_gltf_load.c,
 * fuzz_ply_load.c; header only, static inline, as the harnesses compile chosen sources):
 *
 *   fuzz_make_directory(prefix, out, size)   a private temporary directory ($TMPDIR or
 *                                            /tmp) named PREFIX.XXXXXX, or abort
 *   fuzz_write_file(path, data, size)        writes the bytes, or aborts (the harness
 *                                            would be useless)
 *   fuzz_pack_and_trace(s)                   packs a loaded scene and traces four camera
 *                                            rays through the packed BVH on the CPU; aborts
 *                                            when a failure has no message or a ray hits a
 *                                            primitive slot that does not exist
 */
#ifndef RT_FUZZ_SUPPORT_H
#define RT_FUZZ_SUPPORT_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "pack.h"
#include "packed_traverse.h"
#include "scene.h"

static inline void fuzz_make_directory(const char *prefix, char *out, size_t size)
{
    const char *temporary = getenv("TMPDIR");
    snprintf(out, size, "%s/%s.XXXXXX", temporary != NULL && temporary[0] != '\0' ? temporary : "/tmp", prefix);
    if (mkdtemp(out) == NULL) {
        perror("fuzz: mkdtemp");
        abort();
    }
}

static inline void fuzz_write_file(const char *path, const void *data, size_t size)
{
    FILE *file = fopen(path, "wb");
    if (file == NULL || (size > 0 && fwrite(data, 1, size, file) != size) || fclose(file) != 0) {
        fprintf(stderr, "fuzz: cannot write %s\n", path);
        abort();
    }
}

static inline void fuzz_pack_and_trace(const scene *s)
{
    packed_scene packed;
    rt_error error = {{0}};
    if (pack_scene(s, NULL, &packed, &error) != RT_OK) {
        if (error.message[0] == '\0')
            abort();
        return;
    }
    camera_frame frame;
    if (camera_frame_compute(&s->camera, s->render.width, s->render.height, &frame, &error) == RT_OK) {
        static const float film[][2] = {{0.5f, 0.5f}, {0.3f, 0.6f}, {0.7f, 0.4f}, {0.5f, 0.2f}};
        for (size_t i = 0; i < sizeof film / sizeof film[0]; i++) {
            float origin[3], direction[3];
            camera_frame_ray(&frame, film[i][0], film[i][1], 0.0f, 0.0f, origin, direction);
            packed_hit hit;
            if (packed_intersect_nearest(&packed, origin, direction, 1e-4f, 1e30f, &hit) &&
                hit.primitive >= packed.primitive_count)
                abort();
        }
    }
    packed_scene_free(&packed);
}

#endif
