/* postprocess.c: see postprocess.h. */
#include "postprocess.h"

#include <cglm/cglm.h>
#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "luminance.h"

#define DEFAULT_ITERATIONS 5
#define DEFAULT_SIGMA_COLOUR 4.0f
#define DEFAULT_SIGMA_NORMAL 0.3f
#define DEFAULT_SIGMA_DEPTH 0.02f
#define DEFAULT_SIGMA_ALBEDO 0.1f
#define DEFAULT_ALBEDO_EPSILON 0.01f

/* Half-width of the window the initial noise variance is measured over (7x7). */
#define VARIANCE_RADIUS 3
/* The bias check (postprocess.h, step 4): the neighbourhood of (2 BIAS_RADIUS + 1)^2
 * pixels whose mean residual is weighed, and the z-scores of that mean from which some
 * of it is added back and from which all of it is. */
#define BIAS_RADIUS 1
#define BIAS_Z_FROM 1.0
#define BIAS_Z_ALL 3.0
/* The denoiser's threads: at most this many, and each with at least this many rows. */
#define DENOISE_THREADS_MAX 64
#define DENOISE_ROWS_PER_THREAD_MIN 16

postprocess_denoise_options postprocess_denoise_options_defaults(void)
{
    postprocess_denoise_options options;
    memset(&options, 0, sizeof options);
    return options;
}

/* Returns value, or fallback when value is zero ("zero means default"). */
static float or_default(float value, float fallback)
{
    return value == 0.0f ? fallback : value;
}

