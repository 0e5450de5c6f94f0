/* display_tev.h: streams images to the tev viewer (render --display HOST:PORT) over its
 * TCP protocol, as pbrt-v4's --display-server speaks it. Plain POSIX sockets; no GL.
 *
 * Every packet is little-endian: int32 its whole length in bytes (these four included),
 * uint8 its type, then its fields; strings are NUL-terminated.
 *   CreateImage (type 4): uint8 grab focus (1), string image name, int32 width, int32
 *     height, int32 channel count, that many strings: the channel names.
 *   UpdateImage (type 3): uint8 grab focus (0), string image name, string channel name,
 *     int32 x, y, width, height of the tile, then width x height float32 values of that
 *     channel, rows top to bottom.
 * An image is created once (the first time its name is sent), then each send updates every
 * channel in tiles of at most DISPLAY_TEV_TILE x DISPLAY_TEV_TILE pixels.
 *
 * A viewer that is not there, or goes away, is not an error: the first failure sets a
 * warning (display_tev_take_warning) and every later send does nothing, so a render goes
 * on. Writing to a closed socket must not kill the process: SIGPIPE is ignored from
 * display_tev_create() on.
 */
#ifndef RT_DISPLAY_TEV_H
#define RT_DISPLAY_TEV_H

#include <stdbool.h>
#include <stddef.h>

#include "image_io.h"
#include "status.h"

#define DISPLAY_TEV_TILE 128
#define DISPLAY_TEV_NAME_MAX 256

typedef struct display_tev display_tev;

/* Checks address ("HOST:PORT", PORT 1 to 65535) and makes a display for it in *out (free
 * with display_tev_destroy()); it connects on the first send. A malformed address:
 * RT_ERROR_INPUT. */
rt_status display_tev_create(const char *address, display_tev **out, rt_error *error);

/* Sends image's first three channels (named R, G, B in tev; a samples channel or layers
 * after them are not sent) as the image called name: created on its first send, then
 * updated. Returns false when the viewer could not be reached now or before (then a
 * warning is waiting, once). */
bool display_tev_send(display_tev *display, const char *name, const rt_image *image);

/* Copies the warning of the first failure into text (size bytes) and returns true, once;
 * false when there is none (left to take). */
bool display_tev_take_warning(display_tev *display, char *text, size_t size);

/* Closes the connection and frees the display. NULL is ignored. */
void display_tev_destroy(display_tev *display);

#endif
