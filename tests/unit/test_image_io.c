/* test_image_io.c: writing and reading images through OpenImageIO: exact EXR round trips,
 * the 8-bit conversion, metadata, errors, and that a failed write never damages an
 * existing file or leaves a temporary file behind. Each test works in its own scratch
 * directory under $TMPDIR. These tests run as root too, where permissions do not stop a
 * write; the failures they cause are ones root meets as well (a missing directory, a path
 * through a regular file, a file size limit, a format that cannot hold the image). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image_io.h"
#include "support.h"

/* Under SAN=1: OpenImageIO 2.4 leaks one error string when libpng gives up on a truncated
 * PNG (it longjmps past the string's destructor). These hooks, read by the sanitizer
 * runtime and unused otherwise, skip that one leak; the slow unwinder is needed for the
 * stack to reach OIIO's frame through libstdc++. */
const char *__asan_default_options(void);
const char *__lsan_default_suppressions(void);
const char *__asan_default_options(void) { return "fast_unwind_on_malloc=0"; }
const char *__lsan_default_suppressions(void) { return "leak:PNGInput::PngReadCallback\n"; }

/* Asserts the scratch directory holds exactly the names given (NULL-terminated list), so
 * that no temporary file was left behind. */
static void assert_directory_holds(scratch *s, const char *const *names)
{
    int expected = 0;
    while (names[expected] != NULL)
        expected++;
    DIR *dir = opendir(s->directory);
    assert_non_null(dir);
    int found = 0;
    struct dirent *entry;
    while ((entry = readdir(dir)) != NULL) {
        if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0)
            continue;
        bool known = false;
        for (int i = 0; i < expected; i++)
            known = known || strcmp(entry->d_name, names[i]) == 0;
        if (!known)
            print_error("unexpected file '%s' in %s\n", entry->d_name, s->directory);
        assert_true(known);
        found++;
    }
    closedir(dir);
    assert_int_equal(found, expected);
}

/* Reads a whole file into a malloc'ed buffer (caller frees); *size gets its length. */
static unsigned char *read_file(const char *path, size_t *size)
{
    FILE *file = fopen(path, "rb");
    assert_non_null(file);
    assert_int_equal(fseek(file, 0, SEEK_END), 0);
    long length = ftell(file);
    assert_true(length >= 0);
    rewind(file);
    unsigned char *bytes = malloc((size_t)length + 1);
    assert_non_null(bytes);
    assert_int_equal(fread(bytes, 1, (size_t)length, file), (size_t)length);
    fclose(file);
    *size = (size_t)length;
    return bytes;
}

/* Makes an image of pseudo-random values in [0, 1) that no compressor can shrink much. */
static rt_image noise_image(int width, int height, int channels)
{
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, width, height, channels, &error), RT_OK);
    uint32_t state = 12345;
    for (int i = 0; i < width * height * channels; i++) {
        state = state * 1664525u + 1013904223u;
        image.pixels[i] = (float)(state >> 8) / 16777216.0f;
    }
    return image;
}

static void write_ok(const char *path, const rt_image *image, const image_write_options *options)
{
    rt_error error = {{0}};
    rt_status status = image_write(path, image, options, &error);
    if (status != RT_OK)
        print_error("image_write: %s\n", error.message);
    assert_int_equal(status, RT_OK);
}

/* Reads path with image_read(), failing the test (with the message) unless it succeeds;
 * the caller frees the image. */
static rt_image read_ok(const char *path)
{
    rt_image image;
    rt_error error = {{0}};
    rt_status status = image_read(path, &image, &error);
    if (status != RT_OK)
        print_error("image_read: %s\n", error.message);
    assert_int_equal(status, RT_OK);
    return image;
}

static void test_create_and_free(void **state)
{
    (void)state;
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, 3, 2, 4, &error), RT_OK);
    assert_int_equal(image.width, 3);
    assert_int_equal(image.height, 2);
    assert_int_equal(image.channels, 4);
    for (int i = 0; i < 3 * 2 * 4; i++)
        assert_true(image.pixels[i] == 0.0f);
    for (int c = 0; c < IMAGE_MAX_CHANNELS; c++)
        assert_string_equal(image.channel_names[c], "");
    image_free(&image);
    assert_null(image.pixels);
    assert_int_equal(image.width, 0);

    assert_int_equal(image_create(&image, 0, 2, 4, &error), RT_ERROR_INPUT);
    assert_int_equal(image_create(&image, 2, 2, IMAGE_MAX_CHANNELS + 1, &error), RT_ERROR_INPUT);
    assert_null(image.pixels);
}

