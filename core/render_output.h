/* render_output.h: the files a render leaves: an image with its rtspheres metadata
 * (metadata_keys.h says what each key holds), the partial file beside an output (written by
 * checkpoints and by an interrupted render), and reading a partial back to resume it. Used
 * by render jobs (render_job.h) and by the merge command; never prints.
 *
 * An image here has the layout render_scene() returns (render.h): channels R, G, B (the
 * mean of each pixel's finished samples) and samples (how many finished), and its place
 * in the full image (rt_image x, y, full_width, full_height; image_io.h).
 *
 * Formats (image_io.h): an EXR keeps the four channels, then any extra layers (the AOVs),
 * the place as its data window, and the metadata; HDR and the 8-bit formats get the colour
 * (R, G, B) only, since they cannot hold a sample count.
 */
#ifndef RT_RENDER_OUTPUT_H
#define RT_RENDER_OUTPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image_io.h"
#include "status.h"

/* The metadata written with an image; each field is the key of its name (metadata_keys.h). */
typedef struct render_output_metadata {
    const char *scene;                   /* the scene file's path */
    const char *scene_hash;              /* 16 hex digits */
    const char *options_hash;            /* 16 hex digits, or NULL: no such key (a merge) */
    long long spp;
    unsigned long long sample_start;
    unsigned long long seed;
    int max_depth;
    int frame;                           /* -1 without frames */
    unsigned long long samples_finished;
    double path_segments;
    bool complete;
    double render_seconds;
    int merged_parts;                    /* 0: no rtspheres:merged_parts key (not a merge) */
    const char *stop_reason;             /* NULL: no stop_reason, noise_threshold and min_spp
                                          * keys (a merge) */
    float noise_threshold;
    int min_spp;
    const char *light_groups;            /* NULL: no rtspheres:light_groups key; else the
                                          * layers' group names, comma-separated */
    const char *postprocess;             /* NULL: no rtspheres:postprocess key; else what
                                          * changed the colour (metadata_keys.h) */
} render_output_metadata;

/* What a partial file must match to continue a render: its seed, first sample, samples
 * per pixel and region (x0, y0, x1, y1 of the full image: where the image sits and its size). */
typedef struct render_output_resume_check {
    uint32_t seed;
    long long sample_start;
    int spp;
    int region[4];
} render_output_resume_check;

/* Writes image (R, G, B, samples; see above) to path, atomically (image_write()), with the
 * metadata. layers (NULL or without pixels: none) are channels appended after the
 * four in an EXR (its channel names kept) and left out of other formats. exposure is
 * image_write_options.exposure (8-bit formats only). Errors: those of image_write(),
 * image_create() and image_append_channels(); nothing is allocated for the caller. */
rt_status render_output_write(const char *path, const rt_image *image, const rt_image *layers,
                              const render_output_metadata *metadata, float exposure, rt_error *error);

/* An output written band by band (image_io.h image_stream), for tiled renders
 * (render_job.h): the same file render_output_write() makes of the whole image. */
typedef struct render_output_stream render_output_stream;

/* Opens path for an image of layout's size, place and channels (R, G, B, samples and the
 * layers, named; its pixels are not read), with the metadata and exposure of
 * render_output_write(), which must be final: the header is written first. Frees
 * nothing of the caller's; close or abandon *out. Errors: image_stream_open()'s. */
rt_status render_output_stream_open(const char *path, const rt_image *layout, const render_output_metadata *metadata,
                                    float exposure, render_output_stream **out, rt_error *error);

/* Writes the next rows (all the layout's channels; the format keeps what it keeps). */
rt_status render_output_stream_rows(render_output_stream *stream, const rt_image *rows, rt_error *error);

/* Finishes the file and renames it over its path; frees stream whatever happens. */
rt_status render_output_stream_close(render_output_stream *stream, rt_error *error);

/* Drops the file (its path stays as it was) and frees stream. NULL is ignored. */
void render_output_stream_abandon(render_output_stream *stream);

/* The metadata of an image made from the rtspheres image at input by a step (rtspheres
 * denoise, relight), into *out (emptied first; the caller frees it with
 * image_attribute_set_free()): every rtspheres:* key of input (metadata_keys.h) but
 * options_hash, since the file is no longer what those options render (so --skip-existing
 * renders over it instead of taking it for done), and step appended to
 * rtspheres:postprocess after what it held ("denoise; relight key=2"). An input without
 * rtspheres keys gives the postprocess key alone. Errors: image_read_attributes()'s,
 * image_attribute_set_put()'s; *out empty then. */
rt_status render_output_derived_metadata(const char *input, const char *step, image_attribute_set *out,
                                         rt_error *error);

/* Writes the partial file name of output into path (size bytes): output without its
 * extension, then ".partial.exr" ("out/frame-7.png" -> "out/frame-7.partial.exr"). */
void render_output_partial_path(const char *output, char *path, size_t size);

/* Reads the partial render at path into *image (allocated; free with image_free()) and
 * its rtspheres:scene_hash into *scene_hash, and checks that it belongs to the render
 * described by expected. A file that cannot be read is RT_ERROR_INPUT "--resume: " and
 * image_read()'s message; one without rtspheres metadata, or with another seed, first
 * sample, samples per pixel or region, is RT_ERROR_INPUT "--resume PATH does not belong
 * to this render: " and what differs. *image is empty on failure. */
rt_status render_output_read_partial(const char *path, const render_output_resume_check *expected, rt_image *image,
                                     uint64_t *scene_hash, rt_error *error);

#endif
