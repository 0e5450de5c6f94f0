/* render_job_tiles.c: images too large for the device or the memory budget, rendered in
 * tiles and streamed into their output (render_job.h, "Tiles"). Cycles renders large
 * images the same way: tiles into a file on disk, the output written from it at the end,
 * when its metadata (samples, time, why it stopped) is known; an image file's header
 * comes first, so the output cannot be written while the tiles are still rendering. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "adaptive.h"
#include "clock.h"
#include "image_io.h"
#include "pack.h"
#include "postprocess.h"
#include "render_denoise.h"
#include "render_job_internal.h"

/* Tiles of fewer rows than this are avoided while narrower tiles can have them: each
 * tile costs a packing and a tracer's set-up. */
#define TILE_MIN_ROWS 16

uint64_t render_job_default_memory_budget(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
    uint64_t quarter = pages > 0 && page_size > 0 ? (uint64_t)pages * (uint64_t)page_size / 4
                                                  : RENDER_JOB_DEFAULT_MEMORY_BUDGET_MAX;
    return quarter < RENDER_JOB_DEFAULT_MEMORY_BUDGET_MAX ? quarter : RENDER_JOB_DEFAULT_MEMORY_BUDGET_MAX;
}

/* Writes bytes as a size for messages ("512 KiB", "1.5 GiB") into text (32 bytes). */
static const char *size_text(double bytes, char text[32])
{
    static const char *const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    int unit = 0;
    while (bytes >= 1024.0 && unit < 4) {
        bytes /= 1024.0;
        unit++;
    }
    snprintf(text, 32, bytes < 10 && unit > 0 ? "%.1f %s" : "%.0f %s", bytes, units[unit]);
    return text;
}

void job_name_memory_budget(const job_image *image, rt_error *error)
{
    const render_job *job = image->run->job;
    size_t length = strlen(error->message);
    const char *tail = "renders the image in smaller tiles";
    if (length < strlen(tail) || strcmp(error->message + length - strlen(tail), tail) != 0)
        return;
    char budget[32];
    size_text((double)(job->memory_budget ? job->memory_budget : render_job_default_memory_budget()), budget);
    snprintf(error->message + length, sizeof error->message - length, " (this render's budget: %s%s)", budget,
             job->memory_budget ? "" : ", the default");
}

/* The refusals of render_job.h's "Tiles": the option the tiled job asks for that tiles
 * cannot do, and what to do instead; NULL when there is none. */
static const char *unsupported_under_tiles(const render_job *job, const render_options *options,
                                           const char **instead)
{
    *instead = "raise --memory-budget if the machine has the memory, or render a smaller image";
    if (job->checkpoint_seconds > 0 || job->resume_path != NULL) {
        *instead = "split the work with --tile i/n or --shard (each part its own file, joined by `rtspheres "
                   "merge`), or raise --memory-budget";
        return job->resume_path != NULL ? "--resume continues a partial file of the whole image"
                                        : "--checkpoint writes a partial file of the whole image";
    }
    if (options->preview != NULL)
        return "--display sends the whole image";
    return NULL;
}