/* EXR keeps float32 bit for bit: huge, tiny, negative, beyond half precision. */
/* image_append_channels: a's channels then b's, pixel by pixel, names kept (unnamed
 * ones by their defaults), a's place; sizes must match and the channels fit. */
static void test_append_channels(void **state)
{
    (void)state;
    rt_image a, b, joined;
    rt_error error;
    assert_int_equal(image_create(&a, 3, 2, 3, &error), RT_OK);
    assert_int_equal(image_create(&b, 3, 2, 2, &error), RT_OK);
    strcpy(b.channel_names[0], "albedo.R");
    strcpy(b.channel_names[1], "samples");
    for (int i = 0; i < 3 * 2 * 3; i++)
        a.pixels[i] = (float)i;
    for (int i = 0; i < 3 * 2 * 2; i++)
        b.pixels[i] = 100.0f + (float)i;
    a.x = 4, a.y = 5, a.full_width = 20, a.full_height = 10;
    assert_int_equal(image_append_channels(&a, &b, &joined, &error), RT_OK);
    assert_int_equal(joined.width, 3);
    assert_int_equal(joined.height, 2);
    assert_int_equal(joined.channels, 5);
    const char *names[5] = {"R", "G", "B", "albedo.R", "samples"};
    for (int c = 0; c < 5; c++)
        assert_string_equal(joined.channel_names[c], names[c]);
    for (int p = 0; p < 6; p++)
        for (int c = 0; c < 5; c++)
            assert_true(joined.pixels[p * 5 + c] == (c < 3 ? a.pixels[p * 3 + c] : b.pixels[p * 2 + c - 3]));
    assert_int_equal(joined.x, 4);
    assert_int_equal(joined.y, 5);
    assert_int_equal(joined.full_width, 20);
    assert_int_equal(joined.full_height, 10);
    image_free(&joined);

    rt_image wide;
    assert_int_equal(image_create(&wide, 4, 2, 1, &error), RT_OK);
    assert_int_equal(image_append_channels(&a, &wide, &joined, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "IMAGE: cannot join a 3x2 and a 4x2 image");
    assert_null(joined.pixels);
    rt_image many;
    assert_int_equal(image_create(&many, 3, 2, IMAGE_MAX_CHANNELS - 2, &error), RT_OK);
    assert_int_equal(image_append_channels(&a, &many, &joined, &error), RT_ERROR_INPUT);
    assert_null(joined.pixels);
    image_free(&many);
    image_free(&wide);
    image_free(&a);
    image_free(&b);
}

static void test_exr_round_trip_exact(void **state)
{
    scratch *s = *state;
    const float values[] = {
        0.0f, 1.0f, 0.5f, 0.1f, 3.14159265f, -2.5f, 1e6f, 65504.0f, 65520.0f, 123456.789f,
        FLT_MAX, 3e38f, 1e-30f, FLT_MIN, 1e-40f /* subnormal */, -1e-20f, 1.0f / 3.0f,
        2.2f, 1e10f, 7.0e-5f, 0.999999f, 1.000001f, 17.25f, 1e-7f,
    };
    const int count = (int)(sizeof values / sizeof values[0]);  /* 24 = 3 x 2 x 4 */
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, 3, 2, 4, &error), RT_OK);
    memcpy(image.pixels, values, sizeof values);
    write_ok(in_scratch(s, "exact.exr"), &image, NULL);

    rt_image back = read_ok(in_scratch(s, "exact.exr"));
    assert_int_equal(back.width, 3);
    assert_int_equal(back.height, 2);
    assert_int_equal(back.channels, 4);
    for (int i = 0; i < count; i++) {
        if (memcmp(&back.pixels[i], &values[i], sizeof(float)) != 0)
            print_error("sample %d: wrote %.9g, read %.9g\n", i, values[i], back.pixels[i]);
        assert_memory_equal(&back.pixels[i], &values[i], sizeof(float));
    }
    assert_string_equal(back.channel_names[0], "R");
    assert_string_equal(back.channel_names[3], "A");
    image_free(&back);
    image_free(&image);
    assert_directory_holds(s, (const char *const[]){"exact.exr", NULL});
}