/* Returns RT_OK when image has pixels, else RT_ERROR_INPUT naming it. */
static rt_status check_image(const rt_image *image, const char *which, rt_error *error)
{
    if (image == NULL || image->pixels == NULL || image->width <= 0 || image->height <= 0 || image->channels <= 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: the %s image is empty", which);
    return RT_OK;
}

static size_t pixel_count(const rt_image *image)
{
    return (size_t)image->width * (size_t)image->height;
}

/* The number of colour channels: 3, or 1 for a grey image (whose second channel, if
 * any, is alpha). */
static int colour_channels(const rt_image *image)
{
    return image->channels >= 3 ? 3 : 1;
}

/* ---------------------------------------------------------------------------------- */
/* Gaussian blur                                                                        */

/* Maps i to [0, n) by mirroring at the borders (-1 -> 0, -2 -> 1, n -> n-1): the image
 * repeated as a mirror-symmetric sequence of period 2n, so any kernel radius works. */
static int mirror_index(long long i, int n)
{
    long long period = 2LL * n;
    long long m = i % period;
    if (m < 0)
        m += period;
    return (int)(m < n ? m : period - 1 - m);
}

/* Convolves count samples of channels-strided data (sample k at data[k * stride]) with
 * the kernel weights[-radius .. radius] (passed as its centre), mirrored at both ends,
 * through scratch (count floats). */
static void convolve_line(float *data, size_t stride, int count, const float *centre, int radius, float *scratch)
{
    for (int i = 0; i < count; i++) {
        double sum = 0.0;
        for (int t = -radius; t <= radius; t++)
            sum += centre[t] * data[(size_t)mirror_index((long long)i + t, count) * stride];
        scratch[i] = (float)sum;
    }
    for (int i = 0; i < count; i++)
        data[(size_t)i * stride] = scratch[i];
}

rt_status postprocess_gaussian_blur(rt_image *image, float sigma_pixels, int passes, rt_error *error)
{
    rt_status status = check_image(image, "blurred", error);
    if (status != RT_OK)
        return status;
    if (!(sigma_pixels >= 0.0f) || sigma_pixels > POSTPROCESS_MAX_BLUR_SIGMA)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: blur sigma %g is not between 0 and %g pixels",
                            sigma_pixels, POSTPROCESS_MAX_BLUR_SIGMA);
    if (passes < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: blur passes %d is negative", passes);
    if (sigma_pixels == 0.0f || passes == 0)
        return RT_OK;

    int radius = (int)ceilf(3.0f * sigma_pixels);
    int longest = image->width > image->height ? image->width : image->height;
    float *kernel = malloc((size_t)(2 * radius + 1) * sizeof *kernel);
    float *scratch = malloc((size_t)longest * sizeof *scratch);
    if (kernel == NULL || scratch == NULL) {
        free(kernel);
        free(scratch);
        return rt_error_set(error, RT_ERROR_RUNTIME, "POSTPROCESS: out of memory for a blur of sigma %g",
                            sigma_pixels);
    }
    double sum = 0.0;
    for (int t = -radius; t <= radius; t++) {
        kernel[t + radius] = expf(-(float)t * (float)t / (2.0f * sigma_pixels * sigma_pixels));
        sum += kernel[t + radius];
    }
    for (int t = 0; t <= 2 * radius; t++)
        kernel[t] = (float)(kernel[t] / sum);

    const float *centre = kernel + radius;
    int channels = image->channels;
    for (int pass = 0; pass < passes; pass++)
        for (int c = 0; c < colour_channels(image); c++) {
            for (int y = 0; y < image->height; y++)
                convolve_line(image->pixels + (size_t)y * image->width * channels + c, (size_t)channels, image->width,
                              centre, radius, scratch);
            for (int x = 0; x < image->width; x++)
                convolve_line(image->pixels + (size_t)x * channels + c, (size_t)image->width * channels,
                              image->height, centre, radius, scratch);
        }
    free(kernel);
    free(scratch);
    return RT_OK;
}

/* ---------------------------------------------------------------------------------- */
/* Denoiser                                                                             */

/* The guides of one pixel, copied out of the caller's images once, with non-finite
 * values made 0 so that a stray NaN in a guide cannot poison every weight around it. */
typedef struct guide_pixel {
    float normal[3];
    float albedo[3];
    float depth;
    float gradient[2];           /* d depth / dx, d depth / dy */
    bool hit;                    /* false: the ray hit nothing (sky) */
    bool noise_measured;         /* its noise measured around it: no variance guide there */
} guide_pixel;

/* Everything the filter iterations share. */
typedef struct denoiser {
    int width, height;
    const guide_pixel *guides;
    bool use_normal, use_depth, use_albedo;
    float inverse_normal_sigma2, inverse_albedo_sigma2, sigma_depth;
    float sigma_colour;          /* this iteration's, for pixels with the render's variance */
    float sigma_colour_measured; /* every iteration's, for pixels whose noise was measured */
} denoiser;

static float finite_or_zero(float value)
{
    return isfinite(value) ? value : 0.0f;
}

/* The one-sided difference of smaller size between centre and its two neighbours (each
 * NAN when missing or not a hit): on a surface both agree; next to a depth step the one
 * across the step is the large one and is ignored. 0 when neither neighbour counts. */
static float smaller_difference(float before, float centre, float after)
{
    bool has_before = !isnan(before), has_after = !isnan(after);
    float backward = centre - before, forward = after - centre;
    if (has_before && has_after)
        return fabsf(backward) < fabsf(forward) ? backward : forward;
    if (has_before)
        return backward;
    if (has_after)
        return forward;
    return 0.0f;
}

/* Fills guides (one per pixel) from the optional guide images. */
static void load_guides(const rt_image *albedo, const rt_image *normal, const rt_image *depth, int width, int height,
                        guide_pixel *guides)
{
    size_t count = (size_t)width * height;
    for (size_t i = 0; i < count; i++) {
        guide_pixel *g = &guides[i];
        memset(g, 0, sizeof *g);
        g->hit = true;
        for (int c = 0; c < 3; c++) {
            if (normal != NULL)
                g->normal[c] = finite_or_zero(normal->pixels[i * normal->channels + c]);
            if (albedo != NULL)
                g->albedo[c] = finite_or_zero(albedo->pixels[i * albedo->channels + c]);
        }
        if (depth != NULL) {
            float z = depth->pixels[i * depth->channels];
            g->hit = isfinite(z) && z > 0.0f;
            g->depth = g->hit ? z : 0.0f;
        }
    }
    if (depth == NULL)
        return;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            guide_pixel *g = &guides[(size_t)y * width + x];
            if (!g->hit)
                continue;
#define HIT_DEPTH(xx, yy)                                                                                    \
    (((xx) >= 0 && (xx) < width && (yy) >= 0 && (yy) < height && guides[(size_t)(yy) * width + (xx)].hit) \
         ? guides[(size_t)(yy) * width + (xx)].depth                                                        \
         : NAN)
            g->gradient[0] = smaller_difference(HIT_DEPTH(x - 1, y), g->depth, HIT_DEPTH(x + 1, y));
            g->gradient[1] = smaller_difference(HIT_DEPTH(x, y - 1), g->depth, HIT_DEPTH(x, y + 1));
#undef HIT_DEPTH
        }
}

/* The product of the normal, depth and albedo weights of tap q for pixel p, q sitting
 * (dx, dy) pixels from p: 0 between a hit and a sky pixel, 1 between two sky pixels. */
