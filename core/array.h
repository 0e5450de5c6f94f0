/* array.h: the one growth helper for the code base's dynamic arrays (scene lists, the
 * packer's lists, merge parts, frame lists).
 *
 *   bool array_reserve(void **items, size_t *capacity, size_t needed, size_t element_size)
 *
 * Makes room for at least `needed` elements of element_size bytes in *items, whose room is
 * *capacity elements: the room is doubled (at least 16) and the array moved with realloc.
 * Returns true when the room is there (also when it already was), false when memory runs
 * out or the size would overflow; *items and *capacity are then unchanged. The array stays
 * the caller's to free. Header-only (static inline) so that the fuzz harnesses, which
 * compile chosen core sources, need no extra file.
 */
#ifndef RT_ARRAY_H
#define RT_ARRAY_H

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

static inline bool array_reserve(void **items, size_t *capacity, size_t needed, size_t element_size)
{
    if (needed <= *capacity)
        return true;
    size_t grown = *capacity ? *capacity : 8;
    while (grown < needed) {
        if (grown > SIZE_MAX / 2)
            return false;
        grown *= 2;
    }
    if (element_size != 0 && grown > SIZE_MAX / element_size)
        return false;
    void *moved = realloc(*items, grown * element_size);
    if (moved == NULL)
        return false;
    *items = moved;
    *capacity = grown;
    return true;
}

#endif