/* Channel names and typed metadata survive an EXR round trip. OpenEXR files list their
 * channels by name, and OIIO reads them back R, G, B, A first, then the rest in name order,
 * so the names here are already in that order. */
static void test_exr_channel_names_and_attributes(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(5, 4, 6);
    const char *names[] = {"R", "G", "B", "A", "depth", "normal.x"};
    for (int c = 0; c < 6; c++)
        snprintf(image.channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
    const image_attribute attributes[] = {
        {.name = "rtspheres:scene", .type = IMAGE_ATTRIBUTE_STRING,
         .string_value = "three-balls.txt"},
        {.name = "rtspheres:spp", .type = IMAGE_ATTRIBUTE_INT, .int_value = 64},
        {.name = "rtspheres:seed", .type = IMAGE_ATTRIBUTE_INT, .int_value = 5000000000LL},
        {.name = "rtspheres:seconds", .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = 12.345},
        {.name = "rtspheres:exposure", .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = -0.5},
    };
    image_write_options options = image_write_options_defaults();
    options.attributes = attributes;
    options.attribute_count = 5;
    write_ok(in_scratch(s, "layers.exr"), &image, &options);

    rt_error error = {{0}};
    rt_image back = read_ok(in_scratch(s, "layers.exr"));
    assert_int_equal(back.channels, 6);
    for (int c = 0; c < 6; c++)
        assert_string_equal(back.channel_names[c], names[c]);
    assert_memory_equal(back.pixels, image.pixels, sizeof(float) * 5 * 4 * 6);
    image_free(&back);

    const char *expected[][2] = {
        {"rtspheres:scene", "three-balls.txt"},
        {"rtspheres:spp", "64"},
        {"rtspheres:seed", "5000000000"},  /* beyond OpenEXR's int: kept as text */
        {"rtspheres:seconds", "12.345"},
        {"rtspheres:exposure", "-0.5"},
    };
    char value[64];
    for (int i = 0; i < 5; i++) {
        rt_status status = image_read_attribute(in_scratch(s, "layers.exr"), expected[i][0], value,
                                                sizeof value, &error);
        if (status != RT_OK)
            print_error("%s\n", error.message);
        assert_int_equal(status, RT_OK);
        assert_string_equal(value, expected[i][1]);
    }

    /* A buffer too small gets as much as fits, still terminated. */
    char small[6];
    assert_int_equal(image_read_attribute(in_scratch(s, "layers.exr"), "rtspheres:scene", small,
                                          sizeof small, &error),
                     RT_OK);
    assert_string_equal(small, "three");

    assert_int_equal(image_read_attribute(in_scratch(s, "layers.exr"), "rtspheres:nothing", value,
                                          sizeof value, &error),
                     RT_ERROR_INPUT);
    assert_contains(error.message, "IMAGE: ");
    assert_contains(error.message, "rtspheres:nothing");
    assert_contains(error.message, "layers.exr");

    assert_int_equal(image_read_attribute(in_scratch(s, "missing.exr"), "rtspheres:spp", value,
                                          sizeof value, &error),
                     RT_ERROR_INPUT);
    assert_contains(error.message, in_scratch(s, "missing.exr"));
    image_free(&image);
}

/* image_read_attributes() gives back a file's attributes of a prefix with their types, in
 * a set that can be changed and written again: what rtspheres denoise and relight do to
 * carry a render's metadata on (render_output_derived_metadata). */
static void test_read_all_attributes(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(3, 2, 3);
    const image_attribute attributes[] = {
        {.name = "rtspheres:scene", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "a.txt"},
        {.name = "rtspheres:spp", .type = IMAGE_ATTRIBUTE_INT, .int_value = 64},
        {.name = "rtspheres:seed", .type = IMAGE_ATTRIBUTE_INT, .int_value = 5000000000LL},
        {.name = "rtspheres:seconds", .type = IMAGE_ATTRIBUTE_FLOAT, .float_value = 12.345},
        {.name = "other:thing", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "x"},
    };
    image_write_options options = image_write_options_defaults();
    options.attributes = attributes;
    options.attribute_count = 5;
    write_ok(in_scratch(s, "attributes.exr"), &image, &options);

    rt_error error = {{0}};
    image_attribute_set set = {0};
    assert_int_equal(image_read_attributes(in_scratch(s, "attributes.exr"), "rtspheres:", &set, &error), RT_OK);
    assert_int_equal(set.count, 4);   /* not other:thing, nor OpenEXR's own */
    const image_attribute *scene = image_attribute_set_find(&set, "rtspheres:scene");
    assert_non_null(scene);
    assert_int_equal(scene->type, IMAGE_ATTRIBUTE_STRING);
    assert_string_equal(scene->string_value, "a.txt");
    const image_attribute *spp = image_attribute_set_find(&set, "rtspheres:spp");
    assert_non_null(spp);
    assert_int_equal(spp->type, IMAGE_ATTRIBUTE_INT);
    assert_int_equal(spp->int_value, 64);
    const image_attribute *seed = image_attribute_set_find(&set, "rtspheres:seed");
    assert_non_null(seed);   /* written as text: beyond OpenEXR's int */
    assert_int_equal(seed->type, IMAGE_ATTRIBUTE_STRING);
    assert_string_equal(seed->string_value, "5000000000");
    const image_attribute *seconds = image_attribute_set_find(&set, "rtspheres:seconds");
    assert_non_null(seconds);
    assert_int_equal(seconds->type, IMAGE_ATTRIBUTE_FLOAT);
    assert_true(seconds->float_value == 12.345);
    assert_null(image_attribute_set_find(&set, "other:thing"));

    /* Put replaces in place or appends; remove keeps the rest in order. */
    image_attribute spp_now = {.name = "rtspheres:spp", .type = IMAGE_ATTRIBUTE_INT, .int_value = 8};
    image_attribute added = {.name = "rtspheres:added", .type = IMAGE_ATTRIBUTE_STRING, .string_value = "yes"};
    assert_int_equal(image_attribute_set_put(&set, &spp_now, &error), RT_OK);
    assert_int_equal(image_attribute_set_put(&set, &added, &error), RT_OK);
    assert_int_equal(set.count, 5);
    assert_int_equal(image_attribute_set_find(&set, "rtspheres:spp")->int_value, 8);
    image_attribute_set_remove(&set, "rtspheres:scene");
    image_attribute_set_remove(&set, "rtspheres:absent");
    assert_int_equal(set.count, 4);
    assert_string_equal(set.attributes[3].name, "rtspheres:added");

    /* What the set holds writes as it reads: a derived file says what its input said. */
    options.attributes = set.attributes;
    options.attribute_count = set.count;
    write_ok(in_scratch(s, "again.exr"), &image, &options);
    image_attribute_set again = {0};
    assert_int_equal(image_read_attributes(in_scratch(s, "again.exr"), "", &again, &error), RT_OK);
    assert_true(again.count > 4);   /* with OpenEXR's own */
    assert_int_equal(image_attribute_set_find(&again, "rtspheres:spp")->int_value, 8);
    assert_string_equal(image_attribute_set_find(&again, "rtspheres:added")->string_value, "yes");
    assert_true(image_attribute_set_find(&again, "rtspheres:seconds")->float_value == 12.345);
    assert_null(image_attribute_set_find(&again, "rtspheres:scene"));
    image_attribute_set_free(&again);
    image_attribute_set_free(&set);
    assert_int_equal(set.count, 0);
    assert_null(set.attributes);

    /* A missing file: bad input naming it, the set empty. */
    assert_int_equal(image_read_attributes(in_scratch(s, "missing.exr"), "rtspheres:", &set, &error), RT_ERROR_INPUT);
    assert_contains(error.message, in_scratch(s, "missing.exr"));
    assert_int_equal(set.count, 0);
    image_free(&image);
}

/* The sRGB transfer function, written out independently of the code under test. */
static double srgb(double linear)
{
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1 / 2.4) - 0.055;
}

