/* compare_arguments.c: see compare_arguments.h. */
#include "compare_arguments.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    OPTION_TEST = COMPARE_OPTION_FIRST, OPTION_FAIL, OPTION_FAIL_PERCENT, OPTION_HARD_FAIL, OPTION_SCALE,
    OPTION_ALPHA, OPTION_PASS_PERCENT, OPTION_BLOCK_ALPHA, OPTION_SCALES, OPTION_NOISE_FLOOR,
    OPTION_NOISE_FLOOR_ABSOLUTE, OPTION_END,
};

const struct option compare_long_options[COMPARE_LONG_OPTION_COUNT + 1] = {
    {"test", required_argument, NULL, OPTION_TEST},
    {"fail", required_argument, NULL, OPTION_FAIL},
    {"failpercent", required_argument, NULL, OPTION_FAIL_PERCENT},
    {"hardfail", required_argument, NULL, OPTION_HARD_FAIL},
    {"scale", required_argument, NULL, OPTION_SCALE},
    {"alpha", required_argument, NULL, OPTION_ALPHA},
    {"pass-percent", required_argument, NULL, OPTION_PASS_PERCENT},
    {"block-alpha", required_argument, NULL, OPTION_BLOCK_ALPHA},
    {"scales", required_argument, NULL, OPTION_SCALES},
    {"noise-floor", required_argument, NULL, OPTION_NOISE_FLOOR},
    {"noise-floor-absolute", required_argument, NULL, OPTION_NOISE_FLOOR_ABSOLUTE},
    {NULL, 0, NULL, 0},
};

_Static_assert(OPTION_END - COMPARE_OPTION_FIRST == COMPARE_LONG_OPTION_COUNT, "one table entry per option");

void compare_arguments_init(compare_arguments *arguments, image_compare_test default_test)
{
    memset(arguments, 0, sizeof *arguments);
    arguments->options = image_compare_options_defaults();
    arguments->options.test = default_test;
    arguments->fail_threshold = IMAGE_DIFF_DEFAULT_FAIL_THRESHOLD;
    arguments->fail_percent = IMAGE_DIFF_DEFAULT_FAIL_PERCENT;
    arguments->scale = IMAGE_DIFF_DEFAULT_SCALE;
}

bool compare_arguments_owns(int option)
{
    return option >= COMPARE_OPTION_FIRST && option < OPTION_END;
}

/* Parses all of text as a finite number in [minimum, maximum] into *value. Returns true
 * on success; "", "abc", "1x", "nan" and out-of-range values are refused. */
static bool parse_number(const char *text, double minimum, double maximum, double *value)
{
    char *end = NULL;
    errno = 0;
    double parsed = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(parsed) || parsed < minimum
        || parsed > maximum)
        return false;
    *value = parsed;
    return true;
}

/* The options treat 0 as "use the default", so a tolerance of exactly zero is passed as
 * the smallest positive double. The differences of float samples are either 0 or far
 * above DBL_MIN, so "error > DBL_MIN" means the same as "error > 0". */
static double zero_as_smallest(double value)
{
    return value == 0.0 ? DBL_MIN : value;
}

/* --scales: "none", or a comma-separated list of block sides (2 to 65536) and "image". */
static bool parse_scales(const char *text, image_stat_options *stat)
{
    if (strcmp(text, "none") == 0) {
        stat->pixels_only = true;
        stat->block_count = 0;
        return true;
    }
    stat->pixels_only = false;
    stat->block_count = 0;
    const char *part = text;
    for (;;) {
        const char *comma = strchr(part, ',');
        size_t length = comma ? (size_t)(comma - part) : strlen(part);
        char word[16];
        if (length == 0 || length >= sizeof word || stat->block_count == IMAGE_STAT_MAX_BLOCK_SCALES)
            return false;
        memcpy(word, part, length);
        word[length] = '\0';
        double side = 0;
        if (strcmp(word, "image") == 0)
            stat->block_sizes[stat->block_count++] = IMAGE_STAT_WHOLE_IMAGE;
        else if (parse_number(word, 2, 65536, &side) && side == floor(side))
            stat->block_sizes[stat->block_count++] = (int)side;
        else
            return false;
        if (comma == NULL)
            return true;
        part = comma + 1;
    }
}

/* A significance level: above 0 and below 1. */
static bool parse_level(const char *text, double *value)
{
    return parse_number(text, 0.0, 1.0, value) && *value > 0 && *value < 1;
}

