/* tracer_interface.h: the one definition of what the C side hands the GLSL tracer besides
 * the packed scene (core/packed_layout.h): the parameter block, the integrator ids, the
 * sky kinds and where the pass state lives.
 *
 * Like packed_layout.h, this file is included by C (core/gpu.h, core/render.h,
 * core/scene.h) and prepended, byte for byte, to the tracer's GLSL (the module table in
 * core/shader_sources.S). It must stay valid in both languages: only comments, include
 * guards and #define of plain numbers, of the parameter list below and of the name its
 * members have in the GLSL block (TRACER_BLOCK_MEMBER).
 *
 * The parameter list is expanded twice: into the C struct tracer_parameter_block
 * (core/gpu.h) and into the GLSL uniform block of the same name (glsl/parameters.glsl),
 * a std140 block that core/gpu_tracer.c uploads with one glBufferData. Each entry is
 * P(GLSL type, name); the types used are float, int, uint, ivec2, uvec2 and vec3 (core/gpu.h
 * maps each to a C type with its std140 alignment; tests/unit/test_tracer_parameters.c
 * checks the C offsets against the std140 rules and against what the GL reports).
 * Adding a parameter: one line here (any order: C and std140 agree on every layout these
 * types make), then set it in core/render.c tracer_parameters() or core/gpu_tracer.c and read it
 * by name in the GLSL.
 */
#ifndef RT_TRACER_INTERFACE_H
#define RT_TRACER_INTERFACE_H

/* ---- integrators (render_options.integrator, the parameter integrator); the GLSL
 * table of integrators is glsl/integrators.glsl */
#define INTEGRATOR_PATH 0            /* unbiased path tracing with light sampling (default) */
#define INTEGRATOR_WHITTED 1         /* Whitted recursive ray tracing with Phong shading */
#define INTEGRATOR_COUNT 2

/* ---- sky kinds (scene_sky.type, the parameter sky_type; glsl/sky.glsl) */
#define SKY_GRADIENT 0               /* lerp(bottom, top, 0.5 * (direction.y + 1)) */
#define SKY_CONSTANT 1               /* bottom colour everywhere */
#define SKY_BOX 2                    /* a cube map from six images (faces) */
#define SKY_ENVIRONMENT 3            /* an equirectangular (latitude-longitude) image */
#define SKY_TYPE_COUNT 4

/* ---- samplers (the parameter sampler; glsl/random.glsl) */
#define SAMPLER_SOBOL 0              /* padded, shuffled, Owen-scrambled Sobol pairs (default) */
#define SAMPLER_INDEPENDENT 1        /* independent hashed numbers */
#define SAMPLER_COUNT 2

/* ---- luminance: Rec. 709's weights of R, G and B, the one measure of brightness:
 * variance.Y (glsl/path_state.glsl, core/render.c), adaptive sampling's error
 * (core/adaptive.c), light powers (core/pack_lights.c, glsl/lights.glsl), a merge's
 * recombined variance, Reinhard's tone mapping. C reads them through core/luminance.h */
#define LUMINANCE_R 0.2126
#define LUMINANCE_G 0.7152
#define LUMINANCE_B 0.0722

/* ---- light choice (glsl/lights.glsl): scenes of 2 to this many lights choose a light by its
 * estimated irradiance at the point; more by the light tree (or by power alone, with the
 * tree left out) */
#define LIGHT_LOCAL_CHOICE_MAX 8
/* Whitted (glsl/direct_light.glsl) sends a shadow ray to every light of scenes of up to this
 * many lights, and to one chosen (by the light tree, or by power) beyond */
#define LIGHT_WHITTED_ALL_MAX 16

/* ---- pass state: one texture per target, read by unit TRACER_STATE_* (sampler binding)
 * and written to colour attachment TRACER_STATE_* (output location) of each pass
 * (glsl/main.glsl says what each holds) */
