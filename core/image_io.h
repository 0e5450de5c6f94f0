/* image_io.h: reading and writing images through OpenImageIO (a thin C shim over C++).
 *
 * Pixel layout of rt_image: 32-bit floats, channels interleaved, rows top to bottom,
 * pixels[(y * width + x) * channels + c]. Channel names are "R","G","B","A" unless
 * channel_names says otherwise.
 *
 * Writing picks the format from the file extension:
 *   .exr        linear float32, all channels and names kept, attributes stored as metadata;
 *               compressed losslessly with EXR_COMPRESSION (below)
 *   .hdr        linear float (RGB only)
 *   .png .jpg .jpeg .tif .tiff  8-bit sRGB: multiplied by 2^exposure, clamped to [0,1],
 *               sRGB-encoded; alpha (if any) is written linearly
 * Writing goes to a temporary file in the destination's directory which is renamed over
 * the destination only when it is complete: a failed write leaves any existing file as
 * it was and no partial file behind.
 *
 * Reading returns what the file stores, converted to float: 8-bit files come back in
 * [0,1] in their own encoding (sRGB stays sRGB). Channel names are kept.
 *
 * Defaults of image_write_options (all zero): exposure 0 stops, no attributes,
 * channel names from the channel count.
 */
#ifndef RT_IMAGE_IO_H
#define RT_IMAGE_IO_H

#include <stdbool.h>
#include <stddef.h>

#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IMAGE_MAX_CHANNELS 128
/* The EXR files' compression, as OpenImageIO names it: PIZ (lossless; docs/performance.md,
 * the log, has what it saves against ZIP). */
#define EXR_COMPRESSION "piz"
#define IMAGE_CHANNEL_NAME_MAX 32

typedef struct rt_image {
    int width, height, channels;
    float *pixels;               /* owned; free with image_free() */
    char channel_names[IMAGE_MAX_CHANNELS][IMAGE_CHANNEL_NAME_MAX];  /* "" = default name */
    /* Where these pixels sit in a larger image (a crop or tile): top-left pixel x, y (row 0
     * at the top) and the full image's size. full_width 0 means "this is the full image".
     * EXR keeps them as the data and display windows; reading fills them from the file. */
    int x, y;
    int full_width, full_height;
} rt_image;

typedef enum image_attribute_type {
    IMAGE_ATTRIBUTE_STRING = 0,
    IMAGE_ATTRIBUTE_INT,
    IMAGE_ATTRIBUTE_FLOAT,
} image_attribute_type;

/* One metadata entry, e.g. {METADATA_KEY_SPP, IMAGE_ATTRIBUTE_INT, .int_value = 64} (the
 * rtspheres keys are in metadata_keys.h). */
typedef struct image_attribute {
    const char *name;
    image_attribute_type type;
    const char *string_value;
    long long int_value;
    double float_value;
} image_attribute;

typedef struct image_write_options {
    float exposure;              /* stops, for 8-bit outputs only */
    const image_attribute *attributes;
    int attribute_count;
} image_write_options;

/* The formats image_write() writes, as listed above. */
typedef enum image_format {
    IMAGE_FORMAT_UNKNOWN = 0,    /* an extension image_write() refuses, or none */
    IMAGE_FORMAT_EXR,            /* .exr */
    IMAGE_FORMAT_HDR,            /* .hdr */
    IMAGE_FORMAT_EIGHT_BIT,      /* .png .jpg .jpeg .tif .tiff */
} image_format;

/* Returns options with every field at its default (all zero). */
image_write_options image_write_options_defaults(void);

/* Returns the format image_write() picks for path by its extension (case-insensitive, of
 * the last path component), so callers can refuse an output before they work for it. */
image_format image_format_of(const char *path);

/* Allocates a width x height x channels image filled with zeros, with default channel
 * names. Returns RT_ERROR_RUNTIME when memory runs out. Free with image_free(). */
rt_status image_create(rt_image *image, int width, int height, int channels, rt_error *error);

/* Makes *out (allocated; free with image_free()) holding a's channels then b's, with their
 * names (ImageBufAlgo::channel_append's: a name of b that a already has becomes
 * "channelN", N its place in out), and a's place (x, y, full size). Different sizes:
 * RT_ERROR_INPUT; more than IMAGE_MAX_CHANNELS together: RT_ERROR_INPUT. */
rt_status image_append_channels(const rt_image *a, const rt_image *b, rt_image *out, rt_error *error);

/* Maps channel of image, values 0 to 1, through OpenImageIO's colour map named map
 * ("inferno", "viridis", "magma", "plasma", "turbo", "heat", ...) into *out, a new RGB image
 * of image's size (the caller frees it; empty on failure). The maps' colours are linear
 * values (matplotlib's inferno at 0.5, sRGB 0.735 0.216 0.330, is 0.500 0.038 0.089 here),
 * so that an 8-bit file, whose writer encodes them, shows the map's own colours.
 * RT_ERROR_INPUT for a channel image has not or a map OpenImageIO does not know. */
rt_status image_color_map(const rt_image *image, int channel, const char *map, rt_image *out, rt_error *error);

/* Returns the index of the channel of image named name (exactly), or -1. */
int image_channel_index(const rt_image *image, const char *name);

/* Frees image->pixels and zeroes *image. */
void image_free(rt_image *image);

/* Writes image to path (format by extension, see above). options may be NULL.
 * Unknown extension: RT_ERROR_INPUT. Failed write: RT_ERROR_RUNTIME, destination intact. */
