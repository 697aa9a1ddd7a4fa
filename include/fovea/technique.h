/* fovea — the technique interface, its parameters and statistics.
 *
 * Every rendering method (the reference path tracer, each foveated technique and each baseline)
 * is an fv_technique_class found by name in the registry. The CLI, the viewer and the benchmark
 * harness drive all of them through this interface only, so comparisons are fair: same scene,
 * same cameras, same gaze, same film. A technique never parses the command line, writes files or
 * exits; it keeps whatever temporal state it needs between frames in its own state object.
 */
#ifndef FOVEA_TECHNIQUE_H
#define FOVEA_TECHNIQUE_H

#include <stdint.h>
#include "fovea/camera.h"
#include "fovea/film.h"
#include "fovea/gaze.h"
#include "fovea/scene.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- parameters: a typed key/value bag validated by each technique's create ---- */

typedef struct fv_params fv_params;

fv_status fv_params_create(fv_params **out, fv_error *err);
void fv_params_destroy(fv_params *p);
/* Sets key to value (both copied; a later set of the same key replaces it). Keys are
 * [a-z0-9_-]+, non-empty. */
fv_status fv_params_set(fv_params *p, const char *key, const char *value, fv_error *err);
/* Parses "key=value". */
fv_status fv_params_parse(fv_params *p, const char *key_eq_value, fv_error *err);
int fv_params_count(const fv_params *p);
const char *fv_params_key(const fv_params *p, int i);
const char *fv_params_value(const fv_params *p, int i);
/* Copy of all entries; `used` marks are not copied. */
fv_status fv_params_clone(const fv_params *p, fv_params **out, fv_error *err);

/* Readers used by techniques: missing key -> def; present but malformed or outside [lo, hi]
 * -> FV_ERR_INVALID naming the key and value. Each read marks the key as used. */
fv_status fv_params_int(fv_params *p, const char *key, int def, int lo, int hi, int *out, fv_error *err);
fv_status fv_params_float(fv_params *p, const char *key, double def, double lo, double hi, double *out,
                          fv_error *err);
fv_status fv_params_bool(fv_params *p, const char *key, bool def, bool *out, fv_error *err);
/* Value must be one of the NULL-terminated `choices`; *out gets its index. */
fv_status fv_params_choice(fv_params *p, const char *key, int def, const char *const *choices, int *out,
                           fv_error *err);
/* After reading: any key never read is an error "unknown parameter 'k' for method 'm'". */
fv_status fv_params_check_used(const fv_params *p, const char *technique, fv_error *err);

/* ---- statistics: named stage timings and counters of one frame ---- */

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

void fv_stats_clear(fv_stats *s);
/* Add to the named entry, creating it on first use (entries beyond FV_STATS_MAX are dropped). */
void fv_stats_add_ms(fv_stats *s, const char *stage, double ms);
void fv_stats_add_count(fv_stats *s, const char *counter, double v);
double fv_stats_get_ms(const fv_stats *s, const char *stage);       /* 0 when absent */
double fv_stats_get_count(const fv_stats *s, const char *counter);  /* 0 when absent */
/* Milliseconds on a monotonic clock. */
double fv_time_ms(void);

/* ---- one frame ---- */

typedef void (*fv_progress_fn)(void *user, double fraction);

typedef struct fv_frame {
    double time;                      /* scene time in seconds; the scene is already set to it */
    int index;                        /* 0 for the first frame of a sequence */
    uint64_t seed;                    /* all randomness derives from (seed, pixel, sample, frame) */
    int threads;                      /* 0: all available */
    const fv_camera *camera;          /* this frame (left eye when stereo) */
    const fv_camera *prev_camera;     /* the previous frame's, NULL on the first frame */
    const fv_camera *camera_right;    /* stereo right eye, NULL when mono */
    const fv_camera *prev_camera_right;
    fv_gaze gaze;                     /* gaze of the (left) eye */
    fv_gaze gaze_right;
    const fv_eye_model *eye;          /* display/eye model for the regions; NULL: fv_eye_model_default
                                         for the film's size */
    fv_progress_fn progress;          /* optional, called with the fraction of the frame done */
    void *progress_user;
} fv_frame;

/* ---- the interface ---- */

typedef struct fv_technique_class {
    const char *name;     /* "pt", "fpm", ... */
    const char *summary;  /* one line */
    const char *params_help; /* lines "key=type (default): meaning" */
    /* Reads and validates its parameters (fv_params_check_used at the end) and prepares state. */
    fv_status (*create)(const fv_scene *scene, fv_params *params, const fv_log *log, void **state,
                        fv_error *err);
    /* Renders one frame into film (and film_right when the frame is stereo). */
    fv_status (*render)(void *state, const fv_frame *frame, fv_film *film, fv_film *film_right,
                        fv_stats *stats, fv_error *err);
    void (*destroy)(void *state);
} fv_technique_class;

/* The first step of every technique's render: the camera's basis, and a check that the camera and
 * the film have the same size. */
fv_status fv_frame_camera(const fv_camera *cam, const fv_film *film, fv_camera_basis *out, fv_error *err);
/* The frame's display/eye model, or when it has none the default one for a width x height film,
 * built in *def. */
const fv_eye_model *fv_frame_eye(const fv_frame *frame, int width, int height, fv_eye_model *def);

int fv_technique_count(void);
const fv_technique_class *fv_technique_at(int i);
/* NULL when unknown. */
const fv_technique_class *fv_technique_find(const char *name);

/* A technique instance: class + state. */
typedef struct fv_technique fv_technique;

/* Unknown name -> FV_ERR_INVALID listing the known ones. */
fv_status fv_technique_create(const char *name, const fv_scene *scene, fv_params *params,
                              const fv_log *log, fv_technique **out, fv_error *err);
fv_status fv_technique_render(fv_technique *t, const fv_frame *frame, fv_film *film, fv_film *film_right,
                              fv_stats *stats, fv_error *err);
const fv_technique_class *fv_technique_class_of(const fv_technique *t);
void fv_technique_destroy(fv_technique *t);

#ifdef __cplusplus
}
#endif
#endif