static float guide_weight(const denoiser *d, const guide_pixel *p, const guide_pixel *q, int dx, int dy)
{
    if (p->hit != q->hit)
        return 0.0f;
    if (!p->hit)
        return 1.0f;
    float exponent = 0.0f;
    if (d->use_normal)
        exponent += glm_vec3_distance2((float *)q->normal, (float *)p->normal) * d->inverse_normal_sigma2;
    if (d->use_albedo)
        exponent += glm_vec3_distance2((float *)q->albedo, (float *)p->albedo) * d->inverse_albedo_sigma2;
    if (d->use_depth) {
        float predicted = p->depth + p->gradient[0] * (float)dx + p->gradient[1] * (float)dy;
        exponent += fabsf(q->depth - predicted) / (d->sigma_depth * p->depth);
    }
    return expf(-exponent);
}

/* The arrays of one stage of the filter, which runs rows y0 .. y1-1 of it at a time
 * (run_rows): every pixel of a stage depends only on the stage's inputs. */
typedef struct stage {
    const denoiser *d;
    int step;                    /* atrous_rows: the taps' spacing */
    const float *signal;         /* three floats a pixel */
    const float *variance;
    float *variance_out;         /* estimate_rows, atrous_rows */
    float *blurred;              /* blur_rows's output, atrous_rows's input */
    float *filtered;             /* atrous_rows */
    float *colour;               /* correct_bias_rows's output: the caller's colour image, */
    int channels;                /* channels floats a pixel */
} stage;

/* Measures the noise variance (mean over the three channels) of each pixel of rows y0 ..
 * y1-1 whose variance_out is still unknown (< 0) over its (2 VARIANCE_RADIUS + 1)^2
 * neighbourhood, weighted by the guides so that geometric edges are not mistaken for
 * noise. */
static void estimate_rows(const stage *s, int y0, int y1)
{
    const denoiser *d = s->d;
    const float *signal = s->signal;
    float *variance = s->variance_out;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < d->width; x++) {
            size_t p = (size_t)y * d->width + x;
            if (variance[p] >= 0.0f)
                continue;
            double weight_sum = 0.0, sum[3] = {0, 0, 0}, square_sum[3] = {0, 0, 0};
            for (int dy = -VARIANCE_RADIUS; dy <= VARIANCE_RADIUS; dy++)
                for (int dx = -VARIANCE_RADIUS; dx <= VARIANCE_RADIUS; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qx >= d->width || qy < 0 || qy >= d->height)
                        continue;
                    size_t q = (size_t)qy * d->width + qx;
                    double w = guide_weight(d, &d->guides[p], &d->guides[q], dx, dy);
                    weight_sum += w;
                    for (int c = 0; c < 3; c++) {
                        sum[c] += w * signal[3 * q + c];
                        square_sum[c] += w * signal[3 * q + c] * signal[3 * q + c];
                    }
                }
            double total = 0.0;
            for (int c = 0; c < 3; c++) {
                double mean = sum[c] / weight_sum;
                total += fmax(0.0, square_sum[c] / weight_sum - mean * mean);
            }
            variance[p] = (float)(total / 3.0);
        }
}

/* Blurs rows y0 .. y1-1 of variance with the 3x3 binomial kernel over pixels of the same
 * class (hit or sky), into blurred: one noisy variance estimate must not decide a colour
 * weight. */
static void blur_rows(const stage *s, int y0, int y1)
{
    static const float binomial[3] = {0.25f, 0.5f, 0.25f};
    const denoiser *d = s->d;
    const float *variance = s->variance;
    float *blurred = s->blurred;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < d->width; x++) {
            size_t p = (size_t)y * d->width + x;
            float sum = 0.0f, weight_sum = 0.0f;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qx >= d->width || qy < 0 || qy >= d->height)
                        continue;
                    size_t q = (size_t)qy * d->width + qx;
                    if (d->guides[q].hit != d->guides[p].hit)
                        continue;
                    float w = binomial[dx + 1] * binomial[dy + 1];
                    sum += w * variance[q];
                    weight_sum += w;
                }
            blurred[p] = sum / weight_sum;
        }
}

/* Rows y0 .. y1-1 of one à-trous iteration with taps step pixels apart: filters signal
 * into filtered and carries the variance along from variance into variance_out, the
 * colour weight reading blurred (blur_rows's, of the whole image). */
