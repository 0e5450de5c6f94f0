/* image_diff.cpp: see image_diff.h. A thin extern "C" shim over OpenImageIO, like
 * image_io.cpp; no C++ exception crosses the C boundary.
 *
 * ImageBufAlgo::compare computes the errors: the mean and RMS of the absolute differences
 * over the compared samples, the largest and the first pixel where it is, and the pixels
 * over the threshold (it counts a pixel once when any compared channel is over, which is
 * image_diff.h's "error of a pixel is its largest channel's"). It takes the threshold as a
 * float: a pixel fails when its error exceeds (float)fail_threshold. ImageBufAlgo::absdiff
 * makes the difference image. What they do not do is here:
 *   - a NaN is an input error naming its pixel (compare matches NaN with NaN);
 *   - equal infinities differ by 0 and an infinity against anything else is an infinite
 *     error (compare matches +inf with -inf, and leaves the first infinite error out of
 *     its sums and counts; absdiff makes inf - inf a NaN): such samples are compared as
 *     finite stand-ins, and the infinite results are set afterwards;
 *   - the PSNR with peak 1 (compare's peak is the brightest value, when over 1);
 *   - the verdict (share of failing pixels, hard fail).
 */
#include "image_diff.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

namespace {

const double default_fail_threshold = IMAGE_DIFF_DEFAULT_FAIL_THRESHOLD;
const double default_fail_percent = IMAGE_DIFF_DEFAULT_FAIL_PERCENT;
const double default_diff_scale = IMAGE_DIFF_DEFAULT_SCALE;

/* Returns value, or fallback when value is zero ("zero means default"). */
double or_default(double value, double fallback)
{
    return value == 0.0 ? fallback : value;
}

/* Looks for a NaN in any channel of image (named "A" or "B" in the message). Returns
 * RT_OK, or RT_ERROR_INPUT naming the first NaN's pixel and channel. */
rt_status check_for_nan(const rt_image *image, const char *which, rt_error *error)
{
    size_t count = (size_t)image->width * image->height * image->channels;
    for (size_t i = 0; i < count; i++) {
        if (std::isnan(image->pixels[i])) {
            size_t pixel = i / image->channels;
            return rt_error_set(error, RT_ERROR_INPUT,
                                "DIFF: image %s has NaN at pixel (%d, %d), channel %d", which,
                                (int)(pixel % image->width), (int)(pixel / image->width),
                                (int)(i % image->channels));
        }
    }
    return RT_OK;
}

/* Returns RT_OK when image has pixels to compare, else RT_ERROR_INPUT. */
rt_status check_image(const rt_image *image, const char *which, rt_error *error)
{
    if (image == nullptr || image->pixels == nullptr || image->width <= 0 || image->height <= 0
        || image->channels <= 0)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: image %s is empty", which);
    return RT_OK;
}

/* Whether two samples differ infinitely: one is infinite and they are not equal. */
bool infinitely_apart(float a, float b)
{
    return a != b && (std::isinf(a) || std::isinf(b));
}

/* The pixels compare and absdiff see: a's and b's own, or, when a compared sample of
 * either is infinite, copies with each such pair of samples replaced by finite stand-ins:
 * (0, 0) for equal infinities, (0, FLT_MAX) for an infinite difference. */
struct compared_pixels {
    const float *a, *b;
    std::vector<float> a_copy, b_copy;
    bool infinite = false;   /* some pair differs infinitely */
    int first_x = 0, first_y = 0;  /* the first such pair's pixel */
};

compared_pixels finite_pixels(const rt_image *a, const rt_image *b, int compared)
{
    compared_pixels out;
    out.a = a->pixels;
    out.b = b->pixels;
    size_t pixels = (size_t)a->width * a->height;
    for (size_t p = 0; p < pixels; p++)
        for (int c = 0; c < compared; c++) {
            size_t in_a = p * a->channels + c, in_b = p * b->channels + c;
            float value_a = a->pixels[in_a], value_b = b->pixels[in_b];
            if (!std::isinf(value_a) && !std::isinf(value_b))
                continue;
            if (out.a_copy.empty()) {
                out.a_copy.assign(a->pixels, a->pixels + pixels * a->channels);
                out.b_copy.assign(b->pixels, b->pixels + pixels * b->channels);
                out.a = out.a_copy.data();
                out.b = out.b_copy.data();
            }
            bool apart = infinitely_apart(value_a, value_b);
            if (apart && !out.infinite) {
                out.infinite = true;
                out.first_x = (int)(p % a->width);
                out.first_y = (int)(p / a->width);
            }
            out.a_copy[in_a] = 0.0f;
            out.b_copy[in_b] = apart ? FLT_MAX : 0.0f;
        }
    return out;
}

/* An ImageBuf over pixels of image's size and channel count, neither copied nor owned. */
OIIO::ImageBuf wrap(const rt_image *image, const float *pixels)
{
    OIIO::ImageSpec spec(image->width, image->height, image->channels, OIIO::TypeDesc::FLOAT);
    return OIIO::ImageBuf(spec, const_cast<float *>(pixels));
}

/* Fills difference (allocated here) with |a - b| * scale of the compared channels as RGB:
 * one compared channel is shown as grey, a missing third as 0. */
rt_status make_difference_image(const OIIO::ImageBuf &a, const OIIO::ImageBuf &b, int compared, double scale,
                                rt_image *difference, rt_error *error)
{
    rt_status status = image_create(difference, a.spec().width, a.spec().height, 3, error);
    if (status != RT_OK)
        return status;
    OIIO::ROI roi = a.roi();
    roi.chend = compared;
    OIIO::ImageBuf d = OIIO::ImageBufAlgo::absdiff(a, b, roi);
    bool ok = d.initialized() && OIIO::ImageBufAlgo::mul(d, d, (float)scale);
    static const int grey[3] = {0, 0, 0}, two[3] = {0, 1, -1}, rgb[3] = {0, 1, 2};
    const int *order = compared == 1 ? grey : compared == 2 ? two : rgb;
    OIIO::ImageBuf shown = ok ? OIIO::ImageBufAlgo::channels(d, 3, OIIO::cspan<int>(order, 3), {0.0f, 0.0f, 0.0f}) : d;
    ok = ok && shown.initialized() && shown.get_pixels(shown.roi(), OIIO::TypeDesc::FLOAT, difference->pixels);
    if (!ok) {
        image_free(difference);
        return rt_error_set(error, RT_ERROR_RUNTIME, "DIFF: cannot make the difference image: %s",
                            shown.geterror().c_str());
    }
    return RT_OK;
}

/* Compares a and b (checked: same size, no NaN); see image_diff.h. */
rt_status compare_images(const rt_image *a, const rt_image *b, const image_diff_options *options,
                         image_diff_result *result, rt_image *difference_image, rt_error *error)
{
    double fail_threshold = or_default(options->fail_threshold, default_fail_threshold);
    double fail_percent = or_default(options->fail_percent, default_fail_percent);
    double hard_fail = options->hard_fail;
    double diff_scale = or_default(options->diff_scale, default_diff_scale);
    int compared = a->channels < b->channels ? a->channels : b->channels;
    if (compared > 3)
        compared = 3;

    compared_pixels pixels = finite_pixels(a, b, compared);
    OIIO::ImageBuf image_a = wrap(a, pixels.a), image_b = wrap(b, pixels.b);
    OIIO::ROI roi = image_a.roi();
    roi.chend = compared;
    OIIO::ImageBufAlgo::CompareResults compared_result =
        OIIO::ImageBufAlgo::compare(image_a, image_b, (float)fail_threshold, (float)fail_threshold, roi);
    /* Not compared_result.error: OIIO 2.4 sets it whenever a pixel fails. */
    if (image_a.has_error() || image_b.has_error())
        return rt_error_set(error, RT_ERROR_RUNTIME, "DIFF: OpenImageIO could not compare the images: %s",
                            (image_a.geterror() + image_b.geterror()).c_str());

    result->mean_error = compared_result.meanerror;
    result->rms_error = compared_result.rms_error;
    result->max_error = compared_result.maxerror;
    result->max_x = compared_result.maxx;
    result->max_y = compared_result.maxy;
    if (pixels.infinite) {
        result->mean_error = result->rms_error = result->max_error = INFINITY;
        result->max_x = pixels.first_x;
        result->max_y = pixels.first_y;
    }
    double mse = result->rms_error * result->rms_error;
    result->psnr = mse == 0.0 ? INFINITY : 10.0 * std::log10(1.0 / mse);
    result->failing_pixels = (long)compared_result.nfail;
    result->failing_percent = 100.0 * (double)compared_result.nfail / ((double)a->width * a->height);
    result->passed = result->failing_percent <= fail_percent && !(hard_fail > 0.0 && result->max_error > hard_fail);

    if (difference_image == nullptr)
        return RT_OK;
    rt_status status = make_difference_image(image_a, image_b, compared, diff_scale, difference_image, error);
    if (status != RT_OK || !pixels.infinite)
        return status;
    size_t count = (size_t)a->width * a->height;
    for (size_t p = 0; p < count; p++)
        for (int c = 0; c < compared; c++)
            if (infinitely_apart(a->pixels[p * a->channels + c], b->pixels[p * b->channels + c]))
                difference_image->pixels[p * 3 + c] = INFINITY;
    if (compared == 1)
        for (size_t p = 0; p < count; p++)
            difference_image->pixels[p * 3 + 1] = difference_image->pixels[p * 3 + 2] = difference_image->pixels[p * 3];
    return RT_OK;
}

}  // namespace

