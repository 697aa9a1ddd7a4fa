/* fovea — what one frame was made of, as the metadata written into its image (fovea/film.h:
 * fv_image_write_meta; the keys are listed in docs/metrics.md). `fovea render` and the bench both
 * write it, so any image fovea renders says how it was made. */
#ifndef FV_DRIVE_FRAME_META_H
#define FV_DRIVE_FRAME_META_H

#include "fovea/drive.h"
#include "fovea/params.h"

/* What is the same for every frame of one run. */
typedef struct fv_frame_meta_run {
    const char *method, *scene;
    const fv_params *params;
    int width, height, threads;
    unsigned long long seed;
    float exposure;
    int warmup; /* frames rendered at frame 0's views before frame 0 (fv_drive_opts.warmup) */
} fv_frame_meta_run;

/* The metadata of eye `eye` of frame `frame` (its views from fv_driver_views) into a new bag *out;
 * render_ms < 0 leaves the render time out (a reference read from the cache). */
fv_status fv_frame_meta(const fv_frame_meta_run *run, int frame, const fv_frame_views *v, int eye, double render_ms,
                        fv_params **out, fv_error *err);

/* Marks a frame's metadata as drawn over (key `overlay`: `fovea render --overlay` drew the eye
 * model's rings and the gaze cross on its pixels): `fovea compare` refuses such an image, whose
 * pixels are no longer what was rendered. Written even under --no-metadata, as the one key. */
fv_status fv_frame_meta_overlay(fv_params *meta, fv_error *err);

#endif
