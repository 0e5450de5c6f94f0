/* relight.c: see relight.h. */
#include "relight.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Returns the index of the channel called name in image, or -1. */
static int channel_index(const rt_image *image, const char *name)
{
    for (int c = 0; c < image->channels; c++)
        if (strncmp(image->channel_names[c], name, IMAGE_CHANNEL_NAME_MAX) == 0)
            return c;
    return -1;
}

rt_status relight_find_layers(const rt_image *image, const char *groups, relight_layers *layers, rt_error *error)
{
    memset(layers, 0, sizeof *layers);
    if (groups == NULL || groups[0] == '\0')
        return rt_error_set(error, RT_ERROR_INPUT, "RELIGHT: the image has no light group layers");
    const char *start = groups;
    while (*start != '\0') {
        const char *end = strchr(start, ',');
        size_t length = end != NULL ? (size_t)(end - start) : strlen(start);
        if (length == 0 || length >= SCENE_NAME_MAX || layers->count == SCENE_LIGHT_GROUP_MAX)
            return rt_error_set(error, RT_ERROR_INPUT, "RELIGHT: the light group list '%s' is malformed", groups);
        char *name = layers->names[layers->count];
        memcpy(name, start, length);
        name[length] = '\0';
        static const char components[3] = {'R', 'G', 'B'};
        for (int c = 0; c < 3; c++) {
            char channel[IMAGE_CHANNEL_NAME_MAX];
            snprintf(channel, sizeof channel, "%s.%c", name, components[c]);
            layers->channels[layers->count][c] = channel_index(image, channel);
            if (layers->channels[layers->count][c] < 0)
                return rt_error_set(error, RT_ERROR_INPUT, "RELIGHT: light group '%s' has no channel %s", name,
                                    channel);
        }
        layers->count++;
        start += length;
        if (*start == ',')
            start++;
    }
    return RT_OK;
}

void relight_group_list(const relight_layers *layers, char *text, size_t size)
{
    if (size == 0)
        return;
    text[0] = '\0';
    for (int g = 0; g < layers->count; g++) {
        size_t used = strlen(text);
        snprintf(text + used, size - used, "%s%s", g > 0 ? "," : "", layers->names[g]);
    }
}

void relight_describe(const relight_weight *weights, int count, char *text, size_t size)
{
    if (size == 0)
        return;
    snprintf(text, size, "relight");
    for (int w = 0; w < count; w++) {
        const float *rgb = weights[w].rgb;
        size_t used = strlen(text);
        if (rgb[0] == rgb[1] && rgb[1] == rgb[2])
            snprintf(text + used, size - used, " %s=%g", weights[w].group, rgb[0]);
        else
            snprintf(text + used, size - used, " %s=%g,%g,%g", weights[w].group, rgb[0], rgb[1], rgb[2]);
    }
}

/* Parses all of text as a finite number into *value. */
static bool parse_finite(const char *text, float *value)
{
    char *end = NULL;
    double parsed = strtod(text, &end);
    if (end == text || *end != '\0' || !isfinite(parsed) || fabs(parsed) > 3.4e38)
        return false;
    *value = (float)parsed;
    return true;
}

rt_status relight_parse_weight(const char *text, relight_weight *weight, rt_error *error)
{
    memset(weight, 0, sizeof *weight);
    const char *equals = strchr(text, '=');
    size_t length = equals != NULL ? (size_t)(equals - text) : 0;
    if (equals == NULL || length == 0 || length >= SCENE_NAME_MAX)
        return rt_error_set(error, RT_ERROR_INPUT, "RELIGHT: '%s' is not NAME=SCALE or NAME=R,G,B", text);
    memcpy(weight->group, text, length);
    char values[3][64] = {"", "", ""};
    int count = 0;
    const char *value = equals + 1;
    while (count < 3) {
        const char *comma = strchr(value, ',');
        size_t part = comma != NULL ? (size_t)(comma - value) : strlen(value);
        if (part >= sizeof values[0])
            break;
        memcpy(values[count], value, part);
        count++;
        if (comma == NULL) {
            value = NULL;
            break;
        }
        value = comma + 1;
    }
    bool good = value == NULL && (count == 1 || count == 3);
    for (int c = 0; c < count && good; c++)
        good = parse_finite(values[c], &weight->rgb[c]);
    if (!good)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "RELIGHT: the weight of '%s' in '%s' is not a number SCALE or three numbers R,G,B",
                            weight->group, text);
    if (count == 1)
        weight->rgb[1] = weight->rgb[2] = weight->rgb[0];
    return RT_OK;
}

rt_status relight_apply(const rt_image *image, const relight_layers *layers, const relight_weight *weights,
                        int count, rt_image *out, rt_error *error)
{
    float factors[SCENE_LIGHT_GROUP_MAX][3];
    for (int g = 0; g < layers->count; g++)
        factors[g][0] = factors[g][1] = factors[g][2] = 1.0f;
    for (int w = 0; w < count; w++) {
        int g = 0;
        while (g < layers->count && strcmp(layers->names[g], weights[w].group) != 0)
            g++;
        if (g == layers->count) {
            char list[SCENE_LIGHT_GROUP_MAX * SCENE_NAME_MAX];
            relight_group_list(layers, list, sizeof list);
            return rt_error_set(error, RT_ERROR_INPUT, "RELIGHT: no light group '%s' in the image; it has %s",
                                weights[w].group, list);
        }
        memcpy(factors[g], weights[w].rgb, sizeof factors[g]);
    }
    int samples = channel_index(image, "samples");
    int first_layer = samples >= 0 ? 4 : 3;
    rt_status status = image_create(out, image->width, image->height, first_layer + 3 * layers->count, error);
    if (status != RT_OK)
        return status;
    static const char components[3] = {'R', 'G', 'B'};
    for (int c = 0; c < 3; c++)
        snprintf(out->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%c", components[c]);
    if (samples >= 0)
        snprintf(out->channel_names[3], IMAGE_CHANNEL_NAME_MAX, "samples");
    for (int g = 0; g < layers->count; g++)
        for (int c = 0; c < 3; c++)
            snprintf(out->channel_names[first_layer + 3 * g + c], IMAGE_CHANNEL_NAME_MAX, "%s.%c", layers->names[g],
                     components[c]);
    out->x = image->x;
    out->y = image->y;
    out->full_width = image->full_width;
    out->full_height = image->full_height;
    size_t pixel_count = (size_t)image->width * image->height;
    for (size_t i = 0; i < pixel_count; i++) {
        const float *in = image->pixels + i * (size_t)image->channels;
        float *pixel = out->pixels + i * (size_t)out->channels;
        if (samples >= 0)
            pixel[3] = in[samples];
        for (int g = 0; g < layers->count; g++)
            for (int c = 0; c < 3; c++) {
                float value = factors[g][c] * in[layers->channels[g][c]];
                pixel[first_layer + 3 * g + c] = value;
                pixel[c] += value;
            }
    }
    return RT_OK;
}
