/* gpu_tracer.c: the GLSL tracer on a gpu_context (gpu.h, "the tracer"): its program
 * variants (built by core/gpu_program.c) and their cache, the packed scene on the device,
 * the parameter block, the passes over its state (made by core/gpu_state.c) and their
 * read-back. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "gpu_internal.h"
#include "hash.h"
#include "large_pages.h"
#include "shader_sources.h"

/* Builds a program of the shared full-screen vertex shader and the fragment program
 * (SHADER_PROGRAM_*) with defines. Returns the program or 0 with error set. */
static GLuint build_fragment_program(uintptr_t program, const char *defines, rt_error *error)
{
    return gpu_build_program(shader_source_fullscreen_vertex, program, defines, error);
}

/* The context's tracer program for the variant of the parameters (omitted_features,
 * integrator, sky type, sampler), compiled on first use and kept (the oldest goes when the cache
 * is full; a render holding it still has it, since only the next render asks again). */
static rt_status build_program(gpu_tracer *tracer, const gpu_tracer_parameters *parameters, rt_error *error)
{
    gpu_context *context = tracer->context;
    uint32_t omitted = parameters->omitted_features;
    uint64_t key = gpu_variant_key(omitted, &parameters->shader);
    for (int i = 0; i < context->tracer_program_count; i++)
        if (context->tracer_programs[i].key == key) {
            tracer->program = context->tracer_programs[i].program;
            return RT_OK;
        }
    char defines[2048];
    gpu_variant_defines(omitted, &parameters->shader, defines, sizeof defines);
    GLuint program = build_fragment_program(SHADER_PROGRAM_PASS, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    tracer->compiled_program = true;
    int slot = context->tracer_program_count;
    if (slot == GPU_PROGRAM_CACHE_SIZE) {
        slot = context->next_eviction;
        context->next_eviction = (context->next_eviction + 1) % GPU_PROGRAM_CACHE_SIZE;
        glDeleteProgram(context->tracer_programs[slot].program);
    } else {
        context->tracer_program_count++;
    }
    context->tracer_programs[slot].key = key;
    context->tracer_programs[slot].program = program;
    tracer->program = program;
    return RT_OK;
}

void gpu_create_buffer_texture(GLenum format, const void *data, size_t bytes, GLuint *buffer, GLuint *texture)
{
    static const uint32_t empty[4] = {0, 0, 0, 0};
    glGenBuffers(1, buffer);
    glBindBuffer(GL_TEXTURE_BUFFER, *buffer);
    glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)(bytes ? bytes : sizeof empty), bytes ? data : (const void *)empty,
                 GL_STATIC_DRAW);
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
    glGenTextures(1, texture);
    glBindTexture(GL_TEXTURE_BUFFER, *texture);
    glTexBuffer(GL_TEXTURE_BUFFER, format, *buffer);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
}

void gpu_bind_packed_scene(GLuint texture)
{
    glBindImageTexture(TRACER_PACKED_SCENE_IMAGE_UNIT, texture, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32UI);
}

rt_status gpu_check_packed_size(const gpu_context *context, uint32_t texel_count, rt_error *error)
{
    int64_t max_texels = context->info.max_texture_buffer_size;
    if ((int64_t)texel_count > max_texels)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "GPU: the packed scene needs %u texels of 16 bytes, more than this device's "
                            "buffer textures hold (GL_MAX_TEXTURE_BUFFER_SIZE %lld): %lld texels too many",
                            texel_count, (long long)max_texels, (long long)texel_count - (long long)max_texels);
    return RT_OK;
}

/* Uploads the packed scene into a buffer object behind an RGBA32UI buffer texture, checked
 * against GL_MAX_TEXTURE_BUFFER_SIZE; the programs read it as an image of that texture
 * (gpu_bind_packed_scene). A buffer rather than a 2D texture because a read of it is a
 * bounds check and a load: on llvmpipe a 2D texelFetch also looks up each lane's mip level
 * and row pitch, and a texelFetch of any texture is a call (docs/performance.md has what
 * each cost). */
