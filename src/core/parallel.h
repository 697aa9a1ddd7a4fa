/* fovea — the shared tile loop and parallel-for.
 *
 * Work is split into fixed tiles handed out dynamically to OpenMP threads. Each tile knows its
 * thread index, so per-thread scratch and counters need no locks. Progress is reported from the
 * calling thread's view of finished tiles. Results never depend on which thread ran a tile.
 */
#ifndef FV_CORE_PARALLEL_H
#define FV_CORE_PARALLEL_H

#include <stdint.h>
#include <stdbool.h>
#include "fovea/frame.h"

#define FV_TILE_SIZE 16
#define FV_MAX_THREADS 256

typedef struct fv_tile {
    int x0, y0, x1, y1; /* pixel rectangle [x0,x1) x [y0,y1) */
    int thread;         /* 0 .. fv_thread_count(frame)-1 */
} fv_tile;

typedef void (*fv_tile_fn)(void *ctx, const fv_tile *tile);

/* Number of threads a frame asks for (frame->threads, or all when 0), capped to FV_MAX_THREADS. */
int fv_thread_count(int requested);

/* Runs fn over all tiles of a width x height image with `threads` threads (0: all), calling
 * progress(user, fraction) now and then from one thread, and last with 1. When progress returns
 * false, tiles not yet started are skipped and the call returns false (cancelled). */
bool fv_parallel_tiles(int width, int height, int threads, fv_tile_fn fn, void *ctx,
                       fv_progress_fn progress, void *progress_user);

/* Runs fn(ctx, begin, end, thread) over [0, n) in chunks of `chunk`. */
typedef void (*fv_range_fn)(void *ctx, int64_t begin, int64_t end, int thread);
void fv_parallel_for(int64_t n, int64_t chunk, int threads, fv_range_fn fn, void *ctx);
/* The same with progress and cancel as in fv_parallel_tiles; false when cancelled. */
bool fv_parallel_for_progress(int64_t n, int64_t chunk, int threads, fv_range_fn fn, void *ctx, fv_progress_fn progress,
                              void *progress_user);

/* The parallel regions the calling thread has opened so far. Every `#pragma omp parallel` in
 * fovea is preceded by fv_region_opened() (fv_parallel_* call it themselves), so that
 * fv_technique_render can report "parallel_regions" per frame: each region wakes the team, and
 * the wake-ups are what pacing depends on (docs/threads.md). tests/cli/test_regions.sh checks the
 * count against the runtime's own. */
uint64_t fv_region_count(void);
void fv_region_opened(void);

#endif
