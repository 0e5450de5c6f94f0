/* gpu_compact.c: compacted passes of the tracer (gpu.h gpu_tracer_set_pass_pixels).
 *
 * Why: llvmpipe runs 8 pixels as one SIMD vector (a GPU runs a warp of 32), every loop of
 * the tracer until its slowest lane is done, and both sides of every branch
 * (docs/performance.md). Under adaptive sampling the pixels still going are scattered over
 * the image, so a vector of the full image often holds one busy pixel and seven that are
 * done, and costs as much as eight busy ones. Here the pixels still going are packed
 * densely into compact state textures, so that every lane of a vector has work. And since
 * a pass may give a pixel only so many samples (the loop cap, glsl/work.glsl), a short
 * list would take many short passes, each with its fixed cost: so each pixel's samples
 * are split into runs, one slot each, traced side by side.
 *
 * How: after the first list the host keeps every pixel's sums (sums[]: the state's sums
 * read back once, when the first list is set), so the state textures' texels are free to
 * be slots: the pixel map (RGBA32UI, core/tracer_interface.h) gives each slot its pixel
 * and its run of sample indices. Slot k + r * count holds run r of the list's pixel k;
 * eight consecutive slots take a 4 x 2 block, which is what llvmpipe shades as one vector
 * (and a quarter of a GPU's 8 x 4 warp), and on llvmpipe the blocks are dealt to as many
 * 64-wide tile columns as it has rasteriser threads, so that the threads finish together
 * (slot_of). Every run starts with no path in flight and sums of zero (the map's round
 * number, glsl/main.glsl read_state), and the host adds the runs' sums to the pixel's,
 * run after run in order: so a pixel's result depends on its samples and runs, never on
 * how many pixels the list has or where their slots are, and a tile of a render equals
 * the render's pixels to the bit (core/render.h). Reads of the
 * state are served from the host's sums plus the current slots (gpu_compact_read). When
 * the runs of all pixels need more slots than the textures have, they go in rounds, each
 * added to the host's sums before the next starts. */
#include <stdlib.h>
#include <string.h>

#include "gpu_internal.h"
#include "large_pages.h"

/* llvmpipe's rasteriser threads take the framebuffer's 64 x 64 tiles one at a time, so a
 * pass is done when the tile that started last is: slots laid row by row across a width of
 * 200 fill tiles 64, 64, 64 and 8 wide, and in a pass of one band of tiles one of two
 * threads does 128 columns' work, the other 72 (docs/performance.md, the log: compacted
 * passes in balanced tiles). */
#define RASTER_TILE 64

/* The slot (x, y) of slot index k in the state textures (width x height): in 4 x 2 blocks
 * of 8 slots (blocks), which is what llvmpipe shades as one vector (and a quarter of a
 * GPU's 8 x 4 warp), else row by row. Blocks go along the rows, or, with tile_columns
 * (>= 2), dealt in turn to that many RASTER_TILE-wide columns, each filled along its
 * rows, so that every column, and so every tile of a band, takes the same share. */
static void slot_of(int k, int width, bool blocks, int tile_columns, int *x, int *y)
{
    if (!blocks) {
        *x = k % width;
        *y = k / width;
        return;
    }
    int block = k >> 3, lane = k & 7;
    if (tile_columns >= 2) {
        int column = block % tile_columns, index = block / tile_columns, column_blocks = RASTER_TILE / 4;
        *x = column * RASTER_TILE + (index % column_blocks) * 4 + (lane & 3);
        *y = (index / column_blocks) * 2 + (lane >> 2);
        return;
    }
    int blocks_per_row = width / 4;
    *x = (block % blocks_per_row) * 4 + (lane & 3);
    *y = (block / blocks_per_row) * 2 + (lane >> 2);
}

