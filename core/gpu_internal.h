/* gpu_internal.h: what core/gpu.c (the EGL context), core/gpu_program.c (GLSL programs),
 * core/gpu_tracer.c (the tracer on it), core/gpu_state.c (its pass state),
 * core/gpu_compact.c (its compacted passes),
 * core/gpu_cull.c (full passes that skip finished pixels) and core/gpu_test_programs.c
 * (the programs only tests use) share; no other file includes it. */
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
    GLuint cull_program;                  /* glsl/cull.frag, built when first used (0 before) */
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
 * the pixels still going, each in one or more slots (runs) of the state textures, and the
 * host's copy of every pixel's sums that the runs add to. */
typedef struct gpu_compact {
    int count;                   /* pixels traced compactly; 0: passes draw the whole image */
    uint32_t *pixels;            /* the list (indices y * width + x, rows from the top) */
    uint32_t *list_start, *list_limit;   /* each listed pixel's samples started when the list
                                          * was set, and its limit (in the pixels block) */
    int runs;                    /* runs a pixel's samples are split into */
    int first_run, round_runs;   /* the runs the slots trace now: a round (when all runs at
                                  * once would not fit, rounds follow one another) */
    uint32_t round;              /* the round's number (core/tracer_interface.h), from 1 */
    bool blocks;                 /* the round's slots go in 4 x 2 blocks (else row by row) */
    int tile_columns;            /* >= 2: the blocks dealt to that many 64-wide columns
                                  * (gpu_compact.c slot_of); 0: along the whole rows */
    int used_width, used_height; /* the slots of the round: drawn (a scissor), the rest not */
    GLuint pixel_map;            /* RGBA32UI, the state textures' size (core/tracer_interface.h) */
    uint32_t *slot_map;          /* the pixel map's texels as uploaded, rows from the bottom */
    /* The host's sums of every pixel (from the first list on; NULL before): the full
     * state's sums when the first list was set, plus every finished round's, rows top to
     * bottom, 4 floats a pixel each: TRACER_STATE_ACCUMULATED, _STATISTICS, _SQUARES. */
    float *sums[3];
    uint32_t *started;           /* samples started per pixel: the limits before the last ones */
    /* Copies of the full state's sums as a read took them before the first list, and the
     * tracer's passes then (under sample limits only: adaptive sampling's first check). */
    float *full_copies[3];
    uint64_t full_copy_passes[3];
    uint32_t *limits;            /* per pixel, rows from the top: gpu_tracer_set_sample_limits */
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
    GLuint no_pixel_map;         /* RGBA32UI, 1 or 3 texels a side, on the pixel map's unit in full
                                  * passes (core/gpu_state.c gpu_state_create says why) */
    gpu_compact compact;         /* compacted passes (gpu_compact.c) */
    GLuint light_group_texture;  /* the light group layers (2D array, rgba32f), or 0 when the
                                  * program has no light group code */
    GLuint direct_emission_texture;  /* the direct emission sums (a 2D array of one rgba32f
                                      * layer), or 0 when the program has no such code */
    GLuint depth_buffer;         /* both full state sets' depth: 0 where full passes skip the
                                  * pixel (gpu_tracer_cull_finished), else 1 */
    bool culling;                /* some pixel is marked: full passes test the depth */
    int state_count;             /* state textures a set has: TRACER_STATE_COUNT, or one less
                                  * when the squares are left out (GPU_OMIT_SQUARES; the last) */
    int image_units;             /* the program's image units: the packed scene's, and the light
                                  * group layers' and direct emission's when it has them */
    int current;                 /* which state set holds the latest pass */
    uint64_t passes;             /* passes run */
    gpu_tracer_parameters parameters;   /* as created, for the AOV pass */
    bool reused_scene;           /* the packed scene was already on the device */
    uint64_t uploaded_bytes;     /* of the packed scene, uploaded for this tracer */
    bool compiled_program;       /* its program was compiled for it (not in the cache) */
    gpu_tracer_timings timings;
};

/* Unmarks every pixel gpu_tracer_cull_finished marked (the depth back to 1): what was
 * finished may go on once the sample limits or the pixels traced change. */
void gpu_uncull(gpu_tracer *tracer);

/* Reads the sums of state TRACER_STATE_ACCUMULATED, _STATISTICS or _SQUARES of every
 * pixel into out (4 floats a pixel, rows top to bottom) when passes have been compacted:
 * the host's sums plus the current round's slots (gpu_compact.c), and sets *compacted.
 * Clears it, reading nothing, when they have not (the full state textures hold every
 * pixel). RT_ERROR_RUNTIME when memory runs out. */
rt_status gpu_compact_read(gpu_tracer *tracer, int state, float *out, bool *compacted, rt_error *error);

/* Keeps a copy of sums, just read from the full state textures' state (TRACER_STATE_*), for
 * the first list to start from (gpu_compact.c): when sample limits are set and no list
 * has been. */
void gpu_compact_note_full_read(gpu_tracer *tracer, int state, const float *sums);

/* After a compacted pass that left no slot unfinished: when runs of the list remain, adds
 * the round's sums to the host's and starts the next round, and sets *next (the pass loop
 * goes on); else clears it. RT_ERROR_RUNTIME when memory runs out. */
rt_status gpu_compact_next_round(gpu_tracer *tracer, bool *next, rt_error *error);

/* Cuts the draws that follow to the compact slots the list takes (on), or lets them cover
 * their whole framebuffer again (off). */
