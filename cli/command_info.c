/* TEMPORARY placeholder while the renderer is written; replaced before any commit. */
#include "commands.h"
int command_info(int argc, char **argv) { (void)argc; (void)argv; return EXIT_RUNTIME; }