#define TRACER_STATE_ORIGIN 0
#define TRACER_STATE_DIRECTION 1
#define TRACER_STATE_THROUGHPUT 2
#define TRACER_STATE_RADIANCE 3
#define TRACER_STATE_COUNTERS 4      /* the one integer (RGBA32UI) target; the others are RGBA32F */
#define TRACER_STATE_ACCUMULATED 5
#define TRACER_STATE_STATISTICS 6
#define TRACER_STATE_SQUARES 7       /* rgb: sums of the finished samples' squared radiance, */
                                     /* per channel (render.c's variance layers) */
#define TRACER_STATE_COUNT 8         /* llvmpipe has 8 draw buffers: this is all of them */

/* ---- the AOV pass's outputs (glsl/aov.glsl) */
#define TRACER_AOV_ALBEDO_DEPTH 0
#define TRACER_AOV_NORMAL 1
#define TRACER_AOV_COUNT 2

/* ---- the material test program (gpu.h gpu_material_test, glsl/material_test.frag): its
 * queries, MATERIAL_TEST_QUERY_TEXELS RGBA32F texels each in a buffer texture on unit
 * MATERIAL_TEST_QUERY_UNIT, and its MATERIAL_TEST_OUTPUTS RGBA32F outputs (locations 0 on) */
#define MATERIAL_TEST_QUERY_UNIT 0
#define MATERIAL_TEST_QUERY_TEXELS 5
#define MATERIAL_TEST_OUTPUTS 4

/* ---- the light choice test (glsl/light_test.frag, gpu.h gpu_light_choice_test): its
 * queries, LIGHT_TEST_QUERY_TEXELS RGBA32F texels each in a buffer texture on unit
 * LIGHT_TEST_QUERY_UNIT, and its LIGHT_TEST_OUTPUTS RGBA32F outputs (locations 0 on) */
#define LIGHT_TEST_QUERY_UNIT 0
#define LIGHT_TEST_QUERY_TEXELS 2
#define LIGHT_TEST_OUTPUTS 2

/* ---- bindings: uniform buffer of the parameter block, atomic counter buffer (unfinished
 * pixels at offset 0, finished samples at offset 4), texture unit of the per-pixel sample
 * limits (R32UI: a pixel starts no sample at or past min(its limit, samples_per_pixel);
 * adaptive sampling, core/adaptive.h) */
#define TRACER_SAMPLE_LIMITS_UNIT 9
#define TRACER_PARAMETER_BINDING 0
#define TRACER_COUNTER_BINDING 0
/* image unit of the light group layers (glsl/light_groups.glsl): an rgba32f 2D array */
#define TRACER_LIGHT_GROUP_IMAGE_UNIT 0
/* with this many light groups or fewer, a variant holds the pixel's layers in registers
 * through a pass instead of adding to the image in every segment (glsl/light_groups.glsl;
 * the count is compiled in and tells variants apart: core/gpu_program.c) */
#define TRACER_LIGHT_GROUP_REGISTERS_MAX 8
/* image unit of the direct emission sums (glsl/direct_emission.glsl): an rgba32f 2D image */
#define TRACER_DIRECT_EMISSION_IMAGE_UNIT 1
/* image unit of the packed scene (core/packed_layout.h): its RGBA32UI buffer texture bound
 * as a read-only uimageBuffer, read with imageLoad (glsl/scene_access.glsl) */
#define TRACER_PACKED_SCENE_IMAGE_UNIT 2

/* ---- compacted passes (core/gpu_compact.c; gpu.h gpu_tracer_set_pass_pixels): the pixels
 * still taking samples packed densely into compact state textures, so that no lane of a
 * SIMD vector idles on a pixel that is done, each pixel in one or more slots (runs), each
 * run tracing its own range of the pixel's sample indices from sums of zero. The pixel
 * map (RGBA32UI, on unit TRACER_PIXEL_MAP_UNIT) gives each compact slot
 *   x: its pixel as x | y << TRACER_PIXEL_MAP_SHIFT (framebuffer rows, bottom up), or
 *      TRACER_NO_PIXEL for a slot that holds none;
 *   y: the first sample index of its run (relative to sample_start);
 *   z: the end of its run (the run is samples y to z - 1);
 *   w: the round (never 0): a slot whose state's counters.w differs holds another round's
 *      run, and the pass starts the slot's run from no path and sums of zero.
 * The slot's samples_started counts from its run's first sample. The parameter
 * compact_pixels is nonzero while a pass traces the compact textures. */
