/* gpu.h: the only module that talks to EGL and OpenGL: core/gpu.c (the context) and
 * core/gpu_tracer.c (the tracer on it, with core/gpu_program.c, core/gpu_state.c,
 * core/gpu_compact.c and core/gpu_cull.c) implement it.
 *
 * Context set-up, in order (as piglit does it): check EGL client extensions; try the
 * EGL devices of EGL_EXT_platform_device (hardware devices first, so a real GPU wins;
 * gpu_options.device picks one); then EGL_MESA_platform_surfaceless (Mesa's llvmpipe on a
 * CPU-only machine); create a desktop OpenGL 4.5 core context with no surface and no
 * config; everything renders into framebuffer objects.
 *
 * Failures are told apart: RT_ERROR_NO_DEVICE when no EGL platform or device is there at
 * all (the message says what to install), RT_ERROR_RUNTIME when one is there but the
 * driver fails (the message names the EGL/GL call and its error).
 *
 * The tracer part runs the GLSL tracer (glsl/, joined as core/shader_sources.S lists it)
 * over ping-pong state textures, one bounded pass at a time (see render.h for why).
 *
 * Defaults of gpu_options (all zero): automatic device choice, no GL debug output, the
 * software device's own thread count (llvmpipe: LP_NUM_THREADS as the environment has it,
 * else one thread per CPU).
 *
 * Threads (gpu_options.threads > 0): llvmpipe reads LP_NUM_THREADS when its screen and
 * context are made, so gpu_create() sets it for the duration of the set-up and puts the
 * environment back as it was afterwards. A hardware device ignores it:
 * gpu_info.threads_ignored says so, for the caller to warn. gpu_info.software_threads is
 * what the device really runs: the llvmpipe worker threads (named "llvmpipe-N") counted in
 * /proc/self/task once the context exists.
 */
#ifndef RT_GPU_H
#define RT_GPU_H

#include <stdbool.h>
#include <stdint.h>

#include "status.h"
#include "tracer_interface.h"

typedef struct gpu_options {
    int device;                  /* 0: automatic; N >= 1: use EGL device N-1 (see `info`) */
    bool debug_output;           /* KHR_debug messages to the debug callback (--verbose) */
    void (*log)(void *log_context, const char *message);  /* where debug messages go */
    void *log_context;
    int threads;                 /* 0: the device's default; N >= 1: CPU threads of a software
                                  * device (llvmpipe's LP_NUM_THREADS); see "Threads" above */
} gpu_options;

/* The most threads gpu_options.threads may ask for (llvmpipe's own cap is lower). */
#define GPU_MAX_THREADS 1024

/* The EGL devices of EGL_EXT_device_enumeration are listed (at most GPU_MAX_DEVICES), in
 * EGL's order: --device N and gpu_options.device N + 1 pick devices[N]. */
#define GPU_MAX_DEVICES 16

/* What EGL tells about one device without opening it; "" where its driver does not say. */
typedef struct gpu_device_description {
    char extensions[512];        /* its EGL_EXTENSIONS, which name the driver's kind
                                  * (EGL_MESA_device_software, EGL_EXT_device_drm, ...) */
    bool software;               /* EGL_MESA_device_software: a CPU rasteriser (llvmpipe) */
    char drm_device_file[128];   /* EGL_EXT_device_drm: e.g. "/dev/dri/card0" */
    char drm_render_node[128];   /* EGL_EXT_device_drm_render_node: e.g. "/dev/dri/renderD128" */
    char vendor[128];            /* EGL_EXT_device_query_name: EGL_VENDOR of the device */
    char renderer[128];          /* EGL_EXT_device_query_name: EGL_RENDERER_EXT */
    char driver[128];            /* EGL_EXT_device_persistent_id: EGL_DRIVER_NAME_EXT */
} gpu_device_description;

