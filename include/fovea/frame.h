/* fovea — one eye of one frame: what a technique renders (time, cameras, gaze, eye model, seed).
 *
 * The sequence driver (fovea/drive.h) fills frames for the CLI, the benchmark harness and the
 * viewer; a C user who drives a technique by hand starts from fv_frame_init. A stereo frame is two
 * calls of fv_technique_render, eye 0 (left) then eye 1 (right), with the same index and time, or
 * one call of fv_technique_render_pair with both (what the driver does).
 * A frame only points at cameras and the eye model: they must outlive the render call.
 */
#ifndef FOVEA_FRAME_H
#define FOVEA_FRAME_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/camera.h"
#include "fovea/export.h"
#include "fovea/gaze.h"
#include "fovea/progress.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_frame {
    double time;                  /* scene time in seconds; the scene is already set to it */
    int index;                    /* 0 for the first frame of a sequence */
    uint64_t seed;                /* all randomness derives from (seed, pixel, sample, frame) */
    int threads;                  /* 0: all available */
    int eye;                      /* 0: mono or the left eye; 1: the right eye of a stereo pair */
    int eye_count;                /* 1 mono, 2 stereo */
    const fv_camera *camera;      /* this eye's camera */
    const fv_camera *prev_camera; /* this eye's camera in the previous frame, NULL on the first */
    const fv_camera *left_camera; /* right eye only: the left eye's camera of this frame, whose
                                     result a technique may reproject; NULL otherwise */
    fv_gaze gaze;                 /* this eye's gaze */
    const fv_eye_model *eye_model;/* display/eye model for the regions; NULL: the default one for
                                     the film's size */
    fv_progress_fn progress;      /* optional */
    void *progress_user;
} fv_frame;

/* A mono first frame at time 0, seed 1, all threads, gaze at the centre, for `camera`. */
FV_API void fv_frame_init(fv_frame *frame, const fv_camera *camera);

#ifdef __cplusplus
}
#endif
#endif