#define TRACER_PIXEL_MAP_UNIT 10
#define TRACER_PIXEL_MAP_SHIFT 16
#define TRACER_NO_PIXEL 4294967295u

/* The GLSL uniform block's member of parameter NAME is TRACER_BLOCK_MEMBER(NAME); the
 * tracer reads a copy of it called NAME (glsl/parameters.glsl says why), and C asks the GL
 * for the member by this name (core/gpu_test_programs.c). */
#define TRACER_BLOCK_MEMBER(name) block_##name

/* ---- the parameter block. Vectors are world space; pixels count from the top left. */
#define TRACER_PARAMETERS(P) \
    P(ivec2, image_size)             /* the region rendered: the whole image or a crop */ \
    P(ivec2, region_origin)          /* its top-left pixel in the full image */ \
    P(ivec2, full_size)              /* the full image: camera and random numbers use its pixels */ \
    P(vec3, camera_origin) \
    P(float, lens_radius) \
    P(vec3, camera_lower_left)       /* point on the focus plane at the image's bottom left */ \
    P(vec3, camera_horizontal)       /* focus-plane vector across the image width */ \
    P(vec3, camera_vertical)         /* focus-plane vector up the image height */ \
    P(vec3, camera_u)                /* lens axes (right, up), unit length */ \
    P(vec3, camera_v) \
    P(float, shutter_open)           /* ray times are uniform in [open, close] */ \
    P(float, shutter_close) \
    P(uint, camera_media)            /* volumes the camera is in, as a path keeps them */ \
                                     /* (glsl/media.glsl; the packer's packed_media_at) */ \
    P(int, sky_type)                 /* SKY_* */ \
    P(vec3, sky_bottom)              /* gradient: colour straight down; constant: the colour */ \
    P(vec3, sky_top)                 /* gradient: colour straight up */ \
    P(float, sky_intensity)          /* multiplies every kind of sky */ \
    P(float, sky_rotation)           /* box and environment: radians about +Y */ \
    P(uvec2, sky_faces_x)            /* box: image indices of the +X and -X faces */ \
    P(uvec2, sky_faces_y)            /* +Y, -Y */ \
    P(uvec2, sky_faces_z)            /* +Z, -Z */ \
    P(uint, sky_environment)         /* environment: image index */ \
    P(uint, seed)                    /* the random seed */ \
    P(int, sampler)                  /* SAMPLER_* */ \
    P(uint, sample_start)            /* first sample index (sample ranges) */ \
    P(uint, samples_per_pixel) \
    P(uint, max_depth)               /* at most this many path segments per sample */ \
    P(uint, russian_roulette_depth)  /* paths may end at random after this many segments */ \
    P(int, integrator)               /* INTEGRATOR_* */ \
    P(int, light_sampling)           /* 0: BSDF sampling only (to compare the estimators) */ \
    P(vec3, ambient)                 /* Whitted: ambient light */ \
    P(uint, light_group_count)       /* layers of light groups collected (0: none) */ \
    P(uint, sky_light_group)         /* the sky's (and Whitted's ambient's) light group */ \
    P(uint, direct_emission)         /* nonzero: sum the emission camera rays see at once */ \
                                     /* (glsl/direct_emission.glsl) */ \
    P(int, pass_work_budget)         /* work units a pixel may start in one pass (core/gpu_tracer.c */ \
                                     /* clamps it to what the device allows) */ \
    P(int, work_cap)                 /* no invocation does more (core/gpu_tracer.c, from the device) */ \
    P(int, aov_samples)              /* the AOV pass: jittered camera rays per pixel */ \
    P(uint, compact_pixels)          /* nonzero: the pass traces the compact state (above) */

#endif
