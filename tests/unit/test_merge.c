/* test_merge.c: the merge rules of core/merge.h on small hand-made parts whose expected
 * results are worked out in the comments: weighted means, uneven and zero counts, tiles
 * put in place, and every refusal (overlaps, missing pieces, mismatched renders). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "merge.h"
#include "support.h"

/* Makes a part: a width x height region at (x, y) of a full_width x full_height image,
 * channels R, G, B, samples, every pixel colour (r, g, b) with n samples. full_width 0
 * makes it the full image. */
static rt_image make_part(int x, int y, int width, int height, int full_width, int full_height, float r, float g,
                          float b, float n)
{
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, width, height, 4, &error), RT_OK);
    static const char *const names[4] = {"R", "G", "B", "samples"};
    for (int c = 0; c < 4; c++)
        strcpy(image.channel_names[c], names[c]);
    for (int i = 0; i < width * height; i++) {
        image.pixels[4 * i + 0] = r;
        image.pixels[4 * i + 1] = g;
        image.pixels[4 * i + 2] = b;
        image.pixels[4 * i + 3] = n;
    }
    image.x = x;
    image.y = y;
    image.full_width = full_width;
    image.full_height = full_height;
    return image;
}

/* The metadata of a complete part of samples start .. start+spp-1 of one common render. */
static merge_metadata make_metadata(unsigned long long start, long long spp)
{
    merge_metadata metadata;
    memset(&metadata, 0, sizeof metadata);
    strcpy(metadata.scene, "scene.txt");
    strcpy(metadata.scene_hash, "00112233aabbccdd");
    metadata.seed = 1;
    metadata.max_depth = 16;
    metadata.frame = -1;
    metadata.sample_start = start;
    metadata.spp = spp;
    metadata.complete = true;
    metadata.render_seconds = 0.5;
    metadata.path_segments = 100;
    return metadata;
}

static float *pixel(rt_image *image, int x, int y)
{
    return &image->pixels[((size_t)y * image->width + x) * image->channels];
}

/* Adds part under name and frees its pixels (the merger keeps none). */
static rt_status add(merger *m, const char *name, rt_image part, merge_metadata metadata, rt_error *error)
{
    rt_status status = merger_add(m, name, &part, &metadata, error);
    image_free(&part);
    return status;
}

/* Asserts that text contains every one of the NULL-terminated fragments. */
#define assert_mentions(text, ...) check_mentions((text), __FILE__, __LINE__, __VA_ARGS__)

static void check_mentions(const char *text, const char *file, int line, ...)
{
    va_list fragments;
    va_start(fragments, line);
    const char *fragment;
    while ((fragment = va_arg(fragments, const char *)) != NULL)
        support_check_contains(text, fragment, file, line);
    va_end(fragments);
}

/* Two sample-range parts of a 2x1 image: colour 0.25 with 6 samples and 0.75 with 10 give
 * (0.25*6 + 0.75*10) / 16 = 9 / 16 = 0.5625, exactly; G and B the same way. */
static void test_weighted_mean(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "a.exr", make_part(0, 0, 2, 1, 0, 0, 0.25f, 1.0f, 0.0f, 6), make_metadata(0, 6), &error),
                     RT_OK);
    assert_int_equal(add(m, "b.exr", make_part(0, 0, 2, 1, 0, 0, 0.75f, 0.5f, 2.0f, 10), make_metadata(6, 10), &error),
                     RT_OK);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(out.width, 2);
    assert_int_equal(out.height, 1);
    assert_int_equal(out.channels, 4);
    assert_string_equal(out.channel_names[3], "samples");
    assert_int_equal(out.x, 0);
    assert_int_equal(out.full_width, 0);
    for (int x = 0; x < 2; x++) {
        assert_true(pixel(&out, x, 0)[0] == 0.5625f);
        assert_true(pixel(&out, x, 0)[1] == (1.0f * 6 + 0.5f * 10) / 16);  /* 0.6875 */
        assert_true(pixel(&out, x, 0)[2] == 20.0f / 16);
        assert_true(pixel(&out, x, 0)[3] == 16.0f);
    }
    assert_int_equal(summary.part_count, 2);
    assert_int_equal(summary.region_count, 1);
    assert_int_equal(summary.min_samples, 16);
    assert_true(summary.total_samples == 32);
    assert_int_equal(summary.sample_start, 0);
    assert_true(summary.complete);
    assert_int_equal(summary.warning_count, 0);
    assert_true(summary.render_seconds == 1.0);
    assert_true(summary.path_segments == 200);
    assert_string_equal(summary.metadata.scene_hash, "00112233aabbccdd");
    image_free(&out);
    merger_free(m);
}