typedef struct gpu_info {
    char platform[64];           /* "device" or "surfaceless" */
    int device_index;            /* EGL device used (0-based), -1 for surfaceless */
    int device_count;            /* EGL devices seen (at most GPU_MAX_DEVICES) */
    gpu_device_description devices[GPU_MAX_DEVICES];   /* devices[0 .. device_count - 1] */
    char device_extensions[512]; /* of the chosen device, "" for surfaceless */
    char egl_vendor[128], egl_version[128];
    char gl_vendor[128], gl_renderer[256], gl_version[128], glsl_version[128];
    int max_texture_size;        /* GL_MAX_TEXTURE_SIZE as the driver says */
    /* The widest and tallest tile the tracer can render: the least of GL_MAX_TEXTURE_SIZE,
     * GL_MAX_FRAMEBUFFER_WIDTH/HEIGHT and GL_MAX_RENDERBUFFER_SIZE. Larger images are
     * rendered in tiles (render_job.h). The test hook RTSPHERES_TEST_MAX_TEXTURE_SIZE
     * lowers, never raises, it. */
    int max_tile_side;
    int max_texture_buffer_size; /* texels of a buffer texture: bounds the packed scene */
    int max_draw_buffers;
    int max_color_attachments;
    int max_fragment_atomic_counters;
    int max_fragment_image_units;   /* GL_MAX_FRAGMENT_IMAGE_UNIFORMS: the tracer uses 1 to 3 */
    int max_images_and_outputs;  /* GL_MAX_COMBINED_IMAGE_UNITS_AND_FRAGMENT_OUTPUTS */
    bool software;               /* a CPU rasteriser (llvmpipe, softpipe) */
    int software_threads;        /* llvmpipe rasteriser threads running for this context
                                  * (0: rasterising in the calling thread, or not llvmpipe;
                                  * -1: /proc/self/task cannot be read) */
    bool threads_ignored;        /* gpu_options.threads was given but the device is not a
                                  * software one: it changed nothing */
    /* The work bound (glsl/work.glsl). On llvmpipe, which ends all
     * loops of an invocation after 65,535 iterations together and runs simd_lanes pixels
     * as one invocation: work_cap = 65535 / (simd_lanes + 1) - 1024 (1024: what a pixel
     * may still run after reaching the cap), and passes of at most work_cap / 2. On
     * other devices there is no such cap (simd_lanes 0): work_cap 1,000,000 only stops
     * a runaway traversal, and the budget is at most 50,000. */
    int simd_lanes;
    int work_cap;
    int max_pass_work_budget;
} gpu_info;

typedef struct gpu_context gpu_context;

/* Returns options with every field at its default (all zero). */
gpu_options gpu_options_defaults(void);

/* Creates the EGL display and an OpenGL 4.5 core context and makes it current.
 * options may be NULL. On success *out is the context; free it with gpu_destroy(). */
rt_status gpu_create(const gpu_options *options, gpu_context **out, rt_error *error);

/* Releases the context and the display. NULL is ignored. */
void gpu_destroy(gpu_context *context);

/* Copies what was chosen and the limits that matter into *info. */
void gpu_get_info(const gpu_context *context, gpu_info *info);

/* ---- the tracer -------------------------------------------------------------------- */

