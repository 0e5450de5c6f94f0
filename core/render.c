/* render.c: see render.h. Plain C: the GL work is the GPU module's (core/gpu.c, gpu_tracer.c). */
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "adaptive.h"
#include "camera.h"
#include "clock.h"
#include "hash.h"
#include "large_pages.h"
#include "luminance.h"
#include "pack.h"
#include "packed_traverse.h"
#include "render_internal.h"

#define DEFAULT_RUSSIAN_ROULETTE_DEPTH 4

render_options render_options_defaults(void)
{
    return (render_options){0};
}

/* Whether the tracer keeps the sums of squares in its state (else gpu.h GPU_OMIT_SQUARES):
 * for the variance layers, or in the whole tracer. */
static bool keeps_squares(const render_options *options)
{
    return options->variance || options->full_tracer;
}

uint64_t render_bytes_per_pixel(const render_options *options, int light_group_count)
{
    /* Read-back: the rgba sums and the statistics, 2 x 16 more where GL's bottom-up copies
     * of them were until read-backs flipped rows in place (2026-12-03): kept as headroom,
     * so that tiles, and the peaks measured with them (docs/performance.md), stay as they
     * were; the result's four channels and the copy a region's crop makes. The other GL
     * copies below are gone the same way and kept the same way. */
    uint64_t bytes = GPU_TRACER_STATE_BYTES_PER_PIXEL + 4 * 16 + 2 * 16;
    if (!keeps_squares(options))
        bytes -= GPU_TRACER_SQUARES_BYTES_PER_PIXEL;
    if (options->aovs)           /* two AOV textures, their read-back, the 8-channel image twice */
        bytes += 2 * 16 + 2 * 16 + 16 + 2 * 32 + 4;
    if (options->variance)       /* the squares and GL's copy, the 3 layers, joined to the AOVs */
        bytes += 2 * 16 + 12 + 44;
    if (options->direct_emission)   /* the sums on the device, their read-back and copy, 3 channels twice */
        bytes += 16 + 2 * 16 + 2 * 12;
    if (options->light_groups)   /* per group: the layer on the device, its read-back and copy, 3 channels twice */
        bytes += (uint64_t)light_group_count * (16 + 2 * 16 + 2 * 12);
    if (options->noise_threshold > 0)   /* the checks' read-back, limits, the sampler's arrays; */
        bytes += 16 + 4 + 4 + 16        /* compacted passes (core/gpu_compact.c): the host's sums, */
                 + 3 * 16 + 4 + 4 + 2 * 16    /* started, limits, the pixel map on the device and */
                 + 2 * 4 * RENDER_ADAPTIVE_STATE_CHANNELS;   /* the host; at a stop the state
                                                              * layer and its copy joined to the
                                                              * AOVs (render_job.c) */
    return bytes;
}

const char *render_stop_reason_name(render_stop_reason reason)
{
    switch (reason) {
    case RENDER_STOP_NOISE: return "noise";
    case RENDER_STOP_TIME: return "time";
    case RENDER_STOP_INTERRUPTED: return "interrupted";
    default: return "spp";
    }
}

const char *render_light_choice_name(render_light_choice choice)
{
    switch (choice) {
    case RENDER_LIGHTS_ONE: return "one";
    case RENDER_LIGHTS_ALL: return "all";
    case RENDER_LIGHTS_BY_POINT: return "point";
    case RENDER_LIGHTS_BY_TREE: return "tree";
    case RENDER_LIGHTS_BY_POWER: return "power";
    default: return "none";
    }
}

/* Fills the tracer's parameters from the scene, its camera frame and the options
 * (tracer_interface.h says what each is); core/gpu_tracer.c adds the device's work cap. */
