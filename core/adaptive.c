/* adaptive.c: see adaptive.h. */
#include "adaptive.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "large_pages.h"
#include "luminance.h"

struct adaptive_sampler {
    int width, height;
    float threshold;
    uint32_t min_spp, max_spp;
    uint32_t *limits;            /* per pixel, rows top to bottom */
    uint8_t *going;              /* 1: the pixel still takes samples */
    uint8_t *unconverged;        /* scratch of adaptive_check */
    uint32_t checked_at, next_check;   /* the sample counts of the last check and the next */
    bool stopped_early;
    adaptive_noise noise;        /* of the last check */
};

float adaptive_pixel_error(float luminance_sum, float luminance_squares, uint32_t n)
{
    if (n < 2)
        return INFINITY;
    double mean = (double)luminance_sum / n;
    double variance = ((double)luminance_squares - n * mean * mean) / (n - 1);
    if (variance < 0)
        variance = 0;  /* float rounding of the sums */
    double floor = mean > ADAPTIVE_LUMINANCE_FLOOR ? mean : ADAPTIVE_LUMINANCE_FLOOR;
    return (float)(sqrt(variance / n) / floor);
}

uint32_t adaptive_next_check(uint32_t samples, uint32_t min_spp, uint32_t max_spp)
{
    uint64_t next = samples < min_spp ? min_spp : (uint64_t)samples + (min_spp > samples / 4 ? min_spp : samples / 4);
    return next > max_spp ? max_spp : (uint32_t)next;
}

int adaptive_reach(uint32_t min_spp, uint32_t max_spp)
{
    int checks = 0;
    uint32_t n = adaptive_next_check(0, min_spp, max_spp);
    for (; n < max_spp; n = adaptive_next_check(n, min_spp, max_spp))
        checks++;
    return checks;
}

void adaptive_free(adaptive_sampler *sampler)
{
    if (sampler == NULL)
        return;
    free(sampler->limits);
    free(sampler->going);
    free(sampler->unconverged);
    free(sampler);
}

rt_status adaptive_create(int width, int height, float threshold, uint32_t min_spp, uint32_t max_spp,
                          adaptive_sampler **out, rt_error *error)
{
    *out = NULL;
    adaptive_sampler *sampler = calloc(1, sizeof *sampler);
    size_t pixels = (size_t)width * height;
    if (sampler != NULL) {
        sampler->limits = large_pages_alloc(pixels * sizeof *sampler->limits);
        sampler->going = large_pages_alloc(pixels);
        sampler->unconverged = large_pages_alloc(pixels);
    }
    if (sampler == NULL || !sampler->limits || !sampler->going || !sampler->unconverged) {
        adaptive_free(sampler);
        return rt_error_set(error, RT_ERROR_RUNTIME, "RENDER: out of memory for adaptive sampling");
    }
    sampler->width = width;
    sampler->height = height;
    sampler->threshold = threshold;
    sampler->max_spp = max_spp;
    sampler->min_spp = min_spp == 0 ? ADAPTIVE_DEFAULT_MIN_SPP : min_spp > max_spp ? max_spp : min_spp;
    uint32_t first = adaptive_next_check(0, sampler->min_spp, max_spp);
    for (size_t i = 0; i < pixels; i++)
        sampler->limits[i] = first;
    sampler->next_check = first;
    memset(sampler->going, 1, pixels);
    *out = sampler;
    return RT_OK;
}

/* True when count is one of the schedule's check counts; *before (when not NULL) gets the
 * check before it (0 for the first) and *checks (when not NULL) how many come before it. */
static bool is_check_count(const adaptive_sampler *sampler, uint32_t count, uint32_t *before, int *checks)
{
    uint32_t previous = 0;
    int made = 0;
    for (uint32_t n = adaptive_next_check(0, sampler->min_spp, sampler->max_spp);;
         n = adaptive_next_check(n, sampler->min_spp, sampler->max_spp)) {
        if (n == count) {
            if (before != NULL)
                *before = previous;
            if (checks != NULL)
                *checks = made;
            return true;
        }
        if (n > count || n >= sampler->max_spp)
            return false;
        previous = n;
        made++;
    }
}

