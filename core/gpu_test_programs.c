/* gpu_test_programs.c: the programs of the GPU module that only tests use (gpu.h): the
 * random-number test (glsl/random_test.frag), the material test (glsl/material_test.frag),
 * the light choice test (glsl/light_test.frag) and the parameter block's layout as the GLSL
 * compiler lays it out. They share the tracer's program assembly and helpers through
 * gpu_internal.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu_internal.h"
#include "shader_sources.h"

/* A program of the shared full-screen vertex shader and the fragment program (a
 * SHADER_PROGRAM_* bit) with defines; 0 with error set when it does not build. */
static GLuint build_program(uintptr_t program, const char *defines, rt_error *error)
{
    return gpu_build_program(shader_source_fullscreen_vertex, program, defines, error);
}

rt_status gpu_random_numbers(gpu_context *context, const gpu_random_request *request, float *rgba,
                             rt_error *error)
{
    (void)context;
    int width = request->width, height = request->height;
    GLuint program = build_program(SHADER_PROGRAM_RANDOM_TEST, "", error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    GLuint texture, framebuffer, vertex_array;
    glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
    GLenum draw_buffer = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &draw_buffer);
    glGenVertexArrays(1, &vertex_array);
    glBindVertexArray(vertex_array);
    glViewport(0, 0, width, height);
    glUseProgram(program);
    glUniform1ui(glGetUniformLocation(program, "sample_index"), request->sample_index);
    glUniform1ui(glGetUniformLocation(program, "seed"), request->seed);
    glUniform1ui(glGetUniformLocation(program, "dimension"), request->dimension);
    glUniform1i(glGetUniformLocation(program, "image_height"), height);
    glUniform1i(glGetUniformLocation(program, "image_width"), width);
    glUniform1i(glGetUniformLocation(program, "sampler"), request->sampler);
    glUniform2i(glGetUniformLocation(program, "fixed_pixel"), request->over_samples ? request->fixed_pixel[0] : -1,
                request->fixed_pixel[1]);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    size_t row_floats = (size_t)width * 4;
    float *bottom_up = malloc(row_floats * (size_t)height * sizeof(float));
    if (bottom_up != NULL) {
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, bottom_up);
        for (int row = 0; row < height; row++)
            memcpy(rgba + (size_t)row * row_floats, bottom_up + (size_t)(height - 1 - row) * row_floats,
                   row_floats * sizeof(float));
        free(bottom_up);
    }
    glDeleteVertexArrays(1, &vertex_array);
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(1, &texture);
    glDeleteProgram(program);
    if (bottom_up == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading random numbers");
    return gpu_check_gl("drawing random numbers", error);
}

/* Queries per draw of the query tests (rows of QUERY_TEST_WIDTH). */
#define QUERY_TEST_WIDTH 1024
#define QUERY_TEST_ROWS 256
#define QUERY_TEST_MAX_OUTPUTS 4

/* Runs a query test's program (a SHADER_PROGRAM_* bit, the whole tracer's variant: no
 * part left out) over count queries of texels_per_query RGBA32F texels each (query_texels,
 * on the buffer texture unit query_unit) against a packed scene, one pixel a query, row by
 * row: outputs[k] (output_count of them, each count RGBA floats) receives what the
 * program writes to location k for each query. The caller owns every array. */