const char *compare_arguments_take(compare_arguments *arguments, int option, const char *value)
{
    image_compare_options *options = &arguments->options;
    double number = 0;
    arguments->given |= 1u << (option - COMPARE_OPTION_FIRST);
    switch (option) {
    case OPTION_TEST:
        if (strcmp(value, "idiff") == 0)
            options->test = IMAGE_COMPARE_IDIFF;
        else if (strcmp(value, "z") == 0)
            options->test = IMAGE_COMPARE_Z;
        else
            return "--test wants idiff or z";
        return NULL;
    case OPTION_FAIL:
        if (!parse_number(value, 0.0, HUGE_VAL, &arguments->fail_threshold))
            return "--fail wants an error of 0 or more, e.g. 0.016";
        options->idiff.fail_threshold = zero_as_smallest(arguments->fail_threshold);
        return NULL;
    case OPTION_FAIL_PERCENT:
        if (!parse_number(value, 0.0, 100.0, &arguments->fail_percent))
            return "--failpercent wants a percentage from 0 to 100";
        options->idiff.fail_percent = zero_as_smallest(arguments->fail_percent);
        return NULL;
    case OPTION_HARD_FAIL:
        if (!parse_number(value, 0.0, HUGE_VAL, &arguments->hard_fail))
            return "--hardfail wants an error of 0 or more";
        /* --hardfail 0 means "no difference at all", not image_diff's "off". */
        arguments->hard_fail_set = true;
        options->idiff.hard_fail = zero_as_smallest(arguments->hard_fail);
        return NULL;
    case OPTION_SCALE:
        if (!parse_number(value, 0.0, HUGE_VAL, &arguments->scale) || arguments->scale == 0.0)
            return "--scale wants a factor above 0, e.g. 16";
        options->idiff.diff_scale = arguments->scale;
        return NULL;
    case OPTION_ALPHA:
        if (!parse_level(value, &options->stat.alpha))
            return "--alpha wants a significance level between 0 and 1, e.g. 0.01";
        return NULL;
    case OPTION_BLOCK_ALPHA:
        if (!parse_level(value, &options->stat.block_alpha))
            return "--block-alpha wants a significance level between 0 and 1, e.g. 0.01";
        return NULL;
    case OPTION_PASS_PERCENT:
        if (!parse_number(value, 0.0, 100.0, &number) || number == 0)
            return "--pass-percent wants a percentage above 0 and at most 100, e.g. 99.75";
        options->stat.pass_share = number / 100.0;
        return NULL;
    case OPTION_SCALES:
        if (!parse_scales(value, &options->stat))
            return "--scales wants block sizes of 2 or more and 'image', comma-separated, e.g. 4,16,image, or none";
        return NULL;
    case OPTION_NOISE_FLOOR:
        if (!parse_number(value, 0.0, 1.0, &number))
            return "--noise-floor wants a relative difference from 0 to 1, e.g. 0.001";
        options->stat.relative_floor = zero_as_smallest(number);
        return NULL;
    case OPTION_NOISE_FLOOR_ABSOLUTE:
        if (!parse_number(value, 0.0, HUGE_VAL, &number))
            return "--noise-floor-absolute wants a difference of 0 or more, e.g. 1e-5";
        options->stat.absolute_floor = zero_as_smallest(number);
        return NULL;
    }
    return "is not a comparison option";
}

const char *compare_arguments_finish(compare_arguments *arguments, char *text, size_t size)
{
    static const int idiff_only[] = {OPTION_FAIL, OPTION_FAIL_PERCENT, OPTION_HARD_FAIL};
    static const int z_only[] = {OPTION_ALPHA, OPTION_PASS_PERCENT, OPTION_BLOCK_ALPHA, OPTION_SCALES,
                                 OPTION_NOISE_FLOOR, OPTION_NOISE_FLOOR_ABSOLUTE};
    bool z = arguments->options.test == IMAGE_COMPARE_Z;
    const int *other = z ? idiff_only : z_only;
    int count = z ? (int)(sizeof idiff_only / sizeof idiff_only[0]) : (int)(sizeof z_only / sizeof z_only[0]);
    for (int i = 0; i < count; i++)
        if (arguments->given & 1u << (other[i] - COMPARE_OPTION_FIRST)) {
            snprintf(text, size, "--%s is an option of --test %s, not of --test %s",
                     compare_long_options[other[i] - COMPARE_OPTION_FIRST].name, z ? "idiff" : "z",
                     z ? "z" : "idiff");
            return text;
        }
    return NULL;
}

const char *compare_arguments_parse(int argc, char **argv, compare_arguments *arguments, char *text, size_t size,
                                    int *at)
{
    for (int i = 0; i < argc; i++) {
        *at = i;
        const char *word = argv[i];
        const struct option *found = NULL;
        const char *value = NULL;
        if (strncmp(word, "--", 2) == 0) {
            const char *equals = strchr(word, '=');
            size_t length = equals ? (size_t)(equals - word - 2) : strlen(word + 2);
            for (int k = 0; k < COMPARE_LONG_OPTION_COUNT && found == NULL; k++)
                if (strlen(compare_long_options[k].name) == length
                    && strncmp(compare_long_options[k].name, word + 2, length) == 0)
                    found = &compare_long_options[k];
            value = equals ? equals + 1 : NULL;
        }
        if (found == NULL) {
            snprintf(text, size, "unknown comparison option '%s'", word);
            return text;
        }
        if (value == NULL) {
            if (i + 1 == argc) {
                snprintf(text, size, "--%s needs a value", found->name);
                return text;
            }
            value = argv[++i];
        }
        const char *complaint = compare_arguments_take(arguments, found->val, value);
        if (complaint != NULL) {
            snprintf(text, size, "%s, not '%s'", complaint, value);
            return text;
        }
    }
    *at = -1;
    return compare_arguments_finish(arguments, text, size);
}
