/* fovea — a stage's time and its serial part (docs/threads.md, "Serial share per stage").
 *
 * A stage clock reads the wall clock and the calling thread's time inside parallel regions
 * (core/parallel.h); between two readings, the wall time not spent inside regions is the stage's
 * serial part: set-up, reductions and bookkeeping that one thread does while the others wait,
 * the part that bounds the stage's speed-up on many cores (Amdahl). It is measured, not
 * estimated from runs at several thread counts, so it holds on a loaded machine too (a thread
 * taken off its core inside a region counts as parallel time, one taken off outside as serial).
 * Limits: regions opened with fv_region_opened() alone are not timed and count as serial. */
#ifndef FV_CORE_STAGE_TIME_H
#define FV_CORE_STAGE_TIME_H

#include "fovea/stats.h"

typedef struct fv_stage_clock {
    double wall;     /* fv_time_ms() */
    double parallel; /* fv_region_parallel_ms() */
} fv_stage_clock;

fv_stage_clock fv_stage_clock_now(void);
/* Adds the stage's milliseconds from `from` to `to` and its serial part (clamped to [0, wall]). */
void fv_stage_add(fv_stats *s, const char *stage, fv_stage_clock from, fv_stage_clock to);
/* The same up to now. */
void fv_stage_stop(fv_stats *s, const char *stage, fv_stage_clock from);

#endif
