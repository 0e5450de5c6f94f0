/* gpu_state.c: a tracer's pass state on the device (gpu_internal.h "core/gpu_state.c"): the
 * two ping-pong sets of state textures with their framebuffers and shared depth buffer, the
 * per-pixel sample limits, the sum layers beside them (light groups, direct emission), a
 * resumed render's sums loaded into them, and the message a device too small for them
 * gets. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu_internal.h"
#include "large_pages.h"

/* The message of a device that could not hold a width x height image's state (bytes of
 * it; what: the failure as the driver put it): the size, and what the user can do. */
static rt_status state_out_of_memory(const gpu_tracer *tracer, const char *what, rt_error *error)
{
    double bytes_per_pixel = GPU_TRACER_STATE_BYTES_PER_PIXEL
                             - GPU_TRACER_SQUARES_BYTES_PER_PIXEL * (TRACER_STATE_COUNT - tracer->state_count);
    double mib = (double)tracer->width * tracer->height * bytes_per_pixel / (1024.0 * 1024.0);
    bool gib = mib >= 1024;
    return rt_error_set(error, RT_ERROR_RUNTIME,
                        "GPU: out of memory for the state of a %dx%d image (%.1f %s on the device; %s): give a "
                        "smaller --memory-budget, which renders the image in smaller tiles",
                        tracer->width, tracer->height, gib ? mib / 1024 : mib, gib ? "GiB" : "MiB", what);
}

GLenum gpu_create_state_set(GLuint textures[TRACER_STATE_COUNT], int count, GLuint *framebuffer, int width,
                            int height)
{
    GLenum draw_buffers[TRACER_STATE_COUNT];
    memset(textures, 0, TRACER_STATE_COUNT * sizeof *textures);
    glGenTextures(count, textures);
    glGenFramebuffers(1, framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, *framebuffer);
    for (int target = 0; target < count; target++) {
        /* Nearest filtering: an integer texture with the default (mipmapped, linear) filter
         * is incomplete, and texelFetch reads zeros from it. */
        glBindTexture(GL_TEXTURE_2D, textures[target]);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexStorage2D(GL_TEXTURE_2D, 1, target == TRACER_STATE_COUNTERS ? GL_RGBA32UI : GL_RGBA32F, width, height);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + target, GL_TEXTURE_2D, textures[target], 0);
        draw_buffers[target] = GL_COLOR_ATTACHMENT0 + target;
    }
    glDrawBuffers(count, draw_buffers);
    return glCheckFramebufferStatus(GL_FRAMEBUFFER);
}