/* Parts of the tracer a scene may not need (omitted_features below). Leaving them out of
 * the shader changes no image: a scene without lights never samples one. It makes the
 * shader smaller, and llvmpipe runs both sides of every branch (only loops really jump),
 * so every piece of code in the tracer's loops costs on every iteration, run or not
 * (docs/performance.md has what leaving it out gained).
 * Each combination is compiled once per context, on first use.
 *   GPU_OMIT_DIRECT_LIGHT    no light sampling: path tracing of a scene with no lights,
 *                            or with light sampling off (never for Whitted: ambient)
 *   GPU_OMIT_VOLUMES         no volume anywhere, the camera in none
 *   GPU_OMIT_TEXTURES        no texture and no normal map on any material
 *   GPU_OMIT_SPHERES         no sphere (moving or not) in any BVH
 *   GPU_OMIT_MOVING_SPHERES  no moving sphere
 *   GPU_OMIT_TRIANGLES       no triangle
 *   GPU_OMIT_INSTANCES       no instance record: one BVH level
 *   GPU_OMIT_EMITTERS        no emissive material
 *   GPU_OMIT_QUADS           no quad
 *   GPU_OMIT_LIGHT_CHOICE    lights are chosen by power alone (1 light, or more than
 *                            LIGHT_LOCAL_CHOICE_MAX of core/tracer_interface.h), never by
 *                            their estimated irradiance at the point (glsl/lights.glsl)
 *   GPU_OMIT_RECTANGLE_LIGHTS  no quad light, so no sampling by spherical rectangles
 *   GPU_OMIT_PBR             no pbr material
 *   GPU_OMIT_ALPHA_MASK      no alpha-masked material (the traversal's alpha test)
 *   GPU_OMIT_VERTEX_COLORS   no vertex colour section
 *   GPU_OMIT_LIGHT_GROUPS    no light group layers asked for (render_options.light_groups)
 *   GPU_OMIT_DIRECT_EMISSION  no direct emission sums asked for (render_options.direct_emission)
 *   GPU_OMIT_SQUARES         no per-channel sums of squares asked for (render_options.variance):
 *                            the pass state has 7 textures instead of 8 (TRACER_STATE_SQUARES
 *                            left out), and gpu_tracer_read_squares is an error
 *   GPU_OMIT_STACK_WALK      the packed scene has the threaded walk (packed_layout.h; a
 *                            scene of still spheres and quads in one level) and no alpha
 *                            mask: the tracer walks its lists, with no stack, instead of
 *                            the nodes
 *   GPU_OMIT_SPHERE_LIGHTS, GPU_OMIT_TRIANGLE_LIGHTS, GPU_OMIT_DELTA_LIGHTS (point, spot,
 *   GPU_OMIT_ENVIRONMENT_LIGHT  sun)  no light of that kind in the light section
 *   GPU_OMIT_MANY_LIGHTS     at most one light: no light to choose, no search for a hit
 *                            emitter's light
 *   GPU_OMIT_LAMBERTIAN, GPU_OMIT_METAL, GPU_OMIT_DIELECTRIC  no material of that kind
 *   GPU_OMIT_LIGHT_TREE      no light tree (at most LIGHT_LOCAL_CHOICE_MAX lights, or no
 *                            light sampling): lights are not chosen by walking it
 *   GPU_FIX_UNIFORMS         the integrator, the sky type and the sampler compiled in as constants
 *                            (the values in the parameters), not read from the
 *                            parameter block
 * glsl/variant.glsl turns them into the constants HAS_* the tracer tests. */
#define GPU_OMIT_DIRECT_LIGHT (1u << 0)
#define GPU_OMIT_VOLUMES (1u << 1)
#define GPU_OMIT_TEXTURES (1u << 2)
#define GPU_OMIT_SPHERES (1u << 3)
#define GPU_OMIT_MOVING_SPHERES (1u << 4)
#define GPU_OMIT_TRIANGLES (1u << 5)
#define GPU_OMIT_INSTANCES (1u << 6)
#define GPU_OMIT_EMITTERS (1u << 7)
#define GPU_OMIT_QUADS (1u << 8)
#define GPU_FIX_UNIFORMS (1u << 9)
#define GPU_OMIT_LIGHT_CHOICE (1u << 10)
#define GPU_OMIT_RECTANGLE_LIGHTS (1u << 11)
#define GPU_OMIT_PBR (1u << 12)
#define GPU_OMIT_ALPHA_MASK (1u << 13)
#define GPU_OMIT_VERTEX_COLORS (1u << 14)
#define GPU_OMIT_LIGHT_GROUPS (1u << 15)
#define GPU_OMIT_SPHERE_LIGHTS (1u << 16)
#define GPU_OMIT_TRIANGLE_LIGHTS (1u << 17)
#define GPU_OMIT_DELTA_LIGHTS (1u << 18)
#define GPU_OMIT_ENVIRONMENT_LIGHT (1u << 19)
#define GPU_OMIT_MANY_LIGHTS (1u << 20)
#define GPU_OMIT_LAMBERTIAN (1u << 21)
#define GPU_OMIT_METAL (1u << 22)
#define GPU_OMIT_DIELECTRIC (1u << 23)
#define GPU_OMIT_LIGHT_TREE (1u << 24)
#define GPU_OMIT_DIRECT_EMISSION (1u << 25)
#define GPU_OMIT_SQUARES (1u << 26)
#define GPU_OMIT_STACK_WALK (1u << 27)
/* The bits a program variant is told apart by (core/gpu_program.c gpu_variant_key): every bit
 * above, GPU_FIX_UNIFORMS with them. */
#define GPU_VARIANT_BITS 28