static rt_status upload_packed_scene(gpu_tracer *tracer, const uint32_t *texels, uint32_t texel_count,
                                     rt_error *error)
{
    rt_status status = gpu_check_packed_size(tracer->context, texel_count, error);
    if (status != RT_OK)
        return status;
    gpu_create_buffer_texture(GL_RGBA32UI, texels, (size_t)texel_count * 4 * sizeof(uint32_t), &tracer->packed_buffer,
                          &tracer->packed_texture);
    return gpu_check_gl("uploading the packed scene", error);
}

/* The number of GPU_PACKED_BLOCK_TEXELS blocks of texel_count texels (the last may be short). */
static uint32_t packed_block_count(uint32_t texel_count)
{
    return (uint32_t)(((uint64_t)texel_count + GPU_PACKED_BLOCK_TEXELS - 1) / GPU_PACKED_BLOCK_TEXELS);
}

/* Hashes block b of texel_count texels. */
static uint64_t packed_block_hash(const uint32_t *texels, uint32_t texel_count, uint32_t b, size_t *bytes)
{
    uint64_t first = (uint64_t)b * GPU_PACKED_BLOCK_TEXELS;
    uint64_t count = texel_count - first < GPU_PACKED_BLOCK_TEXELS ? texel_count - first : GPU_PACKED_BLOCK_TEXELS;
    *bytes = (size_t)count * 16u;
    return hash_bytes(HASH_START, texels + 4 * first, *bytes);
}

/* Notes the block hashes of the scene just uploaded on the context (without them, a
 * later scene of the same size is uploaded whole). */
static void note_packed_blocks(gpu_context *context, const uint32_t *texels, uint32_t texel_count)
{
    free(context->packed_block_hashes);
    uint32_t blocks = packed_block_count(texel_count);
    context->packed_block_hashes = malloc(((size_t)blocks + 1) * sizeof *context->packed_block_hashes);
    size_t bytes;
    for (uint32_t b = 0; context->packed_block_hashes != NULL && b < blocks; b++)
        context->packed_block_hashes[b] = packed_block_hash(texels, texel_count, b, &bytes);
}

/* Replaces the context's packed scene, of the same texel count, by texels: only the blocks
 * whose hash changed are uploaded (a sweep row that changes a light or a material, not
 * the geometry, uploads a block or two). Adds the bytes uploaded to tracer->uploaded_bytes. */
static rt_status update_packed_scene(gpu_tracer *tracer, const uint32_t *texels, uint32_t texel_count,
                                     rt_error *error)
{
    gpu_context *context = tracer->context;
    glBindBuffer(GL_TEXTURE_BUFFER, context->packed_buffer);
    for (uint32_t b = 0; b < packed_block_count(texel_count); b++) {
        size_t bytes;
        uint64_t hash = packed_block_hash(texels, texel_count, b, &bytes);
        if (hash == context->packed_block_hashes[b])
            continue;
        size_t offset = (size_t)b * GPU_PACKED_BLOCK_TEXELS * 16u;
        glBufferSubData(GL_TEXTURE_BUFFER, (GLintptr)offset, (GLsizeiptr)bytes, (const char *)texels + offset);
        context->packed_block_hashes[b] = hash;
        tracer->uploaded_bytes += bytes;
    }
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
    return gpu_check_gl("updating the packed scene", error);
}

/* Returns budget within what the device's work bound allows (gpu.h). */
static uint32_t clamp_budget(const gpu_info *info, uint32_t budget)
{
    uint32_t most = (uint32_t)info->max_pass_work_budget;
    return budget < 1 ? 1 : budget > most ? most : budget;
}

/* Uploads the tracer's parameter block: the parameters' block with what the device
 * decides (the work cap, the budget within its bound) and full_size defaulted. */
