/* fovea — the per-pixel kit's out-of-line parts (see kit.h). */
#include <stdlib.h>
#include <string.h>
#include "technique/kit.h"

fv_kit_counters *fv_kit_counters_create(void)
{
    /* sizeof is a multiple of the 64-byte alignment, as aligned_alloc requires */
    fv_kit_counters *k = aligned_alloc(64, sizeof *k);
    if (k) memset(k, 0, sizeof *k);
    return k;
}

void fv_kit_counters_destroy(fv_kit_counters *k) { free(k); }

fv_kit_counters *fv_kit_counters_reuse(fv_kit_counters **keep)
{
    if (*keep) memset(*keep, 0, sizeof **keep);
    else *keep = fv_kit_counters_create();
    return *keep;
}

uint64_t fv_kit_sum(const fv_kit_counters *k, int slot)
{
    uint64_t s = 0;
    for (int i = 0; i < FV_MAX_THREADS; i++) s += k->t[i].c[slot];
    return s;
}

void fv_kit_report(const fv_kit_counters *k, fv_stats *stats)
{
    fv_stats_add_count(stats, "rays", (double)fv_kit_sum(k, FV_KIT_RAYS));
    fv_stats_add_count(stats, "nan_samples", (double)fv_kit_sum(k, FV_KIT_NAN));
}

void fv_kit_phase(fv_kit_progress *p, const fv_frame *frame, double base, double span)
{
    p->frame = frame;
    p->base = base;
    p->span = span; /* a cancel seen in an earlier phase stays */
}

bool fv_kit_progress_fn(void *user, double fraction)
{
    fv_kit_progress *p = user;
    if (p->cancelled) return false;
    if (p->frame && p->frame->progress && !p->frame->progress(p->frame->progress_user, p->base + p->span * fraction))
        p->cancelled = true;
    return !p->cancelled;
}

fv_status fv_kit_phase_end(fv_kit_progress *p, fv_error *err)
{
    if (!fv_kit_progress_fn(p, 1.0)) return fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    return FV_OK;
}