rt_status job_plan_tiles(const job_image *image, const render_options *options, job_tile_grid *grid,
                         rt_error *error)
{
    const render_job *job = image->run->job;
    const scene_render_settings *settings = &image->scene.render;
    static gpu_info device;      /* large (its device list); one job plans at a time */
    device.max_tile_side = INT_MAX;   /* no context (a test of what fails before the GPU) */
    if (image->run->context != NULL)
        gpu_get_info(image->run->context, &device);
    uint64_t budget = job->memory_budget ? job->memory_budget : render_job_default_memory_budget();
    memset(grid, 0, sizeof *grid);
    grid->count = grid->columns = grid->rows = 1;
    grid->budget = budget;
    const int *window = image->plan.window;
    int width = window[2] - window[0], height = window[3] - window[1];
    int reach = options->noise_threshold > 0
                    ? adaptive_reach(options->min_spp ? options->min_spp : ADAPTIVE_DEFAULT_MIN_SPP,
                                     (uint32_t)settings->samples_per_pixel)
                    : 0;
    uint64_t per_pixel = render_bytes_per_pixel(options, image->scene.light_group_count);
    /* What the untiled render would trace: the window and its margins within the image. */
    int traced_width = (window[2] + reach < settings->width ? window[2] + reach : settings->width)
                       - (window[0] - reach > 0 ? window[0] - reach : 0);
    int traced_height = (window[3] + reach < settings->height ? window[3] + reach : settings->height)
                        - (window[1] - reach > 0 ? window[1] - reach : 0);
    int side = device.max_tile_side;
    double untiled_bytes = (double)traced_width * traced_height * (double)per_pixel;
    grid->tile_width = width;
    grid->tile_height = height;
    if (traced_width <= side && traced_height <= side && untiled_bytes <= (double)budget)
        return RT_OK;
    static char reason[256];
    if (traced_width > side || traced_height > side)
        snprintf(reason, sizeof reason, "it is larger than the device's %d pixels a side", side);
    else {
        char need[32], have[32];
        snprintf(reason, sizeof reason, "its render would take about %s, over the memory budget of %s",
                 size_text(untiled_bytes, need), size_text((double)budget, have));
    }
    grid->reason = reason;
    if (side - 2 * reach < 1)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "the device's %d pixels a side leave no room for a tile inside adaptive sampling's "
                            "margins of %d pixels", side, reach);
    /* The widest tiles the device takes, as many rows as the budget allows; narrower
     * when that is fewer than TILE_MIN_ROWS. */
    int tile_width = width < side - 2 * reach ? width : side - 2 * reach;
    int most_rows = height < side - 2 * reach ? height : side - 2 * reach;
    int tile_height = 0;
    for (;;) {
        double rows = (double)budget / (double)per_pixel / (tile_width + 2 * reach) - 2 * reach;
        tile_height = rows >= most_rows ? most_rows : rows >= 1 ? (int)rows : 0;
        if (tile_height >= TILE_MIN_ROWS || tile_height >= most_rows || tile_width == 1)
            break;
        tile_width = (tile_width + 1) / 2;
    }
    if (tile_height < 1) {
        char have[32], least[32];
        return rt_error_set(error, RT_ERROR_INPUT,
                            "--memory-budget %s is too small for even a one-pixel tile of this render (%s)",
                            size_text((double)budget, have),
                            size_text((double)(1 + 2 * reach) * (1 + 2 * reach) * (double)per_pixel, least));
    }
    grid->columns = (width + tile_width - 1) / tile_width;
    grid->rows = (height + tile_height - 1) / tile_height;
    grid->tile_width = (width + grid->columns - 1) / grid->columns;
    grid->tile_height = (height + grid->rows - 1) / grid->rows;
    grid->count = grid->columns * grid->rows;
    const char *instead = NULL;
    const char *refused = unsupported_under_tiles(job, options, &instead);
    if (refused != NULL && grid->count > 1)
        return rt_error_set(error, RT_ERROR_INPUT, "%s, and this %dx%d image is rendered in %d tiles (%s): %s",
                            refused, width, height, grid->count, reason, instead);
    return RT_OK;
}

/* The tiled render in progress: the spool file and what the tiles so far add up to. */
typedef struct tile_run {
    job_image *image;
    int fd;                      /* the spool: window-sized, channels floats per pixel */
    char spool[RENDER_JOB_PATH_MAX];
    int filtered_fd;             /* --denoise, --blur: the filtered R, G, B, 3 floats a pixel */
    char filtered_spool[RENDER_JOB_PATH_MAX];
    int channels;                /* R, G, B, samples, the AOV/variance layers, the light groups */
    char names[IMAGE_MAX_CHANNELS][IMAGE_CHANNEL_NAME_MAX];
    render_result total;         /* the tiles' figures summed (no pixels) */
    bool any_time, any_noise;
    /* Progress over the whole image: the finished tiles' samples and passes added to the
     * tile's own. */
    uint64_t samples_before, samples_total;
    int passes_before;
    double start;
} tile_run;

/* render_options.progress of a tile: the whole image's progress to the job's callback. */
static void tile_progress(void *context, const render_progress *progress)
{
    tile_run *run = context;
    const render_job_callbacks *callbacks = &run->image->run->callbacks;
    render_progress whole = *progress;
    whole.samples_done += run->samples_before;
    whole.samples_total = run->samples_total;
    if (whole.samples_done > whole.samples_total)   /* adaptive margins are traced twice */
        whole.samples_done = whole.samples_total;
    whole.passes += run->passes_before;
    whole.elapsed_seconds = clock_seconds() - run->start;
    callbacks->progress(callbacks->user, &whole);
}