static void atrous_rows(const stage *s, int y0, int y1)
{
    static const float b3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
    const denoiser *d = s->d;
    int step = s->step;
    const float *signal = s->signal, *variance = s->variance, *blurred_variance = s->blurred;
    float *filtered = s->filtered, *filtered_variance = s->variance_out;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < d->width; x++) {
            size_t p = (size_t)y * d->width + x;
            const float *cp = &signal[3 * p];
            /* The noise floor keeps the weight finite on a noise-free image: differences
             * of a thousandth of the pixel's own level count as equal. */
            float level = glm_vec3_norm_one((float *)cp) / 3.0f;
            float sigma = d->guides[p].noise_measured ? d->sigma_colour_measured : d->sigma_colour;
            float colour_scale = sigma * sqrtf(blurred_variance[p]) + 1e-3f * level + 1e-8f;
            float inverse_colour_scale = 1.0f / colour_scale;
            double sum[3] = {0, 0, 0}, weight_sum = 0.0, variance_sum = 0.0;
            for (int j = -2; j <= 2; j++)
                for (int i = -2; i <= 2; i++) {
                    int dx = i * step, dy = j * step, qx = x + dx, qy = y + dy;
                    if (qx < 0 || qx >= d->width || qy < 0 || qy >= d->height)
                        continue;
                    size_t q = (size_t)qy * d->width + qx;
                    float w = b3[i + 2] * b3[j + 2];
                    if (q != p) {
                        float rms = sqrtf(glm_vec3_distance2((float *)&signal[3 * q], (float *)cp) / 3.0f);
                        w *= guide_weight(d, &d->guides[p], &d->guides[q], dx, dy) * expf(-rms * inverse_colour_scale);
                    }
                    weight_sum += w;
                    variance_sum += (double)w * w * variance[q];
                    for (int c = 0; c < 3; c++)
                        sum[c] += w * signal[3 * q + c];
                }
            /* weight_sum > 0 always: the centre tap has weight 9/64. */
            for (int c = 0; c < 3; c++)
                filtered[3 * p + c] = (float)(sum[c] / weight_sum);
            filtered_variance[p] = (float)(variance_sum / (weight_sum * weight_sum));
        }
}

/* Step 4 of postprocess.h, for rows y0 .. y1-1: writes each pixel's denoised colour
 * (signal) into colour, plus as much of the mean residual (filtered: the input colour
 * less the denoised one) of its neighbourhood as that mean's z-score against its standard
 * error asks for, the standard error from the variance of each pixel's mean luminance
 * (variance: < 0 where the render did not give it; such a neighbourhood is left alone). */
static void correct_bias_rows(const stage *s, int y0, int y1)
{
    const denoiser *d = s->d;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < d->width; x++) {
            size_t p = (size_t)y * d->width + x;
            float *out = s->colour + p * s->channels;
            memcpy(out, &s->signal[3 * p], 3 * sizeof *out);
            double residual[3] = {0, 0, 0}, variance_sum = 0.0;
            int n = 0;
            bool known = true;
            for (int dy = -BIAS_RADIUS; dy <= BIAS_RADIUS; dy++)
                for (int dx = -BIAS_RADIUS; dx <= BIAS_RADIUS; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qx >= d->width || qy < 0 || qy >= d->height)
                        continue;
                    size_t q = (size_t)qy * d->width + qx;
                    known = known && s->variance[q] >= 0.0f;
                    variance_sum += s->variance[q];
                    for (int c = 0; c < 3; c++)
                        residual[c] += s->filtered[3 * q + c];
                    n++;
                }
            if (!known)
                continue;
            for (int c = 0; c < 3; c++)
                residual[c] /= n;
            double standard_error = sqrt(variance_sum) / n;
            double z = fabs(luminance_double(residual[0], residual[1], residual[2])) / (standard_error + 1e-20);
            double share = z <= BIAS_Z_FROM ? 0.0
                           : z >= BIAS_Z_ALL ? 1.0
                                             : (z - BIAS_Z_FROM) / (BIAS_Z_ALL - BIAS_Z_FROM);
            for (int c = 0; c < 3; c++)
                out[c] = (float)(out[c] + share * residual[c]);
        }
}

/* One thread's share of a stage: rows y0 .. y1-1. */
typedef struct row_band {
    const stage *stage;
    void (*rows)(const stage *, int, int);
    int y0, y1;
} row_band;

static void *run_band(void *argument)
{
    const row_band *band = argument;
    band->rows(band->stage, band->y0, band->y1);
    return NULL;
}

