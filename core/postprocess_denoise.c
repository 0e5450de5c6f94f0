/* postprocess_denoise.c: the denoiser of postprocess.h (postprocess_denoise() and what it
 * shares with tiled renders, postprocess_denoise_reach()); the blur, tone mapping and
 * montage are core/postprocess.c. */
#include "postprocess.h"

#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "luminance.h"
#include "postprocess_internal.h"

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
/* The wider window whose mean variance the check's standard error is never below. */
#define BIAS_POOL_RADIUS 2
#define BIAS_Z_FROM 1.0
#define BIAS_Z_ALL 3.0
/* The choice among the iterations' images (postprocess.h, step 5): each one's risk is
 * averaged over a pixel's neighbours out to CHOICE_RADIUS pixels in x and in y, with a
 * Gaussian of CHOICE_RADIUS / 2 and the guides' weights. */
#define CHOICE_RADIUS 9
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

/* The tap loops (atrous_taps, estimate_taps, smooth_taps) are written for the compiler to make
 * vector loops of: planes of one float per pixel, each tap applied to a run of consecutive
 * pixels, no branch in the loop, no library call (exp_negative below). The Makefile
 * builds this file with -O3, which vectorises them, and GCC compiles one clone of each for
 * AVX-512, AVX2 and the baseline, chosen by the CPU when the program starts. With
 * -ffp-contract=off (C11's default, said in the Makefile) no clone fuses a multiply and an
 * add, so every clone computes every pixel alike, in a vector lane or not: the image does
 * not depend on the CPU, the threads or where a block of a tiled render starts. 2026-12-03:
 * a 1920x1080 image's five iterations took 3.4 CPU-s as scalar code (docs/performance.md,
 * the log). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) \
    && !defined(RT_NO_TARGET_CLONES)
#define VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define VECTOR_CLONES
#endif

/* Pixels a tap loop runs over at a time: its sums stay in the first-level cache. */
#define DENOISE_RUN 256

/* The guides of every pixel, one plane (count floats) per component, copied out of the
 * caller's images once with non-finite values made 0 (a stray NaN in a guide must not
 * poison every weight around it). A missing guide is a plane of zeros, which weighs
 * nothing (its inverse sigma or depth scale is 0 too). */
typedef struct guide_planes {
    float *normal[3];
    float *albedo[3];
    float *depth;                /* distance to the first hit; 0 on sky */
    float *gradient[2];          /* d depth / dx, d depth / dy */
    float *depth_scale;          /* 1 / (sigma_depth depth) on a hit; 0 on sky or without depth */
    float *hit;                  /* 1: the ray hit something; 0: sky */
    unsigned char *noise_measured;   /* its noise measured around it: no variance guide there */
} guide_planes;

/* Everything the filter iterations share. */
typedef struct denoiser {
    int width, height;
    guide_planes g;
    float inverse_normal_sigma2, inverse_albedo_sigma2;   /* 0 without that guide */
    float sigma_colour;          /* this iteration's, for pixels with the render's variance */
    float sigma_colour_measured; /* every iteration's, for pixels whose noise was measured */
    /* The choice (step 5), with the render's variance only; self_weight NULL without it. */
    float *self_weight;          /* dF_p / dy_p of the image so far: its iterations' centre weights' product */
    const rt_image *input;       /* the caller's colour as given */
    const rt_image *emission;    /* the emission guide, or NULL */
    const rt_image *mean_variance;   /* the variance guide */
    bool demodulate;             /* with an albedo guide */
    float albedo_epsilon;
} denoiser;

static float finite_or_zero(float value)
{
    return isfinite(value) ? value : 0.0f;
}

/* Returns e^-x for x >= 0 to within a few float ulps (x over 87 as 87: below 2^-125,
 * a weight that counts for nothing), in plain arithmetic so that vector loops can have it:
 * x = n ln 2 + r with |r| <= ln 2 / 2, e^-x = 2^-n e^-r, e^-r by its Taylor series to r^7
 * (the rest is below 6e-9). ln 2 is split in two so that n ln2_high is exact. */
