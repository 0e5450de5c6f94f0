/* compare_arguments.h: the comparison options of `rtspheres diff` and of a suite case's
 * `compare` part (`rtspheres check`), turned into image_compare_options (core/image_compare.h):
 * one parser, so that both take the same words with the same messages.
 *
 *   --test idiff|z        which test (diff's default: idiff; check's: z)
 *   idiff:  --fail X, --failpercent P, --hardfail X
 *   z:      --alpha A, --pass-percent P, --block-alpha A, --scales LIST|none,
 *           --noise-floor REL, --noise-floor-absolute ABS
 *   both:   --scale S (amplification of the difference image)
 *
 * A command puts compare_long_options into its getopt_long table (their codes are
 * COMPARE_OPTION_FIRST and on) and hands each such option to compare_arguments_take(). */
#ifndef RT_COMPARE_ARGUMENTS_H
#define RT_COMPARE_ARGUMENTS_H

#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>

#include "image_compare.h"

#define COMPARE_OPTION_FIRST 1000

typedef struct compare_arguments {
    image_compare_options options;
    bool hard_fail_set;          /* --hardfail was given (0 then means "no difference") */
    double fail_threshold, fail_percent, hard_fail, scale;   /* as given, for messages */
    unsigned given;              /* a bit per option given (1 << (code - COMPARE_OPTION_FIRST)) */
} compare_arguments;

/* The options, terminated by an all-zero entry; COMPARE_LONG_OPTION_COUNT before it. */
#define COMPARE_LONG_OPTION_COUNT 11
extern const struct option compare_long_options[COMPARE_LONG_OPTION_COUNT + 1];

/* Starts *arguments with every option at its default and default_test. */
void compare_arguments_init(compare_arguments *arguments, image_compare_test default_test);

/* True when option (a getopt_long code) is one of compare_long_options. */
bool compare_arguments_owns(int option);

/* Takes option with its value. Returns NULL, or the complaint (a constant sentence to be
 * followed by ", not 'VALUE'"). */
const char *compare_arguments_take(compare_arguments *arguments, int option, const char *value);

/* Checks the options given against the test chosen: an option of the other test is
 * refused. Returns NULL, or the complaint (written into text, size bytes). */
const char *compare_arguments_finish(compare_arguments *arguments, char *text, size_t size);

/* Parses argv[0 .. argc-1] (all comparison options, no operands; argv[0] is the first
 * option, not a program name) into *arguments (init first). Returns NULL, or the
 * complaint written into text (size bytes) with the offending word's index in argv in
 * *at (-1: not one word's). */
const char *compare_arguments_parse(int argc, char **argv, compare_arguments *arguments, char *text, size_t size,
                                    int *at);

#endif