static void tracer_parameters(const scene *s, const camera_frame *frame, const render_options *options,
                              const int region[4], gpu_tracer_parameters *parameters)
{
    memset(parameters, 0, sizeof *parameters);
    tracer_parameter_block *p = &parameters->shader;
    p->region_origin[0] = region[0];
    p->region_origin[1] = region[1];
    p->image_size[0] = region[2] - region[0];
    p->image_size[1] = region[3] - region[1];
    p->full_size[0] = s->render.width;
    p->full_size[1] = s->render.height;
    memcpy(p->camera_origin, frame->origin, sizeof p->camera_origin);
    memcpy(p->camera_lower_left, frame->lower_left, sizeof p->camera_lower_left);
    memcpy(p->camera_horizontal, frame->horizontal, sizeof p->camera_horizontal);
    memcpy(p->camera_vertical, frame->vertical, sizeof p->camera_vertical);
    memcpy(p->camera_u, frame->u, sizeof p->camera_u);
    memcpy(p->camera_v, frame->v, sizeof p->camera_v);
    p->lens_radius = frame->lens_radius;
    p->shutter_open = s->camera.shutter_open;
    p->shutter_close = s->camera.shutter_close;
    p->sky_type = s->sky.type;
    memcpy(p->sky_bottom, s->sky.bottom, sizeof p->sky_bottom);
    memcpy(p->sky_top, s->sky.top, sizeof p->sky_top);
    p->sky_intensity = s->sky.intensity;
    p->sky_rotation = s->sky.rotation_degrees * 3.14159265358979f / 180.0f;
    uint32_t *faces[SKY_FACE_COUNT] = {&p->sky_faces_x[0], &p->sky_faces_x[1], &p->sky_faces_y[0],
                                       &p->sky_faces_y[1], &p->sky_faces_z[0], &p->sky_faces_z[1]};
    for (int face = 0; face < SKY_FACE_COUNT; face++)
        *faces[face] = s->sky.faces[face] >= 0 ? (uint32_t)s->sky.faces[face] : 0;
    p->sky_environment = s->sky.environment >= 0 ? (uint32_t)s->sky.environment : 0;
    p->seed = s->render.seed;
    p->sampler = options->sampler;
    p->sample_start = options->sample_start;
    p->samples_per_pixel = (uint32_t)s->render.samples_per_pixel;
    p->max_depth = (uint32_t)s->render.max_depth;
    p->russian_roulette_depth = options->russian_roulette_depth ? options->russian_roulette_depth
                                                                : DEFAULT_RUSSIAN_ROULETTE_DEPTH;
    p->integrator = options->integrator;
    p->light_sampling = !options->no_light_sampling;
    memcpy(p->ambient, s->ambient, sizeof p->ambient);
    p->light_group_count = options->light_groups ? (uint32_t)s->light_group_count : 0;
    p->sky_light_group = (uint32_t)s->sky.light_group;
    p->direct_emission = options->direct_emission;
    p->pass_work_budget = (int32_t)(options->pass_work_budget ? options->pass_work_budget : INITIAL_ADAPTIVE_BUDGET);
}

/* Returns the GPU_OMIT_* bits of the tracer code this render cannot reach (gpu.h), and
 * GPU_FIX_UNIFORMS, from what the packed scene holds (pack.h, pack_summary): no light
 * sampling in path tracing without lights (or with it switched off), no volumes when there
 * is none and the camera is in none, no textures when there is none and no material has a
 * normal map; primitive types, emitters, the pbr material, alpha masks and vertex colours
 * as the packed records (every BVH level) hold them; light and material kinds as the light
 * and material sections hold them; the stack's walk where the packer wrote the threaded
 * one and no alpha mask needs the stack's walk's test. The --full-tracer option asks for
 * 0: everything, read from uniforms. */
static uint32_t omitted_features(const packed_scene *packed, const render_options *options, uint32_t camera_media)
{
    if (options->full_tracer)
        return 0;
    const pack_summary *contents = &packed->summary;
    uint32_t omitted = GPU_FIX_UNIFORMS;
    if (options->integrator == 0 && (packed->light_count == 0 || options->no_light_sampling))
        omitted |= GPU_OMIT_DIRECT_LIGHT;
    if (!contents->volumes && camera_media == 0)
        omitted |= GPU_OMIT_VOLUMES;
    if (!contents->textures && !contents->normal_maps)
        omitted |= GPU_OMIT_TEXTURES;
    uint32_t types = contents->primitive_types;
    if (!(types & (1u << PRIMITIVE_SPHERE | 1u << PRIMITIVE_MOVING_SPHERE)))
        omitted |= GPU_OMIT_SPHERES;
    if (!(types & 1u << PRIMITIVE_MOVING_SPHERE))
        omitted |= GPU_OMIT_MOVING_SPHERES;
    if (!(types & 1u << PRIMITIVE_TRIANGLE))
        omitted |= GPU_OMIT_TRIANGLES;
    if (!(types & 1u << PRIMITIVE_QUAD))
        omitted |= GPU_OMIT_QUADS;
    if (!(types & 1u << PRIMITIVE_INSTANCE))
        omitted |= GPU_OMIT_INSTANCES;
    if (!contents->emitters)
        omitted |= GPU_OMIT_EMITTERS;
    if (packed->light_count <= 1 || packed->light_count > LIGHT_LOCAL_CHOICE_MAX)
        omitted |= GPU_OMIT_LIGHT_CHOICE;
    if (!(contents->light_types & 1u << LIGHT_QUAD))
        omitted |= GPU_OMIT_RECTANGLE_LIGHTS;
    if (!contents->pbr)
        omitted |= GPU_OMIT_PBR;
    if (!contents->alpha_mask)
        omitted |= GPU_OMIT_ALPHA_MASK;
    if (!contents->vertex_colors)
        omitted |= GPU_OMIT_VERTEX_COLORS;
    if (!options->light_groups)
        omitted |= GPU_OMIT_LIGHT_GROUPS;
    if (!options->direct_emission)
        omitted |= GPU_OMIT_DIRECT_EMISSION;
    if (!keeps_squares(options))
        omitted |= GPU_OMIT_SQUARES;
    if (packed->threaded_items > 0 && !contents->alpha_mask)
        omitted |= GPU_OMIT_STACK_WALK;
    uint32_t lights = contents->light_types;
    if (!(lights & 1u << LIGHT_SPHERE))
        omitted |= GPU_OMIT_SPHERE_LIGHTS;
    if (!(lights & 1u << LIGHT_TRIANGLE))
        omitted |= GPU_OMIT_TRIANGLE_LIGHTS;
    if (!(lights & (1u << LIGHT_POINT | 1u << LIGHT_SPOT | 1u << LIGHT_SUN)))
        omitted |= GPU_OMIT_DELTA_LIGHTS;
    if (!(lights & 1u << LIGHT_ENVIRONMENT))
        omitted |= GPU_OMIT_ENVIRONMENT_LIGHT;
    if (packed->light_count <= 1)
        omitted |= GPU_OMIT_MANY_LIGHTS;
    if (packed->light_tree_offset == PACKED_NONE || (omitted & GPU_OMIT_DIRECT_LIGHT) || options->no_light_tree)
        omitted |= GPU_OMIT_LIGHT_TREE;
    uint32_t materials = contents->material_types;
    if (!(materials & 1u << MATERIAL_LAMBERTIAN))
        omitted |= GPU_OMIT_LAMBERTIAN;
    if (!(materials & 1u << MATERIAL_METAL))
        omitted |= GPU_OMIT_METAL;
    if (!(materials & 1u << MATERIAL_DIELECTRIC))
        omitted |= GPU_OMIT_DIELECTRIC;
    return omitted;
}

