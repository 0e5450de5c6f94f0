/* gpu_compact.c: compacted passes of the tracer (gpu.h gpu_tracer_set_pass_pixels).
 *
 * Why: llvmpipe runs 8 pixels as one SIMD vector (a GPU runs a warp of 32), every loop of
 * the tracer until its slowest lane is done, and both sides of every branch
 * (docs/performance.md). Under adaptive sampling the pixels still going are scattered over
 * the image, so a vector of the full image often holds one busy pixel and seven that are
 * done, and costs as much as eight busy ones. Here the pixels still going are packed
 * densely into compact state textures, so that every lane of a vector has work.
 *
 * How: the compact textures are two ping-pong sets like the full ones (gpu_tracer.c), of
 * width x height slots; the pixel map (R32UI, core/tracer_interface.h) names each slot's
 * pixel. Eight consecutive pixels of the list take a 4 x 2 block of slots, which is what
 * llvmpipe shades as one vector (and a quarter of a GPU's 8 x 4 warp), so the lanes of a
 * vector are pixels near one another in the image. A change of pixel list first writes the
 * compact state back to the full textures (the scatter program: a point per slot, placed
 * on its pixel), then copies the new list's pixels into the compact set (the gather
 * program: a full-screen draw over the slots). Passes trace the compact set
 * (glsl/main.glsl reads its pixel from the map: random numbers, film position, sample
 * limit and light group layers are the pixel's, so the image is the same to the bit).
 * Every read of the state first writes the compact state back (gpu_compact_save), so the
 * full textures of the current set always hold every pixel when they are read. */
#include <stdlib.h>
#include <string.h>

#include "gpu_internal.h"
#include "shader_sources.h"

/* The 64 x 64 tiles of llvmpipe's rasteriser the compact slots are spread over: enough
 * for its threads to share a pass evenly. */
#define COMPACT_TILES 16

/* The slot (x, y) of the pixel at index k of a list, in compact textures width slots wide:
 * blocks of 8 pixels fill 4 x 2 slots, block after block along the rows. */
static void slot_of(int k, int width, int *x, int *y)
{
    int block = k >> 3, lane = k & 7, blocks_per_row = width / 4;
    *x = (block % blocks_per_row) * 4 + (lane & 3);
    *y = (block / blocks_per_row) * 2 + (lane >> 2);
}

/* The tracer interface's text (core/tracer_interface.h), the defines both stages of the
 * compact programs need (the vertex shader is not made of modules). */
static const char *interface_source(void)
{
    for (int i = 0; shader_modules[i].path != NULL; i++)
        if (strcmp(shader_modules[i].path, "core/tracer_interface.h") == 0)
            return shader_modules[i].source;
    return "";
}

/* Gives the bound 2D texture nearest filtering: an integer texture with the default
 * (mipmapped, linear) filter is incomplete, and texelFetch reads zeros from it. */
static void nearest_filtering(void)
{
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

/* Creates the compact textures for at least count slots (none may be larger than the
 * device's side), their framebuffers, the pixel map and the two copy programs. */
static rt_status create_compact(gpu_tracer *tracer, int count, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    /* Wide and short: llvmpipe shares a draw among its threads by 64 x 64 tiles, so the
     * slots are spread over about COMPACT_TILES tiles (or fill them), not packed into one. */
    int max_side = tracer->context->info.max_tile_side;
    int height = (count + COMPACT_TILES * 64 - 1) / (COMPACT_TILES * 64);
    height = height < 4 ? 4 : height > 64 ? 64 : (height + 3) & ~3;   /* whole 4 x 4 blocks */
    int width = ((count + height - 1) / height + 3) & ~3;
    if (width > max_side) {
        width = max_side & ~3;
        height = ((count + width - 1) / width + 3) & ~3;
    }
    if (c->gather_program == 0) {
        c->gather_program = gpu_build_program(shader_source_fullscreen_vertex, SHADER_PROGRAM_COMPACT_GATHER,
                                              interface_source(), error);
        if (c->gather_program == 0)
            return RT_ERROR_RUNTIME;
        c->scatter_program = gpu_build_program(shader_source_compact_scatter_vertex, SHADER_PROGRAM_COMPACT_SCATTER,
                                               interface_source(), error);
        if (c->scatter_program == 0)
            return RT_ERROR_RUNTIME;
    }
    if (c->width != 0) {
        for (int set = 0; set < 2; set++) {
            glDeleteTextures(TRACER_STATE_COUNT, c->state_textures[set]);
            glDeleteFramebuffers(1, &c->framebuffers[set]);
        }
        glDeleteTextures(1, &c->pixel_map);
    }
    /* Names of 0 until made, and the size set now, so that gpu_compact_destroy frees what
     * a failure below leaves (GL ignores the name 0). */
    memset(c->state_textures, 0, sizeof c->state_textures);
    memset(c->framebuffers, 0, sizeof c->framebuffers);
    c->pixel_map = 0;
    c->width = width;
    c->height = height;
    for (int set = 0; set < 2; set++) {
        if (gpu_create_state_set(c->state_textures[set], &c->framebuffers[set], width, height)
            != GL_FRAMEBUFFER_COMPLETE) {
            while (glGetError() != GL_NO_ERROR) {
            }
            return rt_error_set(error, RT_ERROR_RUNTIME,
                                "GPU: out of memory for the compacted state of %d pixels (%.1f MiB)", count,
                                (double)width * height * TRACER_STATE_COUNT * 16 * 2 / (1 << 20));
        }
    }
    glGenTextures(1, &c->pixel_map);
    glBindTexture(GL_TEXTURE_2D, c->pixel_map);
    nearest_filtering();
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_R32UI, width, height);
    return gpu_check_gl("creating the compacted state", error);
}