/* PNG gets value * 2^exposure, clamped to [0,1], sRGB-encoded; alpha is written as it is. */
static void test_png_exposure_clamp_srgb(void **state)
{
    scratch *s = *state;
    /* RGBA pixels; exposure +1 doubles the colour. */
    const float pixels[6][4] = {
        {0.1f, 0.25f, 0.0f, 1.0f},      /* 0.2, 0.5, 0 */
        {0.6f, 2.0f, 1e6f, 0.5f},       /* all over 1: clamp to 255 */
        {-0.5f, -1e6f, 0.0005f, 0.0f},  /* negative: 0; 0.001 on the linear segment */
        {0.01f, 0.2f, 0.45f, 0.25f},
        {NAN, INFINITY, 0.3f, 1.5f},    /* NaN: 0; inf: 1; alpha over 1 clamps */
        {0.125f, 0.375f, 0.4f, -0.25f}, /* alpha under 0 clamps */
    };
    rt_image image;
    rt_error error = {{0}};
    assert_int_equal(image_create(&image, 3, 2, 4, &error), RT_OK);
    memcpy(image.pixels, pixels, sizeof pixels);
    image_write_options options = image_write_options_defaults();
    options.exposure = 1.0f;
    write_ok(in_scratch(s, "exposed.png"), &image, &options);

    rt_image back = read_ok(in_scratch(s, "exposed.png"));
    assert_int_equal(back.width, 3);
    assert_int_equal(back.height, 2);
    assert_int_equal(back.channels, 4);
    for (int p = 0; p < 6; p++) {
        for (int c = 0; c < 4; c++) {
            double value = pixels[p][c];
            if (isnan(value))
                value = 0;
            if (c < 3)
                value *= 2.0;
            value = value < 0 ? 0 : value > 1 ? 1 : value;
            if (c < 3)
                value = srgb(value);
            double expected = round(value * 255) / 255;
            double got = back.pixels[p * 4 + c];
            if (fabs(got - expected) > 1.0 / 255 + 1e-6)
                print_error("pixel %d channel %d: expected %g (%g/255), got %g (%g/255)\n", p, c,
                            expected, expected * 255, got, got * 255);
            assert_true(fabs(got - expected) <= 1.0 / 255 + 1e-6);
        }
    }
    /* Spot checks against values worked out by hand: sRGB(0.5) = 0.7354 -> 188. */
    assert_true(fabs(back.pixels[1] * 255 - 188) < 0.5);
    assert_true(fabs(back.pixels[3] * 255 - 255) < 0.5);  /* alpha 1 */
    assert_true(fabs(back.pixels[7] * 255 - 128) < 0.5);  /* alpha 0.5, not exposed */
    image_free(&back);
    image_free(&image);
}