static rt_status run_query_test(gpu_context *context, uintptr_t program_bit, const char *what,
                                const uint32_t *packed_texels, uint32_t texel_count, const float *query_texels,
                                int texels_per_query, int query_unit, int count, int output_count, float **outputs,
                                rt_error *error)
{
    rt_status status = gpu_check_packed_size(context, texel_count, error);
    if (status != RT_OK || count <= 0)
        return status;
    char defines[2048];
    gpu_variant_defines(0, NULL, defines, sizeof defines);
    GLuint program = build_program(program_bit, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    int rows = (count + QUERY_TEST_WIDTH - 1) / QUERY_TEST_WIDTH;
    rows = rows > QUERY_TEST_ROWS ? QUERY_TEST_ROWS : rows;
    float *image = malloc((size_t)QUERY_TEST_WIDTH * rows * 4 * sizeof(float));
    if (image == NULL) {
        glDeleteProgram(program);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for %s", what);
    }
    GLuint buffers[2], inputs[2], images[QUERY_TEST_MAX_OUTPUTS], framebuffer, vertex_array;
    gpu_create_buffer_texture(GL_RGBA32UI, packed_texels, (size_t)texel_count * 4 * sizeof(uint32_t), &buffers[0],
                              &inputs[0]);
    gpu_create_buffer_texture(GL_RGBA32F, query_texels, (size_t)count * texels_per_query * 4 * sizeof(float),
                              &buffers[1], &inputs[1]);
    glGenTextures(output_count, images);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    GLenum draw_buffers[QUERY_TEST_MAX_OUTPUTS];
    for (int k = 0; k < output_count; k++) {
        glBindTexture(GL_TEXTURE_2D, images[k]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, QUERY_TEST_WIDTH, rows);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + k, GL_TEXTURE_2D, images[k], 0);
        draw_buffers[k] = GL_COLOR_ATTACHMENT0 + k;
    }
    glDrawBuffers(output_count, draw_buffers);
    glGenVertexArrays(1, &vertex_array);
    glBindVertexArray(vertex_array);
    glUseProgram(program);
    gpu_bind_packed_scene(inputs[0]);
    glActiveTexture(GL_TEXTURE0 + query_unit);
    glBindTexture(GL_TEXTURE_BUFFER, inputs[1]);
    glUniform1i(glGetUniformLocation(program, "query_width"), QUERY_TEST_WIDTH);
    /* One draw per QUERY_TEST_ROWS rows of queries, each read back before the next. */
    for (int first = 0; first < count; first += QUERY_TEST_WIDTH * rows) {
        int n = count - first < QUERY_TEST_WIDTH * rows ? count - first : QUERY_TEST_WIDTH * rows;
        int used_rows = (n + QUERY_TEST_WIDTH - 1) / QUERY_TEST_WIDTH;
        glUniform1i(glGetUniformLocation(program, "query_first"), first);
        glUniform1i(glGetUniformLocation(program, "query_count"), n);
        glViewport(0, 0, QUERY_TEST_WIDTH, used_rows);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        for (int k = 0; k < output_count; k++) {
            glReadBuffer(GL_COLOR_ATTACHMENT0 + k);
            glReadPixels(0, 0, QUERY_TEST_WIDTH, used_rows, GL_RGBA, GL_FLOAT, image);
            memcpy(outputs[k] + 4 * (size_t)first, image, (size_t)n * 4 * sizeof(float));
        }
    }
    status = gpu_check_gl(what, error);
    glDeleteVertexArrays(1, &vertex_array);
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(output_count, images);
    glDeleteTextures(2, inputs);
    glDeleteBuffers(2, buffers);
    glDeleteProgram(program);
    free(image);
    return status;
}

/* Allocates output_count arrays of count RGBA floats into outputs; false (and nothing
 * allocated) when memory runs out. */
static bool allocate_outputs(int count, int output_count, float **outputs)
{
    bool allocated = true;
    for (int k = 0; k < output_count; k++)
        allocated = (outputs[k] = malloc((size_t)(count > 0 ? count : 1) * 4 * sizeof(float))) != NULL && allocated;
    if (!allocated)
        for (int k = 0; k < output_count; k++) {
            free(outputs[k]);
            outputs[k] = NULL;
        }
    return allocated;
}

/* The material test's queries as the texels glsl/material_test.frag reads; NULL when
 * memory runs out. The caller frees it. */
static float *material_query_texels(const gpu_material_query *queries, int count)
{
    float *texels = malloc((size_t)(count > 0 ? count : 1) * MATERIAL_TEST_QUERY_TEXELS * 4 * sizeof(float));
    if (texels == NULL)
        return NULL;
    for (int i = 0; i < count; i++) {
        const gpu_material_query *q = &queries[i];
        float *t = texels + (size_t)i * MATERIAL_TEST_QUERY_TEXELS * 4;
        const float rows[MATERIAL_TEST_QUERY_TEXELS][4] = {
            {q->direction[0], q->direction[1], q->direction[2], (float)q->material},
            {q->normal[0], q->normal[1], q->normal[2], q->front_face ? 1.0f : 0.0f},
            {q->shading[0], q->shading[1], q->shading[2], 0},
            {q->u[0], q->u[1], q->u[2], q->u[3]},
            {q->to_light[0], q->to_light[1], q->to_light[2], 0},
        };
        memcpy(t, rows, sizeof rows);
    }
    return texels;
}

/* Copies the material test's outputs (MATERIAL_TEST_OUTPUTS arrays of count RGBA floats,
 * in query order) into results. */
static void material_results(float *const outputs[MATERIAL_TEST_OUTPUTS], int count, gpu_material_result *results)
{
    for (int i = 0; i < count; i++) {
        const float *a = outputs[0] + 4 * (size_t)i, *b = outputs[1] + 4 * (size_t)i;
        const float *c = outputs[2] + 4 * (size_t)i, *d = outputs[3] + 4 * (size_t)i;
        gpu_material_result *r = &results[i];
        memcpy(r->direction, a, sizeof r->direction);
        r->pdf = a[3];
        memcpy(r->weight, b, sizeof r->weight);
        int flags = (int)b[3];
        r->absorbed = (flags & 1) != 0;
        r->light_sampled = (flags & 2) != 0;
        memcpy(r->evaluate, c, sizeof r->evaluate);
        r->evaluate_pdf = c[3];
        memcpy(r->sampled_evaluate, d, sizeof r->sampled_evaluate);
        r->sampled_pdf = d[3];
    }
}