static inline float exp_negative(float x)
{
    const float log2e = 1.44269504f, ln2_high = 0.693145752f, ln2_low = 1.42860677e-6f;
    const float round_magic = 12582912.0f;   /* 1.5 x 2^23: adding it rounds to an integer */
    x = x < 87.0f ? x : 87.0f;
    float n = (x * log2e + round_magic) - round_magic;
    float r = (n * ln2_high - x) + n * ln2_low;   /* -x + n ln 2, in [-0.35, 0.35] */
    float p = 1.0f / 5040.0f;
    p = p * r + 1.0f / 720.0f;
    p = p * r + 1.0f / 120.0f;
    p = p * r + 1.0f / 24.0f;
    p = p * r + 1.0f / 6.0f;
    p = p * r + 0.5f;
    p = p * r + 1.0f;
    p = p * r + 1.0f;
    int32_t bits = (127 - (int32_t)n) << 23;   /* 2^-n, n in [0, 126] */
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

/* The exponent of the normal, albedo and depth weights of pixel q for pixel p, q sitting
 * (dx, dy) pixels from p; 0 when p is sky (between two sky pixels only the colour weight
 * counts; a hit and a sky pixel never mix, see guide_match). */
static inline float guide_exponent(const denoiser *d, size_t p, size_t q, float dx, float dy)
{
    const guide_planes *g = &d->g;
    float n0 = g->normal[0][q] - g->normal[0][p], n1 = g->normal[1][q] - g->normal[1][p],
          n2 = g->normal[2][q] - g->normal[2][p];
    float a0 = g->albedo[0][q] - g->albedo[0][p], a1 = g->albedo[1][q] - g->albedo[1][p],
          a2 = g->albedo[2][q] - g->albedo[2][p];
    float predicted = g->depth[p] + g->gradient[0][p] * dx + g->gradient[1][p] * dy;
    float exponent = (n0 * n0 + n1 * n1 + n2 * n2) * d->inverse_normal_sigma2
                   + (a0 * a0 + a1 * a1 + a2 * a2) * d->inverse_albedo_sigma2
                   + fabsf(g->depth[q] - predicted) * g->depth_scale[p];
    return exponent * g->hit[p];
}

/* 1 when p and q are of one class (both hit something or both are sky), else 0. */
static inline float guide_match(const denoiser *d, size_t p, size_t q)
{
    return d->g.hit[p] == d->g.hit[q] ? 1.0f : 0.0f;
}

/* The variance guide's value at pixel p (the variance of its mean luminance), or -1 where
 * it has none: no guide, or a negative, infinite or NaN value. */
static float guide_variance(const rt_image *mean_variance, size_t p)
{
    float v = mean_variance != NULL ? mean_variance->pixels[p * mean_variance->channels] : -1.0f;
    return v >= 0.0f && isfinite(v) ? v : -1.0f;
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

/* Fills the guide planes (allocated, count each) from the optional guide images; sigma_depth
 * sets the depth scale. */
static void load_guides(const rt_image *albedo, const rt_image *normal, const rt_image *depth, int width, int height,
                        float sigma_depth, guide_planes *g)
{
    size_t count = (size_t)width * height;
    for (size_t i = 0; i < count; i++) {
        for (int c = 0; c < 3; c++) {
            g->normal[c][i] = normal != NULL ? finite_or_zero(normal->pixels[i * normal->channels + c]) : 0.0f;
            g->albedo[c][i] = albedo != NULL ? finite_or_zero(albedo->pixels[i * albedo->channels + c]) : 0.0f;
        }
        float z = depth != NULL ? depth->pixels[i * depth->channels] : 1.0f;
        bool hit = isfinite(z) && z > 0.0f;
        g->hit[i] = hit ? 1.0f : 0.0f;
        g->depth[i] = depth != NULL && hit ? z : 0.0f;
        g->depth_scale[i] = depth != NULL && hit ? 1.0f / (sigma_depth * z) : 0.0f;
        g->gradient[0][i] = g->gradient[1][i] = 0.0f;
    }
    if (depth == NULL)
        return;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            size_t i = (size_t)y * width + x;
            if (g->hit[i] == 0.0f)
                continue;
#define HIT_DEPTH(xx, yy)                                                                                   \
    (((xx) >= 0 && (xx) < width && (yy) >= 0 && (yy) < height && g->hit[(size_t)(yy) * width + (xx)] != 0.0f) \
         ? g->depth[(size_t)(yy) * width + (xx)]                                                           \
         : NAN)
            g->gradient[0][i] = smaller_difference(HIT_DEPTH(x - 1, y), g->depth[i], HIT_DEPTH(x + 1, y));
            g->gradient[1][i] = smaller_difference(HIT_DEPTH(x, y - 1), g->depth[i], HIT_DEPTH(x, y + 1));
#undef HIT_DEPTH
        }
}

/* The arrays of one stage of the filter, which runs rows y0 .. y1-1 of it at a time
 * (run_rows): every pixel of a stage depends only on the stage's inputs. Colours are three
 * planes (count floats each). */
typedef struct stage {
    const denoiser *d;
    int step;                    /* atrous_rows: the taps' spacing */
    float *const *signal;        /* three planes */
    const float *variance;
    float *variance_out;         /* estimate_rows, atrous_rows */
    float *blurred;              /* blur_rows's output, atrous_rows's input */
    float *const *filtered;      /* atrous_rows: three planes */
    float *colour;               /* correct_bias_rows's output: the caller's colour image, */
    int channels;                /* channels floats a pixel */
    float *risk;                 /* risk_rows's output, smooth_rows's input */
    float *smoothed;             /* smooth_rows's horizontal pass, choose_rows's input */
    float *best_risk;            /* choose_rows: the lowest smoothed risk so far, per pixel */
    float *const *best;          /* choose_rows: that image (three planes, output space) */
} stage;

/* The sums one tap loop adds to, one element per pixel of the run. */
typedef struct tap_sums {
    float weight[DENOISE_RUN];
    float colour[3][DENOISE_RUN];
    float square[3][DENOISE_RUN];   /* estimate_taps */
    float variance[DENOISE_RUN];    /* atrous_taps */
} tap_sums;

/* Adds the tap (dx, dy) of an à-trous iteration to the sums of run pixels k0 .. k1-1, the
 * run's pixel k being p = first + k: weight kernel x guide x colour weight (the colour's
 * RMS difference over the pixel's colour scale, inverse_scale[k]). */
VECTOR_CLONES static void atrous_taps(const stage *s, size_t first, ptrdiff_t offset, float dx, float dy,
                                      float kernel, int k0, int k1, const float *restrict inverse_scale,
                                      tap_sums *restrict sums)
{
    const denoiser *d = s->d;
    const float *restrict r = s->signal[0], *restrict g = s->signal[1], *restrict b = s->signal[2];
    const float *restrict variance = s->variance;
    /* Only sums is written, each element by its own k: no iteration depends on another. */
#pragma GCC ivdep
    for (int k = k0; k < k1; k++) {
        size_t p = first + (size_t)k, q = (size_t)((ptrdiff_t)p + offset);
        float dr = r[q] - r[p], dg = g[q] - g[p], db = b[q] - b[p];
        float rms = sqrtf((dr * dr + dg * dg + db * db) / 3.0f);
        float w = kernel * guide_match(d, p, q)
                * exp_negative(guide_exponent(d, p, q, dx, dy) + rms * inverse_scale[k]);
        sums->weight[k] += w;
        sums->variance[k] += w * w * variance[q];
        sums->colour[0][k] += w * r[q];
        sums->colour[1][k] += w * g[q];
        sums->colour[2][k] += w * b[q];
    }
}

/* Rows y0 .. y1-1 of one à-trous iteration with taps step pixels apart: filters signal
 * into filtered and carries the variance along from variance into variance_out, the
 * colour weight reading blurred (blur_rows's, of the whole image). Taps in a fixed order
 * (the centre, then row by row), each over a run of pixels (atrous_taps). */
static void atrous_rows(const stage *s, int y0, int y1)
{
    static const float b3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
    const denoiser *d = s->d;
    int step = s->step, width = d->width;
    tap_sums sums;
    float inverse_scale[DENOISE_RUN];
    for (int y = y0; y < y1; y++)
        for (int x0 = 0; x0 < width; x0 += DENOISE_RUN) {
            int run = width - x0 < DENOISE_RUN ? width - x0 : DENOISE_RUN;
            size_t first = (size_t)y * width + x0;
            float centre = b3[2] * b3[2];
            for (int k = 0; k < run; k++) {
                size_t p = first + k;
                float red = s->signal[0][p], green = s->signal[1][p], blue = s->signal[2][p];
                /* The noise floor keeps the weight finite on a noise-free image: differences
                 * of a thousandth of the pixel's own level count as equal. */
                float level = (fabsf(red) + fabsf(green) + fabsf(blue)) / 3.0f;
                float sigma = d->g.noise_measured[p] ? d->sigma_colour_measured : d->sigma_colour;
                inverse_scale[k] = 1.0f / (sigma * sqrtf(s->blurred[p]) + 1e-3f * level + 1e-8f);
                sums.weight[k] = centre;
                sums.variance[k] = centre * centre * s->variance[p];
                sums.colour[0][k] = centre * red;
                sums.colour[1][k] = centre * green;
                sums.colour[2][k] = centre * blue;
            }
            for (int j = -2; j <= 2; j++) {
                int dy = j * step;
                if (y + dy < 0 || y + dy >= d->height)
                    continue;
                for (int i = -2; i <= 2; i++) {
                    int dx = i * step;
                    int k0 = -dx - x0 > 0 ? -dx - x0 : 0;
                    int k1 = width - dx - x0 < run ? width - dx - x0 : run;
                    if ((i == 0 && j == 0) || k0 >= k1)
                        continue;
                    atrous_taps(s, first, (ptrdiff_t)dy * width + dx, (float)dx, (float)dy, b3[i + 2] * b3[j + 2],
                                k0, k1, inverse_scale, &sums);
                }
            }
            /* weight > 0 always: the centre tap has weight 9/64. */
            for (int k = 0; k < run; k++) {
                size_t p = first + k;
                for (int c = 0; c < 3; c++)
                    s->filtered[c][p] = sums.colour[c][k] / sums.weight[k];
                s->variance_out[p] = sums.variance[k] / (sums.weight[k] * sums.weight[k]);
                if (d->self_weight != NULL)
                    d->self_weight[p] *= centre / sums.weight[k];
            }
        }
}

/* Adds the tap (dx, dy) of the noise estimate to the sums of run pixels k0 .. k1-1 (pixel
 * p = first + k): the guide weight, and the colour less the pixel's own, and its square
 * (so that the variance is not the difference of two large numbers). */
VECTOR_CLONES static void estimate_taps(const stage *s, size_t first, ptrdiff_t offset, float dx, float dy,
                                        int k0, int k1, tap_sums *restrict sums)
{
    const denoiser *d = s->d;
    const float *restrict r = s->signal[0], *restrict g = s->signal[1], *restrict b = s->signal[2];
#pragma GCC ivdep
    for (int k = k0; k < k1; k++) {
        size_t p = first + (size_t)k, q = (size_t)((ptrdiff_t)p + offset);
        float w = guide_match(d, p, q) * exp_negative(guide_exponent(d, p, q, dx, dy));
        float dr = r[q] - r[p], dg = g[q] - g[p], db = b[q] - b[p];
        sums->weight[k] += w;
        sums->colour[0][k] += w * dr;
        sums->colour[1][k] += w * dg;
        sums->colour[2][k] += w * db;
        sums->square[0][k] += w * dr * dr;
        sums->square[1][k] += w * dg * dg;
        sums->square[2][k] += w * db * db;
    }
}

/* Measures the noise variance (mean over the three channels) of each pixel of rows y0 ..
 * y1-1 whose variance_out is still unknown (< 0) over its (2 VARIANCE_RADIUS + 1)^2
 * neighbourhood, weighted by the guides so that geometric edges are not mistaken for
 * noise. A run of pixels none of which needs it is skipped. */
static void estimate_rows(const stage *s, int y0, int y1)
{
    const denoiser *d = s->d;
    int width = d->width;
    float *variance = s->variance_out;
    tap_sums sums;
    for (int y = y0; y < y1; y++)
        for (int x0 = 0; x0 < width; x0 += DENOISE_RUN) {
            int run = width - x0 < DENOISE_RUN ? width - x0 : DENOISE_RUN;
            size_t first = (size_t)y * width + x0;
            bool wanted = false;
            for (int k = 0; k < run; k++)
                wanted = wanted || variance[first + k] < 0.0f;
            if (!wanted)
                continue;
            memset(&sums, 0, sizeof sums);
            for (int dy = -VARIANCE_RADIUS; dy <= VARIANCE_RADIUS; dy++) {
                if (y + dy < 0 || y + dy >= d->height)
                    continue;
                for (int dx = -VARIANCE_RADIUS; dx <= VARIANCE_RADIUS; dx++) {
                    int k0 = -dx - x0 > 0 ? -dx - x0 : 0;
                    int k1 = width - dx - x0 < run ? width - dx - x0 : run;
                    if (k0 < k1)
                        estimate_taps(s, first, (ptrdiff_t)dy * width + dx, (float)dx, (float)dy, k0, k1, &sums);
                }
            }
            for (int k = 0; k < run; k++) {
                if (variance[first + k] >= 0.0f)
                    continue;
                float total = 0.0f;
                for (int c = 0; c < 3; c++) {
                    float mean = sums.colour[c][k] / sums.weight[k];
                    total += fmaxf(0.0f, sums.square[c][k] / sums.weight[k] - mean * mean);
                }
                variance[first + k] = total / 3.0f;
            }
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
                    if (d->g.hit[q] != d->g.hit[p])
                        continue;
                    float w = binomial[dx + 1] * binomial[dy + 1];
                    sum += w * variance[q];
                    weight_sum += w;
                }
            blurred[p] = sum / weight_sum;
        }
}