/* The tracer's parameter block as C sees it: the list of core/tracer_interface.h, each
 * GLSL type made a C type with its std140 alignment, so that the compiler lays the struct
 * out as std140 lays out the GLSL block (tests/unit/test_tracer_parameters.c checks it).
 * Uploaded as it is (one glBufferData); see tracer_interface.h for what each member is. */
typedef float gpu_glsl_float;
typedef int32_t gpu_glsl_int;
typedef uint32_t gpu_glsl_uint;
typedef int32_t gpu_glsl_ivec2[2];
typedef uint32_t gpu_glsl_uvec2[2];
typedef float gpu_glsl_vec3[3];
#define GPU_STD140_ALIGN_float 4
#define GPU_STD140_ALIGN_int 4
#define GPU_STD140_ALIGN_uint 4
#define GPU_STD140_ALIGN_ivec2 8
#define GPU_STD140_ALIGN_uvec2 8
#define GPU_STD140_ALIGN_vec3 16
#define GPU_TRACER_PARAMETER_MEMBER(type, name) _Alignas(GPU_STD140_ALIGN_##type) gpu_glsl_##type name;
typedef struct tracer_parameter_block {
    TRACER_PARAMETERS(GPU_TRACER_PARAMETER_MEMBER)
} tracer_parameter_block;

/* Per-render parameters of the tracer. */
typedef struct gpu_tracer_parameters {
    tracer_parameter_block shader;        /* what the shader reads. gpu_tracer.c sets work_cap (from
                                           * the device) and clamps pass_work_budget to what
                                           * the device allows; full_size 0 means image_size */
    uint32_t omitted_features;            /* GPU_OMIT_* and GPU_FIX_UNIFORMS bits: code this
                                           * scene cannot reach, left out of the compiled
                                           * tracer (0: none, the whole tracer) */
    const float *resume;                  /* NULL, or width*height*4 floats, rows top to bottom:
                                           * (sum r, g, b, finished samples) to continue from;
                                           * a pixel with n finished samples goes on with
                                           * sample index sample_start + n */
    const float *resume_luminance_squares;  /* NULL, or with resume width*height floats, rows
                                           * top to bottom: each pixel's sum of squared
                                           * luminance over those samples (what adaptive
                                           * sampling's checks read; zero when NULL) */
} gpu_tracer_parameters;

/* What one pass reports. */
typedef struct gpu_pass_report {
    uint32_t unfinished_pixels;           /* pixels (compact slots) that still have samples to run */
    uint32_t samples_finished;            /* samples that ended in this pass */
} gpu_pass_report;

/* Sums read back at the end of a render. */
typedef struct gpu_tracer_totals {
    double path_segments;                 /* rays traced (camera + scattered) */
    double traversal_overflows;           /* traversals cut at the hard work cap (must be 0) */
} gpu_tracer_totals;

typedef struct gpu_tracer gpu_tracer;

/* Compiles the tracer (once per context), uploads the packed scene (unless the context
 * already holds exactly these texels; of a scene of the same size only the blocks that
 * differ, see gpu_tracer_uploaded_bytes()) (texel_count texels of 4 uint32 each,
 * see packed_layout.h; texel_hash: their hash, pack.h's packed_scene.texel_hash, which
 * tells whether the context holds them) and creates the state textures for
 * parameters->width x height. Wider or taller than gpu_info.max_tile_side is RT_ERROR_INPUT
 * naming the limit; a device that cannot hold the state (GL_OUT_OF_MEMORY, or a state
 * framebuffer it calls incomplete) is RT_ERROR_RUNTIME "GPU: out of memory for the state
 * of a WxH image (N MiB); ..." naming the size and what to try (a smaller
 * --memory-budget), never a raw framebuffer status. Test hook: RTSPHERES_TEST_GPU_FAILURE
 * = "memory" or "framebuffer" makes the state's creation fail as that failure would.
 * Free with gpu_tracer_destroy(). GPU_TRACER_STATE_BYTES_PER_PIXEL: the two state sets,
 * the sample limits and the depth buffer of gpu_tracer_cull_finished; 2 x 16 bytes less
 * with GPU_OMIT_SQUARES (GPU_TRACER_SQUARES_BYTES_PER_PIXEL). */
