/* test_label.c: labels under images (core/label.h) and the font they use
 * (core/bitmap_font.h): the band's layout, a glyph drawn pixel for pixel, wrapping and
 * the "..." of a text that does not fit. */
#include "bitmap_font.h"
#include "label.h"

#include "support.h"

/* The glyphs fit 5 bits, every printable character but the space has pixels, and no two
 * characters look the same. */
static void font_is_whole(void **state)
{
    (void)state;
    int count = BITMAP_FONT_LAST - BITMAP_FONT_FIRST + 1;
    for (int g = 0; g < count; g++) {
        int pixels = 0;
        for (int row = 0; row < BITMAP_FONT_HEIGHT; row++) {
            assert_true(bitmap_font_glyphs[g][row] < 32);
            pixels += bitmap_font_glyphs[g][row] != 0;
        }
        assert_true(g == 0 ? pixels == 0 : pixels > 0);
        for (int k = 0; k < g; k++)
            assert_true(memcmp(bitmap_font_glyphs[g], bitmap_font_glyphs[k], BITMAP_FONT_HEIGHT) != 0);
    }
}

/* The pixel of a labelled image's band, as 0 or 1 (its G channel). */
static int band_pixel(const rt_image *image, int x, int y)
{
    return image->pixels[((size_t)y * image->width + x) * 3 + 1] > 0.5f;
}

/* "I" under a 7x2 grey image at scale 1: the image copied, then a band of 1 x 8 + 2 = 10
 * rows with the glyph from (1, 1) of the band, exactly. */
static void glyph_drawn_exactly(void **state)
{
    (void)state;
    rt_image image = make_image(7, 2, 1, 0.25f), labelled;
    rt_error error = {{0}};
    assert_int_equal(label_under_image(&image, "I", 1, 1, &labelled, &error), RT_OK);
    assert_int_equal(labelled.width, 7);
    assert_int_equal(labelled.height, 12);
    assert_int_equal(labelled.channels, 3);
    for (int i = 0; i < 14 * 3; i++)
        assert_true(labelled.pixels[i] == 0.25f);   /* the grey image in all three channels */
    const unsigned char *glyph = bitmap_font_glyphs['I' - BITMAP_FONT_FIRST];
    for (int y = 0; y < 10; y++)
        for (int x = 0; x < 7; x++) {
            int expected = 0;
            if (y >= 1 && y < 8 && x >= 1 && x < 6)
                expected = glyph[y - 1] >> (5 - x) & 1;
            assert_int_equal(band_pixel(&labelled, x, 2 + y), expected);
        }
    image_free(&labelled);
    /* At scale 2 each font pixel is 2 x 2: the I's top bar, row 0 of the glyph (.###.),
     * covers x 4..9 of rows 2 and 3 of the band. */
    rt_image wide = make_image(14, 1, 3, 0.0f);
    assert_int_equal(label_under_image(&wide, "I", 1, 2, &labelled, &error), RT_OK);
    assert_int_equal(labelled.height, 1 + 8 * 2 + 2 * 2);
    for (int x = 0; x < 14; x++)
        assert_int_equal(band_pixel(&labelled, x, 1 + 2), x >= 4 && x < 10);
    image_free(&labelled);
    image_free(&wide);
    image_free(&image);
}

/* Lines wrap after label_chars_per_line characters; a text longer than the band's lines
 * ends in "..."; bad arguments are refused. */
static void wrapping_and_cutting(void **state)
{
    (void)state;
    assert_int_equal(label_scale(239), 1);
    assert_int_equal(label_scale(240), 2);
    assert_int_equal(label_chars_per_line(32, 1), 5);
    assert_int_equal(label_chars_per_line(320, 2), 26);
    assert_int_equal(label_lines("", 32, 1), 0);
    assert_int_equal(label_lines("abcde", 32, 1), 1);
    assert_int_equal(label_lines("abcdef", 32, 1), 2);
    assert_int_equal(label_lines("a very long label indeed", 32, 1), LABEL_MAX_LINES);
    rt_image image = make_image(32, 1, 3, 0.0f), cut, dots;
    rt_error error = {{0}};
    /* "abcdefghijk" in one line of 5: "ab..." */
    assert_int_equal(label_under_image(&image, "abcdefghijk", 1, 1, &cut, &error), RT_OK);
    assert_int_equal(label_under_image(&image, "ab...", 1, 1, &dots, &error), RT_OK);
    assert_memory_equal(cut.pixels, dots.pixels, (size_t)cut.width * cut.height * 3 * sizeof(float));
    image_free(&cut);
    image_free(&dots);
    assert_int_equal(label_under_image(&image, "x", 0, 1, &cut, &error), RT_ERROR_INPUT);
    assert_int_equal(label_under_image(&image, "x", 1, 0, &cut, &error), RT_ERROR_INPUT);
    image_free(&image);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(font_is_whole),
        cmocka_unit_test(glyph_drawn_exactly),
        cmocka_unit_test(wrapping_and_cutting),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