/* Per-pixel counts differ (an interrupted part): pixel 0 has 3 samples of 1.0 and 1 of
 * 0.0 -> 0.75; pixel 1 has 0 samples in the first part (its colour 9 means nothing and
 * must not leak) and 2 of 0.5 -> 0.5; pixel 2 has none at all -> 0 with 0 samples. */
static void test_uneven_and_zero_counts(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    rt_image a = make_part(0, 0, 3, 1, 0, 0, 1.0f, 1.0f, 1.0f, 3);
    pixel(&a, 1, 0)[0] = pixel(&a, 1, 0)[1] = pixel(&a, 1, 0)[2] = 9.0f;
    pixel(&a, 1, 0)[3] = 0;
    pixel(&a, 2, 0)[0] = 5.0f;
    pixel(&a, 2, 0)[3] = 0;
    merge_metadata interrupted = make_metadata(0, 4);
    interrupted.complete = false;
    assert_int_equal(add(m, "a.exr", a, interrupted, &error), RT_OK);
    rt_image b = make_part(0, 0, 3, 1, 0, 0, 0.0f, 0.0f, 0.0f, 1);
    pixel(&b, 1, 0)[0] = pixel(&b, 1, 0)[1] = pixel(&b, 1, 0)[2] = 0.5f;
    pixel(&b, 1, 0)[3] = 2;
    pixel(&b, 2, 0)[3] = 0;
    assert_int_equal(add(m, "b.exr", b, make_metadata(4, 4), &error), RT_OK);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_true(pixel(&out, 0, 0)[0] == 0.75f);
    assert_true(pixel(&out, 0, 0)[3] == 4.0f);
    assert_true(pixel(&out, 1, 0)[0] == 0.5f);
    assert_true(pixel(&out, 1, 0)[3] == 2.0f);
    for (int c = 0; c < 4; c++)
        assert_true(pixel(&out, 2, 0)[c] == 0.0f);
    assert_int_equal(summary.min_samples, 0);
    assert_int_equal(summary.max_samples, 4);
    assert_false(summary.complete);  /* a part was interrupted */
    image_free(&out);
    merger_free(m);
}

/* Three horizontal bands of a 5x7 image (rows 0-1, 2-4, 5-6, as --tile I/3 cuts them)
 * with each pixel's red = x + 10 y: the merge puts every pixel back exactly. */
static void test_tiles_assembled(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    const int rows[4] = {0, 2, 5, 7};
    /* Added out of order, to show order does not matter. */
    const int order[3] = {2, 0, 1};
    for (int k = 0; k < 3; k++) {
        int t = order[k];
        rt_image tile = make_part(0, rows[t], 5, rows[t + 1] - rows[t], 5, 7, 0, 0.1f, 0.2f, 8);
        for (int y = 0; y < tile.height; y++)
            for (int x = 0; x < 5; x++)
                pixel(&tile, x, y)[0] = (float)(x + 10 * (rows[t] + y)) / 3.0f;
        char name[32];
        snprintf(name, sizeof name, "tile-%d.exr", t);
        assert_int_equal(add(m, name, tile, make_metadata(0, 8), &error), RT_OK);
    }
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(out.width, 5);
    assert_int_equal(out.height, 7);
    for (int y = 0; y < 7; y++)
        for (int x = 0; x < 5; x++) {
            assert_true(pixel(&out, x, y)[0] == (float)(x + 10 * y) / 3.0f);
            assert_true(pixel(&out, x, y)[1] == 0.1f);
            assert_true(pixel(&out, x, y)[3] == 8.0f);
        }
    assert_int_equal(summary.region_count, 3);
    assert_true(summary.complete);
    image_free(&out);
    merger_free(m);
}

