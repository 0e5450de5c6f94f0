/* hash.h: the one hash of the code base: 64-bit FNV-1a, for telling whether two things
 * are the same (a packed scene already on the device, the scene hash that `merge` and
 * `--resume` compare). Not for security, and not stable across packed-layout versions.
 *
 *   uint64_t hash_bytes(uint64_t hash, const void *data, size_t size)
 *       continues hash (start with HASH_START) over size bytes and returns it
 */
#ifndef RT_HASH_H
#define RT_HASH_H

#include <stddef.h>
#include <stdint.h>

#define HASH_START 0xcbf29ce484222325ull

static inline uint64_t hash_bytes(uint64_t hash, const void *data, size_t size)
{
    const unsigned char *bytes = (const unsigned char *)data;
    for (size_t i = 0; i < size; i++) {
        hash ^= bytes[i];
        hash *= 0x100000001b3ull;
    }
    return hash;
}

#endif