static void upload_parameters(gpu_tracer *tracer)
{
    const gpu_info *info = &tracer->context->info;
    tracer_parameter_block block = tracer->parameters.shader;
    if (block.full_size[0] == 0 || block.full_size[1] == 0) {
        block.full_size[0] = block.image_size[0];
        block.full_size[1] = block.image_size[1];
    }
    block.pass_work_budget = (int32_t)clamp_budget(info, (uint32_t)block.pass_work_budget);
    block.work_cap = info->work_cap;
    tracer->parameters.shader = block;
    glBindBuffer(GL_UNIFORM_BUFFER, tracer->parameter_buffer);
    glBufferData(GL_UNIFORM_BUFFER, sizeof block, &block, GL_DYNAMIC_DRAW);
    glBindBufferBase(GL_UNIFORM_BUFFER, TRACER_PARAMETER_BINDING, tracer->parameter_buffer);
}

/* Changes one int member of the uploaded parameter block (at offset). */
static void update_parameter(gpu_tracer *tracer, size_t offset, int32_t value)
{
    glBindBuffer(GL_UNIFORM_BUFFER, tracer->parameter_buffer);
    glBufferSubData(GL_UNIFORM_BUFFER, (GLintptr)offset, sizeof value, &value);
}

rt_status gpu_tracer_create(gpu_context *context, const uint32_t *packed_texels, uint32_t texel_count,
                            uint64_t texel_hash, const gpu_tracer_parameters *parameters, gpu_tracer **out,
                            rt_error *error)
{
    *out = NULL;
    gpu_tracer *tracer = calloc(1, sizeof *tracer);
    if (tracer == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory");
    tracer->context = context;
    tracer->width = parameters->shader.image_size[0];
    tracer->height = parameters->shader.image_size[1];
    tracer->state_count = TRACER_STATE_COUNT - ((parameters->omitted_features & GPU_OMIT_SQUARES) != 0);
    tracer->image_units = 1 + !(parameters->omitted_features & GPU_OMIT_LIGHT_GROUPS)
                          + !(parameters->omitted_features & GPU_OMIT_DIRECT_EMISSION);
    double step_start = clock_seconds();
    rt_status status = build_program(tracer, parameters, error);
    tracer->timings.compile_seconds = tracer->compiled_program ? clock_seconds() - step_start : 0;
    step_start = clock_seconds();
    bool same_size = context->packed_texture != 0 && context->packed_texel_count == texel_count;
    if (status == RT_OK && same_size && context->packed_hash == texel_hash) {
        tracer->packed_texture = context->packed_texture;
        tracer->packed_buffer = context->packed_buffer;
        tracer->reused_scene = true;
    } else if (status == RT_OK && same_size && context->packed_block_hashes != NULL) {
        tracer->packed_texture = context->packed_texture;
        tracer->packed_buffer = context->packed_buffer;
        context->packed_hash = 0;
        status = update_packed_scene(tracer, packed_texels, texel_count, error);
        if (status == RT_OK) {
            context->packed_hash = texel_hash;
        } else {
            /* What the buffer holds is unknown now: the next scene goes up whole. */
            free(context->packed_block_hashes);
            context->packed_block_hashes = NULL;
        }
    } else if (status == RT_OK) {
        if (context->packed_texture != 0) {
            glDeleteTextures(1, &context->packed_texture);
            glDeleteBuffers(1, &context->packed_buffer);
            context->packed_texture = 0;
            context->packed_buffer = 0;
        }
        status = upload_packed_scene(tracer, packed_texels, texel_count, error);
        if (status == RT_OK) {
            context->packed_texture = tracer->packed_texture;
            context->packed_buffer = tracer->packed_buffer;
            context->packed_hash = texel_hash;
            context->packed_texel_count = texel_count;
            tracer->uploaded_bytes = (uint64_t)texel_count * 16u;
            note_packed_blocks(context, packed_texels, texel_count);
        }
    }
    if (!tracer->reused_scene)
        tracer->timings.upload_seconds = clock_seconds() - step_start;
    step_start = clock_seconds();
    if (status == RT_OK)
        status = gpu_state_create(tracer, error);
    if (status == RT_OK && parameters->resume != NULL)
        status = gpu_state_load_resume(tracer, parameters->resume, parameters->resume_luminance_squares, error);
    tracer->timings.state_seconds = clock_seconds() - step_start;
    if (status != RT_OK) {
        gpu_tracer_destroy(tracer);
        return status;
    }
    glGenVertexArrays(1, &tracer->vertex_array);
    glGenBuffers(1, &tracer->counter_buffer);
    glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, tracer->counter_buffer);
    glBufferData(GL_ATOMIC_COUNTER_BUFFER, 2 * sizeof(GLuint), NULL, GL_DYNAMIC_READ);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, TRACER_COUNTER_BINDING, tracer->counter_buffer);
    tracer->parameters = *parameters;
    tracer->parameters.resume = NULL;
    tracer->parameters.resume_luminance_squares = NULL;
    glGenBuffers(1, &tracer->parameter_buffer);
    upload_parameters(tracer);
    status = gpu_state_create_sums(tracer, error);
    if (status == RT_OK)
        status = gpu_check_gl("setting up the tracer", error);
    if (status != RT_OK) {
        gpu_tracer_destroy(tracer);
        return status;
    }
    *out = tracer;
    return RT_OK;
}