/* Tiles that each have two sample-range parts: regions and ranges combine. */
static void test_tiles_with_sample_ranges(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "t0a", make_part(0, 0, 2, 1, 2, 2, 1, 1, 1, 4), make_metadata(4, 4), &error), RT_OK);
    assert_int_equal(add(m, "t1a", make_part(0, 1, 2, 1, 2, 2, 2, 2, 2, 4), make_metadata(0, 4), &error), RT_OK);
    assert_int_equal(add(m, "t0b", make_part(0, 0, 2, 1, 2, 2, 3, 3, 3, 4), make_metadata(0, 4), &error), RT_OK);
    assert_int_equal(add(m, "t1b", make_part(0, 1, 2, 1, 2, 2, 4, 4, 4, 4), make_metadata(4, 4), &error), RT_OK);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_true(pixel(&out, 1, 0)[0] == 2.0f);
    assert_true(pixel(&out, 1, 1)[0] == 3.0f);
    assert_true(pixel(&out, 0, 1)[3] == 8.0f);
    assert_true(summary.complete);
    assert_int_equal(summary.warning_count, 0);
    image_free(&out);
    merger_free(m);
}

/* Tile 0 with samples 0:16, tile 1 with only 0:8: a warning naming both, not an error;
 * the counts say 16 and 8, spp is the minimum, and the result is not complete. */
static void test_regions_with_different_ranges_warn(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "top.exr", make_part(0, 0, 2, 1, 2, 2, 1, 1, 1, 16), make_metadata(0, 16), &error), RT_OK);
    assert_int_equal(add(m, "bottom.exr", make_part(0, 1, 2, 1, 2, 2, 1, 1, 1, 8), make_metadata(0, 8), &error), RT_OK);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(summary.warning_count, 1);
    assert_mentions(summary.warnings[0], "top.exr", "bottom.exr", "0:16", "0:8", NULL);
    assert_int_equal(summary.min_samples, 8);
    assert_int_equal(summary.max_samples, 16);
    assert_false(summary.complete);
    image_free(&out);
    merger_free(m);
}

/* Samples 0:4 and 8:4 of one region merge (no overlap) but leave a gap: not complete. */
static void test_gap_in_sample_ranges_is_not_complete(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "a", make_part(0, 0, 1, 1, 0, 0, 1, 1, 1, 4), make_metadata(8, 4), &error), RT_OK);
    assert_int_equal(add(m, "b", make_part(0, 0, 1, 1, 0, 0, 1, 1, 1, 4), make_metadata(0, 4), &error), RT_OK);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_false(summary.complete);
    assert_int_equal(summary.sample_start, 0);
    assert_int_equal(summary.min_samples, 8);
    image_free(&out);
    merger_free(m);
}

/* Samples 0:8 and 4:8 share samples 4-7: refused, naming both parts; the merger is left
 * as it was, so the first part alone still merges. */
static void test_overlapping_sample_ranges(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "first.exr", make_part(0, 0, 2, 2, 0, 0, 1, 1, 1, 8), make_metadata(0, 8), &error), RT_OK);
    assert_int_equal(add(m, "second.exr", make_part(0, 0, 2, 2, 0, 0, 1, 1, 1, 8), make_metadata(4, 8), &error),
                     RT_ERROR_INPUT);
    assert_mentions(error.message, "first.exr", "second.exr", "0:8", "4:8", "4-7", NULL);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(summary.part_count, 1);
    assert_true(pixel(&out, 1, 1)[3] == 8.0f);
    image_free(&out);
    merger_free(m);
}