/* Opens the spool file beside output: created, then unlinked at once, so that nothing is
 * left behind whatever ends the process. */
static rt_status open_spool(const char *output, char path[RENDER_JOB_PATH_MAX], int *fd, rt_error *error)
{
    const char *slash = strrchr(output, '/');
    int directory = slash != NULL ? (int)(slash - output + 1) : 0;
    snprintf(path, RENDER_JOB_PATH_MAX, "%.*s.%s.tiles-XXXXXX", directory, output, output + directory);
    *fd = mkstemp(path);
    if (*fd < 0)
        return rt_error_set(error, RT_ERROR_RUNTIME, "cannot create the tile spool file '%s': %s", path,
                            strerror(errno));
    unlink(path);
    return RT_OK;
}

/* Writes or reads (write false) bytes at offset of the spool fd (run->fd or
 * run->filtered_fd), all of them. */
static rt_status spool_io(tile_run *run, int fd, bool write, void *bytes, size_t size, off_t offset, rt_error *error)
{
    char *at = bytes;
    while (size > 0) {
        ssize_t n = write ? pwrite(fd, at, size, offset) : pread(fd, at, size, offset);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            /* The filtered colour's spool holds 3 floats a pixel, the tiles' all channels. */
            const job_image *image = run->image;
            bool filtered = fd == run->filtered_fd;
            double bytes_needed = (double)(image->plan.window[2] - image->plan.window[0])
                                  * (image->plan.window[3] - image->plan.window[1])
                                  * (filtered ? 3 : run->channels) * 4;
            char needed[32];
            return rt_error_set(error, RT_ERROR_RUNTIME,
                                "cannot %s the %s beside %s (%s on disk for the whole image): %s",
                                write ? "write" : "read", filtered ? "filtered colour's spool" : "tile spool",
                                image->plan.output, size_text(bytes_needed, needed),
                                n < 0 ? strerror(errno) : "the file is short");
        }
        at += n;
        size -= (size_t)n;
        offset += n;
    }
    return RT_OK;
}

/* The channel layout of a tile's result: its image, AOV/variance layers and light groups,
 * as the untiled writer joins them. The first tile's sets it; later ones must match. */
static rt_status take_layout(tile_run *run, const render_result *result, rt_error *error)
{
    const rt_image *parts[3] = {&result->image, &result->aovs, &result->light_groups};
    int channels = 0;
    for (int p = 0; p < 3; p++)
        channels += parts[p]->pixels != NULL ? parts[p]->channels : 0;
    if (channels > IMAGE_MAX_CHANNELS)
        return rt_error_set(error, RT_ERROR_INPUT, "an image of %d channels is more than the %d an output holds",
                            channels, IMAGE_MAX_CHANNELS);
    if (run->channels != 0)
        return channels == run->channels ? RT_OK
                                         : rt_error_set(error, RT_ERROR_RUNTIME,
                                                        "the tiles of one image have %d and %d channels",
                                                        run->channels, channels);
    run->channels = channels;
    int c = 0;
    for (int p = 0; p < 3; p++)
        for (int k = 0; parts[p]->pixels != NULL && k < parts[p]->channels; k++, c++) {
            const char *name = parts[p]->channel_names[k];
            static const char *const rgba[4] = {"R", "G", "B", "A"};
            snprintf(run->names[c], IMAGE_CHANNEL_NAME_MAX, "%s",
                     name[0] != '\0' ? name : p == 0 && k < 4 ? rgba[k] : "");
        }
    return RT_OK;
}

/* Writes a finished tile's pixels (result->region of the full image) into the spool. */
static rt_status spool_tile(tile_run *run, const render_result *result, rt_error *error)
{
    rt_status status = take_layout(run, result, error);
    if (status != RT_OK)
        return status;
    const int *window = run->image->plan.window;
    int window_width = window[2] - window[0];
    int width = result->image.width, height = result->image.height;
    float *row = malloc((size_t)width * run->channels * sizeof *row);
    if (row == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "out of memory for a row of a %dx%d tile", width, height);
    const rt_image *parts[3] = {&result->image, &result->aovs, &result->light_groups};
    for (int y = 0; y < height && status == RT_OK; y++) {
        for (int x = 0; x < width; x++) {
            float *out = row + (size_t)x * run->channels;
            for (int p = 0; p < 3; p++) {
                const rt_image *part = parts[p];
                if (part->pixels == NULL)
                    continue;
                memcpy(out, part->pixels + ((size_t)y * width + x) * part->channels, part->channels * sizeof *out);
                out += part->channels;
            }
        }
        size_t first = (size_t)(result->region[1] + y - window[1]) * window_width + (result->region[0] - window[0]);
        status = spool_io(run, run->fd, true, row, (size_t)width * run->channels * sizeof *row,
                          (off_t)(first * run->channels * sizeof *row), error);
    }
    free(row);
    return status;
}