#define GPU_TRACER_STATE_BYTES_PER_PIXEL (2 * TRACER_STATE_COUNT * 16 + 4 + 4)
#define GPU_TRACER_SQUARES_BYTES_PER_PIXEL (2 * 16)
rt_status gpu_tracer_create(gpu_context *context, const uint32_t *packed_texels, uint32_t texel_count,
                            uint64_t texel_hash, const gpu_tracer_parameters *parameters, gpu_tracer **out,
                            rt_error *error);

/* Runs one pass: every unfinished pixel does at most pass_work_budget units of work,
 * keeps its unfinished path in the state textures, and starts new samples while it has
 * budget and samples left. Waits for the pass to finish and fills *report. */
rt_status gpu_tracer_run_pass(gpu_tracer *tracer, gpu_pass_report *report, rt_error *error);

/* Marks the pixels that full passes no longer change (all samples started, no path in
 * flight, in both sets of pass state: the latest pass's and the one before's) so that the
 * following full passes skip them before their shader runs (an early depth test against a
 * depth buffer of the state's size; glsl/cull.frag). Same images, cheaper passes at the
 * end of a render, when most pixels wait for a few slow ones (docs/performance.md: at
 * 1200x675, 45 ms a pass for the whole image, 5 ms with every pixel marked). Costs one
 * draw of the image reading two counter texels a pixel. Nothing to do in compacted
 * passes; the marks go when the sample limits or the pixels traced change. */
rt_status gpu_tracer_cull_finished(gpu_tracer *tracer, rt_error *error);

/* Changes the work budget of the following passes. The image does not depend on it (the
 * random numbers belong to samples, not passes); only the time per pass does. */
void gpu_tracer_set_pass_work_budget(gpu_tracer *tracer, uint32_t budget);

/* Sets each pixel's sample limit: limits holds width*height counts, rows top to bottom; a
 * pixel starts no sample at or past min(its limit, samples_per_pixel) (a path in flight
 * finishes). Until called, only samples_per_pixel limits. For adaptive sampling
 * (core/adaptive.h). */
rt_status gpu_tracer_set_sample_limits(gpu_tracer *tracer, const uint32_t *limits, rt_error *error);

/* Makes the following passes run only the count (> 0) pixels of pixels (indices y * width
 * + x, rows from the top, each at most once; copied), packed densely (core/gpu_compact.c),
 * so that the lanes of a SIMD vector are all pixels of the list: what adaptive sampling
 * (core/adaptive.h) saves shows on the clock. Call it after a pass that reported no
 * unfinished pixel and then gpu_tracer_set_sample_limits: each listed pixel goes on from
 * its limit before those (the samples it has started) to its new limit in runs (at least 1):
 * its samples split into that many ranges of consecutive indices, traced side by side in
 * slots of their own, each summed from zero and added to the pixel's sums in order. So a
 * pixel's sums depend on its samples and runs alone, not on the list (a tile renders its
 * pixels as the whole image does); they differ from one run's (or uncompacted passes') by
 * float rounding. With light group layers a pixel takes 1 run. Pixels left out keep their
 * sums; from the first list on, passes never return to the whole image, and a pass's
 * unfinished_pixels counts slots. Costs one read-back of the state (the first list), one
 * of the slots' sums at each list and round (and at every read of the state), and, kept
 * until the tracer is destroyed, the host's sums of every pixel (48 bytes a pixel) and a
 * pixel map (16 bytes a pixel on the device and on the host): the slots are the state
 * textures' own texels, one a pixel at most (more runs go in rounds, one after another).
 * RT_ERROR_RUNTIME when the device or the host runs out of memory. */
rt_status gpu_tracer_set_pass_pixels(gpu_tracer *tracer, const uint32_t *pixels, int count, int runs,
                                     rt_error *error);

/* Reads the accumulated result: rgba receives width*height*4 floats, rows top to bottom,
 * (sum of finished samples' radiance r, g, b, number of finished samples);
 * luminance_squares (may be NULL) width*height floats: the sum of each finished sample's
 * squared luminance (for the variance). totals may be NULL. */
rt_status gpu_tracer_read(gpu_tracer *tracer, float *rgba, float *luminance_squares, gpu_tracer_totals *totals,
                          rt_error *error);