/* Runs rows over every row of the image, in bands on as many threads as the machine has
 * cores (at most DENOISE_THREADS_MAX; fewer for small images; one when a thread cannot be
 * started, which only costs time). Each pixel is computed alone, so the image is the
 * same whatever the number of threads. */
static void run_rows(const stage *s, void (*rows)(const stage *, int, int))
{
    int height = s->d->height;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int count = cores < 1 ? 1 : cores > DENOISE_THREADS_MAX ? DENOISE_THREADS_MAX : (int)cores;
    if (count > height / DENOISE_ROWS_PER_THREAD_MIN)
        count = height / DENOISE_ROWS_PER_THREAD_MIN;
    if (count <= 1) {
        rows(s, 0, height);
        return;
    }
    pthread_t threads[DENOISE_THREADS_MAX];
    row_band bands[DENOISE_THREADS_MAX];
    bool started[DENOISE_THREADS_MAX];
    for (int t = 0; t < count; t++) {
        bands[t] = (row_band){.stage = s, .rows = rows, .y0 = height * t / count, .y1 = height * (t + 1) / count};
        started[t] = t > 0 && pthread_create(&threads[t], NULL, run_band, &bands[t]) == 0;
    }
    for (int t = 0; t < count; t++)
        if (!started[t])
            run_band(&bands[t]);
    for (int t = 1; t < count; t++)
        if (started[t])
            pthread_join(threads[t], NULL);
}

/* Checks that the first three channels of image (named which in messages) are finite. */
static rt_status check_finite(const rt_image *image, const char *which, rt_error *error)
{
    size_t count = pixel_count(image);
    for (size_t i = 0; i < count; i++)
        for (int c = 0; c < 3; c++)
            if (!isfinite(image->pixels[i * image->channels + c]))
                return rt_error_set(error, RT_ERROR_INPUT,
                                    "POSTPROCESS: the %s image has %s at pixel (%d, %d), channel %d", which,
                                    isnan(image->pixels[i * image->channels + c]) ? "NaN" : "an infinity",
                                    (int)(i % image->width), (int)(i / image->width), c);
    return RT_OK;
}

/* Fills variance (count pixels) with the variance guide's value where it has one (>= 0), in
 * the demodulated signal's units (divided by the squared divisor, averaged over the
 * channels), and -1 (unknown: estimate_rows measures it) elsewhere. */
static void noise_from_guide(const rt_image *mean_variance, const guide_pixel *guides, bool demodulate,
                             float albedo_epsilon, size_t count, float *variance)
{
    for (size_t i = 0; i < count; i++) {
        float v = mean_variance != NULL ? mean_variance->pixels[i * mean_variance->channels] : -1.0f;
        variance[i] = -1.0f;
        if (!(v >= 0.0f) || !isfinite(v))
            continue;
        double total = 0.0;
        for (int c = 0; c < 3; c++) {
            float divisor = demodulate ? fmaxf(guides[i].albedo[c], albedo_epsilon) : 1.0f;
            total += v / ((double)divisor * divisor);
        }
        variance[i] = (float)(total / 3.0);
    }
}

/* Checks a guide image against the colour image: same size, at least needed channels. */
static rt_status check_guide(const rt_image *guide, const char *which, const rt_image *colour, int needed,
                             rt_error *error)
{
    if (guide == NULL)
        return RT_OK;
    rt_status status = check_image(guide, which, error);
    if (status != RT_OK)
        return status;
    if (guide->width != colour->width || guide->height != colour->height)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: the %s image is %dx%d but the colour image is %dx%d",
                            which, guide->width, guide->height, colour->width, colour->height);
    if (guide->channels < needed)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: the %s image has %d channel%s, %d needed", which,
                            guide->channels, guide->channels == 1 ? "" : "s", needed);
    return RT_OK;
}

/* Returns RT_OK when value is a finite number >= 0, else RT_ERROR_INPUT naming it. */
static rt_status check_option(float value, const char *name, rt_error *error)
{
    if (!(value >= 0.0f) || isinf(value))
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: denoise option %s is %g; it must be a number >= 0",
                            name, value);
    return RT_OK;
}