rt_status image_write(const char *path, const rt_image *image, const image_write_options *options,
                      rt_error *error);

/* Writing an image band by band, for images too large to hold (render_job.h's tiles): the
 * same file image_write() makes of the whole image, pixel for pixel (every conversion is
 * per pixel), written to the same kind of temporary file and renamed over path by
 * image_stream_close() only. OpenImageIO writes the file itself: EXR by scanlines (its
 * data window at layout's place), PNG, JPEG, TIFF and HDR by scanlines. */
typedef struct image_stream image_stream;

/* Creates path's temporary file for an image of layout's size, channels, names and place
 * (its pixels are not read) with options' metadata and exposure, and returns the stream
 * in *out. Errors as image_write()'s; nothing is left behind. */
rt_status image_stream_open(const char *path, const rt_image *layout, const image_write_options *options,
                            image_stream **out, rt_error *error);

/* Writes the next rows->height rows (rows->width and channels as the layout's, rows top
 * to bottom). A band that does not continue the image is RT_ERROR_INPUT; a failed write
 * RT_ERROR_RUNTIME (the stream should then be abandoned). */
rt_status image_stream_write_rows(image_stream *stream, const rt_image *rows, rt_error *error);

/* Finishes the file and renames it over path; every row must have been written. Frees
 * stream whatever happens; on failure the temporary file is removed and path untouched. */
rt_status image_stream_close(image_stream *stream, rt_error *error);

/* Removes the temporary file and frees stream: path stays as it was. NULL is ignored. */
void image_stream_abandon(image_stream *stream);

/* Reads the image at path into *out (allocated; caller frees with image_free()).
 * Missing, unreadable or malformed file: RT_ERROR_INPUT naming the file. */
rt_status image_read(const char *path, rt_image *out, rt_error *error);

/* Reads the image at path like image_read(), and converts its colour channels to linear
 * light by the colour space OpenImageIO reports for the file ("oiio:ColorSpace"):
 *   "sRGB" (PNG, JPEG)        decoded with the sRGB curve: 8-bit 128 becomes 0.2158
 *   "Rec709" (PPM, PGM)       decoded with the ITU-R BT.709 curve: 128 becomes 0.2615
 *   "GammaCorrectedG"         raised to the power G
 *   "Linear" (EXR, HDR)       kept
 *   none, or another name     sRGB when the file stores integers (8/16-bit TIFF, TGA,
 *                             BMP), kept when it stores floats
 * Alpha (OIIO's alpha channel, or a channel named "A"/"Alpha") and depth are kept as
 * stored. An image wider or taller than max_side pixels (when max_side > 0) is refused
 * with RT_ERROR_INPUT before its pixels are read. Errors as image_read(). */
rt_status image_read_linear(const char *path, int max_side, rt_image *out, rt_error *error);

/* Reads an image file held in memory (bytes, size: a PNG or JPEG a glTF file embeds) like
 * image_read_linear() when linear is true, else like image_read(); name is what messages
 * call it ("IMAGE: cannot read 'NAME': ..."). An image wider or taller than max_side
 * (when > 0) is refused. The bytes are only read; out as for image_read(). */
rt_status image_read_memory(const void *bytes, size_t size, const char *name, int max_side, bool linear,
                            rt_image *out, rt_error *error);

/* The sRGB transfer function's decoding (IEC 61966-2-1): an encoded value in [0, 1] to
 * linear light, as image_read_linear() decodes 8-bit colour (128/255 becomes 0.2158). */
float image_srgb_decode(float value);

/* Reads one metadata attribute of the file as text into value (at most value_size bytes,
 * NUL-terminated). Returns RT_OK, or RT_ERROR_INPUT if the file or attribute is missing. */
rt_status image_read_attribute(const char *path, const char *name, char *value, int value_size,
                               rt_error *error);

/* A file's metadata, for passing on what it says into a file made from it (rtspheres
 * denoise and relight, core/render_output.h). Owns its entries' names and strings;
 * an empty set is all zero. Free with image_attribute_set_free(). */
typedef struct image_attribute_set {
    image_attribute *attributes;
    int count;
} image_attribute_set;

/* Reads every attribute of the file at path whose name starts with prefix ("" for all)
 * into *out (emptied first; the caller frees it), in the file's order: strings as
 * STRING, 32-bit integers as INT, float and double scalars as FLOAT, anything else as
 * the text image_read_attribute() gives. Missing or unreadable file: RT_ERROR_INPUT, *out
 * empty; out of memory: RT_ERROR_RUNTIME, *out empty. */
rt_status image_read_attributes(const char *path, const char *prefix, image_attribute_set *out, rt_error *error);

/* Puts a copy of attribute into set: replaces the entry of the same name in place, or
 * appends it. Out of memory: RT_ERROR_RUNTIME, set as it was. */
rt_status image_attribute_set_put(image_attribute_set *set, const image_attribute *attribute, rt_error *error);

/* Returns set's entry named name, or NULL. */
const image_attribute *image_attribute_set_find(const image_attribute_set *set, const char *name);

/* Removes set's entry named name, if there is one; the others keep their order. */
void image_attribute_set_remove(image_attribute_set *set, const char *name);

/* Frees what set owns and empties it. */
void image_attribute_set_free(image_attribute_set *set);

#ifdef __cplusplus
}
#endif

#endif
