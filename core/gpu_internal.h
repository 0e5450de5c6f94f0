/* gpu_internal.h: what core/gpu.c (the EGL context), core/gpu_tracer.c (the tracer on it),
 * core/gpu_compact.c (its compacted passes) and core/gpu_test_programs.c (the programs
 * only tests use) share; no other file includes it. */
#ifndef RT_GPU_INTERNAL_H
#define RT_GPU_INTERNAL_H

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include "gpu.h"
#include "tracer_interface.h"

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
        uint64_t key;
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

/* Compacted passes of a tracer (gpu.h gpu_tracer_set_pass_pixels; core/gpu_compact.c):
 * the pixels still going, packed into two ping-pong sets of compact state textures. */
typedef struct gpu_compact {
    int count;                   /* pixels traced compactly; 0: passes draw the whole image */
    int width, height;           /* of the compact textures (0: none made yet) */
    int used_width, used_height; /* the slots of the list: drawn (a scissor), the rest not */
    GLuint state_textures[2][TRACER_STATE_COUNT];
    GLuint framebuffers[2];
    GLuint pixel_map;            /* R32UI, width x height (core/tracer_interface.h) */
    GLuint gather_program, scatter_program;
    int current;                 /* which compact set holds the latest pass */
    bool unsaved;                /* the compact set is newer than the full state */
} gpu_compact;

struct gpu_tracer {
    gpu_context *context;
    int width, height;
    GLuint program;
    GLuint vertex_array;
    GLuint packed_texture;
    GLuint packed_buffer;
    GLuint state_textures[2][TRACER_STATE_COUNT];
    GLuint framebuffers[2];
    GLuint counter_buffer;
    GLuint parameter_buffer;     /* the parameter block (tracer_parameter_block) */
    GLuint sample_limits;        /* R32UI per-pixel sample limits (TRACER_SAMPLE_LIMITS_UNIT) */
    gpu_compact compact;         /* compacted passes (gpu_compact.c) */
    GLuint light_group_texture;  /* the light group layers (2D array, rgba32f), or 0 when the
                                  * program has no light group code */
    int current;                 /* which state set holds the latest pass */
    gpu_tracer_parameters parameters;   /* as created, for the AOV pass */
    bool reused_scene;           /* the packed scene was already on the device */
    uint64_t uploaded_bytes;     /* of the packed scene, uploaded for this tracer */
    bool compiled_program;       /* its program was compiled for it (not in the cache) */
    gpu_tracer_timings timings;
};

/* Writes the compact state back to the full state textures of the current set when it is
 * newer (gpu_compact.c): every read of the state calls it first. */
rt_status gpu_compact_save(gpu_tracer *tracer, rt_error *error);

/* Cuts the draws that follow to the compact slots the list takes (on), or lets them cover
 * their whole framebuffer again (off). */
void gpu_compact_scissor(gpu_tracer *tracer, bool on);

/* Frees the tracer's compact state and programs. */
void gpu_compact_destroy(gpu_tracer *tracer);

/* Creates one set of pass-state textures (TRACER_STATE_COUNT of width x height, nearest
 * filtering; RGBA32F, the counters RGBA32UI) and a framebuffer drawing to them
 * (attachment TRACER_STATE_* for each) into textures and *framebuffer, left bound. Returns
 * the framebuffer's status: GL_FRAMEBUFFER_COMPLETE, or incomplete where the device could
 * not allocate a texture. In gpu_tracer.c; the caller deletes them. */
GLenum gpu_create_state_set(GLuint textures[TRACER_STATE_COUNT], GLuint *framebuffer, int width, int height);

/* Shared by gpu_tracer.c (where they are) and gpu_test_programs.c: */
/* Writes the #defines of a tracer variant into defines (size bytes): every
 * RTSPHERES_OMIT_* as 1 when its GPU_OMIT_* bit is in omitted, else 0 (glsl/variant.glsl
 * reads them), and RTSPHERES_FIX_UNIFORMS with the integrator, sky type and sampler of
 * settings it compiles in (0 when not fixed, so the source does not vary with the
 * parameters; settings may then be NULL). */
void gpu_variant_defines(uint32_t omitted, const tracer_parameter_block *settings, char *defines, size_t size);

/* Creates a buffer object holding bytes bytes of data (at least 16, so that an empty one
 * is still a valid texture store) and a buffer texture of format over it. */
void gpu_create_buffer_texture(GLenum format, const void *data, size_t bytes, GLuint *buffer, GLuint *texture);

/* The error for a packed scene of texel_count texels on a device whose buffer textures
 * hold fewer, or RT_OK. */
rt_status gpu_check_packed_size(const gpu_context *context, uint32_t texel_count, rt_error *error);

/* Checks glGetError and turns any error into RT_ERROR_RUNTIME naming the step. */
rt_status gpu_check_gl(const char *step, rt_error *error);

/* Builds a program of the vertex shader vertex_source and the fragment program program
 * (SHADER_PROGRAM_* of core/shader_sources.h), both after "#version 450 core" and defines.
 * Returns the program or 0 with error set (the compiler's messages naming the modules). */
GLuint gpu_build_program(const char *vertex_source, uintptr_t program, const char *defines, rt_error *error);

/* Frees what the tracer keeps on the context (compiled programs, the packed scene);
 * gpu_destroy() calls it while the context is still current. In gpu_tracer.c. */
void gpu_tracer_release(gpu_context *context);

#endif
