/* fovea — a grow-only scratch arena: the temporary arrays of a piece of work (a tile, one call of a
 * filter), taken one after the other and dropped together, from one block that is kept from
 * frame to frame. Once the block has grown to what the largest piece needs, taking allocates
 * nothing, which is how a frame that sizes its temporaries from its data (hits in a tile, the
 * widest blur kernel) still allocates nothing once warmed up (docs/threads.md, "No allocation in
 * a frame").
 *
 * What does not fit is allocated on its own and freed at the next fv_scratch_begin, which also
 * grows the block to the most the last pieces took, so the arena never fails where malloc would
 * not. One arena belongs to one thread at a time; a technique keeps one per thread of its team.
 */
#ifndef FV_CORE_SCRATCH_H
#define FV_CORE_SCRATCH_H

#include <stddef.h>

typedef struct fv_scratch {
    unsigned char *base; /* the kept block, cap bytes */
    size_t cap, used;
    size_t spilled;      /* bytes of this piece that did not fit, in blocks of their own */
    size_t peak;         /* the most bytes (used + spilled) this piece has taken */
    void *spill;         /* those blocks, chained through their first word */
} fv_scratch;

#define FV_SCRATCH_INIT {NULL, 0, 0, 0, 0, NULL}

/* Starts a piece of work: everything taken before is dropped (spilled blocks freed), and the
 * block grown when the pieces before needed more than it holds. */
void fv_scratch_begin(fv_scratch *s);
/* count * size bytes, aligned to 64, uninitialised (fv_scratch_take_zero: zeroed); NULL only when
 * out of memory (or for a size that overflows). Valid until the next fv_scratch_begin or
 * fv_scratch_release below its mark. */
void *fv_scratch_take(fv_scratch *s, size_t count, size_t size);
void *fv_scratch_take_zero(fv_scratch *s, size_t count, size_t size);
/* The arena's position, and a return to it: what was taken from the block after the mark is
 * dropped (spilled blocks stay until fv_scratch_begin), for temporaries of a nested call. */
static inline size_t fv_scratch_mark(const fv_scratch *s) { return s->used; }
static inline void fv_scratch_release(fv_scratch *s, size_t mark) { s->used = mark; }
void fv_scratch_free(fv_scratch *s);
/* The bytes fv_scratch_take(s, count, size) uses of the block (0 when that overflows), to add up
 * a bound; and the block grown to at least `bytes` now (to be called between pieces, before a
 * begin). Where the pieces' needs depend on which thread runs which piece (dynamic schedules),
 * reserving a bound on the largest is what makes a warmed-up run allocate nothing: each arena
 * would otherwise grow only once its own thread meets a larger piece. */
size_t fv_scratch_bytes(size_t count, size_t size);
void fv_scratch_reserve(fv_scratch *s, size_t bytes);

#endif