/* Channel c of pixel p of the image whose demodulated colour is signal, in the caller's
 * units: multiplied back by the albedo, the emission added back. */
static float remodulated(const denoiser *d, float *const *signal, size_t p, int c)
{
    float factor = d->demodulate ? fmaxf(d->g.albedo[c][p], d->albedo_epsilon) : 1.0f;
    float direct = d->emission != NULL ? d->emission->pixels[p * d->emission->channels + c] : 0.0f;
    return signal[c][p] * factor + direct;
}

/* Step 5's risk of each pixel of rows y0 .. y1-1 in the image whose demodulated colour is
 * s->signal: Stein's unbiased estimate of its luminance's squared error, (L(F) - L(y))^2 -
 * var + 2 var dF/dy, y the input and var the variance of its mean (the variance guide);
 * NAN where that is unknown. */
static void risk_rows(const stage *s, int y0, int y1)
{
    const denoiser *d = s->d;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < d->width; x++) {
            size_t p = (size_t)y * d->width + x;
            float v = guide_variance(d->mean_variance, p);
            if (v < 0.0f) {
                s->risk[p] = NAN;
                continue;
            }
            const float *in = &d->input->pixels[p * d->input->channels];
            float difference[3];
            for (int c = 0; c < 3; c++)
                difference[c] = remodulated(d, s->signal, p, c) - in[c];
            float luminance = luminance_float(difference[0], difference[1], difference[2]);
            s->risk[p] = luminance * luminance - v + 2.0f * v * d->self_weight[p];
        }
}

