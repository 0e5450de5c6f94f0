/* command_montage.c: `rtspheres montage IMAGES... -o SHEET [--columns N] [--gap PIXELS]
 * [--labels | --label-table TABLE]`: lays equal-size images out as a contact sheet
 * (core/postprocess.h), e.g. the frames of a light sweep, each optionally labelled below
 * with its file name or its sweep row's values (core/label.h). Inputs are read as linear light (8-bit sRGB files are decoded) so that the
 * writer's sRGB encoding gives PNG tiles back as they were. Exit codes: 0 ok, 1 runtime
 * failure (write failed, out of memory), 2 bad input (usage, unreadable or mismatched
 * images, -o naming an input). */
#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "image_io.h"
#include "paths.h"
#include "label.h"
#include "postprocess.h"
#include "sweep.h"

#define DEFAULT_GAP 2
#define MAX_GAP 4096
#define MAX_COLUMNS 4096

static void print_help(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres montage IMAGES... -o SHEET [options]\n"
            "\n"
            "Lays the images out as a contact sheet: a grid filled row by row, left to right,\n"
            "in the order given, on black. All images must have the same size; the sheet holds\n"
            "their colour (R, G, B). PNG/JPEG inputs are decoded from sRGB and the sheet is\n"
            "encoded like a render, so 8-bit tiles come out as they went in.\n"
            "\n"
            "options:\n"
            "  -o, --output FILE   the sheet (.png, .jpg, .tif, .exr, .hdr); never one of the inputs\n"
            "      --columns N     images per row (default: ceil(sqrt(count)), so 12 make 4x3)\n"
            "      --gap PIXELS    black space between images (default %d; none around the outside)\n"
            "      --labels        write each image's file name under it (a built-in 5x7 font)\n"
            "      --label-table TABLE  write under image i the values of row i of a sweep table\n"
            "                      (render --sweep's .tsv or .csv), NAME=VALUE each; as many rows\n"
            "                      as images\n"
            "  -q, --quiet         no summary line\n"
            "  -h, --help          this text\n"
            "\n"
            "exit status: 0 ok, 1 runtime failure (write failed), 2 bad input (usage, unreadable\n"
            "or differently sized images)\n",
            DEFAULT_GAP);
}

/* Writes image i's label into text (size bytes): its file name without the directory, or
 * with a table its row's NAME=VALUE pairs. */
static void label_text(const char *path, const sweep_table *table, int i, char *text, size_t size)
{
    text[0] = '\0';
    if (table == NULL) {
        const char *slash = strrchr(path, '/');
        snprintf(text, size, "%s", slash != NULL ? slash + 1 : path);
        return;
    }
    for (int c = 0; c < table->column_count; c++) {
        size_t used = strlen(text);
        snprintf(text + used, size - used, "%s%s=%s", c > 0 ? " " : "", table->names[c],
                 table->values[(size_t)i * table->column_count + c]);
    }
}

/* Replaces each of images[0 .. count-1] by itself with its label below (label_text), all
 * with bands of the same height. */
static rt_status add_labels(rt_image *images, char **paths, int count, const sweep_table *table, rt_error *error)
{
    if (table != NULL && table->row_count != count)
        return rt_error_set(error, RT_ERROR_INPUT, "%s has %d row%s for %d image%s; give one row per image",
                            table->path, table->row_count, table->row_count == 1 ? "" : "s", count,
                            count == 1 ? "" : "s");
    int scale = label_scale(images[0].width), lines = 1;
    char text[1024];
    for (int i = 0; i < count; i++) {
        label_text(paths[i], table, i, text, sizeof text);
        int needed = label_lines(text, images[i].width, scale);
        lines = needed > lines ? needed : lines;
    }
    for (int i = 0; i < count; i++) {
        label_text(paths[i], table, i, text, sizeof text);
        rt_image labelled;
        rt_status status = label_under_image(&images[i], text, lines, scale, &labelled, error);
        if (status != RT_OK)
            return status;
        image_free(&images[i]);
        images[i] = labelled;
    }
    return RT_OK;
}

/* Parses text as a whole number in [0, maximum] into *value. Returns false when it is not. */
static bool parse_count(const char *text, int maximum, int *value)
{
    long long parsed;
    if (command_parse_integer(text, 0, maximum, &parsed) != 0)
        return false;
    *value = (int)parsed;
    return true;
}