rt_status gpu_state_create(gpu_tracer *tracer, rt_error *error)
{
    int max_size = tracer->context->info.max_tile_side;
    if (tracer->width > max_size || tracer->height > max_size)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "GPU: the image %dx%d is larger than the device's textures and framebuffers (%d pixels "
                            "a side): render it in tiles of at most %d pixels a side",
                            tracer->width, tracer->height, max_size, max_size);
    const gpu_info *info = &tracer->context->info;
    int count = tracer->state_count;
    if (info->max_draw_buffers < count)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: the tracer needs %d draw buffers, the device has %d",
                            count, info->max_draw_buffers);
    if (info->max_fragment_image_units < tracer->image_units
        || info->max_images_and_outputs < tracer->image_units + count)
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "GPU: the tracer needs %d image units beside %d outputs, the device has %d (%d together)",
                            tracer->image_units, count, info->max_fragment_image_units,
                            info->max_images_and_outputs);
    /* The test hook forces the two failures a real device shows only for huge images. */
    const char *forced = getenv("RTSPHERES_TEST_GPU_FAILURE");
    if (forced != NULL && strcmp(forced, "memory") == 0)
        return state_out_of_memory(tracer, "GL_OUT_OF_MEMORY", error);
    for (int set = 0; set < 2; set++) {
        GLenum complete = gpu_create_state_set(tracer->state_textures[set], count, &tracer->framebuffers[set],
                                               tracer->width, tracer->height);
        if (forced != NULL && strcmp(forced, "framebuffer") == 0)
            complete = GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT;
        /* A texture the driver could not allocate leaves its attachment incomplete
         * (llvmpipe for a 12000x12000 image, 2.1 GiB a texture): memory, in the user's words. */
        if (complete != GL_FRAMEBUFFER_COMPLETE) {
            while (glGetError() != GL_NO_ERROR) {
            }
            char what[96];
            snprintf(what, sizeof what, "the driver left the state framebuffer incomplete, status 0x%04x", complete);
            return state_out_of_memory(tracer, what, error);
        }
        const GLfloat zero[4] = {0, 0, 0, 0};
        const GLuint zero_uint[4] = {0, 0, 0, 0};
        for (int target = 0; target < count; target++) {
            if (target == TRACER_STATE_COUNTERS)
                glClearBufferuiv(GL_COLOR, target, zero_uint);
            else
                glClearBufferfv(GL_COLOR, target, zero);
        }
    }
    /* One depth buffer for both sets, all 1: no pixel skipped (gpu_tracer_cull_finished). */
    glGenRenderbuffers(1, &tracer->depth_buffer);
    glBindRenderbuffer(GL_RENDERBUFFER, tracer->depth_buffer);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, tracer->width, tracer->height);
    for (int set = 0; set < 2; set++) {
        glBindFramebuffer(GL_FRAMEBUFFER, tracer->framebuffers[set]);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, tracer->depth_buffer);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            while (glGetError() != GL_NO_ERROR) {
            }
            return state_out_of_memory(tracer, "the driver left the state framebuffer's depth incomplete", error);
        }
    }
    const GLfloat far_depth = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
    /* No limit but samples_per_pixel until gpu_tracer_set_sample_limits says otherwise. */
    glGenTextures(1, &tracer->sample_limits);
    glBindTexture(GL_TEXTURE_2D, tracer->sample_limits);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_R32UI, tracer->width, tracer->height);
    const GLuint no_limit[4] = {UINT32_MAX, 0, 0, 0};
    glClearTexImage(tracer->sample_limits, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, no_limit);
    /* Full passes never read the pixel map, but a texture like it sits on its unit:
     * llvmpipe compiles a variant of the shader for each kind of texture bound to a unit it
     * samples (nothing bound, and a power-of-two side or not, are kinds of their own), so
     * without it the first compacted pass of an adaptive render compiled the tracer a second
     * time: 0.2 to 0.3 s whenever Mesa's shader cache lacks that variant (a new machine, a
     * container without a kept ~/.cache; docs/performance.md). Its sides are 1 or 3 texels,
     * a power of two where the map's (the tracer's) are. */
    glGenTextures(1, &tracer->no_pixel_map);
    glBindTexture(GL_TEXTURE_2D, tracer->no_pixel_map);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    bool power_of_two_width = (tracer->width & (tracer->width - 1)) == 0;
    bool power_of_two_height = (tracer->height & (tracer->height - 1)) == 0;
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32UI, power_of_two_width ? 1 : 3, power_of_two_height ? 1 : 3);
    rt_status status = gpu_check_gl("creating the state textures", error);
    if (status != RT_OK && strstr(error->message, "OUT_OF_MEMORY"))
        return state_out_of_memory(tracer, "GL_OUT_OF_MEMORY", error);
    return status;
}

/* Creates *texture, layers rgba32f layers of the image's size (a 2D array), zeroed, into
 * which passes add sums (loaded before their segment loop, stored after it): the light
 * group layers and the direct emission sums. A single texel when the program has the code but nothing is asked for
 * (the full tracer), so that its image unit is never unbound. what names it in messages. */
