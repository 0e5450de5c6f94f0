/* relight.h: relighting an image from its light group layers (render --light-groups):
 * the weighted sum of the layers, each group's weight a scale or an RGB colour, in
 * milliseconds instead of a render.
 *
 * The layers are found by the rtspheres:light_groups metadata (metadata_keys.h): group
 * NAME is the channels NAME.R, NAME.G, NAME.B. A render's layers sum to its R, G, B up to
 * float rounding, so every weight 1 gives the beauty image back; scaling a group by k is
 * (in expectation) the render with that group's lights k times as strong.
 *
 * The relit image has R, G, B (the weighted sum), the input's "samples" channel when it
 * has one, and the layers, each times its weight (so a relit EXR can be relit again).
 */
#ifndef RT_RELIGHT_H
#define RT_RELIGHT_H

#include "image_io.h"
#include "scene.h"
#include "status.h"

/* The light group layers of an image. */
typedef struct relight_layers {
    int count;
    char names[SCENE_LIGHT_GROUP_MAX][SCENE_NAME_MAX];
    int channels[SCENE_LIGHT_GROUP_MAX][3];   /* of NAME.R, NAME.G, NAME.B in the image */
} relight_layers;

/* One group's weight: its layer is multiplied by rgb. */
typedef struct relight_weight {
    char group[SCENE_NAME_MAX];
    float rgb[3];
} relight_weight;

/* Finds the layers that groups (the rtspheres:light_groups value, comma-separated names)
 * names in image. NULL or "" groups, or a named layer missing a channel: RT_ERROR_INPUT
 * ("RELIGHT: ..."). */
rt_status relight_find_layers(const rt_image *image, const char *groups, relight_layers *layers, rt_error *error);

/* Parses "NAME=SCALE" or "NAME=R,G,B" (finite numbers) into *weight. Anything else:
 * RT_ERROR_INPUT saying what was expected. */
rt_status relight_parse_weight(const char *text, relight_weight *weight, rt_error *error);

/* Writes the comma-separated names of layers into text (size bytes). */
void relight_group_list(const relight_layers *layers, char *text, size_t size);

/* Writes what relight_apply() does with weights (count of them) into text (size bytes),
 * as rtspheres:postprocess records it (metadata_keys.h): "relight", then NAME=SCALE or
 * NAME=R,G,B for each weight in order ("relight key=2 fill=1,0.5,0.2"). */
void relight_describe(const relight_weight *weights, int count, char *text, size_t size);

/* Makes the relit image *out (allocated; free with image_free()) from image and its
 * layers: every group weighs 1 unless weights (count of them) say otherwise (a later
 * weight of the same group wins). A weight naming a group the image has not:
 * RT_ERROR_INPUT naming the groups it has. */
rt_status relight_apply(const rt_image *image, const relight_layers *layers, const relight_weight *weights,
                        int count, rt_image *out, rt_error *error);

#endif
