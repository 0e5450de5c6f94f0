/* gpu_test_programs.c: the programs of the GPU module that only tests use (gpu.h): the
 * random-number test (glsl/random_test.frag), the material test (glsl/material_test.frag)
 * and the parameter block's layout as the GLSL compiler lays it out. They share the
 * tracer's program assembly and helpers through gpu_internal.h. */
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

/* Queries per draw of the material test (rows of MATERIAL_TEST_WIDTH). */
#define MATERIAL_TEST_WIDTH 1024
#define MATERIAL_TEST_ROWS 256

/* The material test's queries as the texels glsl/material_test.frag reads; NULL when
 * memory runs out. The caller frees it. */
static float *material_query_texels(const gpu_material_query *queries, int count)
{
    float *texels = malloc((size_t)count * MATERIAL_TEST_QUERY_TEXELS * 4 * sizeof(float));
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

/* Copies the material test's outputs (MATERIAL_TEST_OUTPUTS images of count pixels, row
 * by row as queries are) into results. */
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
    rt_status status = gpu_check_packed_size(context, texel_count, error);
    if (status != RT_OK)
        return status;
    char defines[2048];
    gpu_variant_defines(0, NULL, defines, sizeof defines);
    GLuint program = build_program(SHADER_PROGRAM_MATERIAL_TEST, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    float *query_texels = material_query_texels(queries, count);
    int rows = (count + MATERIAL_TEST_WIDTH - 1) / MATERIAL_TEST_WIDTH;
    rows = rows > MATERIAL_TEST_ROWS ? MATERIAL_TEST_ROWS : rows;
    size_t image_floats = (size_t)MATERIAL_TEST_WIDTH * (rows > 0 ? rows : 1) * 4;
    float *outputs[MATERIAL_TEST_OUTPUTS] = {NULL};
    bool allocated = query_texels != NULL;
    for (int k = 0; k < MATERIAL_TEST_OUTPUTS; k++)
        allocated = (outputs[k] = malloc(image_floats * sizeof(float))) != NULL && allocated;
    if (!allocated || count <= 0) {
        free(query_texels);
        for (int k = 0; k < MATERIAL_TEST_OUTPUTS; k++)
            free(outputs[k]);
        glDeleteProgram(program);
        return allocated ? RT_OK : rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the material test");
    }
    GLuint buffers[2], inputs[2], images[MATERIAL_TEST_OUTPUTS], framebuffer, vertex_array;
    gpu_create_buffer_texture(GL_RGBA32UI, packed_texels, (size_t)texel_count * 4 * sizeof(uint32_t), &buffers[0],
                          &inputs[0]);
    gpu_create_buffer_texture(GL_RGBA32F, query_texels, (size_t)count * MATERIAL_TEST_QUERY_TEXELS * 4 * sizeof(float),
                          &buffers[1], &inputs[1]);
    glGenTextures(MATERIAL_TEST_OUTPUTS, images);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    GLenum draw_buffers[MATERIAL_TEST_OUTPUTS];
    for (int k = 0; k < MATERIAL_TEST_OUTPUTS; k++) {
        glBindTexture(GL_TEXTURE_2D, images[k]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, MATERIAL_TEST_WIDTH, rows);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + k, GL_TEXTURE_2D, images[k], 0);
        draw_buffers[k] = GL_COLOR_ATTACHMENT0 + k;
    }
    glDrawBuffers(MATERIAL_TEST_OUTPUTS, draw_buffers);
    glGenVertexArrays(1, &vertex_array);
    glBindVertexArray(vertex_array);
    glUseProgram(program);
    glActiveTexture(GL_TEXTURE0 + TRACER_PACKED_SCENE_UNIT);
    glBindTexture(GL_TEXTURE_BUFFER, inputs[0]);
    glActiveTexture(GL_TEXTURE0 + MATERIAL_TEST_QUERY_UNIT);
    glBindTexture(GL_TEXTURE_BUFFER, inputs[1]);
    glUniform1i(glGetUniformLocation(program, "query_width"), MATERIAL_TEST_WIDTH);
    /* One draw per MATERIAL_TEST_ROWS rows of queries, each read back before the next. */
    for (int first = 0; first < count; first += MATERIAL_TEST_WIDTH * rows) {
        int n = count - first < MATERIAL_TEST_WIDTH * rows ? count - first : MATERIAL_TEST_WIDTH * rows;
        int used_rows = (n + MATERIAL_TEST_WIDTH - 1) / MATERIAL_TEST_WIDTH;
        glUniform1i(glGetUniformLocation(program, "query_first"), first);
        glUniform1i(glGetUniformLocation(program, "query_count"), n);
        glViewport(0, 0, MATERIAL_TEST_WIDTH, used_rows);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        for (int k = 0; k < MATERIAL_TEST_OUTPUTS; k++) {
            glReadBuffer(GL_COLOR_ATTACHMENT0 + k);
            glReadPixels(0, 0, MATERIAL_TEST_WIDTH, used_rows, GL_RGBA, GL_FLOAT, outputs[k]);
        }
        material_results(outputs, n, results + first);
    }
    status = gpu_check_gl("the material test", error);
    glDeleteVertexArrays(1, &vertex_array);
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(MATERIAL_TEST_OUTPUTS, images);
    glDeleteTextures(2, inputs);
    glDeleteBuffers(2, buffers);
    glDeleteProgram(program);
    free(query_texels);
    for (int k = 0; k < MATERIAL_TEST_OUTPUTS; k++)
        free(outputs[k]);
    return status;
}

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
        GLuint index = GL_INVALID_INDEX;
        glGetUniformIndices(program, 1, &names[i], &index);
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
