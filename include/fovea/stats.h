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
} fv_stats;

FV_API void fv_stats_clear(fv_stats *s);
/* Adds to the named entry, creating it on first use (entries beyond FV_STATS_MAX are dropped). */
FV_API void fv_stats_add_ms(fv_stats *s, const char *stage, double ms);
FV_API void fv_stats_add_count(fv_stats *s, const char *counter, double v);
/* 0 when absent. */
FV_API double fv_stats_get_ms(const fv_stats *s, const char *stage);
FV_API double fv_stats_get_count(const fv_stats *s, const char *counter);
/* Milliseconds on a monotonic clock (thread-safe). */
FV_API double fv_time_ms(void);

#ifdef __cplusplus
}
#endif
#endif