/* Returns how the tracer picks the light it samples at a point (render.h
 * render_light_choice), as glsl/direct_light.glsl and glsl/lights.glsl decide it. */
static render_light_choice light_choice_of(const packed_scene *packed, const render_options *options)
{
    uint32_t lights = packed->light_count;
    bool whitted = options->integrator == INTEGRATOR_WHITTED;
    if (lights == 0 || (!whitted && options->no_light_sampling))
        return RENDER_LIGHTS_NONE;
    if (lights == 1)
        return RENDER_LIGHTS_ONE;
    if (whitted && lights <= LIGHT_WHITTED_ALL_MAX)
        return RENDER_LIGHTS_ALL;
    if (packed->light_tree_offset != PACKED_NONE && !options->no_light_tree)
        return RENDER_LIGHTS_BY_TREE;
    if (!whitted && lights <= LIGHT_LOCAL_CHOICE_MAX)
        return RENDER_LIGHTS_BY_POINT;
    return RENDER_LIGHTS_BY_POWER;
}

/* Returns the scene hash (render.h, render_result): the packed scene's texel hash carried
 * on (FNV-1a runs on from any state, so this is the hash of the texels followed by the
 * rest) over the camera frame, the sky, the shutter, the ambient light, the full size, the
 * depth and the options that change the image. */
static uint64_t scene_hash(const scene *s, const packed_scene *packed, const camera_frame *frame,
                           const render_options *options)
{
    uint64_t hash = packed->texel_hash;
    hash = hash_bytes(hash, frame, sizeof *frame);
    hash = hash_bytes(hash, &s->sky.type, sizeof s->sky.type);
    hash = hash_bytes(hash, s->sky.bottom, sizeof s->sky.bottom);
    hash = hash_bytes(hash, s->sky.top, sizeof s->sky.top);
    hash = hash_bytes(hash, &s->sky.intensity, sizeof s->sky.intensity);
    hash = hash_bytes(hash, &s->sky.rotation_degrees, sizeof s->sky.rotation_degrees);
    hash = hash_bytes(hash, &s->camera.shutter_open, sizeof s->camera.shutter_open);
    hash = hash_bytes(hash, &s->camera.shutter_close, sizeof s->camera.shutter_close);
    hash = hash_bytes(hash, s->ambient, sizeof s->ambient);
    int shape[6] = {s->render.width, s->render.height, s->render.max_depth, options->no_light_sampling,
                    (int)options->integrator, options->sampler};
    return hash_bytes(hash, shape, sizeof shape);
}

rt_status render_scene_hash(const scene *s, const render_options *options, uint64_t *hash, rt_error *error)
{
    render_options defaults = render_options_defaults();
    camera_frame frame;
    rt_status status = camera_frame_compute(&s->camera, s->render.width, s->render.height, &frame, error);
    packed_scene packed;
    if (status == RT_OK)
        status = pack_scene(s, NULL, &packed, error);
    if (status != RT_OK)
        return status;
    *hash = scene_hash(s, &packed, &frame, options != NULL ? options : &defaults);
    packed_scene_free(&packed);
    return RT_OK;
}

/* The accumulation read back as means (render_internal.h). */
rt_status render_read_image(gpu_tracer *tracer, int width, int height, rt_image *image, float *luminance_squares,
                            gpu_tracer_totals *totals, uint64_t *samples, rt_error *error)
{
    /* RTSPHERES_TEST_HOST_FAILURE=memory: the failure a huge image's read-back meets. */
    const char *forced = getenv("RTSPHERES_TEST_HOST_FAILURE");
    rt_status status = forced != NULL && strcmp(forced, "memory") == 0
                           ? RT_ERROR_RUNTIME
                           : image_create(image, width, height, 4, error);
    if (status != RT_OK)
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "RENDER: out of memory reading back a %dx%d image (%.1f MiB and as much again for GL's "
                            "copy): give a smaller --memory-budget, which renders the image in smaller tiles",
                            width, height, (double)width * height * 16 / (1024.0 * 1024.0));
    status = gpu_tracer_read(tracer, image->pixels, luminance_squares, totals, error);
    if (status != RT_OK) {
        image_free(image);
        return status;
    }
    /* Sums to means; the count stays in the fourth channel. */
    float *pixels = image->pixels;
    size_t pixel_count = (size_t)width * height;
    *samples = 0;
    for (size_t i = 0; i < pixel_count; i++) {
        float count = pixels[4 * i + 3];
        *samples += (uint64_t)count;
        for (int c = 0; c < 3; c++)
            pixels[4 * i + c] = count > 0 ? pixels[4 * i + c] / count : 0.0f;
    }
    snprintf(image->channel_names[3], IMAGE_CHANNEL_NAME_MAX, "samples");
    return RT_OK;
}

