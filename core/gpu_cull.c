/* gpu_cull.c: full passes that skip finished pixels (gpu.h gpu_tracer_cull_finished).
 *
 * Why: at the end of a render a few slow pixels (long paths through glass) keep passes
 * going, and a full pass reads and writes every pixel's state whether it traces or not
 * (0.045 s at 1200x675 on llvmpipe, docs/performance.md). How: both state sets'
 * framebuffers share a depth buffer (core/gpu_state.c gpu_state_create, all 1);
 * glsl/cull.frag writes 0 where both sets say a pixel is done, and full passes test the
 * depth early (layout(early_fragment_tests) in glsl/main.glsl), so the marked pixels'
 * shader never runs. A pass leaves a finished pixel's state as it is, so both sets already
 * hold what it would write. Compacted passes (gpu_compact.c) use the state textures'
 * texels as slots: they test no depth, and setting a list or limits unmarks everything. */
#include "gpu_internal.h"
#include "shader_sources.h"

rt_status gpu_tracer_cull_finished(gpu_tracer *tracer, rt_error *error)
{
    gpu_context *context = tracer->context;
    if (tracer->compact.count > 0)
        return RT_OK;
    if (context->cull_program == 0) {
        context->cull_program = gpu_build_program(shader_source_fullscreen_vertex, SHADER_PROGRAM_CULL, "", error);
        if (context->cull_program == 0)
            return RT_ERROR_RUNTIME;
    }
    int latest = tracer->current;
    glBindFramebuffer(GL_FRAMEBUFFER, tracer->framebuffers[latest]);
    glViewport(0, 0, tracer->width, tracer->height);
    glUseProgram(context->cull_program);
    glBindBufferBase(GL_UNIFORM_BUFFER, TRACER_PARAMETER_BINDING, tracer->parameter_buffer);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[latest][TRACER_STATE_COUNTERS]);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[1 - latest][TRACER_STATE_COUNTERS]);
    glActiveTexture(GL_TEXTURE0 + TRACER_SAMPLE_LIMITS_UNIT);
    glBindTexture(GL_TEXTURE_2D, tracer->sample_limits);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glBindVertexArray(tracer->vertex_array);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_DEPTH_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    tracer->culling = true;
    return gpu_check_gl("marking finished pixels", error);
}

void gpu_uncull(gpu_tracer *tracer)
{
    if (!tracer->culling)
        return;
    const GLfloat far_depth = 1.0f;
    glBindFramebuffer(GL_FRAMEBUFFER, tracer->framebuffers[0]);
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
    tracer->culling = false;
}
