/* paths.h: file names and the file-system checks made before work starts: a name's
 * extension, whether two names are one file, whether a file can be created where an
 * output is to go. Plain C on NUL-terminated paths; never prints, never allocates.
 */
#ifndef RT_PATHS_H
#define RT_PATHS_H

#include <stdbool.h>

/* Returns the extension of path's last component including the dot (".exr"), pointing
 * into path, or "" when that component has none. */
const char *path_extension(const char *path);

/* True when a and b name the same existing file (the same device and inode, so links and
 * different spellings count); false when either does not exist. */
bool path_same_file(const char *a, const char *b);

/* True when a file can be created in the directory part of path (the current directory
 * when path has no '/'), so a bad output is found before the work rather than after it.
 * It creates and removes a probe file instead of asking access(): for root, access()
 * approves directories such as /proc and /sys in which no file can be created. */
bool path_directory_writable(const char *path);

#endif
