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
#include "fovea/progress.h"

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
 * fovea is preceded by fv_region_begin() and followed by fv_region_end() (fv_parallel_* and
 * fv_team_for needs none), so that fv_technique_render can report "parallel_regions" per
 * frame: each region wakes the team, and the wake-ups are what pacing depends on
 * (docs/threads.md). tests/cli/test_regions.sh checks the count against the runtime's own.
 * fv_region_opened() counts a region without timing it (for code not yet paired with an end). */
uint64_t fv_region_count(void);
void fv_region_opened(void);

/* The time a frame spends in parallel regions, for each stage's serial share (core/stage_time.h).
 * fv_region_begin counts the region and starts its clock; fv_region_end, after the region, adds
 * its wall time to the calling thread's parallel time. Inside a region, the thread that opened it
 * (`omp master`) reports work only it does while the others wait (before a barrier) with
 * fv_region_serial(ms), which takes it back out. Regions are not nested (nested parallelism is
 * off), so one open region per thread is all there is to track. */
void fv_region_begin(void);
void fv_region_end(void);
void fv_region_serial(double ms);
/* The calling thread's milliseconds inside its regions so far, less their serial parts, an open
 * region counted up to now. */
double fv_region_parallel_ms(void);

/* Work-sharing loops for merged regions: called by every thread of an enclosing region (each with
 * the same arguments), they share [0, n) among the team in chunks of `chunk`, handed out
 * dynamically as fv_parallel_for does, and end with the team's barrier; no region is opened.
 * Outside any region the calling thread runs all chunks. fn's `thread` is the team's thread
 * number. */
void fv_team_for(int64_t n, int64_t chunk, fv_range_fn fn, void *ctx);

/* Progress and cancel for the work-sharing loops of one merged region: declared before the region
 * (shared by the team), set with fv_team_progress_init. As in fv_parallel_for_progress, only the
 * thread that opened the region (team thread 0) calls fn, so it never runs concurrently with
 * itself and runs on the caller's thread. Once fn returns false the cancel is sticky: chunks not
 * yet started, in this loop and in every later one of the region, run empty. */
typedef struct fv_team_progress {
    fv_progress_fn fn; /* NULL: no progress, no cancel */
    void *user;
    int64_t done;      /* chunks finished in the current loop */
    int stop;          /* cancelled */
    int ok;            /* the last loop's result, published to the team behind a barrier */
} fv_team_progress;
void fv_team_progress_init(fv_team_progress *tp, fv_progress_fn fn, void *user);

/* fv_team_for with progress(user, fraction) from thread 0 and last 1, as fv_parallel_for_progress
 * does; returns false (on every thread alike) when the region was cancelled. Two barriers more than
 * fv_team_for: one to reset the count, one to publish the result. */
bool fv_team_for_progress(int64_t n, int64_t chunk, fv_range_fn fn, void *ctx, fv_team_progress *tp);
/* fv_parallel_tiles as a step of a merged region: the same tiles, handed out dynamically to the
 * team, with tp's progress and cancel (tp NULL: none). */
bool fv_team_tiles(int width, int height, fv_tile_fn fn, void *ctx, fv_team_progress *tp);

#endif