/* Exposure 0 (the default) leaves values alone; negative exposure darkens. */
static void test_eight_bit_default_and_negative_exposure(void **state)
{
    scratch *s = *state;
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, 1, 1, 3, &error), RT_OK);
    image.pixels[0] = 0.5f;
    image.pixels[1] = 1.0f;
    image.pixels[2] = 0.0f;
    write_ok(in_scratch(s, "plain.tif"), &image, NULL);
    image_write_options options = image_write_options_defaults();
    options.exposure = -1.0f;
    write_ok(in_scratch(s, "dark.png"), &image, &options);

    rt_image back = read_ok(in_scratch(s, "plain.tif"));
    assert_int_equal(back.channels, 3);
    assert_true(fabs(back.pixels[0] * 255 - 188) < 0.5);  /* sRGB(0.5) */
    assert_true(fabs(back.pixels[1] * 255 - 255) < 0.5);
    assert_true(fabs(back.pixels[2] * 255 - 0) < 0.5);
    image_free(&back);
    back = read_ok(in_scratch(s, "dark.png"));
    assert_true(fabs(back.pixels[0] * 255 - 137) < 0.5);  /* sRGB(0.25) = 0.5371 */
    assert_true(fabs(back.pixels[1] * 255 - 188) < 0.5);  /* sRGB(0.5) */
    image_free(&back);
    image_free(&image);
}

