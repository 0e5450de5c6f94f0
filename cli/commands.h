/* commands.h: the subcommands of the rtspheres program. Each takes the arguments after
 * the subcommand name (argv[0] is the subcommand name, as getopt_long expects) and
 * returns the process exit code:
 *   0 success (diff: images match)
 *   1 runtime failure (diff: images differ)
 *   2 bad input or usage
 */
#ifndef RT_COMMANDS_H
#define RT_COMMANDS_H

#include <stdio.h>

#include "image_io.h"
#include "postprocess.h"

int command_render(int argc, char **argv);
int command_diff(int argc, char **argv);
int command_check(int argc, char **argv);
int command_info(int argc, char **argv);
int command_stats(int argc, char **argv);
int command_merge(int argc, char **argv);
int command_montage(int argc, char **argv);
int command_relight(int argc, char **argv);
int command_denoise(int argc, char **argv);

/* Exit codes shared by all commands. */
#define EXIT_OK 0
#define EXIT_RUNTIME 1
#define EXIT_BAD_INPUT 2

/* Helpers every command uses (cli/command_support.c). */

/* Maps a core status to the exit code above. */
int exit_code_for_status(int status);

/* Parses all of text as a decimal whole number in [minimum, maximum] into *value.
 * Returns 0, or -1 (and leaves *value) when it is not one. */
int command_parse_integer(const char *text, long long minimum, long long maximum, long long *value);

/* What a command does with -h/--help (option 'h': the help on stdout, exit 0) and with an
 * unknown option (any other: the help on stderr after getopt's message, exit 2). Returns
 * the exit code. */
int command_help_exit(int option, void (*print_help)(FILE *stream));

/* The --exposure and --tonemap options of the commands that write images from images
 * (relight, denoise): parse text into *exposure (stops, -64 to 64) or *tonemap (clamp,
 * reinhard, aces). Return 0, or -1 after saying on stderr what `rtspheres COMMAND` wanted. */
int command_parse_exposure(const char *command, const char *text, double *exposure);
int command_parse_tonemap(const char *command, const char *text, postprocess_tonemap_operator *tonemap);

/* The operands of a command that makes one image from another (relight, denoise), after
 * getopt: exactly one input (what: what it must be, for the message) into *input, an
 * output of a format image_write() knows, and never the input itself. Returns EXIT_OK, or
 * EXIT_BAD_INPUT after saying why on stderr. */
int command_image_to_image(const char *command, int argc, char **argv, const char *what, const char *output,
                           const char **input);

/* Writes the first three channels of image (R, G, B) to output, a format other than EXR:
 * 8-bit ones exposed by 2^exposure and tone-mapped as renders are; with metadata's
 * attributes (NULL: none), as renders write theirs into every format. */
rt_status command_write_colour(const char *output, const rt_image *image, postprocess_tonemap_operator tonemap,
                               double exposure, const image_attribute_set *metadata, rt_error *error);

#endif