/* Rows 0-2 and rows 2-3 of a 4x4 image share row 2: refused, naming both. */
static void test_overlapping_regions(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "upper.exr", make_part(0, 0, 4, 3, 4, 4, 1, 1, 1, 1), make_metadata(0, 1), &error), RT_OK);
    assert_int_equal(add(m, "lower.exr", make_part(0, 2, 4, 2, 4, 4, 1, 1, 1, 1), make_metadata(0, 1), &error),
                     RT_ERROR_INPUT);
    assert_mentions(error.message, "upper.exr", "lower.exr", "overlap", "rows 0-2", "rows 2-3", NULL);
    merger_free(m);
}

/* Rows 0-1 and 4-5 of a 3x6 image leave rows 2-3 uncovered: 6 pixels missing. With
 * allow_missing they stay 0 with 0 samples and the result is not complete. */
static void test_missing_pieces(void **state)
{
    (void)state;
    for (int allow = 0; allow <= 1; allow++) {
        merger *m;
        rt_error error;
        assert_int_equal(merger_create(&m, &error), RT_OK);
        assert_int_equal(add(m, "a", make_part(0, 0, 3, 2, 3, 6, 1, 1, 1, 2), make_metadata(0, 2), &error), RT_OK);
        assert_int_equal(add(m, "b", make_part(0, 4, 3, 2, 3, 6, 1, 1, 1, 2), make_metadata(0, 2), &error), RT_OK);
        merge_options options = merge_options_defaults();
        options.allow_missing = allow;
        rt_image out;
        merge_summary summary;
        rt_status status = merger_finish(m, &options, &out, &summary, &error);
        if (!allow) {
            assert_int_equal(status, RT_ERROR_INPUT);
            assert_mentions(error.message, "missing pieces", "6 pixels", "rows 2-3", NULL);
            assert_null(out.pixels);
        } else {
            assert_int_equal(status, RT_OK);
            assert_int_equal(summary.missing_pixels, 6);
            assert_false(summary.complete);
            assert_int_equal(summary.min_samples, 0);
            assert_true(pixel(&out, 1, 2)[0] == 0.0f);
            assert_true(pixel(&out, 1, 3)[3] == 0.0f);
            assert_true(pixel(&out, 1, 4)[0] == 1.0f);
            image_free(&out);
        }
        merger_free(m);
    }
}

/* A missing corner and a missing band are both described, with their columns. */
static void test_missing_pieces_described(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    /* 10x10 image: rows 0-3 full; rows 4-5 only columns 0-4; rows 6-7 full; 8-9 missing. */
    assert_int_equal(add(m, "a", make_part(0, 0, 10, 4, 10, 10, 1, 1, 1, 1), make_metadata(0, 1), &error), RT_OK);
    assert_int_equal(add(m, "b", make_part(0, 4, 5, 2, 10, 10, 1, 1, 1, 1), make_metadata(0, 1), &error), RT_OK);
    assert_int_equal(add(m, "c", make_part(0, 6, 10, 2, 10, 10, 1, 1, 1, 1), make_metadata(0, 1), &error), RT_OK);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "30 pixels", "rows 4-5 (columns 5-9)", "rows 8-9 (columns 0-9)", NULL);
    merger_free(m);
}

/* Every kind of mismatch with the first part is refused, naming both parts and values. */
static void test_mismatched_parts(void **state)
{
    (void)state;
    struct {
        const char *what;
        int full_width;
        merge_metadata metadata;
        const char *mentions[2];
    } cases[5];
    for (int i = 0; i < 5; i++) {
        cases[i].full_width = 4;
        cases[i].metadata = make_metadata(8, 8);
    }
    cases[0].what = "size", cases[0].full_width = 5, cases[0].mentions[0] = "4x4", cases[0].mentions[1] = "5x4";
    cases[1].what = "seed", cases[1].metadata.seed = 7, cases[1].mentions[0] = "seed 1", cases[1].mentions[1] = "seed 7";
    cases[2].what = "depth", cases[2].metadata.max_depth = 3, cases[2].mentions[0] = "16";
    cases[2].mentions[1] = "depth 3";
    cases[3].what = "frame", cases[3].metadata.frame = 12, cases[3].mentions[0] = "frame -1";
    cases[3].mentions[1] = "frame 12";
    cases[4].what = "scene", strcpy(cases[4].metadata.scene_hash, "ffff"), strcpy(cases[4].metadata.scene, "other.txt");
    cases[4].mentions[0] = "ffff", cases[4].mentions[1] = "other.txt";
    for (int i = 0; i < 5; i++) {
        merger *m;
        rt_error error;
        assert_int_equal(merger_create(&m, &error), RT_OK);
        assert_int_equal(add(m, "one.exr", make_part(0, 0, 4, 4, 4, 4, 1, 1, 1, 8), make_metadata(0, 8), &error),
                         RT_OK);
        rt_status status = add(m, "two.exr", make_part(0, 0, 4, 4, cases[i].full_width, 4, 1, 1, 1, 8),
                               cases[i].metadata, &error);
        if (status != RT_ERROR_INPUT) {
            print_error("a different %s was accepted\n", cases[i].what);
            fail();
        }
        assert_mentions(error.message, "one.exr", "two.exr", cases[i].mentions[0], cases[i].mentions[1], NULL);
        merger_free(m);
    }
}

