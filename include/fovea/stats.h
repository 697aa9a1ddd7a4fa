/* fovea — what one frame cost: named stage timings (milliseconds) and counters (rays, photons,
 * NaN samples dropped, ...), filled by the technique that rendered it.
 *
 * An fv_stats is a plain caller-owned struct (no allocation); not thread-safe.
 */
#ifndef FOVEA_STATS_H
#define FOVEA_STATS_H

#include "fovea/export.h"

#ifdef __cplusplus
extern "C" {
#endif

#define FV_STATS_MAX 32
typedef struct fv_stat_entry {
    char name[32];
    double value;
} fv_stat_entry;

typedef struct fv_stats {
    int n_stages, n_counters;
    fv_stat_entry stage[FV_STATS_MAX];   /* milliseconds */
    fv_stat_entry counter[FV_STATS_MAX]; /* counts (rays, photons, NaN samples, ...) */
    /* Serial milliseconds of a stage, by the stage's name: the part of its time spent outside
     * parallel regions or in a region's one-thread part (docs/threads.md), what limits its scaling
     * on many cores. Only stages the technique timed with the region clock have one. */
    int n_serial;
    fv_stat_entry serial[FV_STATS_MAX];
} fv_stats;

FV_API void fv_stats_clear(fv_stats *s);
/* Adds to the named entry, creating it on first use (entries beyond FV_STATS_MAX are dropped). */
FV_API void fv_stats_add_ms(fv_stats *s, const char *stage, double ms);
FV_API void fv_stats_add_count(fv_stats *s, const char *counter, double v);
/* Adds to a stage's serial milliseconds (see serial above). */
FV_API void fv_stats_add_serial_ms(fv_stats *s, const char *stage, double ms);
/* 0 when absent. */
FV_API double fv_stats_get_ms(const fv_stats *s, const char *stage);
FV_API double fv_stats_get_count(const fv_stats *s, const char *counter);
/* The stage's serial milliseconds; -1 when the stage has none measured. */
FV_API double fv_stats_get_serial_ms(const fv_stats *s, const char *stage);
/* Milliseconds on a monotonic clock (thread-safe). */
FV_API double fv_time_ms(void);

#ifdef __cplusplus
}
#endif
#endif