rt_status gpu_tracer_run_pass(gpu_tracer *tracer, gpu_pass_report *report, rt_error *error)
{
    /* A compacted pass traces the slots of the pixel map (gpu_compact.c), which live in the
     * same state textures. */
    gpu_compact *compact = &tracer->compact;
    bool compacted = compact->count > 0;
    int source = tracer->current, target = 1 - source;
    const GLuint *source_textures = tracer->state_textures[source];
    if (tracer->parameters.shader.compact_pixels != (uint32_t)compacted) {
        tracer->parameters.shader.compact_pixels = compacted;
        update_parameter(tracer, offsetof(tracer_parameter_block, compact_pixels), compacted);
    }
    const GLuint zero[2] = {0, 0};
    glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, tracer->counter_buffer);
    glBufferSubData(GL_ATOMIC_COUNTER_BUFFER, 0, sizeof zero, zero);
    glBindFramebuffer(GL_FRAMEBUFFER, tracer->framebuffers[target]);
    glViewport(0, 0, tracer->width, tracer->height);
    glUseProgram(tracer->program);
    glBindBufferBase(GL_UNIFORM_BUFFER, TRACER_PARAMETER_BINDING, tracer->parameter_buffer);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, TRACER_COUNTER_BINDING, tracer->counter_buffer);
    for (int state = 0; state < tracer->state_count; state++) {
        glActiveTexture(GL_TEXTURE0 + state);
        glBindTexture(GL_TEXTURE_2D, source_textures[state]);
    }
    glActiveTexture(GL_TEXTURE0 + TRACER_PIXEL_MAP_UNIT);
    glBindTexture(GL_TEXTURE_2D, compacted ? compact->pixel_map : tracer->no_pixel_map);
    gpu_bind_packed_scene(tracer->packed_texture);
    glActiveTexture(GL_TEXTURE0 + TRACER_SAMPLE_LIMITS_UNIT);
    glBindTexture(GL_TEXTURE_2D, tracer->sample_limits);
    if (tracer->light_group_texture != 0)
        glBindImageTexture(TRACER_LIGHT_GROUP_IMAGE_UNIT, tracer->light_group_texture, 0, GL_TRUE, 0, GL_READ_WRITE,
                           GL_RGBA32F);
    if (tracer->direct_emission_texture != 0)
        glBindImageTexture(TRACER_DIRECT_EMISSION_IMAGE_UNIT, tracer->direct_emission_texture, 0, GL_FALSE, 0,
                           GL_READ_WRITE, GL_RGBA32F);
    glBindVertexArray(tracer->vertex_array);
    if (compacted)
        gpu_compact_scissor(tracer, true);
    /* Marked pixels (gpu_tracer_cull_finished) fail the depth test before the shader runs. */
    bool cull = tracer->culling && !compacted;
    if (cull) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_FALSE);
    }
    glDrawArrays(GL_TRIANGLES, 0, 3);
    if (cull) {
        glDepthMask(GL_TRUE);
        glDisable(GL_DEPTH_TEST);
    }
    if (compacted)
        gpu_compact_scissor(tracer, false);
    /* Image stores of this pass are read by the next pass and by the read-back. */
    glMemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT
                    | (tracer->light_group_texture != 0 || tracer->direct_emission_texture != 0
                           ? GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT : 0));
    GLuint counters[2] = {0, 0};
    glGetBufferSubData(GL_ATOMIC_COUNTER_BUFFER, 0, sizeof counters, counters);
    tracer->current = target;
    tracer->passes++;
    report->unfinished_pixels = counters[0];
    report->samples_finished = counters[1];
    rt_status status = gpu_check_gl("a tracer pass", error);
    /* A compacted list whose runs go in rounds goes on with the next round. */
    bool next_round = false;
    if (status == RT_OK && compacted && counters[0] == 0)
        status = gpu_compact_next_round(tracer, &next_round, error);
    if (next_round)
        report->unfinished_pixels = (uint32_t)compact->count;
    return status;
}