/* Checks postprocess_denoise()'s arguments (postprocess.h says what it refuses). */
static rt_status check_denoise_arguments(const rt_image *colour, const postprocess_denoise_guides *g,
                                         const postprocess_denoise_options *given, rt_error *error)
{
    rt_status status = check_image(colour, "colour", error);
    if (status == RT_OK && colour->channels < 3)
        status = rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: the colour image has %d channel%s, 3 needed",
                              colour->channels, colour->channels == 1 ? "" : "s");
    if (status == RT_OK)
        status = check_guide(g->albedo, "albedo", colour, 3, error);
    if (status == RT_OK)
        status = check_guide(g->normal, "normal", colour, 3, error);
    if (status == RT_OK)
        status = check_guide(g->depth, "depth", colour, 1, error);
    if (status == RT_OK)
        status = check_guide(g->emission, "emission", colour, 3, error);
    if (status == RT_OK)
        status = check_guide(g->variance, "variance", colour, 1, error);
    if (status != RT_OK)
        return status;
    if (given->iterations < 0 || given->iterations > POSTPROCESS_MAX_DENOISE_ITERATIONS)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: denoise iterations %d is not between 0 and %d",
                            given->iterations, POSTPROCESS_MAX_DENOISE_ITERATIONS);
    const struct { float value; const char *name; } checked[] = {
        {given->sigma_colour, "sigma_colour"}, {given->sigma_normal, "sigma_normal"},
        {given->sigma_depth, "sigma_depth"}, {given->sigma_albedo, "sigma_albedo"},
        {given->albedo_epsilon, "albedo_epsilon"},
    };
    for (size_t i = 0; i < sizeof checked / sizeof checked[0]; i++)
        if ((status = check_option(checked[i].value, checked[i].name, error)) != RT_OK)
            return status;
    if ((status = check_finite(colour, "colour", error)) != RT_OK
        || (g->emission != NULL && (status = check_finite(g->emission, "emission", error)) != RT_OK))
        return status;
    return RT_OK;
}

rt_status postprocess_denoise(rt_image *colour, const postprocess_denoise_guides *given_guides,
                              const postprocess_denoise_options *options, rt_error *error)
{
    postprocess_denoise_guides none = {0};
    const postprocess_denoise_guides *g = given_guides != NULL ? given_guides : &none;
    const rt_image *albedo = g->albedo, *normal = g->normal, *depth = g->depth, *emission = g->emission,
                   *mean_variance = g->variance;
    postprocess_denoise_options given = options != NULL ? *options : postprocess_denoise_options_defaults();
    rt_status status = check_denoise_arguments(colour, g, &given, error);
    if (status != RT_OK)
        return status;
    size_t count = pixel_count(colour);
    int channels = colour->channels;

    int iterations = given.iterations != 0 ? given.iterations : DEFAULT_ITERATIONS;
    float sigma_normal = or_default(given.sigma_normal, DEFAULT_SIGMA_NORMAL);
    float sigma_albedo = or_default(given.sigma_albedo, DEFAULT_SIGMA_ALBEDO);
    float albedo_epsilon = or_default(given.albedo_epsilon, DEFAULT_ALBEDO_EPSILON);
    denoiser d = {
        .width = colour->width,
        .height = colour->height,
        .use_normal = normal != NULL,
        .use_depth = depth != NULL,
        .use_albedo = albedo != NULL,
        .inverse_normal_sigma2 = 1.0f / (sigma_normal * sigma_normal),
        .inverse_albedo_sigma2 = 1.0f / (sigma_albedo * sigma_albedo),
        .sigma_depth = or_default(given.sigma_depth, DEFAULT_SIGMA_DEPTH),
        .sigma_colour = or_default(given.sigma_colour, DEFAULT_SIGMA_COLOUR),
    };

    /* One block: guides, two signal buffers (ping-pong), two variances and the blurred one. */
    guide_pixel *guides = malloc(count * sizeof *guides);
    float *signal = malloc(count * 3 * sizeof *signal);
    float *filtered = malloc(count * 3 * sizeof *filtered);
    float *variance = malloc(count * sizeof *variance);
    float *filtered_variance = malloc(count * sizeof *filtered_variance);
    float *blurred_variance = malloc(count * sizeof *blurred_variance);
    if (guides == NULL || signal == NULL || filtered == NULL || variance == NULL || filtered_variance == NULL
        || blurred_variance == NULL) {
        status = rt_error_set(error, RT_ERROR_RUNTIME, "POSTPROCESS: out of memory denoising a %dx%d image",
                              colour->width, colour->height);
        goto done;
    }
    load_guides(albedo, normal, depth, colour->width, colour->height, guides);
    d.guides = guides;

    /* Demodulate: filter the lighting, not the texture, and not the emission seen at once. */
    for (size_t i = 0; i < count; i++)
        for (int c = 0; c < 3; c++) {
            float divisor = albedo != NULL ? fmaxf(guides[i].albedo[c], albedo_epsilon) : 1.0f;
            float direct = emission != NULL ? emission->pixels[i * emission->channels + c] : 0.0f;
            signal[3 * i + c] = (colour->pixels[i * channels + c] - direct) / divisor;
        }
    /* The noise: the render's own estimate where it has one, else measured around the pixel. */
    noise_from_guide(mean_variance, guides, albedo != NULL, albedo_epsilon, count, variance);
    for (size_t i = 0; i < count; i++)
        guides[i].noise_measured = variance[i] < 0.0f;
    run_rows(&(stage){.d = &d, .signal = signal, .variance_out = variance}, estimate_rows);
    d.sigma_colour_measured = d.sigma_colour;
    for (int i = 0; i < iterations; i++) {
        /* 4, 4, 2, 1, 0.5 where the render's variance says the noise (postprocess.h). */
        d.sigma_colour = ldexpf(d.sigma_colour_measured, i > 1 ? 1 - i : 0);
        run_rows(&(stage){.d = &d, .variance = variance, .blurred = blurred_variance}, blur_rows);
        run_rows(&(stage){.d = &d, .step = 1 << i, .signal = signal, .variance = variance,
                          .blurred = blurred_variance, .filtered = filtered, .variance_out = filtered_variance},
                 atrous_rows);
        float *swap = signal;
        signal = filtered;
        filtered = swap;
        swap = variance;
        variance = filtered_variance;
        filtered_variance = swap;
    }
    /* The denoised colour into signal, what it took from the input into filtered, and the
     * render's variance of each pixel's mean luminance into blurred_variance, for step 4. */
    for (size_t i = 0; i < count; i++) {
        for (int c = 0; c < 3; c++) {
            float factor = albedo != NULL ? fmaxf(guides[i].albedo[c], albedo_epsilon) : 1.0f;
            float direct = emission != NULL ? emission->pixels[i * emission->channels + c] : 0.0f;
            signal[3 * i + c] = signal[3 * i + c] * factor + direct;
            filtered[3 * i + c] = colour->pixels[i * channels + c] - signal[3 * i + c];
        }
        float v = mean_variance != NULL ? mean_variance->pixels[i * mean_variance->channels] : -1.0f;
        blurred_variance[i] = v >= 0.0f && isfinite(v) ? v : -1.0f;
    }
    run_rows(&(stage){.d = &d, .signal = signal, .filtered = filtered, .variance = blurred_variance,
                      .colour = colour->pixels, .channels = channels},
             correct_bias_rows);

done:
    free(guides);
    free(signal);
    free(filtered);
    free(variance);
    free(filtered_variance);
    free(blurred_variance);
    return status;
}

