/* fovea — the sequence driver: from a scene, the view data its file carried and the caller's
 * choices to the frames every technique renders. `fovea render`, `fovea bench` and the viewer all
 * build their frames here, so a comparison never depends on which tool made it. The policy, in
 * one place:
 *
 *   time    frame i is at time0 + i / fps;
 *   camera  the view's camera (or one framing the scene), moved along the view's camera path;
 *           then along the options' camera path (a CSV trace, a scenario's path) whose keys take
 *           what they lack from that camera; then the options' overrides (position, look-at, up,
 *           field of view);
 *   stereo  two eyes eye_separation apart (fv_camera_stereo), left rendered first;
 *   gaze    a fixed gaze when set, else the options' gaze path, else the view's, else the centre
 *           (a path may give the right eye its own gaze); while the path says the gaze is
 *           unknown (a blink, track loss), the options' policy, else the path's: hold the last
 *           known gaze, or widen (the gaze at the centre and fv_eye_model_whole_screen);
 *   eye     the options' eye model when given (a scenario's), else the view's display with its
 *           density rescaled to the image width (the regions cover the same part of the view),
 *           else the default model for the image size;
 *   seed    every frame of a driver uses the options' seed (frame index and eye decorrelate);
 *   warm-up the options' warm-up frames come before frame 0, at frame 0's views, and shift the
 *           index every frame's technique sees (fv_driver_warm_up).
 *
 * Lifetime: the scene, the view and whatever the options point to must outlive the driver. A
 * driver is not thread-safe; it renders one frame at a time.
 */
#ifndef FOVEA_DRIVE_H
#define FOVEA_DRIVE_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/camera.h"
#include "fovea/export.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/gaze.h"
#include "fovea/scene.h"
#include "fovea/stats.h"
#include "fovea/technique.h"
#include "fovea/view.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { FV_DRIVE_POS = 1, FV_DRIVE_LOOK = 2, FV_DRIVE_UP = 4, FV_DRIVE_FOV = 8 };

/* The most warm-up frames a driver renders before frame 0. */
#define FV_DRIVE_MAX_WARMUP 1000

typedef struct fv_drive_opts {
    int width, height;                 /* image size per eye */
    double time0, fps;                 /* frame i at time0 + i / fps */
    uint64_t seed;
    int threads;                       /* 0: all cores */
    float eye_separation;              /* > 0: stereo pairs; 0: mono */
    const fv_camera_path *camera_path; /* optional: moves the view's camera further */
    unsigned camera_set;               /* FV_DRIVE_* bits: which of the next fields replace the camera's */
    fv_vec3 pos, look, up;
    float fov_y;
    bool fixed_gaze;                   /* gaze below for every frame and eye */
    fv_gaze gaze;
    const fv_gaze_path *gaze_path;     /* optional: replaces the view's gaze path */
    fv_gaze_missing gaze_missing;      /* while the path's gaze is unknown; PATH (0): the path's policy */
    const fv_eye_model *eye_model;     /* optional: replaces the view's display */
    /* Frames a technique renders before frame 0, unwritten, at frame 0's views
     * (fv_driver_warm_up): a method with temporal state (SVGF's history) then shows frame 0
     * converged. Every frame's index as the technique sees it (fv_frame.index, its random
     * streams) is shifted by this count, so that warm-up frames are 0 .. warmup - 1. */
    int warmup;
} fv_drive_opts;

/* Defaults: 512x512, time 0, 30 fps, seed 1, all threads, mono, nothing overridden. */
FV_API void fv_drive_opts_init(fv_drive_opts *o);

typedef struct fv_driver fv_driver;

/* Checks the options (size, fps, separation) and fixes the eye model. view may be NULL. Release
 * with fv_driver_destroy. */
FV_API fv_status fv_driver_create(fv_scene *scene, const fv_view *view, const fv_drive_opts *opts, fv_driver **out, fv_error *err);
/* NULL is ignored. */
FV_API void fv_driver_destroy(fv_driver *d);

/* What frame `index` looks like, without rendering it. */
typedef struct fv_frame_views {
    double time;
    int eye_count;
    fv_camera camera[2];
    fv_gaze gaze[2];
    bool gaze_known;                /* false while the gaze path marks the gaze missing */
    const fv_eye_model *eye_model;  /* the frame's: the driver's, or its whole-screen widening */
} fv_frame_views;
FV_API void fv_driver_views(const fv_driver *d, int index, fv_frame_views *out);
/* The views a continuing render of frame `index` hands its technique as the previous frame's
 * (fv_frame.prev_camera): those frame index - 1 was actually rendered with when it was the last
 * frame this driver rendered, since a camera set since then (fv_driver_set_camera) must not
 * rewrite the past; otherwise derived as fv_driver_views(index - 1) (index 0: frame 0). */
FV_API void fv_driver_prev_views(const fv_driver *d, int index, fv_frame_views *out);
/* The eye model every frame uses (lives as long as the driver). */
FV_API const fv_eye_model *fv_driver_eye_model(const fv_driver *d);
FV_API int fv_driver_eye_count(const fv_driver *d);
/* From now on every frame uses gaze g for both eyes (the viewer's mouse or eye tracker). */
FV_API void fv_driver_set_gaze(fv_driver *d, fv_gaze g);
/* From now on every frame uses camera c's position, look-at point, up vector and field of view
 * (the viewer's flying camera); its size is ignored (the driver's). Not validated here: a bad
 * camera fails the next render with the camera's message. */
FV_API void fv_driver_set_camera(fv_driver *d, const fv_camera *c);

/* Renders frame `index` with technique t: sets the scene's time, then renders eye 0 (and eye 1)
 * into films[0] (and films[1]), adding both eyes' stats to *stats. A stereo driver given no
 * films[1] renders the left eye alone, as a mono frame at the left eye's view. `continues`: t's previous
 * render was frame index - 1 of this driver, so its history reprojects from that frame's cameras;
 * false starts a new sequence. progress (optional) receives the fraction of the whole frame and
 * may cancel it (FV_ERR_CANCELLED). */
FV_API fv_status fv_driver_render(fv_driver *d, fv_technique *t, int index, bool continues, fv_film *const *films, fv_stats *stats,
                                  fv_progress_fn progress, void *progress_user, fv_error *err);
/* Frame `index` as fv_driver_render takes it, queued rather than rendered (fv_technique_submit):
 * on a device it returns before the frame has run, so that a sequence submits frame N+1 before it
 * collects frame N (two sets of films and stats, each alive and unread until collected). Progress
 * is reported, and may cancel, within the submit. A cancelled or failed submit leaves nothing of
 * its frame in flight; the frames before it stay collectable. */
FV_API fv_status fv_driver_submit(fv_driver *d, fv_technique *t, int index, bool continues, fv_film *const *films, fv_stats *stats,
                                  fv_progress_fn progress, void *progress_user, fv_error *err);
/* Waits for the oldest frame submitted with t and delivers it into the films and stats it was
 * submitted with (fv_technique_collect). */
FV_API fv_status fv_driver_collect(fv_driver *d, fv_technique *t, fv_error *err);
/* Renders the options' warm-up frames with technique t, each at frame 0's views, into films
 * (their pixels are then the last warm-up frame's); a later fv_driver_render(index 0, continues
 * true) goes on from them. Nothing happens when the count is 0. progress (optional) receives the
 * fraction of all warm-up frames and may cancel them. */
FV_API fv_status fv_driver_warm_up(fv_driver *d, fv_technique *t, fv_film *const *films, fv_stats *stats, fv_progress_fn progress,
                                   void *progress_user, fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
