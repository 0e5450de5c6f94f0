/* gpu_internal.h: what core/gpu.c (the EGL context) and core/gpu_tracer.c (the tracer on
 * it) share; no other file includes it. */
#ifndef RT_GPU_INTERNAL_H
#define RT_GPU_INTERNAL_H

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include "gpu.h"

/* Tracer variants kept per context: a render uses one (and the AOV pass one more); an
 * animation or sweep keeps using the same few. */
#define GPU_PROGRAM_CACHE_SIZE 16

struct gpu_context {
    EGLDisplay display;
    EGLContext context;
    gpu_info info;
    gpu_options options;
    /* Kept between renders on this context (frames of an animation, a sweep): the
     * compiled tracer, and the last packed scene uploaded with its hash. */
    struct {                              /* compiled tracer variants, by variant key */
        uint32_t key;
        GLuint program;
    } tracer_programs[GPU_PROGRAM_CACHE_SIZE];
    int tracer_program_count;
    int next_eviction;                    /* the slot a full cache replaces next */
    GLuint packed_texture;                /* a buffer texture over packed_buffer */
    GLuint packed_buffer;
    uint64_t packed_hash;
    uint32_t packed_texel_count;
    uint64_t *packed_block_hashes;        /* hash of each GPU_PACKED_BLOCK_TEXELS texels of the
                                           * scene uploaded, so that the next scene of the
                                           * same size uploads only the blocks that differ */
};

/* Texels per block of the packed scene's partial upload (16 KiB). */
#define GPU_PACKED_BLOCK_TEXELS 1024u

/* Frees what the tracer keeps on the context (compiled programs, the packed scene);
 * gpu_destroy() calls it while the context is still current. In gpu_tracer.c. */
void gpu_tracer_release(gpu_context *context);

#endif