/* Reads the light group layers (glsl/light_groups.glsl) of a tracer created with
 * shader.light_group_count > 0 and without GPU_OMIT_LIGHT_GROUPS: layers receives
 * light_group_count * width * height * 4 floats, layer after layer, rows top to bottom,
 * (sum of the group's radiance over the samples gathered r, g, b, 0). Other tracers:
 * RT_ERROR_RUNTIME. */
rt_status gpu_tracer_read_light_groups(gpu_tracer *tracer, float *layers, rt_error *error);

/* Reads the direct emission sums (glsl/direct_emission.glsl) of a tracer created with
 * shader.direct_emission nonzero and without GPU_OMIT_DIRECT_EMISSION: sums receives
 * width * height * 4 floats, rows top to bottom, (sum over the pixel's samples of the
 * radiance their first segment brought from an emitter or the sky r, g, b, 0). Other
 * tracers: RT_ERROR_RUNTIME. */
rt_status gpu_tracer_read_direct_emission(gpu_tracer *tracer, float *sums, rt_error *error);

/* Reads the per-channel sums of squares: squares receives width*height*4 floats, rows top
 * to bottom, (sum of finished samples' squared radiance r^2, g^2, b^2, 0), from which
 * render.c makes the variance layers. RT_ERROR_RUNTIME for a tracer created with
 * GPU_OMIT_SQUARES, which keeps none. */
rt_status gpu_tracer_read_squares(gpu_tracer *tracer, float *squares, rt_error *error);

/* Renders the first-hit AOVs with samples jittered camera rays per pixel (the same camera
 * rays as the render's first samples): albedo_depth receives width*height*4 floats (albedo
 * r, g, b; distance to the first hit, 0 where nothing was hit), normal_coverage
 * width*height*4 (world shading normal facing the camera, the share of rays that hit),
 * rows top to bottom. */
rt_status gpu_tracer_render_aovs(gpu_tracer *tracer, int samples, float *albedo_depth, float *normal_coverage,
                                 rt_error *error);

/* True when gpu_tracer_create() found the same packed scene already uploaded on the
 * context (frames of an animation whose scene did not change) and did not upload it. The
 * compiled tracer program is always kept by the context between tracers. */
bool gpu_tracer_reused_scene(const gpu_tracer *tracer);

/* The bytes of the packed scene gpu_tracer_create() uploaded: 0 when it was on the device;
 * all of it for a scene of another size; for one of the same size only the 16 KiB blocks
 * whose texels changed (the context keeps a hash per block), so that a sweep row or frame
 * that changes a light or a material uploads those sections' blocks, not the geometry. */
uint64_t gpu_tracer_uploaded_bytes(const gpu_tracer *tracer);

/* True when gpu_tracer_create() compiled the tracer program for this tracer; false when
 * the context's program cache already held its variant (frames and sweep rows after the
 * first, whose variant does not change). */
bool gpu_tracer_compiled_program(const gpu_tracer *tracer);

/* How long gpu_tracer_create() took for its parts, in seconds (0 for a part it did not
 * need: a program from the cache, a scene already on the device). On llvmpipe the
 * shader's machine code is made at its first draw, so compile_seconds is the GLSL
 * compile and link only and the first pass carries the rest. */
typedef struct gpu_tracer_timings {
    double compile_seconds;               /* compiling and linking the tracer program */
    double upload_seconds;                /* the packed scene into its buffer texture */
    double state_seconds;                 /* state textures, framebuffers, resumed sums */
} gpu_tracer_timings;

void gpu_tracer_get_timings(const gpu_tracer *tracer, gpu_tracer_timings *timings);

/* Frees the tracer's GL objects (not the context's program and packed scene). NULL is
 * ignored. */
void gpu_tracer_destroy(gpu_tracer *tracer);

/* ---- tests ------------------------------------------------------------------------ */

/* What gpu_random_numbers() draws. Zero is a default for every field but width/height:
 * sampler SAMPLER_SOBOL (tracer_interface.h), per-pixel layout. */