/* Adds the tap (dx, dy) of step 5's smoothing, one of whose two is 0, to the sums of run
 * pixels k0 .. k1-1 (pixel p = first + k): value[q] by the Gaussian's weight kernel and
 * the guides' weight (0 between a hit and sky; a NAN value makes the sum NAN). */
VECTOR_CLONES static void smooth_taps(const denoiser *d, const float *restrict value, size_t first,
                                      ptrdiff_t offset, float dx, float dy, float kernel, int k0, int k1,
                                      tap_sums *restrict sums)
{
#pragma GCC ivdep
    for (int k = k0; k < k1; k++) {
        size_t p = first + (size_t)k, q = (size_t)((ptrdiff_t)p + offset);
        float w = kernel * guide_match(d, p, q) * exp_negative(guide_exponent(d, p, q, dx, dy));
        sums->weight[k] += w;
        sums->colour[0][k] += w * value[q];
    }
}

/* The smoothing's Gaussian weight of a tap distance pixels away along one axis. */
static float choice_kernel(int distance)
{
    float sigma = CHOICE_RADIUS / 2.0f;
    return expf(-(float)(distance * distance) / (2.0f * sigma * sigma));
}

/* Step 5's average of value over the pixels of row y from column x0 on (run of them), along
 * x (along_x) or along y, into mean[0 .. run-1]. */