/* Adds a tile's figures to the image's. */
static void add_tile(tile_run *run, const render_result *result, int tile)
{
    render_result *total = &run->total;
    if (tile == 0) {
        *total = *result;
        total->image = total->aovs = total->light_groups = (rt_image){0};
    } else {
        total->samples += result->samples;
        total->path_segments += result->path_segments;
        total->steady_seconds += result->steady_seconds;
        total->steady_samples += result->steady_samples;
        total->passes += result->passes;
        total->culled_passes += result->culled_passes;
        total->samples_min = result->samples_min < total->samples_min ? result->samples_min : total->samples_min;
        total->samples_max = result->samples_max > total->samples_max ? result->samples_max : total->samples_max;
    }
    run->any_time = run->any_time || result->stop_reason == RENDER_STOP_TIME;
    run->any_noise = run->any_noise || result->stop_reason == RENDER_STOP_NOISE;
    run->samples_before = total->samples;
    run->passes_before = total->passes;
}

/* --denoise and --blur of the output. They read pixels beyond a pixel's own
 * (postprocess.h, "reach"), so the image is filtered in square blocks, each read from the
 * spool with halo more pixels on every side (within the image), and each block's own
 * pixels of the filtered colour go to a second spool (filter_blocks); the output's bands
 * then take their R, G, B from it: the untiled image's pixels bit for bit, in the order
 * postprocess_result() (render_job.c) applies them, with memory for one block and one
 * band whatever the image's width. */
typedef struct band_postprocess {
    bool denoise;
    float blur_sigma;            /* 0: no blur */
    int blur_passes;
    int halo;                    /* the pixels read beyond a block on each side */
    int block;                   /* a block's side */
    rt_image source;             /* a block and its halo, as spooled */
    rt_image colour;             /* its R, G, B, filtered; then a band's */
    rt_image raw;                /* a band as spooled */
} band_postprocess;

/* The side of the filter's blocks: the largest whose block and halo take about a
 * quarter of budget at bytes_per_pixel (the spooled channels, the filtered colour and
 * the denoiser's own arrays; the tiles' device memory is free by then), at least 64 and at
 * most 1024 pixels. The larger the block, the less of the work is its halo's: (side + 2
 * halo)^2 / side^2 of the image's, 1.4x at the default budget and 76 pixels of halo. */
static int filter_block_side(uint64_t budget, size_t bytes_per_pixel, int halo)
{
    double side = sqrt((double)budget / 4.0 / (double)bytes_per_pixel) - 2.0 * halo;
    return side < 64 ? 64 : side > 1024 ? 1024 : (int)side;
}

/* Filters the spooled image (width x height) block by block into run->filtered_fd (see
 * band_postprocess). */