int postprocess_blur_reach(float sigma_pixels, int passes)
{
    if (!(sigma_pixels > 0.0f) || passes <= 0)
        return 0;
    return passes * (int)ceilf(3.0f * sigma_pixels);
}

int postprocess_denoise_reach(const postprocess_denoise_options *options)
{
    int iterations = options != NULL && options->iterations != 0 ? options->iterations : DEFAULT_ITERATIONS;
    return 2 * ((1 << iterations) - 1) + VARIANCE_RADIUS + 1 + BIAS_RADIUS;
}

/* ---------------------------------------------------------------------------------- */
/* Tone mapping                                                                         */

/* Makes value a number in [0, +inf]: NaN and negatives become 0. */
static float non_negative(float value)
{
    return value > 0.0f ? value : 0.0f;
}

/* Narkowicz's ACES fit of one value in [0, inf], clamped to [0, 1]. */
static float aces_curve(float x)
{
    if (isinf(x))
        return 1.0f;
    float y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    return y < 0.0f ? 0.0f : (y > 1.0f ? 1.0f : y);
}

/* Reinhard on the luminance of rgb (three values in [0, inf]), in place. */
static void reinhard_pixel(float *rgb)
{
    if (isinf(rgb[0]) || isinf(rgb[1]) || isinf(rgb[2])) {
        /* The limit of L/(1+L) with the ratios of the infinite channels: white where all are. */
        for (int c = 0; c < 3; c++)
            rgb[c] = isinf(rgb[c]) ? 1.0f : 0.0f;
        return;
    }
    float luminance = luminance_float(rgb[0], rgb[1], rgb[2]);
    if (luminance <= 0.0f) {
        glm_vec3_zero(rgb);
        return;
    }
    float scale = 1.0f / (1.0f + luminance);   /* (L / (1 + L)) / L */
    float largest = glm_vec3_max(rgb) * scale;
    if (largest > 1.0f)
        scale /= largest;
    glm_vec3_scale(rgb, scale, rgb);
}

