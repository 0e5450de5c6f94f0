/* command_support.c: the helpers every command shares (declared in commands.h). */
#include <errno.h>
#include <stdbool.h>
#include <stdlib.h>

#include "commands.h"
#include "status.h"

int exit_code_for_status(int status)
{
    switch ((rt_status)status) {
    case RT_OK: return EXIT_OK;
    case RT_ERROR_INPUT: return EXIT_BAD_INPUT;
    case RT_ERROR_RUNTIME:
    case RT_ERROR_NO_DEVICE:
    case RT_ERROR_INTERRUPTED: return EXIT_RUNTIME;
    }
    return EXIT_RUNTIME;
}

int command_parse_integer(const char *text, long long minimum, long long maximum, long long *value)
{
    char *end = NULL;
    errno = 0;
    long long parsed = strtoll(text, &end, 10);
    if (end == text || *end != '\0' || errno != 0 || parsed < minimum || parsed > maximum)
        return -1;
    *value = parsed;
    return 0;
}

int command_help_exit(int option, void (*print_help)(FILE *stream))
{
    bool asked = option == 'h';
    print_help(asked ? stdout : stderr);
    return asked ? EXIT_OK : EXIT_BAD_INPUT;
}
