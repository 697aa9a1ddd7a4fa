/* fovea CLI — what `fovea render` records about its frames: the metadata written into each image
 * (fovea/film.h: fv_film_write_meta) and the --stats-json log of every frame's stage timings and
 * counters. */
#ifndef FV_CLI_RENDER_RECORD_H
#define FV_CLI_RENDER_RECORD_H

#include "cli.h"

/* What is the same for every frame of one run. */
typedef struct fv_render_record_run {
    const char *method, *scene;
    const fv_params *params;
    int width, height, threads;
    unsigned long long seed;
    float exposure;
} fv_render_record_run;

/* The metadata of eye `eye` of a frame (views from fv_driver_views) into a new bag *out. */
fv_status fv_render_meta(const fv_render_record_run *run, int frame, const fv_frame_views *v, int eye, double render_ms,
                         fv_params **out, fv_error *err);

/* The --stats-json log: frames are added as they finish; written whole (atomically) at the end. */
typedef struct fv_stats_log fv_stats_log;
fv_status fv_stats_log_create(const fv_render_record_run *run, fv_stats_log **out, fv_error *err);
void fv_stats_log_destroy(fv_stats_log *log);
fv_status fv_stats_log_add(fv_stats_log *log, int frame, const fv_frame_views *v, double ms, const fv_stats *stats, fv_error *err);
/* `complete`: every asked-for frame was rendered (false after an interruption or an error). */
fv_status fv_stats_log_write(fv_stats_log *log, const char *path, bool complete, fv_error *err);

#endif
