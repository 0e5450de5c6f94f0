/* postprocess_internal.h: what core/postprocess.c and core/postprocess_denoise.c share;
 * not for other modules (postprocess.h is the manual). */
#ifndef RT_POSTPROCESS_INTERNAL_H
#define RT_POSTPROCESS_INTERNAL_H

#include <stddef.h>

#include "image_io.h"
#include "status.h"

/* Returns RT_OK when image has pixels, else RT_ERROR_INPUT naming it ("the WHICH image is
 * empty", prefixed POSTPROCESS). */
rt_status postprocess_check_image(const rt_image *image, const char *which, rt_error *error);

/* The image's width times its height. */
size_t postprocess_pixel_count(const rt_image *image);

#endif