/* The tile columns (slot_of) for slot_count slots in blocks in a width x height texture:
 * as many as the device has rasteriser threads, when it is llvmpipe with two or more,
 * the texture is that wide, every column takes at least a whole row of blocks and the
 * columns hold all the slots; else 0 (along the whole rows). RTSPHERES_TEST_TILE_COLUMNS
 * sets the columns wanted in place of the threads, for the test that the layout changes
 * no pixel (tests/render/test-adaptive.sh). */
static int balanced_tile_columns(const gpu_tracer *tracer, int slot_count, int width, int height)
{
    gpu_info device;
    gpu_get_info(tracer->context, &device);
    const char *test_columns = getenv("RTSPHERES_TEST_TILE_COLUMNS");
    int columns = test_columns != NULL ? atoi(test_columns) : device.software ? device.software_threads : 0;
    columns = columns > width / RASTER_TILE ? width / RASTER_TILE : columns;
    if (columns < 2 || slot_count < columns * RASTER_TILE * 2)
        return 0;
    int column_blocks = ((slot_count + 7) / 8 + columns - 1) / columns;
    int rows = (column_blocks + RASTER_TILE / 4 - 1) / (RASTER_TILE / 4) * 2;
    return rows <= (height & ~1) ? columns : 0;
}

/* Gives the bound 2D texture nearest filtering: an integer texture with the default
 * (mipmapped, linear) filter is incomplete, and texelFetch reads zeros from it. */
