/* label.c: see label.h. */
#include "label.h"

#include <string.h>

#include "bitmap_font.h"

int label_scale(int width)
{
    return width >= 240 ? 2 : 1;
}

int label_chars_per_line(int width, int scale)
{
    int chars = (width - scale) / (6 * scale);
    return chars > 0 ? chars : 1;
}

int label_lines(const char *text, int width, int scale)
{
    int length = (int)strlen(text), per_line = label_chars_per_line(width, scale);
    int lines = (length + per_line - 1) / per_line;
    return lines < LABEL_MAX_LINES ? lines : LABEL_MAX_LINES;
}

/* Draws character c with its top-left corner at (x, y) of out (3 channels), in white,
 * each font pixel scale x scale; pixels outside out are left out. */
static void draw_character(rt_image *out, int x, int y, char c, int scale)
{
    unsigned char code = (unsigned char)c;
    if (code < BITMAP_FONT_FIRST || code > BITMAP_FONT_LAST)
        code = '?';
    const unsigned char *glyph = bitmap_font_glyphs[code - BITMAP_FONT_FIRST];
    for (int row = 0; row < BITMAP_FONT_HEIGHT; row++)
        for (int column = 0; column < BITMAP_FONT_WIDTH; column++) {
            if (!(glyph[row] >> (BITMAP_FONT_WIDTH - 1 - column) & 1))
                continue;
            for (int dy = 0; dy < scale; dy++)
                for (int dx = 0; dx < scale; dx++) {
                    int px = x + column * scale + dx, py = y + row * scale + dy;
                    if (px < 0 || py < 0 || px >= out->width || py >= out->height)
                        continue;
                    float *pixel = out->pixels + ((size_t)py * out->width + px) * 3;
                    pixel[0] = pixel[1] = pixel[2] = 1.0f;
                }
        }
}

rt_status label_under_image(const rt_image *image, const char *text, int lines, int scale, rt_image *out,
                            rt_error *error)
{
    *out = (rt_image){0};
    if (image->width <= 0 || image->height <= 0 || image->channels <= 0 || image->pixels == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "LABEL: the image is empty");
    if (scale < 1 || lines < 1 || lines > LABEL_MAX_LINES)
        return rt_error_set(error, RT_ERROR_INPUT, "LABEL: scale %d or %d lines out of range", scale, lines);
    int band = lines * 8 * scale + 2 * scale;
    rt_status status = image_create(out, image->width, image->height + band, 3, error);
    if (status != RT_OK)
        return status;
    size_t pixel_count = (size_t)image->width * image->height;
    for (size_t i = 0; i < pixel_count; i++)
        for (int c = 0; c < 3; c++)
            out->pixels[3 * i + c] = image->pixels[i * image->channels + (image->channels >= 3 ? c : 0)];
    int per_line = label_chars_per_line(image->width, scale), length = (int)strlen(text);
    bool cut = length > per_line * lines;
    for (int i = 0; i < length && i < per_line * lines; i++) {
        char c = text[i];
        if (cut && i >= per_line * lines - 3)
            c = '.';   /* "..." ends a text that does not fit */
        int line = i / per_line, column = i % per_line;
        draw_character(out, scale + column * 6 * scale, image->height + scale + line * 8 * scale, c, scale);
    }
    return RT_OK;
}
