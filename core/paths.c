/* paths.c: see paths.h. */
#include "paths.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

const char *path_extension(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot != NULL && strchr(dot, '/') == NULL ? dot : "";
}

bool path_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

bool path_directory_writable(const char *path)
{
    const char *slash = strrchr(path, '/');
    char probe[4096];
    int length = slash == NULL ? snprintf(probe, sizeof probe, ".rtspheres-probe-XXXXXX")
                               : snprintf(probe, sizeof probe, "%.*s/.rtspheres-probe-XXXXXX",
                                          (int)(slash - path), path);
    if (length < 0 || (size_t)length >= sizeof probe)
        return false;
    int descriptor = mkstemp(probe);
    if (descriptor < 0)
        return false;
    close(descriptor);
    unlink(probe);
    return true;
}