static void nearest_filtering(void)
{
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

/* The state index of sums[] for TRACER_STATE_ACCUMULATED, _STATISTICS, _SQUARES; -1 for
 * the others, and for the squares where the tracer keeps none (gpu.h GPU_OMIT_SQUARES). */
static int sums_index(const gpu_tracer *tracer, int state)
{
    if (state >= tracer->state_count)
        return -1;
    return state == TRACER_STATE_ACCUMULATED ? 0 : state == TRACER_STATE_STATISTICS ? 1
         : state == TRACER_STATE_SQUARES     ? 2 : -1;
}

/* Reads the round's slots of one (float) state texture of the latest set (used_width x
 * used_height texels, rows from the bottom) into out (4 floats a texel). */
static void read_slots(gpu_tracer *tracer, int state, float *out)
{
    gpu_compact *c = &tracer->compact;
    size_t bytes = (size_t)c->used_width * c->used_height * 16;
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureSubImage(tracer->state_textures[tracer->current][state], 0, 0, 0, 0, c->used_width, c->used_height,
                         1, GL_RGBA, GL_FLOAT, (GLsizei)bytes, out);
}

/* Adds the round's sums of state (sums_index) to target (4 floats a pixel, rows from the
 * top), run after run. RT_ERROR_RUNTIME when memory runs out. */
static rt_status add_round(gpu_tracer *tracer, int state, float *target, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    size_t texels = (size_t)c->used_width * c->used_height;
    float *slots = large_pages_alloc(texels * 16);
    if (slots == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading the compacted state");
    read_slots(tracer, state, slots);
    /* Slot k + r * count is run first_run + r of pixel k: in slot order, each pixel's runs
     * are added in run order. */
    int slot_count = c->round_runs * c->count;
    for (int k = 0; k < slot_count; k++) {
        int x, y;
        slot_of(k, tracer->width, c->blocks, c->tile_columns, &x, &y);
        if (c->slot_map[((size_t)y * tracer->width + x) * 4] == TRACER_NO_PIXEL)
            continue;
        size_t texel = (size_t)y * c->used_width + x, pixel = c->pixels[k % c->count];
        for (int i = 0; i < 4; i++)
            target[pixel * 4 + i] += slots[texel * 4 + i];
    }
    free(slots);
    return RT_OK;
}

/* Adds the finished round to the host's sums. */
static rt_status commit_round(gpu_tracer *tracer, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    rt_status status = RT_OK;
    for (int state = 0; state < TRACER_STATE_COUNT && status == RT_OK; state++) {
        int index = sums_index(tracer, state);
        if (index >= 0)
            status = add_round(tracer, state, c->sums[index], error);
    }
    return status == RT_OK ? gpu_check_gl("reading the compacted state", error) : status;
}

/* Lays out the runs first_run and on of the list in the slots (as many as fit) and
 * uploads the pixel map. */
static rt_status start_round(gpu_tracer *tracer, int first_run, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    int width = tracer->width, height = tracer->height;
    /* The slots are the state textures' texels, which the host's sums have made free: in
     * 4 x 2 blocks when the round fits in the whole blocks they hold. */
    size_t capacity = (size_t)width * height, block_capacity = (size_t)(width & ~3) * (height & ~1);
    /* For the test that rounds add up as one round does (tests/render/test-adaptive.sh):
     * RTSPHERES_TEST_COMPACT_SLOTS lowers, never raises, the slots a round may use. */
    const char *test_slots = getenv("RTSPHERES_TEST_COMPACT_SLOTS");
    if (test_slots != NULL && atoi(test_slots) > 0 && (size_t)atoi(test_slots) < block_capacity)
        capacity = block_capacity = (size_t)atoi(test_slots);
    c->blocks = block_capacity >= (size_t)c->count;
    size_t fit = (c->blocks ? block_capacity : capacity) / (size_t)c->count;
    int round_runs = c->runs - first_run;
    round_runs = fit < 1 ? 1 : (size_t)round_runs > fit ? (int)fit : round_runs;
    int slot_count = round_runs * c->count;
    c->first_run = first_run;
    c->round_runs = round_runs;
    /* A new round number tells the slots' old state from the round's (glsl/main.glsl
     * read_state): cheaper than clearing them (8 textures: about 8 ms on llvmpipe). */
    c->round = c->round == UINT32_MAX ? 1 : c->round + 1;
    /* The region the slots take: rows from the bottom (a block row is 2), the whole width
     * (or the tile columns) once they fill a row. Only its rows of the map are written and
     * uploaded: nothing outside it is drawn or read. */
    c->tile_columns = c->blocks ? balanced_tile_columns(tracer, slot_count, width, height) : 0;
    int row_slots = c->blocks ? (width / 4) * 8 : width, used_x, used_y;
    if (c->tile_columns >= 2)
        used_x = c->tile_columns * RASTER_TILE;
    else if (slot_count >= row_slots)
        used_x = c->blocks ? (width / 4) * 4 : width;
    else
        used_x = c->blocks ? (slot_count + 7) / 8 * 4 : slot_count;
    /* The last slot of slot 0's column, the tallest (blocks are dealt to it first). */
    int tallest_last = slot_count - 1;
    if (c->tile_columns >= 2)
        tallest_last = tallest_last / 8 / c->tile_columns * c->tile_columns * 8;
    slot_of(tallest_last, width, c->blocks, c->tile_columns, &(int){0}, &used_y);
    used_y = c->blocks ? (used_y | 1) + 1 : used_y + 1;
    for (size_t i = 0; i < (size_t)width * used_y; i++) {
        c->slot_map[i * 4] = TRACER_NO_PIXEL;
        c->slot_map[i * 4 + 1] = c->slot_map[i * 4 + 2] = c->slot_map[i * 4 + 3] = 0;
    }
    for (int k = 0; k < slot_count; k++) {
        int sx, sy;
        slot_of(k, width, c->blocks, c->tile_columns, &sx, &sy);
        uint64_t run = (uint64_t)(first_run + k / c->count);
        uint64_t start = c->list_start[k % c->count], limit = c->list_limit[k % c->count];
        if (limit <= start)
            continue;
        /* Run r of R covers samples start + (limit - start) r / R up to the next one's. */
        uint32_t first = (uint32_t)(start + (limit - start) * run / (uint64_t)c->runs);
        uint32_t end = (uint32_t)(start + (limit - start) * (run + 1) / (uint64_t)c->runs);
        if (first == end)
            continue;
        /* Rows from the top in the list, from the bottom in the framebuffer. */
        uint32_t pixel = c->pixels[k % c->count];
        uint32_t x = pixel % (uint32_t)width, y = pixel / (uint32_t)width;
        uint32_t *texel = c->slot_map + ((size_t)sy * width + sx) * 4;
        texel[0] = x | ((uint32_t)(height - 1) - y) << TRACER_PIXEL_MAP_SHIFT;
        texel[1] = first;
        texel[2] = end;
        texel[3] = c->round;
    }
    /* Draws are cut to the rows the round's slots take, since a vector of empty slots is
     * not free on llvmpipe (its loops run once, masked). */
    c->used_width = used_x;
    c->used_height = used_y;
    glBindTexture(GL_TEXTURE_2D, c->pixel_map);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, used_y, GL_RGBA_INTEGER, GL_UNSIGNED_INT, c->slot_map);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    return gpu_check_gl("compacting the pass state", error);
}

void gpu_compact_note_full_read(gpu_tracer *tracer, int state, const float *sums)
{
    gpu_compact *c = &tracer->compact;
    int index = sums_index(tracer, state);
    if (c->limits == NULL || c->sums[0] != NULL || index < 0)
        return;
    size_t bytes = (size_t)tracer->width * tracer->height * 4 * sizeof(float);
    if (c->full_copies[index] == NULL)
        c->full_copies[index] = large_pages_alloc(bytes);
    if (c->full_copies[index] != NULL) {
        memcpy(c->full_copies[index], sums, bytes);
        c->full_copy_passes[index] = tracer->passes;
    }
}

rt_status gpu_compact_read(gpu_tracer *tracer, int state, float *out, bool *compacted, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    int index = sums_index(tracer, state);
    *compacted = c->sums[0] != NULL && index >= 0;
    if (!*compacted)
        return RT_OK;
    memcpy(out, c->sums[index], (size_t)tracer->width * tracer->height * 4 * sizeof *out);
    return c->count > 0 ? add_round(tracer, state, out, error) : RT_OK;
}

rt_status gpu_compact_next_round(gpu_tracer *tracer, bool *next, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    *next = c->count > 0 && c->first_run + c->round_runs < c->runs;
    if (!*next)
        return RT_OK;
    rt_status status = commit_round(tracer, error);
    return status == RT_OK ? start_round(tracer, c->first_run + c->round_runs, error) : status;
}

/* Makes the host's sums from the full state textures (the first list). */
static rt_status start_host_sums(gpu_tracer *tracer, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    size_t pixels = (size_t)tracer->width * tracer->height;
    /* What a read since the last pass took from the full state (the check's, before this
     * list) is not read again: a read-back costs llvmpipe about 4 ms a 640 KB texture. */
    for (int state = 0; state < TRACER_STATE_COUNT; state++) {
        int index = sums_index(tracer, state);
        if (index < 0)
            continue;
        if (c->full_copies[index] != NULL && c->full_copy_passes[index] == tracer->passes) {
            c->sums[index] = c->full_copies[index];
            c->full_copies[index] = NULL;
        } else {
            c->sums[index] = large_pages_alloc(pixels * 4 * sizeof(float));
            if (c->sums[index] != NULL && gpu_read_full_state(tracer, state, c->sums[index], error) != RT_OK) {
                free(c->sums[index]);
                c->sums[index] = NULL;
            }
        }
    }
    for (int i = 0; i < 3; i++) {
        free(c->full_copies[i]);
        c->full_copies[i] = NULL;
    }
    bool squares_kept = tracer->state_count > TRACER_STATE_SQUARES;
    if (c->sums[0] == NULL || c->sums[1] == NULL || (c->sums[2] == NULL && squares_kept)) {
        for (int i = 0; i < 3; i++) {
            free(c->sums[i]);
            c->sums[i] = NULL;
        }
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the compacted passes' sums");
    }
    c->slot_map = large_pages_alloc(pixels * 4 * sizeof *c->slot_map);
    if (c->slot_map == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the pixel map");
    glGenTextures(1, &c->pixel_map);
    glBindTexture(GL_TEXTURE_2D, c->pixel_map);
    nearest_filtering();
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32UI, tracer->width, tracer->height);
    return gpu_check_gl("reading the state for compacted passes", error);
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

rt_status gpu_tracer_set_sample_limits(gpu_tracer *tracer, const uint32_t *limits, rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    size_t row = (size_t)tracer->width, pixels = row * tracer->height;
    /* The limits so far are the samples every pixel has started once a pass reports none
     * unfinished, which is when new ones are set (gpu.h): where compacted runs begin.
     * Before any limits: none, or samples_per_pixel once passes have run. */
    uint32_t most = tracer->parameters.shader.samples_per_pixel;
    bool first = c->limits == NULL;
    gpu_uncull(tracer);   /* a finished pixel may have samples to take again */
    if (first) {
        c->limits = large_pages_alloc(pixels * sizeof *c->limits);
        c->started = large_pages_alloc(pixels * sizeof *c->started);
    }
    uint32_t *bottom_up = large_pages_alloc(pixels * sizeof *bottom_up);
    if (bottom_up == NULL || c->limits == NULL || c->started == NULL) {
        free(bottom_up);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the sample limits");
    }
    for (size_t i = 0; i < pixels; i++)
        c->started[i] = first ? (tracer->passes == 0 ? 0 : most) : c->limits[i] > most ? most : c->limits[i];
    memcpy(c->limits, limits, pixels * sizeof *limits);
    for (int y = 0; y < tracer->height; y++)
        memcpy(bottom_up + (size_t)y * row, limits + (size_t)(tracer->height - 1 - y) * row, row * sizeof *limits);
    glBindTexture(GL_TEXTURE_2D, tracer->sample_limits);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, tracer->width, tracer->height, GL_RED_INTEGER, GL_UNSIGNED_INT, bottom_up);
    free(bottom_up);
    return gpu_check_gl("setting the sample limits", error);
}

rt_status gpu_tracer_set_pass_pixels(gpu_tracer *tracer, const uint32_t *pixels, int count, int runs,
                                     rt_error *error)
{
    gpu_compact *c = &tracer->compact;
    if (count <= 0 || pixels == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: a compacted pass needs at least one pixel");
    gpu_uncull(tracer);   /* the slots are the state textures' texels: no pixel's depth applies */
    rt_status status = c->sums[0] == NULL ? start_host_sums(tracer, error)
                       : c->count > 0    ? commit_round(tracer, error)
                                         : RT_OK;
    c->count = 0;
    if (status != RT_OK)
        return status;
    uint32_t *list = realloc(c->pixels, (size_t)count * 3 * sizeof *list);
    if (list == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory for the pixel list of %d pixels", count);
    c->pixels = list;
    c->list_start = list + count;
    c->list_limit = list + 2 * (size_t)count;
    /* Each pixel's samples from here to its limit: fixed for the list's rounds. */
    uint32_t most = tracer->parameters.shader.samples_per_pixel;
    for (int k = 0; k < count; k++) {
        list[k] = pixels[k];
        c->list_start[k] = c->started[pixels[k]];
        uint32_t limit = c->limits != NULL ? c->limits[pixels[k]] : most;
        c->list_limit[k] = limit > most ? most : limit;
    }
    /* Light group layers are added to at the pixel itself (glsl/light_groups.glsl): two
     * slots of one pixel in one pass would lose each other's additions. */
    c->runs = runs < 1 || tracer->light_group_texture != 0 || tracer->direct_emission_texture != 0 ? 1 : runs;
    c->count = count;
    status = start_round(tracer, 0, error);
    if (status != RT_OK)
        c->count = 0;
    return status;
}

void gpu_compact_destroy(gpu_tracer *tracer)
{
    gpu_compact *c = &tracer->compact;
    glDeleteTextures(1, &c->pixel_map);
    free(c->pixels);
    free(c->slot_map);
    for (int i = 0; i < 3; i++) {
        free(c->sums[i]);
        free(c->full_copies[i]);
    }
    free(c->started);
    free(c->limits);
    memset(c, 0, sizeof *c);
}