rt_status gpu_material_test(gpu_context *context, const uint32_t *packed_texels, uint32_t texel_count,
                            const gpu_material_query *queries, int count, gpu_material_result *results,
                            rt_error *error)
{
    float *outputs[MATERIAL_TEST_OUTPUTS] = {NULL};
    float *query_texels = material_query_texels(queries, count);
    if (query_texels == NULL || !allocate_outputs(count, MATERIAL_TEST_OUTPUTS, outputs)) {
        free(query_texels);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the material test");
    }
    rt_status status = run_query_test(context, SHADER_PROGRAM_MATERIAL_TEST, "the material test", packed_texels,
                                      texel_count, query_texels, MATERIAL_TEST_QUERY_TEXELS, MATERIAL_TEST_QUERY_UNIT,
                                      count, MATERIAL_TEST_OUTPUTS, outputs, error);
    if (status == RT_OK)
        material_results(outputs, count, results);
    free(query_texels);
    for (int k = 0; k < MATERIAL_TEST_OUTPUTS; k++)
        free(outputs[k]);
    return status;
}

rt_status gpu_light_choice_test(gpu_context *context, const uint32_t *packed_texels, uint32_t texel_count,
                                const gpu_light_query *queries, int count, gpu_light_result *results,
                                rt_error *error)
{
    float *outputs[LIGHT_TEST_OUTPUTS] = {NULL};
    float *query_texels = malloc((size_t)(count > 0 ? count : 1) * LIGHT_TEST_QUERY_TEXELS * 4 * sizeof(float));
    if (query_texels == NULL || !allocate_outputs(count, LIGHT_TEST_OUTPUTS, outputs)) {
        free(query_texels);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the light choice test");
    }
    for (int i = 0; i < count; i++) {
        const gpu_light_query *q = &queries[i];
        const float rows[LIGHT_TEST_QUERY_TEXELS][4] = {{q->p[0], q->p[1], q->p[2], q->u},
                                                        {q->n[0], q->n[1], q->n[2], (float)q->light}};
        memcpy(query_texels + (size_t)i * LIGHT_TEST_QUERY_TEXELS * 4, rows, sizeof rows);
    }
    rt_status status = run_query_test(context, SHADER_PROGRAM_LIGHT_TEST, "the light choice test", packed_texels,
                                      texel_count, query_texels, LIGHT_TEST_QUERY_TEXELS, LIGHT_TEST_QUERY_UNIT,
                                      count, LIGHT_TEST_OUTPUTS, outputs, error);
    for (int i = 0; status == RT_OK && i < count; i++) {
        const float *a = outputs[0] + 4 * (size_t)i, *b = outputs[1] + 4 * (size_t)i;
        results[i] = (gpu_light_result){.picked = (uint32_t)a[0], .chance = a[1], .memo = {a[2], a[3]},
                                        .picked_again = b[0], .light_chance = b[1]};
    }
    free(query_texels);
    for (int k = 0; k < LIGHT_TEST_OUTPUTS; k++)
        free(outputs[k]);
    return status;
}

/* "block_": what TRACER_BLOCK_MEMBER (core/tracer_interface.h) puts before a parameter's name. */
#define EXPANDED_STRING(x) STRING(x)
#define STRING(x) #x
#define BLOCK_MEMBER_PREFIX EXPANDED_STRING(TRACER_BLOCK_MEMBER())

rt_status gpu_tracer_parameter_layout(gpu_context *context, int count, const char *const *names, int *offsets,
                                      int *block_size, rt_error *error)
{
    (void)context;
    char defines[2048];
    gpu_variant_defines(0, NULL, defines, sizeof defines);
    GLuint program = build_program(SHADER_PROGRAM_PASS, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    for (int i = 0; i < count; i++) {
        char member[128];
        snprintf(member, sizeof member, "%s%s", BLOCK_MEMBER_PREFIX, names[i]);
        const char *member_name = member;
        GLuint index = GL_INVALID_INDEX;
        glGetUniformIndices(program, 1, &member_name, &index);
        offsets[i] = -1;
        if (index != GL_INVALID_INDEX)
            glGetActiveUniformsiv(program, 1, &index, GL_UNIFORM_OFFSET, &offsets[i]);
    }
    *block_size = 0;
    GLuint block = glGetUniformBlockIndex(program, "tracer_parameter_block");
    if (block != GL_INVALID_INDEX)
        glGetActiveUniformBlockiv(program, block, GL_UNIFORM_BLOCK_DATA_SIZE, block_size);
    glDeleteProgram(program);
    return gpu_check_gl("reading the parameter block's layout", error);
}