void gpu_tracer_set_pass_work_budget(gpu_tracer *tracer, uint32_t budget)
{
    tracer->parameters.shader.pass_work_budget = (int32_t)clamp_budget(&tracer->context->info, budget);
    update_parameter(tracer, offsetof(tracer_parameter_block, pass_work_budget),
                     tracer->parameters.shader.pass_work_budget);
}

/* Turns rows read bottom to top (OpenGL's order) into rows top to bottom, in place, so that
 * a read goes straight into the caller's array: a second image-sized buffer would be
 * memory touched the first time, which is slow (core/large_pages.h). False when the one
 * row it needs cannot be allocated. */
static bool flip_rows(void *rows, size_t row_bytes, int height)
{
    char *bytes = rows, *row = malloc(row_bytes);
    if (row == NULL)
        return false;
    for (int top = 0, bottom = height - 1; top < bottom; top++, bottom--) {
        memcpy(row, bytes + (size_t)top * row_bytes, row_bytes);
        memcpy(bytes + (size_t)top * row_bytes, bytes + (size_t)bottom * row_bytes, row_bytes);
        memcpy(bytes + (size_t)bottom * row_bytes, row, row_bytes);
    }
    free(row);
    return true;
}

rt_status gpu_read_full_state(gpu_tracer *tracer, int state, float *out, rt_error *error)
{
    size_t row_bytes = (size_t)tracer->width * 16;
    large_pages_advise(out, row_bytes * tracer->height);
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[tracer->current][state]);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, out);
    if (!flip_rows(out, row_bytes, tracer->height))
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading the pass state");
    return RT_OK;
}

/* Reads the sums of one state (accumulated, statistics or squares) of every pixel into
 * rows top to bottom: from the compacted passes' sums once there are some, else from the
 * full state textures. RT_ERROR_RUNTIME when memory runs out. */
static rt_status read_state(gpu_tracer *tracer, int state, float *rgba, rt_error *error)
{
    bool compacted = false;
    rt_status status = gpu_compact_read(tracer, state, rgba, &compacted, error);
    if (status != RT_OK || compacted)
        return status;
    status = gpu_read_full_state(tracer, state, rgba, error);
    if (status == RT_OK)
        gpu_compact_note_full_read(tracer, state, rgba);
    return status;
}