/* JPEG (lossy, no alpha) and HDR (RGB, shared exponent) come back close; HDR is linear. */
static void test_jpeg_and_hdr(void **state)
{
    scratch *s = *state;
    rt_image image;
    rt_error error = {{0}};
    assert_int_equal(image_create(&image, 8, 8, 4, &error), RT_OK);
    for (int p = 0; p < 64; p++) {
        image.pixels[p * 4 + 0] = 0.5f;
        image.pixels[p * 4 + 1] = 0.25f;
        image.pixels[p * 4 + 2] = 3.0f;
        image.pixels[p * 4 + 3] = 1.0f;
    }
    write_ok(in_scratch(s, "flat.jpg"), &image, NULL);
    write_ok(in_scratch(s, "flat.jpeg"), &image, NULL);
    write_ok(in_scratch(s, "flat.hdr"), &image, NULL);

    rt_image back = read_ok(in_scratch(s, "flat.jpg"));
    assert_int_equal(back.channels, 3);
    assert_true(fabs(back.pixels[0] - srgb(0.5)) < 3.0 / 255);
    assert_true(fabs(back.pixels[1] - srgb(0.25)) < 3.0 / 255);
    assert_true(fabs(back.pixels[2] - 1.0) < 3.0 / 255);
    image_free(&back);

    back = read_ok(in_scratch(s, "flat.hdr"));
    assert_int_equal(back.channels, 3);
    assert_true(fabs(back.pixels[0] - 0.5) < 0.01);
    assert_true(fabs(back.pixels[1] - 0.25) < 0.01);
    assert_true(fabs(back.pixels[2] - 3.0) < 0.03);
    image_free(&back);
    image_free(&image);
    assert_directory_holds(s, (const char *const[]){"flat.jpg", "flat.jpeg", "flat.hdr", NULL});
}

static void test_unknown_extension(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(2, 2, 3);
    rt_error error = {{0}};
    assert_int_equal(image_write(in_scratch(s, "picture.bmp"), &image, NULL, &error),
                     RT_ERROR_INPUT);
    assert_contains(error.message, "IMAGE: ");
    assert_contains(error.message, in_scratch(s, "picture.bmp"));
    assert_contains(error.message, ".bmp");
    const char *supported[] = {".exr", ".hdr", ".png", ".jpg", ".jpeg", ".tif", ".tiff"};
    for (int i = 0; i < 7; i++)
        assert_contains(error.message, supported[i]);

    assert_int_equal(image_write(in_scratch(s, "no-extension"), &image, NULL, &error),
                     RT_ERROR_INPUT);
    assert_contains(error.message, "no-extension");
    /* A dot in a directory name is not an extension. */
    assert_int_equal(image_write(in_scratch(s, "dir.png/file"), &image, NULL, &error),
                     RT_ERROR_INPUT);
    image_free(&image);
    assert_directory_holds(s, (const char *const[]){NULL});
}

/* Upper-case extensions are the same formats. */
static void test_extension_case(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(2, 2, 3);
    write_ok(in_scratch(s, "upper.EXR"), &image, NULL);
    rt_image back = read_ok(in_scratch(s, "upper.EXR"));
    assert_memory_equal(back.pixels, image.pixels, sizeof(float) * 12);
    image_free(&back);
    image_free(&image);
}

/* Directories root cannot write into either: one that does not exist, and a "directory"
 * that is a regular file. */
static void test_unwritable_directory(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(4, 4, 3);
    rt_error error = {{0}};
    char path[600];

    snprintf(path, sizeof path, "%s/no-such-directory/out.png", s->directory);
    assert_int_equal(image_write(path, &image, NULL, &error), RT_ERROR_RUNTIME);
    assert_contains(error.message, "IMAGE: cannot write '");
    assert_contains(error.message, path);

    scratch_write(s, "plain-file", "x", 1);
    snprintf(path, sizeof path, "%s/plain-file/out.exr", s->directory);
    assert_int_equal(image_write(path, &image, NULL, &error), RT_ERROR_RUNTIME);
    assert_contains(error.message, path);

    image_free(&image);
    assert_directory_holds(s, (const char *const[]){"plain-file", NULL});
}

/* Writing over an existing file replaces it completely. */
static void test_overwrite(void **state)
{
    scratch *s = *state;
    rt_image big = noise_image(16, 16, 4), small = noise_image(2, 1, 3);
    write_ok(in_scratch(s, "over.exr"), &big, NULL);
    write_ok(in_scratch(s, "over.exr"), &small, NULL);
    rt_image back = read_ok(in_scratch(s, "over.exr"));
    assert_int_equal(back.width, 2);
    assert_int_equal(back.channels, 3);
    assert_memory_equal(back.pixels, small.pixels, sizeof(float) * 6);
    image_free(&back);
    image_free(&big);
    image_free(&small);
    assert_directory_holds(s, (const char *const[]){"over.exr", NULL});
}

/* The temporary file is created 0600; the result must look like any new file. */
static void test_file_mode_follows_umask(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(2, 2, 3);
    mode_t old_mask = umask(022);
    write_ok(in_scratch(s, "mode.png"), &image, NULL);
    umask(old_mask);
    struct stat info;
    assert_int_equal(stat(in_scratch(s, "mode.png"), &info), 0);
    assert_int_equal(info.st_mode & 0777, 0644);
    image_free(&image);
}