void gpu_compact_scissor(gpu_tracer *tracer, bool on);

/* Reads float state texture state (TRACER_STATE_*) of the latest set into out, rows top
 * to bottom, 4 floats a texel. RT_ERROR_RUNTIME when memory runs out. In gpu_tracer.c. */
rt_status gpu_read_full_state(gpu_tracer *tracer, int state, float *out, rt_error *error);

/* Frees the tracer's compact state. */
void gpu_compact_destroy(gpu_tracer *tracer);

/* ---- core/gpu_state.c: the pass state on the device --------------------------------- */

/* Creates one set of pass-state textures (the first count of TRACER_STATE_COUNT, width x
 * height, nearest filtering; RGBA32F, the counters RGBA32UI; the others' names 0) and a
 * framebuffer drawing to them (attachment TRACER_STATE_* for each) into textures and
 * *framebuffer, left bound. Returns the framebuffer's status: GL_FRAMEBUFFER_COMPLETE, or
 * incomplete where the device could not allocate a texture. The caller deletes them. */
GLenum gpu_create_state_set(GLuint textures[TRACER_STATE_COUNT], int count, GLuint *framebuffer, int width,
                            int height);

/* Creates the tracer's two state sets (tracer->state_count textures each, zeroed) with
 * their framebuffers, the depth buffer both share (all 1: no pixel skipped), the sample
 * limits (none) and the stand-in pixel map, into the tracer's fields; the tracer's
 * width, height, state_count and image_units must be set. RT_ERROR_INPUT for an image
 * larger than the device's textures; RT_ERROR_RUNTIME when the device lacks the outputs
 * or the memory (a message that says how big the state is and what to do). What was
 * created stays in the tracer for gpu_tracer_destroy. */
rt_status gpu_state_create(gpu_tracer *tracer, rt_error *error);

/* Creates the sum layers the tracer's program adds into: one per light group
 * (shader.light_group_count) and the direct emission's, each only when the program has
 * the code (a single texel when nothing is asked for). RT_ERROR_INPUT when the device's
 * memory does not hold them. */
rt_status gpu_state_create_sums(gpu_tracer *tracer, rt_error *error);

/* Loads a partial result (resume: width x height x 4 floats, rows top to bottom, the sums
 * of R, G, B and the finished samples: gpu.h gpu_tracer_parameters) into state set 0, which the first pass reads: the sums, and the
 * finished counts as "samples started" (a path that was in flight is traced again: its
 * random numbers are the same), and luminance_squares (NULL: zero; else width x height
 * floats) as the statistics' sums of squared luminance. RT_ERROR_RUNTIME when memory runs
 * out. */
rt_status gpu_state_load_resume(gpu_tracer *tracer, const float *resume, const float *luminance_squares,
                                rt_error *error);

/* ---- core/gpu_program.c: programs from the modules of core/shader_sources.S ---------- */

/* Writes the #defines of a tracer variant into defines (size bytes): every
 * RTSPHERES_OMIT_* as 1 when its GPU_OMIT_* bit is in omitted, else 0 (glsl/variant.glsl
 * reads them), RTSPHERES_FIX_UNIFORMS with the integrator, sky type and sampler of
 * settings it compiles in (0 when not fixed, so the source does not vary with the
 * parameters; settings may then be NULL), and RTSPHERES_LIGHT_GROUP_REGISTERS, the light
 * group layers a pass holds in registers (glsl/light_groups.glsl; 0 without settings). */
void gpu_variant_defines(uint32_t omitted, const tracer_parameter_block *settings, char *defines, size_t size);

/* The key of a variant in a context's program cache (gpu_tracer.c): everything
 * gpu_variant_defines writes for omitted and settings, so that two keys are equal when
 * their defines are. */
uint64_t gpu_variant_key(uint32_t omitted, const tracer_parameter_block *settings);

/* Checks glGetError and turns any error into RT_ERROR_RUNTIME naming the step. */
rt_status gpu_check_gl(const char *step, rt_error *error);

/* Builds a program of the vertex shader vertex_source and the fragment program program
 * (SHADER_PROGRAM_* of core/shader_sources.h), both after "#version 450 core" and defines.
 * Returns the program or 0 with error set (the compiler's messages naming the modules). */
GLuint gpu_build_program(const char *vertex_source, uintptr_t program, const char *defines, rt_error *error);

/* ---- core/gpu_tracer.c -------------------------------------------------------------- */

/* Creates a buffer object holding bytes bytes of data (at least 16, so that an empty one
 * is still a valid texture store) and a buffer texture of format over it. */
void gpu_create_buffer_texture(GLenum format, const void *data, size_t bytes, GLuint *buffer, GLuint *texture);

/* Binds a packed scene's RGBA32UI buffer texture for the next draws: on the image unit
 * TRACER_PACKED_SCENE_IMAGE_UNIT, read-only (glsl/parameters.glsl packed_scene). */
void gpu_bind_packed_scene(GLuint texture);

/* The error for a packed scene of texel_count texels on a device whose buffer textures
 * hold fewer, or RT_OK. */
rt_status gpu_check_packed_size(const gpu_context *context, uint32_t texel_count, rt_error *error);

/* Frees what the tracer keeps on the context (compiled programs, the packed scene);
 * gpu_destroy() calls it while the context is still current. In gpu_tracer.c. */
void gpu_tracer_release(gpu_context *context);

#endif