static rt_status filter_blocks(tile_run *run, band_postprocess *post, int width, int height, rt_error *error)
{
    size_t channels = (size_t)run->channels, spool_row = (size_t)width * channels * sizeof(float);
    rt_status status = RT_OK;
    for (int by = 0; by < height && status == RT_OK; by += post->block)
        for (int bx = 0; bx < width && status == RT_OK; bx += post->block) {
            int x1 = bx + post->block < width ? bx + post->block : width;
            int y1 = by + post->block < height ? by + post->block : height;
            int sx0 = bx - post->halo > 0 ? bx - post->halo : 0, sy0 = by - post->halo > 0 ? by - post->halo : 0;
            int sx1 = x1 + post->halo < width ? x1 + post->halo : width;
            int sy1 = y1 + post->halo < height ? y1 + post->halo : height;
            rt_image *source = &post->source, *colour = &post->colour;
            source->width = colour->width = sx1 - sx0;
            source->height = colour->height = sy1 - sy0;
            for (int y = sy0; y < sy1 && status == RT_OK; y++)
                status = spool_io(run, run->fd, false, source->pixels + (size_t)(y - sy0) * source->width * channels,
                                  (size_t)source->width * channels * sizeof(float),
                                  (off_t)((size_t)y * spool_row + (size_t)sx0 * channels * sizeof(float)), error);
            size_t pixels = (size_t)source->width * source->height;
            for (size_t i = 0; status == RT_OK && i < pixels; i++)
                memcpy(colour->pixels + 3 * i, source->pixels + i * channels, 3 * sizeof(float));
            if (status == RT_OK && post->denoise)
                status = render_denoise(colour, source, source, error);
            if (status == RT_OK && post->blur_sigma > 0)
                status = postprocess_gaussian_blur(colour, post->blur_sigma, post->blur_passes, error);
            for (int y = by; y < y1 && status == RT_OK; y++)
                status = spool_io(run, run->filtered_fd, true,
                                  colour->pixels + ((size_t)(y - sy0) * colour->width + (size_t)(bx - sx0)) * 3,
                                  (size_t)(x1 - bx) * 3 * sizeof(float),
                                  (off_t)(((size_t)y * width + (size_t)bx) * 3 * sizeof(float)), error);
        }
    return status;
}

/* Reads the output's rows y .. y + band->height - 1 into band (the output's channels): as
 * spooled, or (post not NULL) with the filtered R, G, B of filter_blocks() and, with
 * --denoise, the spooled R, G, B after the spooled channels as noisy.R/G/B, as
 * render_job.c's denoise() appends them. */
static rt_status read_output_band(tile_run *run, band_postprocess *post, int y, rt_image *band, rt_error *error)
{
    size_t row_bytes = (size_t)band->width * run->channels * sizeof(float);
    if (post == NULL)
        return spool_io(run, run->fd, false, band->pixels, band->height * row_bytes, (off_t)((size_t)y * row_bytes),
                        error);
    size_t pixels = (size_t)band->width * band->height, colour_row = (size_t)band->width * 3 * sizeof(float);
    rt_status status = spool_io(run, run->fd, false, post->raw.pixels, band->height * row_bytes,
                                (off_t)((size_t)y * row_bytes), error);
    if (status == RT_OK)
        status = spool_io(run, run->filtered_fd, false, post->colour.pixels, band->height * colour_row,
                          (off_t)((size_t)y * colour_row), error);
    for (size_t i = 0; status == RT_OK && i < pixels; i++) {
        float *out = band->pixels + i * band->channels;
        const float *in = post->raw.pixels + i * run->channels;
        memcpy(out, in, run->channels * sizeof *out);
        memcpy(out, post->colour.pixels + 3 * i, 3 * sizeof *out);
        if (post->denoise)
            memcpy(out + run->channels, in, 3 * sizeof *out);
    }
    return status;
}

/* Streams the spool into the output (and the samples map), band by band, with the
 * final metadata. */
