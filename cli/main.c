/* main.c: the rtspheres program: picks the subcommand and hands it the remaining
 * arguments. Exit codes: 0 ok, 1 runtime failure (diff: images differ), 2 bad input/usage. */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "version.h"

static void print_usage(FILE *stream)
{
    fprintf(stream,
            "usage: rtspheres COMMAND [options]\n"
            "\n"
            "commands:\n"
            "  render SCENE -o OUTPUT   render a scene file to .exr/.png/.jpg/.hdr\n"
            "  diff A B                 compare two images (exit 0 pass, 1 fail, 2 error)\n"
            "  check SUITE              render a regression suite and compare each case with its\n"
            "                           golden image; JUnit XML and an HTML report for CI\n"
            "  info                     list the EGL devices (the numbers --device takes) and show the\n"
            "                           OpenGL renderer a render would use\n"
            "  stats IMAGE              per-channel mean/min/max of an image and its rtspheres metadata\n"
            "  merge PARTS... -o OUT    merge EXR parts of one render (sample ranges, tiles, shards)\n"
            "  montage IMAGES... -o OUT lay equal-size images out as a contact sheet\n"
            "  relight IN.exr -o OUT    reweigh the light group layers of a --light-groups render\n"
            "  denoise IN.exr -o OUT    denoise a render made with --aovs (as render --denoise does)\n"
            "\n"
            "Run 'rtspheres COMMAND --help' for a command's options.\n");
}

/* The subcommands by name. */
static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
} commands[] = {
    {"render", command_render}, {"diff", command_diff},   {"check", command_check},  {"info", command_info},
    {"stats", command_stats},   {"merge", command_merge}, {"montage", command_montage},
    {"relight", command_relight}, {"denoise", command_denoise},
};

int main(int argc, char **argv)
{
    if (argc < 2) {
        print_usage(stderr);
        return EXIT_BAD_INPUT;
    }
    const char *command = argv[1];
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(command, commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
    if (strcmp(command, "--help") == 0 || strcmp(command, "-h") == 0 || strcmp(command, "help") == 0) {
        print_usage(stdout);
        return EXIT_OK;
    }
    if (strcmp(command, "--version") == 0) {
        printf("rtspheres %s\n", RTSPHERES_VERSION);
        return EXIT_OK;
    }
    fprintf(stderr, "rtspheres: unknown command '%s'\n\n", command);
    print_usage(stderr);
    return EXIT_BAD_INPUT;
}