rt_status gpu_tracer_read(gpu_tracer *tracer, float *rgba, float *luminance_squares, gpu_tracer_totals *totals,
                          rt_error *error)
{
    glActiveTexture(GL_TEXTURE0);
    rt_status status = read_state(tracer, TRACER_STATE_ACCUMULATED, rgba, error);
    if (status != RT_OK)
        return status;
    if (totals != NULL || luminance_squares != NULL) {
        size_t count = (size_t)tracer->width * tracer->height;
        float *statistics = large_pages_alloc(count * 4 * sizeof(float));
        if (statistics == NULL)
            return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading statistics");
        status = read_state(tracer, TRACER_STATE_STATISTICS, statistics, error);
        if (status != RT_OK) {
            free(statistics);
            return status;
        }
        gpu_tracer_totals sums = {0};
        for (size_t i = 0; i < count; i++) {
            sums.path_segments += statistics[i * 4 + 0];
            sums.traversal_overflows += statistics[i * 4 + 1];
            if (luminance_squares != NULL)
                luminance_squares[i] = statistics[i * 4 + 2];
        }
        if (totals != NULL)
            *totals = sums;
        free(statistics);
    }
    return gpu_check_gl("reading the result", error);
}

/* Reads count sum layers of texture (create_sum_layers) into layers, layer after layer, rows
 * top to bottom. */
static rt_status read_sum_layers(gpu_tracer *tracer, GLuint texture, uint32_t count, float *layers, const char *what,
                                 rt_error *error)
{
    size_t row_floats = (size_t)tracer->width * 4, layer_floats = row_floats * tracer->height;
    large_pages_advise(layers, layer_floats * count * sizeof(float));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, texture);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA, GL_FLOAT, layers);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    for (uint32_t layer = 0; layer < count; layer++)
        if (!flip_rows(layers + layer * layer_floats, row_floats * sizeof(float), tracer->height))
            return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading the %s", what);
    char doing[64];
    snprintf(doing, sizeof doing, "reading the %s", what);
    return gpu_check_gl(doing, error);
}

rt_status gpu_tracer_read_light_groups(gpu_tracer *tracer, float *layers, rt_error *error)
{
    uint32_t count = tracer->parameters.shader.light_group_count;
    if (tracer->light_group_texture == 0 || count == 0)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: this tracer collects no light groups");
    return read_sum_layers(tracer, tracer->light_group_texture, count, layers, "light groups", error);
}

rt_status gpu_tracer_read_direct_emission(gpu_tracer *tracer, float *sums, rt_error *error)
{
    if (tracer->direct_emission_texture == 0 || tracer->parameters.shader.direct_emission == 0)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: this tracer sums no direct emission");
    return read_sum_layers(tracer, tracer->direct_emission_texture, 1, sums, "direct emission sums", error);
}

rt_status gpu_tracer_read_squares(gpu_tracer *tracer, float *squares, rt_error *error)
{
    if (tracer->state_count <= TRACER_STATE_SQUARES)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: this tracer keeps no sums of squares (GPU_OMIT_SQUARES)");
    glActiveTexture(GL_TEXTURE0);
    rt_status status = read_state(tracer, TRACER_STATE_SQUARES, squares, error);
    if (status != RT_OK)
        return status;
    return gpu_check_gl("reading the sums of squares", error);
}