static rt_status write_from_spool(tile_run *run, rt_error *error)
{
    job_image *image = run->image;
    const render_job *job = image->run->job;
    const int *window = image->plan.window;
    int width = window[2] - window[0], height = window[3] - window[1];
    band_postprocess post = {.denoise = job->denoise, .blur_sigma = job->blur_sigma > 0 ? job->blur_sigma : 0,
                             .blur_passes = job->blur_passes > 0 ? job->blur_passes : 1};
    post.halo = (post.denoise ? render_denoise_reach() : 0) + postprocess_blur_reach(post.blur_sigma, post.blur_passes);
    bool filtered = post.denoise || post.blur_sigma > 0;
    rt_image layout = {.width = width, .height = height, .channels = run->channels + (post.denoise ? 3 : 0),
                       .x = window[0], .y = window[1], .full_width = image->scene.render.width,
                       .full_height = image->scene.render.height};
    memcpy(layout.channel_names, run->names, sizeof layout.channel_names);
    if (layout.channels > IMAGE_MAX_CHANNELS)
        return rt_error_set(error, RT_ERROR_INPUT, "an image of %d channels is more than the %d an output holds",
                            layout.channels, IMAGE_MAX_CHANNELS);
    for (int c = 0; post.denoise && c < 3; c++)
        snprintf(layout.channel_names[run->channels + c], IMAGE_CHANNEL_NAME_MAX, "noisy.%c", "RGB"[c]);
    render_output_metadata metadata;
    job_metadata_texts texts;
    job_image_metadata(image, image->plan.output, run->total.samples, run->total.stop_reason != RENDER_STOP_TIME, false, &run->total,
                       &metadata, &texts);
    render_output_stream *output = NULL;
    image_stream *map = NULL;
    rt_status status =
        render_output_stream_open(image->plan.output, &layout, &metadata, job_output_exposure(job), &output, error);
    if (status == RT_OK && job->samples_map != NULL) {
        rt_image map_layout = {.width = width, .height = height, .channels = 3};
        status = image_stream_open(job->samples_map, &map_layout, NULL, &map, error);
    }
    bool tonemap = image_format_of(image->plan.output) == IMAGE_FORMAT_EIGHT_BIT && job->tonemap != TONEMAP_CLAMP;
    /* A band: an eighth of the budget, with room for the writer's converted copy. */
    size_t row_bytes = (size_t)width * layout.channels * sizeof(float);
    uint64_t budget = job->memory_budget ? job->memory_budget : render_job_default_memory_budget();
    int band_rows = (int)(budget / 8 / row_bytes);
    band_rows = band_rows < 1 ? 1 : band_rows > height ? height : band_rows;
    rt_image band = {0}, colour = {0};
    if (status == RT_OK)
        status = image_create(&band, width, band_rows, layout.channels, error);
    if (status == RT_OK && filtered) {
        /* Per pixel of a block: the spooled channels, the filtered colour and about 28
         * floats of the denoiser's arrays (core/postprocess_denoise.c: 20 planes, 7 for the choice). */
        post.block = filter_block_side(budget, (size_t)run->channels * 4 + 12 + 112, post.halo);
        int block_width = post.block + 2 * post.halo < width ? post.block + 2 * post.halo : width;
        int block_height = post.block + 2 * post.halo < height ? post.block + 2 * post.halo : height;
        size_t block_pixels = (size_t)block_width * block_height, band_pixels = (size_t)width * band_rows;
        status = image_create(&post.source, block_width, block_height, run->channels, error);
        if (status == RT_OK)
            status = image_create(&post.colour, (int)(block_pixels > band_pixels ? block_pixels : band_pixels), 1, 3,
                                  error);
        if (status == RT_OK)
            status = image_create(&post.raw, width, band_rows, run->channels, error);
        if (status == RT_OK) {
            memcpy(post.source.channel_names, run->names, sizeof post.source.channel_names);
            status = open_spool(image->plan.output, run->filtered_spool, &run->filtered_fd, error);
        }
        if (status == RT_OK)
            status = filter_blocks(run, &post, width, height, error);
    }
    if (status == RT_OK && tonemap)
        status = image_create(&colour, width, band_rows, 3, error);
    for (int y = 0; y < height && status == RT_OK; y += band_rows) {
        int rows = height - y < band_rows ? height - y : band_rows;
        band.height = colour.height = rows;
        status = read_output_band(run, filtered ? &post : NULL, y, &band, error);
        size_t pixels = (size_t)width * rows;
        if (status == RT_OK && tonemap) {
            for (size_t i = 0; i < pixels; i++)
                memcpy(colour.pixels + 3 * i, band.pixels + i * layout.channels, 3 * sizeof(float));
            status = postprocess_tonemap(&colour, job->tonemap, (float)job->exposure, error);
            for (size_t i = 0; i < pixels && status == RT_OK; i++)
                memcpy(band.pixels + i * layout.channels, colour.pixels + 3 * i, 3 * sizeof(float));
        }
        if (status == RT_OK)
            status = render_output_stream_rows(output, &band, error);
        if (status == RT_OK && map != NULL) {
            rt_image rows_map;
            status = job_samples_map(&band, image->plan.samples_per_pixel, &rows_map, error);
            if (status == RT_OK) {
                status = image_stream_write_rows(map, &rows_map, error);
                image_free(&rows_map);
            }
        }
    }
    image_free(&band);
    image_free(&colour);
    image_free(&post.source);
    image_free(&post.colour);
    image_free(&post.raw);
    if (status == RT_OK) {
        status = render_output_stream_close(output, error);
        output = NULL;
    }
    if (status == RT_OK && map != NULL) {
        status = image_stream_close(map, error);
        map = NULL;
    }
    render_output_stream_abandon(output);
    image_stream_abandon(map);
    return status;
}

