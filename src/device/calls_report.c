/* fovea — a device frame's runtime calls as --stats-json counters (device/calls_report.h). */
#include "device/calls_report.h"

void fv_backend_calls_report(fv_stats *stats, const fv_backend_calls *before, const fv_backend_calls *after)
{
    fv_stats_add_count(stats, "launches", (double)(after->launches - before->launches));
    fv_stats_add_count(stats, "host_waits", (double)(after->host_waits - before->host_waits));
    fv_stats_add_count(stats, "pageable_copies", (double)(after->pageable_copies - before->pageable_copies));
    fv_stats_add_count(stats, "h2d_bytes", (double)(after->bytes_h2d - before->bytes_h2d));
    fv_stats_add_count(stats, "d2h_bytes", (double)(after->bytes_d2h - before->bytes_d2h));
    fv_stats_add_count(stats, "device_allocs", (double)(after->allocations - before->allocations));
    fv_stats_add_count(stats, "device_frees", (double)(after->frees - before->frees));
}