/* Writes a first image to name, tries to write bad over it, and checks the failure left
 * the file byte for byte as it was and no temporary file. */
static void check_failed_write_keeps_file(scratch *s, const char *name, const rt_image *bad,
                                          rt_status expected_status)
{
    rt_image good = noise_image(8, 8, 3);
    write_ok(in_scratch(s, name), &good, NULL);
    size_t before_size, after_size;
    unsigned char *before = read_file(in_scratch(s, name), &before_size);

    rt_error error = {{0}};
    assert_int_equal(image_write(in_scratch(s, name), bad, NULL, &error), expected_status);
    assert_contains(error.message, "IMAGE: cannot write '");
    assert_contains(error.message, in_scratch(s, name));

    unsigned char *after = read_file(in_scratch(s, name), &after_size);
    assert_int_equal(after_size, before_size);
    assert_memory_equal(after, before, before_size);
    free(before);
    free(after);
    image_free(&good);
    assert_directory_holds(s, (const char *const[]){name, NULL});
}

static void test_invalid_image_keeps_existing_file(void **state)
{
    scratch *s = *state;
    rt_image bad = noise_image(4, 4, 3);
    bad.width = 0;
    check_failed_write_keeps_file(s, "keep.exr", &bad, RT_ERROR_INPUT);
    bad.width = 4;
    float *pixels = bad.pixels;
    bad.pixels = NULL;
    check_failed_write_keeps_file(s, "keep.exr", &bad, RT_ERROR_INPUT);
    bad.pixels = pixels;
    image_free(&bad);
}

/* OpenImageIO itself refuses: PNG holds at most 4 channels. */
static void test_format_refusal_keeps_existing_file(void **state)
{
    scratch *s = *state;
    rt_image bad = noise_image(4, 4, 5);
    check_failed_write_keeps_file(s, "keep.png", &bad, RT_ERROR_RUNTIME);
    image_free(&bad);
}

/* The disk write itself fails partway: RLIMIT_FSIZE binds root too. The image is noise so
 * that no format compresses it under the limit. */
static void check_write_fails_over_size_limit(scratch *s, const char *name)
{
    rt_image existing = noise_image(4, 4, 3);
    write_ok(in_scratch(s, name), &existing, NULL);
    size_t before_size, after_size;
    unsigned char *before = read_file(in_scratch(s, name), &before_size);
    assert_true(before_size < 16384);

    rt_image big = noise_image(128, 128, 4);
    struct rlimit old_limit, limit;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
    limit = old_limit;
    limit.rlim_cur = 16384;
    void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &limit), 0);
    rt_error error = {{0}};
    rt_status status = image_write(in_scratch(s, name), &big, NULL, &error);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &old_limit), 0);
    signal(SIGXFSZ, old_handler);

    assert_int_equal(status, RT_ERROR_RUNTIME);
    assert_contains(error.message, "IMAGE: cannot write '");
    assert_contains(error.message, in_scratch(s, name));
    unsigned char *after = read_file(in_scratch(s, name), &after_size);
    assert_int_equal(after_size, before_size);
    assert_memory_equal(after, before, before_size);
    free(before);
    free(after);
    image_free(&big);
    image_free(&existing);
    assert_directory_holds(s, (const char *const[]){name, NULL});
}

static void test_disk_write_failure_keeps_existing_file(void **state)
{
    check_write_fails_over_size_limit(*state, "limited.exr");
}

/* TIFF takes another path inside image_write (OIIO writes the file itself). */
static void test_disk_write_failure_keeps_existing_tiff(void **state)
{
    check_write_fails_over_size_limit(*state, "limited.tif");
}

static void check_read_fails(const char *path)
{
    rt_image image;
    rt_error error = {{0}};
    assert_int_equal(image_read(path, &image, &error), RT_ERROR_INPUT);
    assert_null(image.pixels);
    assert_contains(error.message, "IMAGE: ");
    assert_contains(error.message, path);
}

static void test_read_missing_file(void **state)
{
    scratch *s = *state;
    check_read_fails(in_scratch(s, "missing.exr"));
}

static void test_read_empty_file(void **state)
{
    scratch *s = *state;
    scratch_write(s, "empty.png", "", 0);
    check_read_fails(in_scratch(s, "empty.png"));
}