static rt_status create_sum_layers(gpu_tracer *tracer, uint32_t layers, GLuint *texture, const char *what,
                                   rt_error *error)
{
    int width = layers > 0 ? tracer->width : 1, height = layers > 0 ? tracer->height : 1;
    glGenTextures(1, texture);
    glBindTexture(GL_TEXTURE_2D_ARRAY, *texture);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA32F, width, height, layers > 0 ? (GLsizei)layers : 1);
    const GLfloat zero[4] = {0, 0, 0, 0};
    glClearTexImage(*texture, 0, GL_RGBA, GL_FLOAT, zero);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    char doing[64];
    snprintf(doing, sizeof doing, "creating the %s", what);
    rt_status status = gpu_check_gl(doing, error);
    if (status != RT_OK && strstr(error->message, "OUT_OF_MEMORY"))
        return rt_error_set(error, RT_ERROR_INPUT, "GPU: not enough memory for the %s (%u of %dx%d, %d MB)", what,
                            layers, width, height, (int)((double)width * height * 16 * layers / 1e6));
    return status;
}

rt_status gpu_state_create_sums(gpu_tracer *tracer, rt_error *error)
{
    uint32_t omitted = tracer->parameters.omitted_features;
    rt_status status = RT_OK;
    if (!(omitted & GPU_OMIT_LIGHT_GROUPS))
        status = create_sum_layers(tracer, tracer->parameters.shader.light_group_count, &tracer->light_group_texture,
                                   "light group layers", error);
    if (status == RT_OK && !(omitted & GPU_OMIT_DIRECT_EMISSION))
        status = create_sum_layers(tracer, tracer->parameters.shader.direct_emission != 0 ? 1 : 0,
                                   &tracer->direct_emission_texture, "direct emission sums", error);
    return status;
}

rt_status gpu_state_load_resume(gpu_tracer *tracer, const float *resume, const float *luminance_squares,
                                rt_error *error)
{
    size_t pixel_count = (size_t)tracer->width * tracer->height;
    float *sums = large_pages_alloc(pixel_count * 4 * sizeof(float));
    uint32_t *counters = large_pages_calloc(pixel_count * 4, sizeof(uint32_t));
    float *statistics = luminance_squares != NULL ? large_pages_calloc(pixel_count * 4, sizeof(float)) : NULL;
    if (sums == NULL || counters == NULL || (luminance_squares != NULL && statistics == NULL)) {
        free(sums);
        free(counters);
        free(statistics);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory loading the partial render");
    }
    size_t row_floats = (size_t)tracer->width * 4;
    for (int row = 0; row < tracer->height; row++) {
        /* Rows top to bottom in memory; GL's row 0 is the bottom. */
        size_t source_row = (size_t)(tracer->height - 1 - row);
        const float *source = resume + source_row * row_floats;
        memcpy(sums + (size_t)row * row_floats, source, row_floats * sizeof(float));
        for (int x = 0; x < tracer->width; x++) {
            size_t pixel = (size_t)row * tracer->width + x;
            counters[pixel * 4] = (uint32_t)source[x * 4 + 3];
            if (statistics != NULL)   /* glsl/path_state.glsl: statistics.z */
                statistics[pixel * 4 + 2] = luminance_squares[source_row * tracer->width + x];
        }
    }
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[0][TRACER_STATE_ACCUMULATED]);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, tracer->width, tracer->height, GL_RGBA, GL_FLOAT, sums);
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[0][TRACER_STATE_COUNTERS]);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, tracer->width, tracer->height, GL_RGBA_INTEGER, GL_UNSIGNED_INT, counters);
    if (statistics != NULL) {
        glBindTexture(GL_TEXTURE_2D, tracer->state_textures[0][TRACER_STATE_STATISTICS]);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, tracer->width, tracer->height, GL_RGBA, GL_FLOAT, statistics);
    }
    free(sums);
    free(counters);
    free(statistics);
    return gpu_check_gl("loading the partial render", error);
}