rt_status job_render_tiles(job_image *image, const render_options *options, const job_tile_grid *grid,
                           rt_error *error)
{
    job_run *owner = image->run;
    const render_job *job = owner->job;
    const render_job_callbacks *callbacks = &owner->callbacks;
    const int *window = image->plan.window;
    tile_run run = {.image = image, .fd = -1, .filtered_fd = -1, .start = clock_seconds()};
    run.samples_total = (uint64_t)(window[2] - window[0]) * (window[3] - window[1]) * image->plan.samples_per_pixel;
    rt_status status = open_spool(image->plan.output, run.spool, &run.fd, error);
    if (status != RT_OK)
        return status;
    if (callbacks->tiles_planned != NULL)
        callbacks->tiles_planned(callbacks->user, &image->plan, grid->columns, grid->rows, grid->tile_width,
                                 grid->tile_height, grid->reason);
    if (callbacks->render_started != NULL)
        callbacks->render_started(callbacks->user, &image->plan);
    /* Every tile packs the same scene: a job of one image has no BVH cache of its own, so
     * the tiles get one, and only the first builds the BVHs (pack.h, "The BVH cache"). A
     * cache that cannot be made costs only the rebuilds. */
    pack_bvh_cache *tile_cache = NULL;
    if (options->bvh_cache == NULL) {
        rt_error ignored;
        if (pack_bvh_cache_create(&tile_cache, &ignored) != RT_OK)
            tile_cache = NULL;
    }
    int tile = 0;
    for (int row = 0; row < grid->rows && status == RT_OK; row++) {
        for (int column = 0; column < grid->columns && status == RT_OK; column++, tile++) {
            render_options tile_options = *options;
            if (tile_cache != NULL)
                tile_options.bvh_cache = tile_cache;
            int *region = tile_options.region;
            region[0] = window[0] + column * grid->tile_width;
            region[1] = window[1] + row * grid->tile_height;
            region[2] = region[0] + grid->tile_width < window[2] ? region[0] + grid->tile_width : window[2];
            region[3] = region[1] + grid->tile_height < window[3] ? region[1] + grid->tile_height : window[3];
            /* The time limit shared out: tile k of n ends by start + limit * (k + 1) / n. */
            if (job->time_limit_seconds > 0)
                tile_options.deadline = image->start + job->time_limit_seconds * (tile + 1) / grid->count;
            if (callbacks->progress != NULL) {
                tile_options.progress = tile_progress;
                tile_options.progress_context = &run;
            }
            render_result result;
            status = render_scene(owner->context, &image->scene, &tile_options, &result, error);
            if (status == RT_ERROR_RUNTIME)
                job_name_memory_budget(image, error);
            if (status == RT_OK) {
                status = spool_tile(&run, &result, error);
                add_tile(&run, &result, tile);
            }
            if (status == RT_ERROR_INTERRUPTED)
                rt_error_set(error, RT_ERROR_INTERRUPTED,
                             "interrupted in tile %d of %d; a tiled render keeps no partial file, so nothing was "
                             "written and %s is as it was (split long renders with --tile i/n or --shard)",
                             tile + 1, grid->count, image->plan.output);
            image_free(&result.image);
            image_free(&result.aovs);
            image_free(&result.light_groups);
            image_free(&result.adaptive_state);
        }
    }
    pack_bvh_cache_free(tile_cache);
    run.total.seconds = clock_seconds() - run.start;
    run.total.stop_reason = run.any_time ? RENDER_STOP_TIME : run.any_noise ? RENDER_STOP_NOISE : RENDER_STOP_SAMPLES;
    memcpy(run.total.region, window, sizeof run.total.region);
    if (callbacks->render_finished != NULL)
        callbacks->render_finished(callbacks->user, &image->plan, status);
    if (status == RT_OK)
        status = write_from_spool(&run, error);
    close(run.fd);
    if (run.filtered_fd >= 0)
        close(run.filtered_fd);
    if (status != RT_OK)
        return status;
    /* A partial file of an earlier untiled run of this image is superseded too. */
    unlink(image->plan.partial);
    if (callbacks->image_written != NULL) {
        run.total.image.width = window[2] - window[0];
        run.total.image.height = window[3] - window[1];
        callbacks->image_written(callbacks->user, &image->plan, &run.total);
    }
    return RT_OK;
}
