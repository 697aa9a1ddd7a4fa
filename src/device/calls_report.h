/* fovea — a device frame's runtime calls (fv_backend_calls, device/backend.h) as --stats-json
 * counters. The counts come from the backend's own calls, so they read the same on a GPU and on
 * the CUDA simulator; the families report them for cuda only (the CPU's stats stay as they were). */
#ifndef FV_DEVICE_CALLS_REPORT_H
#define FV_DEVICE_CALLS_REPORT_H

#include "device/backend.h"
#include "fovea/stats.h"

/* Adds after - before to stats as the counters launches, host_waits, pageable_copies, h2d_bytes,
 * d2h_bytes, device_allocs and device_frees. */
void fv_backend_calls_report(fv_stats *stats, const fv_backend_calls *before, const fv_backend_calls *after);

#endif