static void average_run(const denoiser *d, const float *value, int y, int x0, int run, bool along_x, float *mean)
{
    tap_sums sums;
    size_t first = (size_t)y * d->width + x0;
    memset(sums.weight, 0, sizeof sums.weight);
    memset(sums.colour[0], 0, sizeof sums.colour[0]);
    for (int t = -CHOICE_RADIUS; t <= CHOICE_RADIUS; t++) {
        if (along_x) {
            int k0 = -t - x0 > 0 ? -t - x0 : 0, k1 = d->width - t - x0 < run ? d->width - t - x0 : run;
            if (k0 < k1)
                smooth_taps(d, value, first, t, (float)t, 0.0f, choice_kernel(t), k0, k1, &sums);
        } else if (y + t >= 0 && y + t < d->height) {
            smooth_taps(d, value, first, (ptrdiff_t)t * d->width, 0.0f, (float)t, choice_kernel(t), 0, run, &sums);
        }
    }
    for (int k = 0; k < run; k++)
        mean[k] = sums.colour[0][k] / sums.weight[k];
}

/* Step 5's average along x of rows y0 .. y1-1: s->risk into s->smoothed. */
static void smooth_rows(const stage *s, int y0, int y1)
{
    int width = s->d->width;
    for (int y = y0; y < y1; y++)
        for (int x0 = 0; x0 < width; x0 += DENOISE_RUN)
            average_run(s->d, s->risk, y, x0, width - x0 < DENOISE_RUN ? width - x0 : DENOISE_RUN, true,
                        s->smoothed + (size_t)y * width + x0);
}