int command_montage(int argc, char **argv)
{
    enum { OPTION_COLUMNS = 256, OPTION_GAP, OPTION_LABELS, OPTION_LABEL_TABLE };
    static const struct option long_options[] = {
        {"output", required_argument, NULL, 'o'},
        {"columns", required_argument, NULL, OPTION_COLUMNS},
        {"gap", required_argument, NULL, OPTION_GAP},
        {"labels", no_argument, NULL, OPTION_LABELS},
        {"label-table", required_argument, NULL, OPTION_LABEL_TABLE},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    const char *output = NULL;
    int columns = 0, gap = DEFAULT_GAP;
    bool quiet = false, labels = false;
    const char *label_table = NULL;
    optind = 1;
    int option;
    while ((option = getopt_long(argc, argv, "o:qh", long_options, NULL)) != -1) {
        switch (option) {
        case 'o': output = optarg; break;
        case OPTION_COLUMNS:
            if (!parse_count(optarg, MAX_COLUMNS, &columns) || columns == 0) {
                fprintf(stderr, "rtspheres montage: --columns wants a whole number from 1 to %d, not '%s'\n",
                        MAX_COLUMNS, optarg);
                return EXIT_BAD_INPUT;
            }
            break;
        case OPTION_GAP:
            if (!parse_count(optarg, MAX_GAP, &gap)) {
                fprintf(stderr, "rtspheres montage: --gap wants a whole number of pixels from 0 to %d, not '%s'\n",
                        MAX_GAP, optarg);
                return EXIT_BAD_INPUT;
            }
            break;
        case 'q': quiet = true; break;
        case OPTION_LABELS: labels = true; break;
        case OPTION_LABEL_TABLE: label_table = optarg; break;
        default: return command_help_exit(option, print_help);
        }
    }
    if (output == NULL) {
        fprintf(stderr, "rtspheres montage: no output; give -o SHEET.png\n");
        return EXIT_BAD_INPUT;
    }
    if (labels && label_table != NULL) {
        fprintf(stderr, "rtspheres montage: --labels and --label-table both label the images; give one\n");
        return EXIT_BAD_INPUT;
    }
    if (image_format_of(output) == IMAGE_FORMAT_UNKNOWN) {
        fprintf(stderr, "rtspheres montage: cannot tell the format of '%s'; use .png, .jpg, .tif, .exr or .hdr\n",
                output);
        return EXIT_BAD_INPUT;
    }
    if (optind >= argc) {
        fprintf(stderr, "rtspheres montage: no images; give the images before or after -o\n");
        return EXIT_BAD_INPUT;
    }
    char **paths = argv + optind;
    int count = argc - optind;
    for (int i = 0; i < count; i++)
        if (strcmp(paths[i], output) == 0 || path_same_file(paths[i], output)) {
            fprintf(stderr, "rtspheres montage: the output '%s' is one of the inputs; refusing to overwrite it\n",
                    output);
            return EXIT_BAD_INPUT;
        }

    rt_image *images = calloc((size_t)count, sizeof *images);
    if (images == NULL) {
        fprintf(stderr, "rtspheres montage: out of memory for %d images\n", count);
        return EXIT_RUNTIME;
    }
    rt_error error = {{0}};
    rt_status status = RT_OK;
    for (int i = 0; i < count && status == RT_OK; i++)
        status = image_read_linear(paths[i], POSTPROCESS_MAX_MONTAGE_SIDE, &images[i], &error);
    /* The core would refuse too; here the message can name the files. */
    for (int i = 1; i < count && status == RT_OK; i++)
        if (images[i].width != images[0].width || images[i].height != images[0].height)
            status = rt_error_set(&error, RT_ERROR_INPUT, "'%s' is %dx%d but '%s' is %dx%d; all images must have one size",
                                  paths[i], images[i].width, images[i].height, paths[0], images[0].width,
                                  images[0].height);
    sweep_table table = {0};
    if (status == RT_OK && label_table != NULL)
        status = sweep_table_load(label_table, &table, &error);
    if (status == RT_OK && (labels || label_table != NULL))
        status = add_labels(images, paths, count, label_table != NULL ? &table : NULL, &error);
    sweep_table_free(&table);
    rt_image sheet = {0};
    if (status == RT_OK)
        status = postprocess_montage(images, count, columns, gap, &sheet, &error);
    for (int i = 0; i < count; i++)
        image_free(&images[i]);
    free(images);
    if (status == RT_OK)
        status = image_write(output, &sheet, NULL, &error);
    if (status != RT_OK) {
        image_free(&sheet);
        fprintf(stderr, "rtspheres montage: %s\n", error.message);
        return exit_code_for_status(status);
    }
    if (!quiet)
        fprintf(stderr, "rtspheres montage: %d image%s -> %s: %dx%d\n", count, count == 1 ? "" : "s", output,
                sheet.width, sheet.height);
    image_free(&sheet);
    return EXIT_OK;
}