/* A part without a samples channel, or with a data window outside its image, is refused. */
static void test_malformed_parts(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    rt_image no_samples = make_part(0, 0, 2, 2, 0, 0, 1, 1, 1, 1);
    strcpy(no_samples.channel_names[3], "A");
    assert_int_equal(add(m, "rgba.exr", no_samples, make_metadata(0, 1), &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "rgba.exr", "samples", NULL);
    assert_int_equal(add(m, "outside.exr", make_part(3, 0, 2, 2, 4, 4, 1, 1, 1, 1), make_metadata(0, 1), &error),
                     RT_ERROR_INPUT);
    assert_mentions(error.message, "outside.exr", "outside", NULL);
    assert_int_equal(add(m, "negative.exr", make_part(0, 0, 2, 2, 0, 0, 1, 1, 1, -1), make_metadata(0, 1), &error),
                     RT_ERROR_INPUT);
    rt_image out;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "no parts", NULL);
    merger_free(m);
}

/* merge_read_part reads what render writes: the data window and the metadata. */
static void test_read_part(void **state)
{
    scratch *s = *state;
    rt_error error;
    rt_image tile = make_part(0, 2, 3, 2, 3, 6, 0.5f, 0.25f, 0.125f, 12);
    image_attribute attributes[] = {
        {.name = "rtspheres:scene", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "scenes/x.txt"},
        {.name = "rtspheres:scene_hash", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "0123456789abcdef"},
        {.name = "rtspheres:spp", .type = IMAGE_ATTRIBUTE_INT, .int_value = 12},
        {.name = "rtspheres:sample_start", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "4000000000"},
        {.name = "rtspheres:seed", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "4294967295"},
        {.name = "rtspheres:max_depth", .type = IMAGE_ATTRIBUTE_INT, .int_value = 50},
        {.name = "rtspheres:frame", .type = IMAGE_ATTRIBUTE_INT, .int_value = -1},
        {.name = "rtspheres:complete", .type = IMAGE_ATTRIBUTE_INT, .int_value = 0},
        {.name = "rtspheres:render_seconds", .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = 2.5},
        {.name = "rtspheres:path_segments", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "123456"},
    };
    image_write_options options = image_write_options_defaults();
    options.attributes = attributes;
    options.attribute_count = (int)(sizeof attributes / sizeof attributes[0]);
    assert_int_equal(image_write(in_scratch(s, "part.exr"), &tile, &options, &error), RT_OK);

    rt_image image;
    merge_metadata metadata;
    assert_int_equal(merge_read_part(in_scratch(s, "part.exr"), &image, &metadata, &error), RT_OK);
    assert_int_equal(image.y, 2);
    assert_int_equal(image.height, 2);
    assert_int_equal(image.full_height, 6);
    assert_merge_metadata_equal(&metadata, (&(merge_metadata){
                                               .scene = "scenes/x.txt", .scene_hash = "0123456789abcdef",
                                               .spp = 12, .sample_start = 4000000000ull, .seed = 4294967295ull,
                                               .max_depth = 50, .frame = -1, .complete = false,
                                               .render_seconds = 2.5, .path_segments = 123456}));
    image_free(&image);

    /* Without metadata: refused, naming the file and what is missing. */
    assert_int_equal(image_write(in_scratch(s, "bare.exr"), &tile, NULL, &error), RT_OK);
    assert_int_equal(merge_read_part(in_scratch(s, "bare.exr"), &image, &metadata, &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "bare.exr", "rtspheres:scene_hash", NULL);
    assert_null(image.pixels);

    /* Without a samples channel: refused. */
    rt_image rgb;
    assert_int_equal(image_create(&rgb, 2, 2, 3, &error), RT_OK);
    assert_int_equal(image_write(in_scratch(s, "rgb.exr"), &rgb, &options, &error), RT_OK);
    image_free(&rgb);
    assert_int_equal(merge_read_part(in_scratch(s, "rgb.exr"), &image, &metadata, &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "rgb.exr", "samples", NULL);

    /* A missing file: refused as bad input. */
    assert_int_equal(merge_read_part(in_scratch(s, "absent.exr"), &image, &metadata, &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "absent.exr", NULL);
    image_free(&tile);
}

/* Adds light group layers "key" and "fill" to part: key (k, 2k, 3k) and fill its colour
 * minus key, channels ordered as an EXR lists them (alphabetically), and names the groups
 * in metadata. */
static rt_image with_layers(rt_image part, float k, merge_metadata *metadata)
{
    rt_image layered;
    rt_error error;
    assert_int_equal(image_create(&layered, part.width, part.height, 10, &error), RT_OK);
    static const char *const names[10] = {"B", "G", "R", "fill.B", "fill.G", "fill.R", "key.B", "key.G", "key.R",
                                          "samples"};
    for (int c = 0; c < 10; c++)
        strcpy(layered.channel_names[c], names[c]);
    for (int i = 0; i < part.width * part.height; i++) {
        float *in = part.pixels + 4 * i, *out = layered.pixels + 10 * i;
        for (int c = 0; c < 3; c++) {
            out[2 - c] = in[c];
            out[8 - c] = k * (float)(c + 1);
            out[5 - c] = in[c] - out[8 - c];
        }
        out[9] = in[3];
    }
    layered.x = part.x;
    layered.y = part.y;
    layered.full_width = part.full_width;
    layered.full_height = part.full_height;
    image_free(&part);
    strcpy(metadata->light_groups, "key,fill");
    return layered;
}

/* Light group layers merge as the colour does: two sample ranges (key 0.25 with 6
 * samples, 0.75 with 10: 0.5625 as in test_weighted_mean) weighted, and two tiles put in
 * place exactly; the groups in the metadata's order. Parts with other groups, or one
 * with layers and one without, are refused naming both. */
static void test_light_group_layers(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    merge_metadata a = make_metadata(0, 6), b = make_metadata(6, 10);
    rt_image part_a = with_layers(make_part(0, 0, 2, 1, 0, 0, 1, 1, 1, 6), 0.25f, &a);
    rt_image part_b = with_layers(make_part(0, 0, 2, 1, 0, 0, 1, 1, 1, 10), 0.75f, &b);
    assert_int_equal(add(m, "a.exr", part_a, a, &error), RT_OK);
    assert_int_equal(add(m, "b.exr", part_b, b, &error), RT_OK);
    rt_image out, layers;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(merger_light_groups(m, &layers, &error), RT_OK);
    assert_string_equal(summary.metadata.light_groups, "key,fill");
    assert_int_equal(layers.channels, 6);
    assert_string_equal(layers.channel_names[0], "key.R");
    assert_string_equal(layers.channel_names[5], "fill.B");
    for (int x = 0; x < 2; x++)
        for (int c = 0; c < 3; c++) {
            float key = pixel(&layers, x, 0)[c], fill = pixel(&layers, x, 0)[3 + c];
            assert_true(key == 0.5625f * (float)(c + 1));
            assert_float_equal(key + fill, pixel(&out, x, 0)[c], 1e-6);
        }
    image_free(&out);
    image_free(&layers);
    merger_free(m);

    /* Two bands of a 1x2 image, each with its own key: each pixel's exactly. */
    assert_int_equal(merger_create(&m, &error), RT_OK);
    a = make_metadata(0, 4);
    b = make_metadata(0, 4);
    assert_int_equal(add(m, "top", with_layers(make_part(0, 0, 1, 1, 1, 2, 1, 1, 1, 4), 0.1f, &a), a, &error),
                     RT_OK);
    assert_int_equal(add(m, "bottom", with_layers(make_part(0, 1, 1, 1, 1, 2, 1, 1, 1, 4), 0.3f, &b), b, &error),
                     RT_OK);
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(merger_light_groups(m, &layers, &error), RT_OK);
    assert_true(pixel(&layers, 0, 0)[0] == 0.1f);
    assert_true(pixel(&layers, 0, 1)[0] == 0.3f);
    assert_true(pixel(&layers, 0, 1)[3] == 1.0f - 0.3f);
    image_free(&out);
    image_free(&layers);
    merger_free(m);

    /* Without layers there are none to merge. */
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "plain", make_part(0, 0, 1, 1, 0, 0, 1, 1, 1, 4), make_metadata(0, 4), &error), RT_OK);
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(merger_light_groups(m, &layers, &error), RT_OK);
    assert_null(layers.pixels);
    image_free(&out);
    merger_free(m);

    /* Mismatches. */
    assert_int_equal(merger_create(&m, &error), RT_OK);
    a = make_metadata(0, 4);
    assert_int_equal(add(m, "layered.exr", with_layers(make_part(0, 0, 1, 1, 0, 0, 1, 1, 1, 4), 0.1f, &a), a, &error),
                     RT_OK);
    assert_int_equal(add(m, "plain.exr", make_part(0, 0, 1, 1, 0, 0, 1, 1, 1, 4), make_metadata(4, 4), &error),
                     RT_ERROR_INPUT);
    assert_mentions(error.message, "'layered.exr' has light groups 'key,fill' but 'plain.exr' none", NULL);
    b = make_metadata(4, 4);
    rt_image other = with_layers(make_part(0, 0, 1, 1, 0, 0, 1, 1, 1, 4), 0.1f, &b);
    strcpy(b.light_groups, "key");
    assert_int_equal(add(m, "other.exr", other, b, &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "but 'other.exr' 'key'", NULL);
    merger_free(m);
    assert_int_equal(merger_create(&m, &error), RT_OK);
    a = make_metadata(0, 4);
    rt_image lacking = make_part(0, 0, 1, 1, 0, 0, 1, 1, 1, 4);
    strcpy(a.light_groups, "key");
    assert_int_equal(add(m, "lacking.exr", lacking, a, &error), RT_ERROR_INPUT);
    assert_mentions(error.message, "'lacking.exr' lists light groups 'key' but its layers are not all there",
                    "no channel key.R", NULL);
    merger_free(m);
}

/* A 1x1 part (samples n of colour c, grey) with --aovs layers: guides g (albedo g, normal
 * (0, g, 0), depth 10 g), the samples' variance of luminance v and, with emission, e. */
static rt_image make_aov_part(float c, float n, float g, float v, bool with_emission, float e)
{
    rt_image base = make_part(0, 0, 1, 1, 0, 0, c, c, c, n), layers, part;
    rt_error error;
    int count = with_emission ? 11 : 8;
    static const char *const names[11] = {"albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z",
                                          "depth.Z", "variance.Y", "emission.R", "emission.G", "emission.B"};
    const float values[11] = {g, g, g, 0, g, 0, 10 * g, v, e, e, e};
    assert_int_equal(image_create(&layers, 1, 1, count, &error), RT_OK);
    for (int k = 0; k < count; k++) {
        strcpy(layers.channel_names[k], names[k]);
        layers.pixels[k] = values[k];
    }
    assert_int_equal(image_append_channels(&base, &layers, &part, &error), RT_OK);
    image_free(&base);
    image_free(&layers);
    return part;
}

/* Sample ranges with AOVs: the guides of the part that starts lowest, emission weighted by
 * samples, variance.Y recombined: parts of 4 samples (mean 1, variance 0.5) and 12 (mean
 * 3, variance 2) are 16 samples of mean 2.5 and E[L^2] = (4 * 1.5 + 12 * 11) / 16 = 8.625,
 * so variance 8.625 - 6.25 = 2.375. Emission (4 * 1 + 12 * 2) / 16 = 1.75. */
static void test_aov_layers_merged(void **state)
{
    (void)state;
    merger *m;
    rt_error error;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(add(m, "late", make_aov_part(3, 12, 0.75f, 2, true, 2), make_metadata(4, 12), &error), RT_OK);
    assert_int_equal(add(m, "early", make_aov_part(1, 4, 0.25f, 0.5f, true, 1), make_metadata(0, 4), &error), RT_OK);
    rt_image out, aovs;
    merge_summary summary;
    assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
    assert_int_equal(merger_aovs(m, &aovs, &error), RT_OK);
    assert_int_equal(aovs.channels, 11);
    assert_string_equal(aovs.channel_names[7], "variance.Y");
    assert_string_equal(aovs.channel_names[10], "emission.B");
    float *p = pixel(&aovs, 0, 0);
    assert_true(p[0] == 0.25f && p[4] == 0.25f && p[6] == 2.5f);   /* the early part's guides */
    assert_relative(p[7], 2.375, 1e-5);
    assert_relative(p[8], 1.75, 1e-6);
    assert_relative(pixel(&out, 0, 0)[0], 2.5, 1e-6);
    assert_int_equal(summary.warning_count, 0);
    image_free(&out);
    image_free(&aovs);
    merger_free(m);

    /* A part without emission (resumed): the AOVs without it, and a warning. A part
     * without AOVs at all: none, and a warning. */
    for (int without = 0; without < 2; without++) {
        assert_int_equal(merger_create(&m, &error), RT_OK);
        assert_int_equal(add(m, "a", make_aov_part(1, 4, 0.25f, 0.5f, true, 1), make_metadata(0, 4), &error), RT_OK);
        rt_image second = without == 0 ? make_aov_part(3, 12, 0.75f, 2, false, 0)
                                        : make_part(0, 0, 1, 1, 0, 0, 3, 3, 3, 12);
        assert_int_equal(add(m, "b", second, make_metadata(4, 12), &error), RT_OK);
        assert_int_equal(merger_finish(m, NULL, &out, &summary, &error), RT_OK);
        assert_int_equal(merger_aovs(m, &aovs, &error), RT_OK);
        assert_int_equal(summary.warning_count, 1);
        if (without == 0) {
            assert_int_equal(aovs.channels, 8);
            assert_mentions(summary.warnings[0], "1 of the 2 parts have emission.R/G/B", NULL);
        } else {
            assert_null(aovs.pixels);
            assert_mentions(summary.warnings[0], "1 of the 2 parts have AOV layers", NULL);
        }
        image_free(&out);
        image_free(&aovs);
        merger_free(m);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_weighted_mean),
        cmocka_unit_test(test_light_group_layers),
        cmocka_unit_test(test_uneven_and_zero_counts),
        cmocka_unit_test(test_tiles_assembled),
        cmocka_unit_test(test_tiles_with_sample_ranges),
        cmocka_unit_test(test_regions_with_different_ranges_warn),
        cmocka_unit_test(test_gap_in_sample_ranges_is_not_complete),
        cmocka_unit_test(test_overlapping_sample_ranges),
        cmocka_unit_test(test_overlapping_regions),
        cmocka_unit_test(test_missing_pieces),
        cmocka_unit_test(test_missing_pieces_described),
        cmocka_unit_test(test_mismatched_parts),
        cmocka_unit_test(test_malformed_parts),
        cmocka_unit_test(test_aov_layers_merged),
        scratch_test(test_read_part),
    };
    return cmocka_run_group_tests_name("merge", tests, NULL, NULL);
}