/* Reads the light group layers into a new image of the colour's size: NAME.R/G/B per group
 * of s, each the group's sum over a pixel's finished samples divided by their count (the
 * fourth channel of colour), as render_read_image makes the beauty's means. The caller frees
 * groups. */
static rt_status read_light_groups(gpu_tracer *tracer, const scene *s, const rt_image *colour, rt_image *groups,
                                   rt_error *error)
{
    int width = colour->width, height = colour->height, count = s->light_group_count;
    size_t pixel_count = (size_t)width * height;
    float *layers = large_pages_alloc(pixel_count * 4 * (size_t)count * sizeof(float));
    if (layers == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory for the light groups");
    rt_status status = gpu_tracer_read_light_groups(tracer, layers, error);
    if (status == RT_OK)
        status = image_create(groups, width, height, 3 * count, error);
    if (status != RT_OK) {
        free(layers);
        return status;
    }
    static const char channels[3] = {'R', 'G', 'B'};
    for (int g = 0; g < count; g++) {
        for (int c = 0; c < 3; c++)
            snprintf(groups->channel_names[3 * g + c], IMAGE_CHANNEL_NAME_MAX, "%s.%c", s->light_groups[g],
                     channels[c]);
        const float *layer = layers + (size_t)g * pixel_count * 4;
        for (size_t i = 0; i < pixel_count; i++) {
            float samples = colour->pixels[4 * i + 3];
            for (int c = 0; c < 3; c++)
                groups->pixels[i * 3 * (size_t)count + 3 * (size_t)g + c] = samples > 0 ? layer[4 * i + c] / samples
                                                                                        : 0.0f;
        }
    }
    free(layers);
    return RT_OK;
}

#define AOV_SAMPLES 8

/* Builds the AOV image: albedo, normal and depth of the first hit (averaged over
 * AOV_SAMPLES camera rays) and each pixel's sample variance of luminance
 * (E[L^2] - E[L]^2 over its finished samples). The caller frees aovs. */
static rt_status render_aovs(gpu_tracer *tracer, int width, int height, const rt_image *colour,
                             const float *luminance_squares, rt_image *aovs, rt_error *error)
{
    size_t pixel_count = (size_t)width * height;
    float *albedo_depth = large_pages_alloc(pixel_count * 4 * sizeof(float));
    float *normal = large_pages_alloc(pixel_count * 4 * sizeof(float));
    rt_status status = albedo_depth && normal ? RT_OK : rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory");
    if (status == RT_OK)
        status = gpu_tracer_render_aovs(tracer, AOV_SAMPLES, albedo_depth, normal, error);
    if (status == RT_OK)
        status = image_create(aovs, width, height, 8, error);
    if (status == RT_OK) {
        static const char *const names[8] = {"albedo.R", "albedo.G", "albedo.B", "normal.X",
                                             "normal.Y", "normal.Z", "depth.Z", "variance.Y"};
        for (int c = 0; c < 8; c++)
            snprintf(aovs->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
        for (size_t i = 0; i < pixel_count; i++) {
            float *out = aovs->pixels + 8 * i;
            for (int c = 0; c < 3; c++) {
                out[c] = albedo_depth[4 * i + c];
                out[3 + c] = normal[4 * i + c];
            }
            out[6] = albedo_depth[4 * i + 3];
            const float *pixel = colour->pixels + 4 * i;
            float count = pixel[3];
            float mean = luminance_float(pixel[0], pixel[1], pixel[2]);
            out[7] = count > 0 ? fmaxf(0.0f, luminance_squares[i] / count - mean * mean) : 0.0f;
        }
    }
    free(albedo_depth);
    free(normal);
    return status;
}

/* Appends the channels of layers to result->aovs (or makes them the AOVs when there are
 * none yet); layers is consumed either way. */
static rt_status append_to_aovs(render_result *result, rt_image *layers, rt_error *error)
{
    if (result->aovs.pixels == NULL) {
        result->aovs = *layers;
        *layers = (rt_image){0};
        return RT_OK;
    }
    rt_image joined;
    rt_status status = image_append_channels(&result->aovs, layers, &joined, error);
    if (status == RT_OK) {
        image_free(&result->aovs);
        result->aovs = joined;
    }
    image_free(layers);
    return status;
}

/* Builds the variance layers variance.R/G/B: each pixel's sample variance of each colour
 * channel, E[c^2] - E[c]^2 over its finished samples (as variance.Y is of luminance), from
 * the means in colour and the tracer's sums of squares (width*height*4). Float rounding
 * can make a constant pixel's difference slightly negative: it is 0 then. The caller
 * frees layers. */
static rt_status variance_layers(int width, int height, const rt_image *colour, const float *squares,
                                 rt_image *layers, rt_error *error)
{
    rt_status status = image_create(layers, width, height, 3, error);
    if (status != RT_OK)
        return status;
    static const char *const names[3] = {"variance.R", "variance.G", "variance.B"};
    for (int c = 0; c < 3; c++)
        snprintf(layers->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
    size_t pixel_count = (size_t)width * height;
    for (size_t i = 0; i < pixel_count; i++) {
        const float *pixel = colour->pixels + 4 * i;
        float count = pixel[3];
        for (int c = 0; c < 3; c++)
            layers->pixels[3 * i + c] =
                count > 0 ? fmaxf(0.0f, squares[4 * i + c] / count - pixel[c] * pixel[c]) : 0.0f;
    }
    return RT_OK;
}

/* Reads the tracer's sums of squares and adds the variance layers to result->aovs (after
 * the AOVs when there are any). */
static rt_status add_variance_layers(gpu_tracer *tracer, int width, int height, render_result *result,
                                     rt_error *error)
{
    float *squares = large_pages_alloc((size_t)width * height * 4 * sizeof *squares);
    if (squares == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory");
    rt_image layers = {0};
    rt_status status = gpu_tracer_read_squares(tracer, squares, error);
    if (status == RT_OK)
        status = variance_layers(width, height, &result->image, squares, &layers, error);
    free(squares);
    if (status == RT_OK)
        status = append_to_aovs(result, &layers, error);
    return status;
}

/* Appends emission.R/G/B to result->aovs (render_result): the tracer's direct emission sums
 * over each pixel's finished samples divided by their count, as the beauty's means are. */
static rt_status add_direct_emission_layer(gpu_tracer *tracer, int width, int height, render_result *result,
                                           rt_error *error)
{
    size_t pixel_count = (size_t)width * height;
    float *sums = large_pages_alloc(pixel_count * 4 * sizeof *sums);
    if (sums == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory");
    rt_image layer = {0};
    rt_status status = gpu_tracer_read_direct_emission(tracer, sums, error);
    if (status == RT_OK)
        status = image_create(&layer, width, height, 3, error);
    if (status == RT_OK) {
        static const char *const names[3] = {"emission.R", "emission.G", "emission.B"};
        for (int c = 0; c < 3; c++)
            snprintf(layer.channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
        for (size_t i = 0; i < pixel_count; i++) {
            float samples = result->image.pixels[4 * i + 3];
            for (int c = 0; c < 3; c++)
                layer.pixels[3 * i + c] = samples > 0 ? sums[4 * i + c] / samples : 0.0f;
        }
    }
    free(sums);
    if (status == RT_OK)
        status = append_to_aovs(result, &layer, error);
    return status;
}

void render_resume_free(render_resume *resume)
{
    free(resume->sums);
    free(resume->luminance_squares);
    free(resume->limits);
    free(resume->samples);
    memset(resume, 0, sizeof *resume);
}

bool render_partial_has_adaptive_state(const rt_image *partial)
{
    static const char *const names[RENDER_ADAPTIVE_STATE_CHANNELS] = RENDER_ADAPTIVE_STATE_CHANNEL_NAMES;
    for (int i = 0; i < RENDER_ADAPTIVE_STATE_CHANNELS; i++)
        if (image_channel_index(partial, names[i]) < 0)
            return false;
    return true;
}

/* Checks that count is a pixel's sample count of a render of samples_per_pixel. */
static rt_status check_count(float count, const char *what, size_t pixel, uint32_t samples_per_pixel,
                             rt_error *error)
{
    if (count >= 0 && count <= (float)samples_per_pixel && count == floorf(count))
        return RT_OK;
    return rt_error_set(error, RT_ERROR_INPUT, "RENDER: the partial render has %g %s at pixel %zu, outside 0..%u",
                        count, what, pixel, samples_per_pixel);
}

/* Turns a partial result (region-sized: R, G, B means and a samples channel, and maybe the
 * adaptive state layer, render.h) into what the render continues from (*resume; the caller
 * frees it with render_resume_free()): the sums of the state layer when the partial has
 * it (its limits and samples too when adaptive), else means * samples. An adaptive render
 * needs the layer. Nothing to free on failure. */
static rt_status resume_from_partial(const rt_image *partial, int width, int height, uint32_t samples_per_pixel,
                                     bool adaptive, render_resume *resume, rt_error *error)
{
    memset(resume, 0, sizeof *resume);
    int samples_channel = image_channel_index(partial, "samples");
    if (partial->width != width || partial->height != height || partial->channels < 4 || samples_channel < 0)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "RENDER: the partial render is %dx%d with %d channels; resuming needs %dx%d with R, G, B "
                            "and samples", partial->width, partial->height, partial->channels, width, height);
    static const char *const state_names[RENDER_ADAPTIVE_STATE_CHANNELS] = RENDER_ADAPTIVE_STATE_CHANNEL_NAMES;
    int state[RENDER_ADAPTIVE_STATE_CHANNELS], found = 0;
    for (int i = 0; i < RENDER_ADAPTIVE_STATE_CHANNELS; i++)
        found += (state[i] = image_channel_index(partial, state_names[i])) >= 0;
    if (found != 0 && found != RENDER_ADAPTIVE_STATE_CHANNELS)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "RENDER: the partial render has %d of the %d channels of the adaptive state (%s ... %s)",
                            found, RENDER_ADAPTIVE_STATE_CHANNELS, state_names[0],
                            state_names[RENDER_ADAPTIVE_STATE_CHANNELS - 1]);
    bool has_state = found == RENDER_ADAPTIVE_STATE_CHANNELS;
    if (adaptive && !has_state)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "RENDER: an adaptive render (noise threshold) resumes from the adaptive state a partial "
                            "file of one keeps (%s, ...), and this partial has none: it was rendered without "
                            "--noise-threshold, or by an rtspheres from before that layer; resume it without "
                            "--noise-threshold, or render afresh", state_names[0]);
    size_t pixels = (size_t)width * height;
    resume->sums = large_pages_alloc(pixels * 4 * sizeof(float));
    if (has_state) {
        resume->luminance_squares = large_pages_alloc(pixels * sizeof(float));
        if (adaptive) {
            resume->limits = large_pages_alloc(pixels * sizeof(uint32_t));
            resume->samples = large_pages_alloc(pixels * sizeof(uint32_t));
        }
    }
    if (resume->sums == NULL || (has_state && resume->luminance_squares == NULL)
        || (has_state && adaptive && (resume->limits == NULL || resume->samples == NULL))) {
        render_resume_free(resume);
        return rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory");
    }
    for (size_t i = 0; i < pixels; i++) {
        const float *pixel = partial->pixels + i * partial->channels;
        float count = has_state ? pixel[state[3]] : pixel[samples_channel];
        rt_status status = check_count(count, "samples", i, samples_per_pixel, error);
        if (status == RT_OK && has_state)
            status = check_count(pixel[state[5]], "as its adaptive limit", i, samples_per_pixel, error);
        if (status != RT_OK) {
            render_resume_free(resume);
            return status;
        }
        for (int c = 0; c < 3; c++)
            resume->sums[i * 4 + c] = has_state ? pixel[state[c]] : pixel[c] * count;
        resume->sums[i * 4 + 3] = count;
        resume->samples_total += (uint64_t)count;
        if (has_state)
            resume->luminance_squares[i] = pixel[state[4]];
        if (resume->limits != NULL) {
            resume->limits[i] = (uint32_t)pixel[state[5]];
            resume->samples[i] = (uint32_t)count;
        }
    }
    return RT_OK;
}

/* The part of render_scene before the passes: checks the region, frames the camera,
 * packs the scene (its figures go into *result, with the region and the scene hash),
 * checks the resumed partial against the hash and creates the tracer (*tracer, which the
 * caller destroys) with the partial's sums. *region is the region of the result, *traced
 * the region the tracer renders (region, and with adaptive sampling the pixels around it
 * whose decisions reach into it), *resume what the partial brought (the caller frees it
 * with render_resume_free()) and *pass_work_budget the first pass's budget. On failure
 * nothing is left to free. */
static rt_status set_up_tracer(gpu_context *context, const scene *s, const render_options *options,
                               render_result *result, int region[4], int traced[4], render_resume *resume,
                               gpu_tracer **tracer, uint32_t *pass_work_budget, rt_error *error)
{
    region[0] = 0;
    region[1] = 0;
    region[2] = s->render.width;
    region[3] = s->render.height;
    if (options->region[0] || options->region[1] || options->region[2] || options->region[3]) {
        const int *r = options->region;
        if (r[0] < 0 || r[1] < 0 || r[2] > s->render.width || r[3] > s->render.height || r[0] >= r[2] || r[1] >= r[3])
            return rt_error_set(error, RT_ERROR_INPUT,
                                "RENDER: region %d,%d,%d,%d is not a non-empty part of the %dx%d image", r[0], r[1],
                                r[2], r[3], s->render.width, s->render.height);
        memcpy(region, r, 4 * sizeof *region);
    }
    memcpy(result->region, region, sizeof result->region);
    memset(resume, 0, sizeof *resume);
    /* Adaptive decisions reach adaptive_reach() pixels: the tracer renders that much around
     * the region, so that the region's pixels are the full render's (render.h). */
    memcpy(traced, region, 4 * sizeof *traced);
    if (options->noise_threshold > 0) {
        int reach = adaptive_reach(options->min_spp ? options->min_spp : ADAPTIVE_DEFAULT_MIN_SPP,
                                   (uint32_t)s->render.samples_per_pixel);
        traced[0] = region[0] - reach > 0 ? region[0] - reach : 0;
        traced[1] = region[1] - reach > 0 ? region[1] - reach : 0;
        traced[2] = region[2] + reach < s->render.width ? region[2] + reach : s->render.width;
        traced[3] = region[3] + reach < s->render.height ? region[3] + reach : s->render.height;
        if (options->resume != NULL && memcmp(traced, region, sizeof *traced * 4) != 0)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "RENDER: an adaptive render of part of the image (--crop, --tile, --shard-by tiles) "
                                "cannot resume: its decisions reach %d pixels past the part, whose state a partial "
                                "file does not hold; render the part afresh",
                                reach);
    }
    /* A partial file keeps no light groups (and its paths in flight are traced again). */
    if (options->light_groups && options->resume != NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "RENDER: light groups cannot be resumed from a partial render");
    if (options->direct_emission && options->resume != NULL)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "RENDER: direct emission sums cannot be resumed from a partial render");
    int width = region[2] - region[0], height = region[3] - region[1];

    camera_frame frame;
    rt_status status = camera_frame_compute(&s->camera, s->render.width, s->render.height, &frame, error);
    if (status != RT_OK)
        return status;
    packed_scene packed;
    double pack_start = clock_seconds();
    pack_options pack = pack_options_defaults();
    pack.bvh_cache = options->bvh_cache;
    status = pack_scene(s, &pack, &packed, error);
    if (status != RT_OK)
        return status;
    result->pack_seconds = clock_seconds() - pack_start;
    result->bvh_built = packed.bvh_built;
    result->bvh_reused = packed.bvh_reused;
    result->bvh_depth = packed.bvh_depth;
    result->bvh_build_seconds = packed.bvh_build_seconds;
    result->packed_bytes = (uint64_t)packed.texel_count * 16u;
    for (int i = 0; i < s->image_count; i++)
        result->image_bytes += (uint64_t)s->images[i].width * s->images[i].height * 16u;
    result->triangle_count = packed.triangle_count;
    result->primitive_count = packed.primitive_count;
    result->instance_count = packed.instance_count;
    result->light_count = packed.light_count;
    result->light_choice = light_choice_of(&packed, options);
    result->light_tree_depth = result->light_choice == RENDER_LIGHTS_BY_TREE ? packed.light_tree_depth : 0;
    uint64_t hash = scene_hash(s, &packed, &frame, options);
    result->scene_hash = hash;
    if (options->resume != NULL && options->resume_scene_hash != 0 && options->resume_scene_hash != hash) {
        packed_scene_free(&packed);
        return rt_error_set(error, RT_ERROR_INPUT,
                            "RENDER: the partial render was made from another scene, camera, size or depth, "
                            "or by an rtspheres that packs scenes another way (scene hash %016llx, this "
                            "render %016llx)",
                            (unsigned long long)options->resume_scene_hash, (unsigned long long)hash);
    }

    gpu_tracer_parameters parameters;
    tracer_parameters(s, &frame, options, traced, &parameters);
    parameters.shader.camera_media = packed_media_at(&packed, s->camera.look_from);
    parameters.omitted_features = omitted_features(&packed, options, parameters.shader.camera_media);
    result->threaded_walk = (parameters.omitted_features & GPU_OMIT_STACK_WALK) != 0;
    *pass_work_budget = parameters.shader.pass_work_budget;
    if (options->resume != NULL) {
        status = resume_from_partial(options->resume, width, height, (uint32_t)s->render.samples_per_pixel,
                                     options->noise_threshold > 0, resume, error);
        if (status != RT_OK) {
            packed_scene_free(&packed);
            return status;
        }
        parameters.resume = resume->sums;
        parameters.resume_luminance_squares = resume->luminance_squares;
    }
    status = gpu_tracer_create(context, packed.texels, packed.texel_count, packed.texel_hash, &parameters, tracer,
                               error);
    packed_scene_free(&packed);
    if (status != RT_OK)
        render_resume_free(resume);
    return status;
}

/* The sum of the samples channel (render_internal.h). */
uint64_t render_sample_total(const rt_image *image)
{
    uint64_t total = 0;
    for (size_t i = 0; i < (size_t)image->width * image->height; i++)
        total += (uint64_t)image->pixels[4 * i + 3];
    return total;
}

/* An image cut down to a region, in place (render_internal.h). */
rt_status render_crop_to_region(rt_image *image, const int traced[4], const int region[4], rt_error *error)
{
    if (memcmp(traced, region, 4 * sizeof *traced) == 0 || image->pixels == NULL)
        return RT_OK;
    rt_image cropped;
    rt_status status = image_create(&cropped, region[2] - region[0], region[3] - region[1], image->channels, error);
    if (status != RT_OK)
        return status;
    memcpy(cropped.channel_names, image->channel_names, sizeof cropped.channel_names);
    size_t row_floats = (size_t)cropped.width * image->channels;
    for (int y = 0; y < cropped.height; y++) {
        size_t from = ((size_t)(y + region[1] - traced[1]) * image->width + (region[0] - traced[0])) * image->channels;
        memcpy(cropped.pixels + y * row_floats, image->pixels + from, row_floats * sizeof(float));
    }
    image_free(image);
    *image = cropped;
    return RT_OK;
}





/* The read-back of render_scene: the image (and the AOVs and variance layers asked for) into
 * *result, with the path segments; an error, with nothing allocated, when a path
 * reached the work cap. */
static rt_status read_result(gpu_context *context, gpu_tracer *tracer, const scene *s, const render_options *options,
                             int width, int height, render_result *result, rt_error *error)
{
    gpu_tracer_totals totals = {0};
    float *luminance_squares = NULL;
    rt_status status = RT_OK;
    if (options->aovs) {
        luminance_squares = large_pages_alloc((size_t)width * height * sizeof *luminance_squares);
        if (luminance_squares == NULL)
            status = rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory");
    }
    if (status == RT_OK)
        status = render_read_image(tracer, width, height, &result->image, luminance_squares, &totals, &result->samples,
                                   error);
    if (status == RT_OK && options->aovs)
        status = render_aovs(tracer, width, height, &result->image, luminance_squares, &result->aovs, error);
    if (status == RT_OK && options->variance)
        status = add_variance_layers(tracer, width, height, result, error);
    if (status == RT_OK && options->direct_emission)
        status = add_direct_emission_layer(tracer, width, height, result, error);
    free(luminance_squares);
    if (status == RT_OK && options->light_groups)
        status = read_light_groups(tracer, s, &result->image, &result->light_groups, error);
    if (status != RT_OK) {
        image_free(&result->image);
        image_free(&result->aovs);
        image_free(&result->light_groups);
        return status;
    }
    if (totals.traversal_overflows > 0) {
        gpu_info device;
        gpu_get_info(context, &device);
        image_free(&result->image);
        image_free(&result->aovs);
        image_free(&result->light_groups);
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "RENDER: %.0f paths reached the shader's work cap (%d loop iterations per pass, "
                            "`rtspheres info`) or the traversal stack and were cut short; the image would be "
                            "wrong. The scene's BVH is degenerate (many overlapping primitives, or a huge leaf "
                            "of instances)",
                            totals.traversal_overflows, device.work_cap);
    }
    result->path_segments = totals.path_segments;
    return RT_OK;
}