rt_status postprocess_tonemap(rt_image *image, postprocess_tonemap_operator op, float exposure_stops,
                              rt_error *error)
{
    rt_status status = check_image(image, "tone-mapped", error);
    if (status != RT_OK)
        return status;
    if (op != TONEMAP_CLAMP && op != TONEMAP_REINHARD && op != TONEMAP_ACES)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: unknown tone mapping operator %d", (int)op);
    if (!isfinite(exposure_stops))
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: exposure %g stops is not a finite number",
                            exposure_stops);
    float gain = exp2f(exposure_stops);
    size_t count = pixel_count(image);
    int channels = image->channels, used = colour_channels(image);
    for (size_t i = 0; i < count; i++) {
        float *pixel = &image->pixels[i * channels];
        if (op == TONEMAP_CLAMP) {
            for (int c = 0; c < used; c++)
                pixel[c] *= gain;
            continue;
        }
        float rgb[3];
        for (int c = 0; c < 3; c++)
            rgb[c] = non_negative(pixel[used == 3 ? c : 0] * gain);  /* grey: one value thrice */
        if (op == TONEMAP_REINHARD)
            reinhard_pixel(rgb);
        else
            for (int c = 0; c < 3; c++)
                rgb[c] = aces_curve(rgb[c]);
        for (int c = 0; c < used; c++)
            pixel[c] = rgb[c];
    }
    return RT_OK;
}

/* ---------------------------------------------------------------------------------- */
/* Montage                                                                              */

rt_status postprocess_montage(const rt_image *images, int count, int columns, int gap_pixels, rt_image *out,
                              rt_error *error)
{
    memset(out, 0, sizeof *out);
    if (images == NULL || count < 1)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: a montage needs at least one image");
    if (columns < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: montage columns %d is negative", columns);
    if (gap_pixels < 0)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: montage gap %d is negative", gap_pixels);
    for (int i = 0; i < count; i++) {
        char which[32];
        snprintf(which, sizeof which, "montage's image %d", i + 1);
        rt_status status = check_image(&images[i], which, error);
        if (status != RT_OK)
            return status;
        if (images[i].width != images[0].width || images[i].height != images[0].height)
            return rt_error_set(error, RT_ERROR_INPUT,
                                "POSTPROCESS: montage images must have one size: image %d is %dx%d, image 1 is %dx%d",
                                i + 1, images[i].width, images[i].height, images[0].width, images[0].height);
    }
    if (columns == 0) {
        columns = (int)ceil(sqrt((double)count));
        while ((long long)columns * columns < count)  /* sqrt rounding, for very large counts */
            columns++;
    }
    if (columns > count)
        columns = count;
    int rows = (count + columns - 1) / columns;
    int tile_width = images[0].width, tile_height = images[0].height;
    long long sheet_width = (long long)columns * tile_width + (long long)(columns - 1) * gap_pixels;
    long long sheet_height = (long long)rows * tile_height + (long long)(rows - 1) * gap_pixels;
    if (sheet_width > POSTPROCESS_MAX_MONTAGE_SIDE || sheet_height > POSTPROCESS_MAX_MONTAGE_SIDE)
        return rt_error_set(error, RT_ERROR_INPUT, "POSTPROCESS: the montage would be %lldx%lld pixels, more than %d a side",
                            sheet_width, sheet_height, POSTPROCESS_MAX_MONTAGE_SIDE);
    rt_status status = image_create(out, (int)sheet_width, (int)sheet_height, 3, error);
    if (status != RT_OK)
        return status;
    for (int i = 0; i < count; i++) {
        const rt_image *tile = &images[i];
        int left = (i % columns) * (tile_width + gap_pixels);
        int top = (i / columns) * (tile_height + gap_pixels);
        int used = colour_channels(tile);
        for (int y = 0; y < tile_height; y++)
            for (int x = 0; x < tile_width; x++) {
                const float *from = &tile->pixels[((size_t)y * tile_width + x) * tile->channels];
                float *to = &out->pixels[((size_t)(top + y) * out->width + (left + x)) * 3];
                for (int c = 0; c < 3; c++)
                    to[c] = from[used == 3 ? c : 0];
            }
    }
    return RT_OK;
}
