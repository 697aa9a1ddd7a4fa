/* fovea — allocation helpers that check the size arithmetic before calling malloc.
 * An absurd request (count * size overflowing size_t) fails like an allocation failure. */
#ifndef FV_CORE_ALLOC_H
#define FV_CORE_ALLOC_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static inline void *fv_alloc_array(size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size) return NULL;
    size_t bytes = count * size;
    return malloc(bytes ? bytes : 1);
}

static inline void *fv_calloc_array(size_t count, size_t size)
{
    return calloc(count ? count : 1, size ? size : 1);
}

/* Grows *ptr to hold at least `need` elements of `size` bytes, doubling; returns 0 on success. */
static inline int fv_grow(void **ptr, int *cap, int need, size_t size)
{
    if (need <= *cap) return 0;
    int nc = *cap ? *cap : 8;
    while (nc < need) {
        if (nc > INT32_MAX / 2) return -1;
        nc *= 2;
    }
    if ((size_t)nc > SIZE_MAX / size) return -1;
    void *p = realloc(*ptr, (size_t)nc * size);
    if (!p) return -1;
    *ptr = p;
    *cap = nc;
    return 0;
}

#endif