/* Binds the state textures of one set (units TRACER_STATE_*). */
static void bind_state(const GLuint textures[TRACER_STATE_COUNT])
{
    for (int state = 0; state < TRACER_STATE_COUNT; state++) {
        glActiveTexture(GL_TEXTURE0 + state);
        glBindTexture(GL_TEXTURE_2D, textures[state]);
    }
}

rt_status gpu_compact_save(gpu_tracer *tracer, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    if (c->count == 0 || !c->unsaved)
        return RT_OK;
    glBindFramebuffer(GL_FRAMEBUFFER, tracer->framebuffers[tracer->current]);
    glViewport(0, 0, tracer->width, tracer->height);
    glUseProgram(c->scatter_program);
    glUniform2f(glGetUniformLocation(c->scatter_program, "frame_size"), (float)tracer->width, (float)tracer->height);
    bind_state(c->state_textures[c->current]);
    glActiveTexture(GL_TEXTURE0 + TRACER_PIXEL_MAP_UNIT);
    glBindTexture(GL_TEXTURE_2D, c->pixel_map);
    glBindVertexArray(tracer->vertex_array);
    glDrawArrays(GL_POINTS, 0, c->width * c->height);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    c->unsaved = false;
    return gpu_check_gl("writing the compacted state back", error);
}

void gpu_compact_scissor(gpu_tracer *tracer, bool on)
{
    if (!on) {
        glDisable(GL_SCISSOR_TEST);
        return;
    }
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, tracer->compact.used_width, tracer->compact.used_height);
}

rt_status gpu_tracer_set_pass_pixels(gpu_tracer *tracer, const uint32_t *pixels, int count, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    rt_status status = gpu_compact_save(tracer, error);
    if (status != RT_OK)
        return status;
    c->count = 0;
    if (pixels == NULL)
        return RT_OK;
    if (c->width == 0 || (size_t)c->width * c->height < (size_t)count) {
        status = create_compact(tracer, count > 0 ? count : 1, error);
        if (status != RT_OK)
            return status;
    }
    uint32_t *map = malloc((size_t)c->width * c->height * sizeof *map);
    if (map == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the pixel map of %d pixels", count);
    for (size_t i = 0; i < (size_t)c->width * c->height; i++)
        map[i] = TRACER_NO_PIXEL;
    for (int k = 0; k < count; k++) {
        /* Rows from the top in the list, from the bottom in the framebuffer. */
        uint32_t x = pixels[k] % (uint32_t)tracer->width, y = pixels[k] / (uint32_t)tracer->width;
        int sx, sy;
        slot_of(k, c->width, &sx, &sy);
        map[(size_t)sy * c->width + sx] = x | ((uint32_t)(tracer->height - 1) - y) << TRACER_PIXEL_MAP_SHIFT;
    }
    glBindTexture(GL_TEXTURE_2D, c->pixel_map);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, c->width, c->height, GL_RED_INTEGER, GL_UNSIGNED_INT, map);
    free(map);
    /* The region the list's slots take (whole 4 x 4 blocks): draws are cut to it, since a
     * vector of empty slots is not free on llvmpipe (its loops run once, masked), and a
     * list shorter than the one the textures were made for leaves most of them empty. */
    int blocks = (count + 7) / 8, blocks_per_row = c->width / 4;
    int block_rows = (blocks + blocks_per_row - 1) / blocks_per_row;
    c->used_width = block_rows > 1 ? c->width : 4 * blocks;
    c->used_height = (2 * block_rows + 3) & ~3;
    c->used_height = c->used_height > c->height ? c->height : c->used_height;
    /* The gather: the full state of the current set into compact set 0. */
    glBindFramebuffer(GL_FRAMEBUFFER, c->framebuffers[0]);
    glViewport(0, 0, c->width, c->height);
    gpu_compact_scissor(tracer, true);
    glUseProgram(c->gather_program);
    bind_state(tracer->state_textures[tracer->current]);
    glActiveTexture(GL_TEXTURE0 + TRACER_PIXEL_MAP_UNIT);
    glBindTexture(GL_TEXTURE_2D, c->pixel_map);
    glBindVertexArray(tracer->vertex_array);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    gpu_compact_scissor(tracer, false);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    c->current = 0;
    c->count = count;
    c->unsaved = false;
    return gpu_check_gl("compacting the pass state", error);
}

void gpu_compact_destroy(gpu_tracer *tracer)
{
    gpu_compact *c = &tracer->compact;
    if (c->width != 0) {
        for (int set = 0; set < 2; set++) {
            glDeleteTextures(TRACER_STATE_COUNT, c->state_textures[set]);
            glDeleteFramebuffers(1, &c->framebuffers[set]);
        }
        glDeleteTextures(1, &c->pixel_map);
    }
    glDeleteProgram(c->gather_program);
    glDeleteProgram(c->scatter_program);
    memset(c, 0, sizeof *c);
}