extern "C" {

image_diff_options image_diff_options_defaults(void)
{
    return image_diff_options{};
}

rt_status image_diff(const rt_image *a, const rt_image *b, const image_diff_options *options,
                     image_diff_result *result, rt_image *difference_image, rt_error *error)
{
    memset(result, 0, sizeof *result);
    if (difference_image != nullptr)
        memset(difference_image, 0, sizeof *difference_image);

    rt_status status = check_image(a, "A", error);
    if (status == RT_OK)
        status = check_image(b, "B", error);
    if (status != RT_OK)
        return status;
    if (a->width != b->width || a->height != b->height)
        return rt_error_set(error, RT_ERROR_INPUT, "DIFF: sizes differ: %dx%d vs %dx%d", a->width,
                            a->height, b->width, b->height);
    status = check_for_nan(a, "A", error);
    if (status == RT_OK)
        status = check_for_nan(b, "B", error);
    if (status != RT_OK)
        return status;

    image_diff_options defaults = image_diff_options_defaults();
    try {
        return compare_images(a, b, options != nullptr ? options : &defaults, result, difference_image, error);
    } catch (const std::bad_alloc &) {
        if (difference_image != nullptr)
            image_free(difference_image);
        return rt_error_set(error, RT_ERROR_RUNTIME, "DIFF: out of memory comparing %dx%d images", a->width,
                            a->height);
    } catch (const std::exception &e) {
        if (difference_image != nullptr)
            image_free(difference_image);
        return rt_error_set(error, RT_ERROR_RUNTIME, "DIFF: %s", e.what());
    }
}

}  // extern "C"
