/* fovea — the grow-only scratch arena (scratch.h). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/scratch.h"

#define ALIGN 64

/* n rounded up to the alignment; 0 when that overflows. */
static size_t round_up(size_t n) { return n > SIZE_MAX - (ALIGN - 1) ? 0 : (n + ALIGN - 1) / ALIGN * ALIGN; }

static void free_spill(fv_scratch *s)
{
    while (s->spill) {
        void *next;
        memcpy(&next, s->spill, sizeof next);
        free(s->spill);
        s->spill = next;
    }
    s->spilled = 0;
}

void fv_scratch_begin(fv_scratch *s)
{
    free_spill(s);
    if (s->peak > s->cap) {
        /* the last piece needed more than the block: one block for all of it next time */
        free(s->base);
        s->base = aligned_alloc(ALIGN, s->peak);
        s->cap = s->base ? s->peak : 0;
    }
    s->used = 0;
    s->peak = 0;
}

size_t fv_scratch_bytes(size_t count, size_t size)
{
    if (size != 0 && count > SIZE_MAX / size) return 0;
    const size_t want = count * size;
    return round_up(want ? want : 1);
}

void fv_scratch_reserve(fv_scratch *s, size_t bytes)
{
    if (bytes > s->peak) s->peak = bytes;
    fv_scratch_begin(s);
}

void *fv_scratch_take(fv_scratch *s, size_t count, size_t size)
{
    const size_t bytes = fv_scratch_bytes(count, size);
    if (bytes == 0) return NULL;
    void *p;
    if (bytes <= s->cap - s->used) {
        p = s->base + s->used;
        s->used += bytes;
    } else {
        /* a block of its own, its first ALIGN bytes the chain's link */
        if (bytes > SIZE_MAX - ALIGN) return NULL;
        unsigned char *b = aligned_alloc(ALIGN, bytes + ALIGN);
        if (!b) return NULL;
        memcpy(b, &s->spill, sizeof s->spill);
        s->spill = b;
        s->spilled += bytes;
        p = b + ALIGN;
    }
    const size_t total = s->used + s->spilled;
    if (total > s->peak) s->peak = total;
    return p;
}

void *fv_scratch_take_zero(fv_scratch *s, size_t count, size_t size)
{
    void *p = fv_scratch_take(s, count, size);
    if (p) memset(p, 0, count * size);
    return p;
}

void fv_scratch_free(fv_scratch *s)
{
    free_spill(s);
    free(s->base);
    memset(s, 0, sizeof *s);
}
