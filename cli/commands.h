/* commands.h: the subcommands of the rtspheres program. Each takes the arguments after
 * the subcommand name (argv[0] is the subcommand name, as getopt_long expects) and
 * returns the process exit code:
 *   0 success (diff: images match)
 *   1 runtime failure (diff: images differ)
 *   2 bad input or usage
 */
#ifndef RT_COMMANDS_H
#define RT_COMMANDS_H

int command_render(int argc, char **argv);
int command_diff(int argc, char **argv);
int command_info(int argc, char **argv);
int command_stats(int argc, char **argv);
int command_merge(int argc, char **argv);
int command_montage(int argc, char **argv);

/* Exit codes shared by all commands. */
#define EXIT_OK 0
#define EXIT_RUNTIME 1
#define EXIT_BAD_INPUT 2

/* Maps a core status to the exit code above. */
int exit_code_for_status(int status);

#endif