/* Step 5's average along y of rows y0 .. y1-1 (s->smoothed), and the choice: where a
 * pixel's averaged risk is below the lowest so far, the image whose demodulated colour is
 * s->signal becomes its best. A NAN risk (the variance unknown nearby) chooses nothing. */
static void choose_rows(const stage *s, int y0, int y1)
{
    const denoiser *d = s->d;
    float risk[DENOISE_RUN];
    for (int y = y0; y < y1; y++)
        for (int x0 = 0; x0 < d->width; x0 += DENOISE_RUN) {
            int run = d->width - x0 < DENOISE_RUN ? d->width - x0 : DENOISE_RUN;
            average_run(d, s->smoothed, y, x0, run, false, risk);
            for (int k = 0; k < run; k++) {
                size_t p = (size_t)y * d->width + x0 + k;
                if (!(risk[k] < s->best_risk[p]))
                    continue;
                s->best_risk[p] = risk[k];
                for (int c = 0; c < 3; c++)
                    s->best[c][p] = remodulated(d, s->signal, p, c);
            }
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
            for (int c = 0; c < 3; c++)
                out[c] = s->signal[c][p];
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
                        residual[c] += s->filtered[c][q];
                    n++;
                }
            if (!known)
                continue;
            for (int c = 0; c < 3; c++)
                residual[c] /= n;
            /* Not below the 5x5 mean variance, so that pixels whose few samples all missed
             * a rare bright path (variance near 0: heavy-tailed noise) do not pass for
             * certain and get their dark or bright speck back (docs/sampling.md). */
            double pooled_sum = 0.0;
            int pooled = 0;
            for (int dy = -BIAS_POOL_RADIUS; dy <= BIAS_POOL_RADIUS; dy++)
                for (int dx = -BIAS_POOL_RADIUS; dx <= BIAS_POOL_RADIUS; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qx >= d->width || qy < 0 || qy >= d->height)
                        continue;
                    float v = s->variance[(size_t)qy * d->width + qx];
                    if (v >= 0.0f) {
                        pooled_sum += v;
                        pooled++;
                    }
                }
            variance_sum = fmax(variance_sum, n * pooled_sum / pooled);
            double standard_error = sqrt(variance_sum) / n;
            double z = fabs(luminance_double(residual[0], residual[1], residual[2])) / (standard_error + 1e-20);
            double share = z <= BIAS_Z_FROM ? 0.0
                           : z >= BIAS_Z_ALL ? 1.0
                                             : (z - BIAS_Z_FROM) / (BIAS_Z_ALL - BIAS_Z_FROM);
            /* What it gives back never takes a colour below 0 (a render's never is), nor
             * below what the filter left where that already was. */
            for (int c = 0; c < 3; c++)
                out[c] = fmaxf(fminf(out[c], 0.0f), (float)(out[c] + share * residual[c]));
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
    size_t count = postprocess_pixel_count(image);
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
static void noise_from_guide(const rt_image *mean_variance, const guide_planes *guides, bool demodulate,
                             float albedo_epsilon, size_t count, float *variance)
{
    for (size_t i = 0; i < count; i++) {
        float v = guide_variance(mean_variance, i);
        variance[i] = -1.0f;
        if (v < 0.0f)
            continue;
        double total = 0.0;
        for (int c = 0; c < 3; c++) {
            float divisor = demodulate ? fmaxf(guides->albedo[c][i], albedo_epsilon) : 1.0f;
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
    rt_status status = postprocess_check_image(guide, which, error);
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
    rt_status status = postprocess_check_image(colour, "colour", error);
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

/* The planes postprocess_denoise() works in, count floats each (bytes for noise_measured),
 * in one allocation: the guides' eleven float planes and the variance, the signal and
 * filtered colours, the filtered and blurred variances, and with step 5 its seven: dF/dy,
 * the risk and its average along x, the lowest risk so far and its image. */
enum { GUIDE_FLOAT_PLANES = 12, SIGNAL_PLANES = 3, OTHER_PLANES = 2, CHOICE_PLANES = 7 };
typedef struct denoise_planes {
    float *block;
    float *signal[SIGNAL_PLANES], *filtered[SIGNAL_PLANES];   /* ping-pong */
    float *variance, *filtered_variance, *blurred_variance;
    float *best[3];              /* step 5's (NULL without it), as choice.best points at */
    stage choice;                /* step 5's planes: risk, smoothed, best_risk, best */
} denoise_planes;

/* Allocates the planes of a count-pixel image into *planes and the guides into *g, with
 * step 5's (choosing; then d->self_weight too, all 1, and every best risk infinite); false
 * when out of memory (nothing to free then). Free with free(planes->block). */
static bool allocate_planes(size_t count, bool choosing, denoise_planes *planes, denoiser *d)
{
    guide_planes *g = &d->g;
    size_t floats = GUIDE_FLOAT_PLANES + 2 * SIGNAL_PLANES + OTHER_PLANES + (choosing ? CHOICE_PLANES : 0);
    if (count > SIZE_MAX / (floats * sizeof(float) + 1))
        return false;
    memset(planes, 0, sizeof *planes);
    planes->block = malloc(count * (floats * sizeof(float) + 1));
    if (planes->block == NULL)
        return false;
    float *next = planes->block;
    float **float_planes[GUIDE_FLOAT_PLANES + 2 * SIGNAL_PLANES + OTHER_PLANES + CHOICE_PLANES] = {
        &g->normal[0], &g->normal[1], &g->normal[2], &g->albedo[0], &g->albedo[1], &g->albedo[2],
        &g->depth, &g->gradient[0], &g->gradient[1], &g->depth_scale, &g->hit, &planes->variance,
        &planes->signal[0], &planes->signal[1], &planes->signal[2],
        &planes->filtered[0], &planes->filtered[1], &planes->filtered[2],
        &planes->filtered_variance, &planes->blurred_variance,
        &d->self_weight, &planes->choice.risk, &planes->choice.smoothed, &planes->choice.best_risk,
        &planes->best[0], &planes->best[1], &planes->best[2],
    };
    for (size_t i = 0; i < floats; i++, next += count)
        *float_planes[i] = next;
    g->noise_measured = (unsigned char *)next;   /* the count bytes after the floats */
    if (choosing) {
        planes->choice.best = planes->best;
        for (size_t i = 0; i < count; i++) {
            d->self_weight[i] = 1.0f;
            planes->choice.best_risk[i] = INFINITY;
        }
    }
    return true;
}

/* Step 5 for the image after an iteration, whose demodulated colour is signal: its risk,
 * smoothed, and where lower than the best so far, it becomes the best (choice's planes). */
static void offer_choice(const denoiser *d, float *const *signal, const stage *choice)
{
    stage s = *choice;
    s.d = d;
    s.signal = signal;
    run_rows(&s, risk_rows);
    run_rows(&s, smooth_rows);
    run_rows(&s, choose_rows);
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
    size_t count = postprocess_pixel_count(colour);
    int channels = colour->channels;

    int iterations = given.iterations != 0 ? given.iterations : DEFAULT_ITERATIONS;
    float sigma_normal = or_default(given.sigma_normal, DEFAULT_SIGMA_NORMAL);
    float sigma_albedo = or_default(given.sigma_albedo, DEFAULT_SIGMA_ALBEDO);
    float albedo_epsilon = or_default(given.albedo_epsilon, DEFAULT_ALBEDO_EPSILON);
    denoiser d = {
        .width = colour->width,
        .height = colour->height,
        .inverse_normal_sigma2 = normal != NULL ? 1.0f / (sigma_normal * sigma_normal) : 0.0f,
        .inverse_albedo_sigma2 = albedo != NULL ? 1.0f / (sigma_albedo * sigma_albedo) : 0.0f,
        .sigma_colour = or_default(given.sigma_colour, DEFAULT_SIGMA_COLOUR),
    };
    /* Step 5 where the render's variance is known. */
    bool choosing = mean_variance != NULL;
    denoise_planes planes;
    if (!allocate_planes(count, choosing, &planes, &d))
        return rt_error_set(error, RT_ERROR_RUNTIME, "POSTPROCESS: out of memory denoising a %dx%d image",
                            colour->width, colour->height);
    load_guides(albedo, normal, depth, colour->width, colour->height,
                or_default(given.sigma_depth, DEFAULT_SIGMA_DEPTH), &d.g);
    d.input = colour;
    d.emission = emission;
    d.mean_variance = mean_variance;
    d.demodulate = albedo != NULL;
    d.albedo_epsilon = albedo_epsilon;
    float **signal = planes.signal, **filtered = planes.filtered;
    float *variance = planes.variance, *filtered_variance = planes.filtered_variance,
          *blurred_variance = planes.blurred_variance;

    /* Demodulate: filter the lighting, not the texture, and not the emission seen at once. */
    for (size_t i = 0; i < count; i++)
        for (int c = 0; c < 3; c++) {
            float divisor = albedo != NULL ? fmaxf(d.g.albedo[c][i], albedo_epsilon) : 1.0f;
            float direct = emission != NULL ? emission->pixels[i * emission->channels + c] : 0.0f;
            signal[c][i] = (colour->pixels[i * channels + c] - direct) / divisor;
        }
    /* The noise: the render's own estimate where it has one, else measured around the pixel. */
    noise_from_guide(mean_variance, &d.g, albedo != NULL, albedo_epsilon, count, variance);
    for (size_t i = 0; i < count; i++)
        d.g.noise_measured[i] = variance[i] < 0.0f;
    run_rows(&(stage){.d = &d, .signal = signal, .variance_out = variance}, estimate_rows);
    d.sigma_colour_measured = d.sigma_colour;
    for (int i = 0; i < iterations; i++) {
        /* 4, 4, 2, 1, 0.5 where the render's variance says the noise (postprocess.h). */
        d.sigma_colour = ldexpf(d.sigma_colour_measured, i > 1 ? 1 - i : 0);
        run_rows(&(stage){.d = &d, .variance = variance, .blurred = blurred_variance}, blur_rows);
        run_rows(&(stage){.d = &d, .step = 1 << i, .signal = signal, .variance = variance,
                          .blurred = blurred_variance, .filtered = filtered, .variance_out = filtered_variance},
                 atrous_rows);
        float **swap = signal;
        signal = filtered;
        filtered = swap;
        float *swap_variance = variance;
        variance = filtered_variance;
        filtered_variance = swap_variance;
        if (choosing)
            offer_choice(&d, signal, &planes.choice);
    }
    /* The denoised colour (step 5's choice where it made one) into signal, what it took from
     * the input into filtered, and the render's variance of each pixel's mean luminance into
     * blurred_variance, for step 4. */
    for (size_t i = 0; i < count; i++) {
        bool chosen = choosing && planes.choice.best_risk[i] < INFINITY;
        for (int c = 0; c < 3; c++) {
            signal[c][i] = chosen ? planes.best[c][i] : remodulated(&d, signal, i, c);
            filtered[c][i] = colour->pixels[i * channels + c] - signal[c][i];
        }
        blurred_variance[i] = guide_variance(mean_variance, i);
    }
    run_rows(&(stage){.d = &d, .signal = signal, .filtered = filtered, .variance = blurred_variance,
                      .colour = colour->pixels, .channels = channels},
             correct_bias_rows);
    free(planes.block);
    return RT_OK;
}
int postprocess_denoise_reach(const postprocess_denoise_options *options)
{
    int iterations = options != NULL && options->iterations != 0 ? options->iterations : DEFAULT_ITERATIONS;
    return 2 * ((1 << iterations) - 1) + VARIANCE_RADIUS + 1 + CHOICE_RADIUS + BIAS_RADIUS;
}