rt_status render_scene(gpu_context *context, const scene *s, const render_options *options,
                       render_result *result, rt_error *error)
{
    double start = clock_seconds();
    memset(result, 0, sizeof *result);
    render_options defaults = render_options_defaults();
    if (options == NULL)
        options = &defaults;

    int region[4], traced[4];
    render_resume resume;
    uint32_t budget = 0;
    gpu_tracer *tracer = NULL;
    rt_status status = set_up_tracer(context, s, options, result, region, traced, &resume, &tracer, &budget, error);
    if (status != RT_OK)
        return status;
    result->reused_scene = gpu_tracer_reused_scene(tracer);
    result->uploaded_bytes = gpu_tracer_uploaded_bytes(tracer);
    result->compiled_program = gpu_tracer_compiled_program(tracer);
    gpu_tracer_timings timings;
    gpu_tracer_get_timings(tracer, &timings);
    result->compile_seconds = timings.compile_seconds;
    result->upload_seconds = timings.upload_seconds;
    int traced_width = traced[2] - traced[0], traced_height = traced[3] - traced[1];

    render_progress progress = {
        .samples_total = (uint64_t)traced_width * traced_height * s->render.samples_per_pixel,
        .samples_done = resume.samples_total,
        .pixel_count = traced_width * traced_height,
        .noise_threshold = options->noise_threshold,
    };
    render_stop_reason stop = RENDER_STOP_SAMPLES;
    status = render_run_passes(context, tracer, options, (uint32_t)s->render.samples_per_pixel, traced, region,
                               budget, &resume, start, &progress, &stop, result, error);
    render_resume_free(&resume);
    if (status == RT_OK)
        status = read_result(context, tracer, s, options, traced_width, traced_height, result, error);
    gpu_tracer_destroy(tracer);
    if (status == RT_OK && memcmp(traced, region, sizeof traced) != 0) {
        status = render_crop_to_region(&result->image, traced, region, error);
        if (status == RT_OK)
            status = render_crop_to_region(&result->aovs, traced, region, error);
        if (status == RT_OK)
            status = render_crop_to_region(&result->light_groups, traced, region, error);
        if (status == RT_OK)
            result->samples = render_sample_total(&result->image);
        if (status != RT_OK) {
            image_free(&result->image);
            image_free(&result->aovs);
            image_free(&result->light_groups);
        }
    }
    if (status != RT_OK) {
        image_free(&result->adaptive_state);
        return status;
    }

    result->samples_min = UINT32_MAX;
    for (size_t i = 0; i < (size_t)result->image.width * result->image.height; i++) {
        uint32_t count = (uint32_t)result->image.pixels[4 * i + 3];
        result->samples_min = count < result->samples_min ? count : result->samples_min;
        result->samples_max = count > result->samples_max ? count : result->samples_max;
    }
    result->passes = progress.passes;
    result->stop_reason = stop;
    result->seconds = clock_seconds() - start;
    if (stop == RENDER_STOP_INTERRUPTED)
        return rt_error_set(error, RT_ERROR_INTERRUPTED, "RENDER: interrupted after %llu of %llu samples",
                            (unsigned long long)result->samples,
                            (unsigned long long)(region[2] - region[0]) * (region[3] - region[1])
                                * s->render.samples_per_pixel);
    return RT_OK;
}