rt_status adaptive_resume(adaptive_sampler *sampler, const uint32_t *limits, const uint32_t *samples,
                          rt_error *error)
{
    size_t pixels = (size_t)sampler->width * sampler->height;
    uint32_t next = 0;
    for (size_t i = 0; i < pixels; i++)
        next = limits[i] > next ? limits[i] : next;
    uint32_t before = 0;
    int checks = 0;
    if (!is_check_count(sampler, next, &before, &checks))
        return rt_error_set(error, RT_ERROR_INPUT,
                            "RENDER: the partial render's adaptive state waits for a check at %u samples, which is "
                            "not of this render's schedule (--min-spp %u, --spp %u): resume with the options it "
                            "was rendered with", next, sampler->min_spp, sampler->max_spp);
    bool stopped_early = false;
    for (size_t i = 0; i < pixels; i++) {
        bool going = limits[i] == next;
        if (going ? samples[i] > next : samples[i] != limits[i] || !is_check_count(sampler, limits[i], NULL, NULL)) {
            return rt_error_set(error, RT_ERROR_INPUT,
                                "RENDER: the partial render's adaptive state at pixel %zu,%zu (%u samples, limit %u) "
                                "is not of this render's schedule (--min-spp %u, --spp %u, next check at %u)",
                                i % (size_t)sampler->width, i / (size_t)sampler->width, samples[i], limits[i],
                                sampler->min_spp, sampler->max_spp, next);
        }
        stopped_early |= !going;
    }
    for (size_t i = 0; i < pixels; i++) {
        sampler->going[i] = limits[i] == next;
        sampler->limits[i] = limits[i];
    }
    sampler->checked_at = before;
    sampler->next_check = next;
    sampler->stopped_early = stopped_early;
    sampler->noise.checks = checks;
    return RT_OK;
}

const uint32_t *adaptive_limits(const adaptive_sampler *sampler)
{
    return sampler->limits;
}

bool adaptive_stopped_early(const adaptive_sampler *sampler)
{
    return sampler->stopped_early;
}

/* True when a pixel of the 3x3 neighbourhood of (x, y) inside the image is unconverged. */
static bool neighbourhood_unconverged(const adaptive_sampler *sampler, int x, int y)
{
    for (int dy = -1; dy <= 1; dy++) {
        int row = y + dy;
        if (row < 0 || row >= sampler->height)
            continue;
        for (int dx = -1; dx <= 1; dx++) {
            int column = x + dx;
            if (column >= 0 && column < sampler->width && sampler->unconverged[(size_t)row * sampler->width + column])
                return true;
        }
    }
    return false;
}

int adaptive_check(adaptive_sampler *sampler, const float *rgba, const float *luminance_squares)
{
    size_t pixels = (size_t)sampler->width * sampler->height;
    double error_sum = 0;
    int checked = 0, unconverged = 0;
    for (size_t i = 0; i < pixels; i++) {
        const float *pixel = rgba + 4 * i;
        float luminance = luminance_float(pixel[0], pixel[1], pixel[2]);
        float error = sampler->going[i] ? adaptive_pixel_error(luminance, luminance_squares[i], (uint32_t)pixel[3]) : 0;
        sampler->unconverged[i] = sampler->going[i] && error >= sampler->threshold;
        if (sampler->going[i] && isfinite(error)) {
            error_sum += error;
            checked++;
        }
        unconverged += sampler->unconverged[i];
    }
    sampler->noise.checks++;
    sampler->checked_at = sampler->next_check;
    sampler->next_check = adaptive_next_check(sampler->checked_at, sampler->min_spp, sampler->max_spp);
    sampler->noise.unconverged_pixels = unconverged;
    sampler->noise.mean_error = checked > 0 ? (float)(error_sum / checked) : 0.0f;
    int going = 0;
    for (int y = 0; y < sampler->height; y++)
        for (int x = 0; x < sampler->width; x++) {
            size_t i = (size_t)y * sampler->width + x;
            if (!sampler->going[i])
                continue;
            uint32_t samples = (uint32_t)rgba[4 * i + 3];
            if (samples >= sampler->max_spp) {
                sampler->going[i] = 0;
            } else if (!neighbourhood_unconverged(sampler, x, y)) {
                sampler->going[i] = 0;
                sampler->stopped_early = true;
            }
            if (sampler->going[i]) {
                sampler->limits[i] = adaptive_next_check(samples, sampler->min_spp, sampler->max_spp);
                going++;
            } else {
                sampler->limits[i] = samples;
            }
        }
    sampler->noise.going_pixels = going;
    return going;
}

int adaptive_runs(const adaptive_sampler *sampler)
{
    uint32_t runs = (sampler->next_check - sampler->checked_at) / ADAPTIVE_RUN_SAMPLES;
    return runs < 1 ? 1 : runs > ADAPTIVE_MAX_RUNS ? ADAPTIVE_MAX_RUNS : (int)runs;
}

void adaptive_get_noise(const adaptive_sampler *sampler, adaptive_noise *noise)
{
    *noise = sampler->noise;
}

int adaptive_going_pixels(const adaptive_sampler *sampler, uint32_t *pixels)
{
    int count = 0;
    size_t total = (size_t)sampler->width * sampler->height;
    for (size_t i = 0; i < total; i++)
        if (sampler->going[i])
            pixels[count++] = (uint32_t)i;
    return count;
}
