/* fovea CLI — the --stats-json log of `fovea render`: every frame's stage timings and counters
 * (each image's metadata is drive/frame_meta.h's). */
#ifndef FV_CLI_RENDER_RECORD_H
#define FV_CLI_RENDER_RECORD_H

#include "cli.h"
#include "drive/frame_meta.h"

/* The --stats-json log: frames are added as they finish; written whole (atomically) at the end. */
typedef struct fv_stats_log fv_stats_log;
fv_status fv_stats_log_create(const fv_frame_meta_run *run, fv_stats_log **out, fv_error *err);
void fv_stats_log_destroy(fv_stats_log *log);
fv_status fv_stats_log_add(fv_stats_log *log, int frame, const fv_frame_views *v, double ms, const fv_stats *stats, fv_error *err);
/* `complete`: every asked-for frame was rendered (false after an interruption or an error). */
fv_status fv_stats_log_write(fv_stats_log *log, const char *path, bool complete, fv_error *err);

#endif