typedef struct gpu_random_request {
    int width, height;           /* the output image, >= 1 */
    uint32_t sample_index, seed, dimension;
    int sampler;                 /* SAMPLER_* of tracer_interface.h */
    bool over_samples;           /* false: pixel (x, y) gets its own values for sample_index;
                                  * true: every output pixel shows pixel fixed_pixel, output
                                  * pixel (x, y) holding sample sample_index + y * width + x */
    int fixed_pixel[2];          /* with over_samples: the image pixel (x, y), row 0 at the top */
} gpu_random_request;

/* Draws the tracer's sample values (glsl/random.glsl) on the device, as the request says:
 * rgba receives width*height*4 floats, rows top to bottom, the four numbers of one
 * dimension per output pixel. For testing the sampler where it runs. */
rt_status gpu_random_numbers(gpu_context *context, const gpu_random_request *request, float *rgba,
                             rt_error *error);

/* One query of the material test: a ray along direction meets a surface (normal: the
 * geometric normal facing the ray, shading: the shading normal, front_face: whether the
 * ray met the primitive's front) whose material is the packed scene's material number
 * material; u are the four uniform numbers its sample function draws from, to_light a
 * direction at which its evaluate and pdf functions are read as well. All directions
 * unit, in the world. */
typedef struct gpu_material_query {
    float direction[3];
    float normal[3];
    float shading[3];
    bool front_face;
    float u[4];
    float to_light[3];
    uint32_t material;
} gpu_material_query;

/* What the material functions of glsl/material_table.glsl return for one query
 * (view = -direction). */
typedef struct gpu_material_result {
    float direction[3];          /* material_sample: where the path goes on */
    float pdf;                   /* its BsdfSample.pdf (the density MIS is given) */
    float weight[3];             /* its f cos / pdf */
    bool absorbed, light_sampled;
    float evaluate[3];           /* material_evaluate(view, to_light): f cos */
    float evaluate_pdf;          /* material_pdf(view, to_light) */
    float sampled_evaluate[3];   /* the same at the sampled direction */
    float sampled_pdf;
} gpu_material_result;

/* Runs the tracer's material functions (the whole tracer's: no part left out) on the
 * device for count queries against a packed scene (texels as gpu_tracer_create takes
 * them; only its header, materials, textures and images are read), filling results[0 ..
 * count - 1]. For testing a material's sampling, density and evaluation where they run
 * (tests/unit/test_material_pbr.c). The caller owns both arrays. */
rt_status gpu_material_test(gpu_context *context, const uint32_t *packed_texels, uint32_t texel_count,
                            const gpu_material_query *queries, int count, gpu_material_result *results,
                            rt_error *error);

/* One query of the light choice test: a point p, on a surface of unit normal n facing the
 * side light is gathered on (all 0: a point in a medium), u the uniform number in [0, 1)
 * the choice draws from, and a light whose chance at p is read as well. */
typedef struct gpu_light_query {
    float p[3];
    float n[3];
    float u;
    uint32_t light;
} gpu_light_query;

/* What glsl/lights.glsl returns for one query. */
typedef struct gpu_light_result {
    uint32_t picked;             /* choose_light_at(u, p, n): the light */
    float chance;                /* the probability it reports for that light */
    float memo[2];               /* the memo it leaves for MIS */
    float picked_again;          /* light_choice_probability(picked, p, memo) */
    float light_chance;          /* light_choice_probability(query's light, p, memo) */
} gpu_light_result;

/* Runs the tracer's light choice (the whole tracer's: no part left out) on the device for
 * count queries against a packed scene (texels as gpu_tracer_create takes them), filling
 * results[0 .. count - 1]. For testing the choice of a light against its probabilities
 * (tests/unit/test_light_choice.c). The caller owns both arrays. */
rt_status gpu_light_choice_test(gpu_context *context, const uint32_t *packed_texels, uint32_t texel_count,
                                const gpu_light_query *queries, int count, gpu_light_result *results,
                                rt_error *error);

/* Compiles the whole tracer (no part left out) and reads where the GL placed the members
 * of its parameter block: offsets[i] receives the byte offset of the member called
 * names[i] (-1 when the program has none of that name), *block_size the block's size
 * (GL_UNIFORM_BLOCK_DATA_SIZE). For checking tracer_parameter_block against the GLSL. */
rt_status gpu_tracer_parameter_layout(gpu_context *context, int count, const char *const *names, int *offsets,
                                      int *block_size, rt_error *error);

#endif
