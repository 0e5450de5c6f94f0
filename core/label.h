/* label.h: text under an image, for contact sheets (`rtspheres montage --labels`): a black
 * band below the image with the text in white, drawn with the 5x7 font of
 * core/bitmap_font.h (no font library).
 *
 * Layout at scale s (font pixels are s x s image pixels): characters advance 6s pixels
 * (5 of glyph, 1 of space), lines 8s (7 and 1); the text starts s pixels in from the left
 * and s pixels below the image, wraps after label_chars_per_line() characters, and keeps
 * at most the band's lines (a longer text ends in "..."). The band is lines x 8s + 2s
 * pixels high and as wide as the image.
 */
#ifndef RT_LABEL_H
#define RT_LABEL_H

#include "image_io.h"
#include "status.h"

#define LABEL_MAX_LINES 4

/* The scale labels use under an image width pixels wide: 2 from 240 pixels on, else 1. */
int label_scale(int width);

/* How many characters fit on a line under an image width pixels wide at scale (>= 1). */
int label_chars_per_line(int width, int scale);

/* How many lines text needs under an image width pixels wide at scale, at most
 * LABEL_MAX_LINES (0 for an empty text). */
int label_lines(const char *text, int width, int scale);

/* Makes *out (allocated; free with image_free()): image's colour (its first three
 * channels; a one- or two-channel image's first channel in all three) with a band of
 * lines (1 to LABEL_MAX_LINES) holding text below it, as above; white is 1 in every
 * channel. An empty image, scale < 1 or lines out of range: RT_ERROR_INPUT. */
rt_status label_under_image(const rt_image *image, const char *text, int lines, int scale, rt_image *out,
                            rt_error *error);

#endif