static void test_read_text_named_png(void **state)
{
    scratch *s = *state;
    const char text[] = "this is not a PNG file, just some text\n";
    scratch_write(s, "text.png", text, sizeof text - 1);
    check_read_fails(in_scratch(s, "text.png"));
}

/* A PNG cut in half: its header is fine, its pixel data ends early. */
static void test_read_truncated_png(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(64, 64, 3);
    write_ok(in_scratch(s, "whole.png"), &image, NULL);
    size_t size;
    unsigned char *bytes = read_file(in_scratch(s, "whole.png"), &size);
    assert_true(size > 1000);
    scratch_write(s, "truncated.png", bytes, size / 2);
    check_read_fails(in_scratch(s, "truncated.png"));
    free(bytes);
    image_free(&image);
}

static void test_read_truncated_exr(void **state)
{
    scratch *s = *state;
    rt_image image = noise_image(64, 64, 3);
    write_ok(in_scratch(s, "whole.exr"), &image, NULL);
    size_t size;
    unsigned char *bytes = read_file(in_scratch(s, "whole.exr"), &size);
    scratch_write(s, "truncated.exr", bytes, size / 2);
    check_read_fails(in_scratch(s, "truncated.exr"));
    free(bytes);
    image_free(&image);
}

static void test_read_directory(void **state)
{
    scratch *s = *state;
    check_read_fails(s->directory);
}

/* A colour map (OpenImageIO's): a ramp 0, 0.5, 1 through "inferno" gives black, then
 * matplotlib's inferno(0.5), sRGB 0.735 0.216 0.330, as linear values (0.500 0.038 0.089),
 * then its yellow end, sRGB 0.988 0.998 0.645 (linear 0.973 0.996 0.374); an unknown map or
 * a channel the image has not is refused. */
static void test_color_map(void **state)
{
    (void)state;
    rt_image ramp, map;
    assert_int_equal(image_create(&ramp, 3, 1, 2, NULL), RT_OK);
    const float values[6] = {9, 0.0f, 9, 0.5f, 9, 1.0f};
    memcpy(ramp.pixels, values, sizeof values);
    assert_int_equal(image_color_map(&ramp, 1, "inferno", &map, NULL), RT_OK);
    assert_int_equal(map.channels, 3);
    const float expected[9] = {0.0f, 0.0f, 0.0f, 0.500f, 0.038f, 0.089f, 0.973f, 0.996f, 0.374f};
    for (int i = 0; i < 9; i++)
        assert_true(fabsf(map.pixels[i] - expected[i]) < 0.01f);
    image_free(&map);
    rt_error error = {{0}};
    assert_int_equal(image_color_map(&ramp, 1, "no such map", &map, &error), RT_ERROR_INPUT);
    assert_null(map.pixels);
    assert_non_null(strstr(error.message, "no such map"));
    assert_int_equal(image_color_map(&ramp, 2, "inferno", &map, &error), RT_ERROR_INPUT);
    image_free(&ramp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_create_and_free),
        cmocka_unit_test(test_append_channels),
        cmocka_unit_test(test_color_map),
        scratch_test(test_exr_round_trip_exact),
        scratch_test(test_exr_channel_names_and_attributes),
        scratch_test(test_read_all_attributes),
        scratch_test(test_png_exposure_clamp_srgb),
        scratch_test(test_eight_bit_default_and_negative_exposure),
        scratch_test(test_jpeg_and_hdr),
        scratch_test(test_unknown_extension),
        scratch_test(test_extension_case),
        scratch_test(test_unwritable_directory),
        scratch_test(test_overwrite),
        scratch_test(test_file_mode_follows_umask),
        scratch_test(test_invalid_image_keeps_existing_file),
        scratch_test(test_format_refusal_keeps_existing_file),
        scratch_test(test_disk_write_failure_keeps_existing_file),
        scratch_test(test_disk_write_failure_keeps_existing_tiff),
        scratch_test(test_read_missing_file),
        scratch_test(test_read_empty_file),
        scratch_test(test_read_text_named_png),
        scratch_test(test_read_truncated_png),
        scratch_test(test_read_truncated_exr),
        scratch_test(test_read_directory),
    };
    return cmocka_run_group_tests_name("image_io", tests, NULL, NULL);
}