rt_status gpu_tracer_render_aovs(gpu_tracer *tracer, int samples, float *albedo_depth, float *normal_coverage,
                                 rt_error *error)
{
    /* The render's variant: the AOV pass reaches no more of the tracer than the render. */
    char defines[2048];
    const gpu_tracer_parameters *p = &tracer->parameters;
    gpu_variant_defines(p->omitted_features, &p->shader, defines, sizeof defines);
    GLuint program = build_fragment_program(SHADER_PROGRAM_AOV, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    int width = tracer->width, height = tracer->height;
    GLuint textures[2], framebuffer;
    glGenTextures(2, textures);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    for (int k = 0; k < 2; k++) {
        glBindTexture(GL_TEXTURE_2D, textures[k]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + k, GL_TEXTURE_2D, textures[k], 0);
    }
    const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, draw_buffers);
    rt_status status = RT_OK;
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        status = rt_error_set(error, RT_ERROR_RUNTIME, "GPU: the AOV framebuffer is incomplete");
    if (status == RT_OK) {
        update_parameter(tracer, offsetof(tracer_parameter_block, aov_samples), samples);
        glUseProgram(program);
        glBindBufferBase(GL_UNIFORM_BUFFER, TRACER_PARAMETER_BINDING, tracer->parameter_buffer);
        glViewport(0, 0, width, height);
        gpu_bind_packed_scene(tracer->packed_texture);
        glBindVertexArray(tracer->vertex_array);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        float *outputs[2] = {albedo_depth, normal_coverage};
        size_t row_bytes = (size_t)width * 4 * sizeof(float);
        for (int k = 0; k < 2 && status == RT_OK; k++) {
            large_pages_advise(outputs[k], row_bytes * height);
            glReadBuffer(GL_COLOR_ATTACHMENT0 + k);
            glPixelStorei(GL_PACK_ALIGNMENT, 4);
            glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, outputs[k]);
            if (!flip_rows(outputs[k], row_bytes, height))
                status = rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading the AOVs");
        }
    }
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(2, textures);
    glDeleteProgram(program);
    glUseProgram(tracer->program);
    if (status != RT_OK)
        return status;
    return gpu_check_gl("the AOV pass", error);
}

bool gpu_tracer_reused_scene(const gpu_tracer *tracer)
{
    return tracer->reused_scene;
}

uint64_t gpu_tracer_uploaded_bytes(const gpu_tracer *tracer)
{
    return tracer->uploaded_bytes;
}

bool gpu_tracer_compiled_program(const gpu_tracer *tracer)
{
    return tracer->compiled_program;
}

void gpu_tracer_get_timings(const gpu_tracer *tracer, gpu_tracer_timings *timings)
{
    *timings = tracer->timings;
}

void gpu_tracer_destroy(gpu_tracer *tracer)
{
    if (tracer == NULL)
        return;
    for (int set = 0; set < 2; set++) {
        glDeleteTextures(TRACER_STATE_COUNT, tracer->state_textures[set]);
        glDeleteFramebuffers(1, &tracer->framebuffers[set]);
    }
    /* The program and the packed scene belong to the context (kept for the next frame). */
    if (tracer->packed_texture != tracer->context->packed_texture) {
        glDeleteTextures(1, &tracer->packed_texture);
        glDeleteBuffers(1, &tracer->packed_buffer);
    }
    glDeleteTextures(1, &tracer->light_group_texture);
    glDeleteTextures(1, &tracer->direct_emission_texture);
    glDeleteBuffers(1, &tracer->counter_buffer);
    glDeleteBuffers(1, &tracer->parameter_buffer);
    glDeleteVertexArrays(1, &tracer->vertex_array);
    glDeleteTextures(1, &tracer->sample_limits);
    glDeleteTextures(1, &tracer->no_pixel_map);
    glDeleteRenderbuffers(1, &tracer->depth_buffer);
    gpu_compact_destroy(tracer);
    free(tracer);
}

void gpu_tracer_release(gpu_context *context)
{
    if (context->cull_program)
        glDeleteProgram(context->cull_program);
    context->cull_program = 0;
    for (int i = 0; i < context->tracer_program_count; i++)
        if (context->tracer_programs[i].program)
            glDeleteProgram(context->tracer_programs[i].program);
    if (context->packed_texture)
        glDeleteTextures(1, &context->packed_texture);
    if (context->packed_buffer)
        glDeleteBuffers(1, &context->packed_buffer);
    free(context->packed_block_hashes);
    context->packed_block_hashes = NULL;
}
