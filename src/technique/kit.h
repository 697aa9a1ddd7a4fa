/* fovea — the per-pixel kit every technique starts from: the seeding convention, the NaN/Inf guard
 * that counts what it drops, per-thread counters without false sharing, and progress with cancel
 * for a technique's phases. pt, vpolar's trace stage and the photon mappers use it; a new family
 * takes it as is, so its images are deterministic and its stats speak the same names.
 */
#ifndef FV_TECHNIQUE_KIT_H
#define FV_TECHNIQUE_KIT_H

#include <stdbool.h>
#include <stdint.h>
#include "core/parallel.h"
#include "core/rng.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/math.h"
#include "fovea/stats.h"
#include "fovea/status.h"
#include "kernel/kpath.h"

/* ---- the frame ---- */

/* The first step of every render: the camera's basis, and a check that camera and film agree. */
fv_status fv_frame_camera(const fv_camera *cam, const fv_film *film, fv_camera_basis *out, fv_error *err);
/* The frame's display/eye model, or when it has none the default one for a width x height film,
 * built in *def. */
const fv_eye_model *fv_frame_eye_model(const fv_frame *frame, int width, int height, fv_eye_model *def);
/* Whether the eye model's fovea, seen from the frame's gaze, holds every pixel centre of a width x
 * height film: the frame of a gaze the driver marks missing under `--gaze-missing widen`
 * (fv_eye_model_whole_screen, docs/gaze.md). A foveated method then spends on every pixel what it
 * spends on its fovea, whatever its own foveal parameters say. False for every ordinary eye model
 * (its fovea is a part of the screen). */
bool fv_frame_fovea_covers(const fv_frame *frame, const fv_eye_model *eye, int width, int height);

/* ---- seeding ---- */

/* The camera stream of sample `sample` of pixel `pixel` (row-major index in whatever grid the
 * technique samples) for this frame and eye: the eye is folded into the pixel index so both eyes
 * get independent noise, the frame index decorrelates frames. */
static inline fv_rng fv_kit_rng(const fv_frame *f, uint64_t pixel, uint64_t sample)
{
    return fv_rng_stream(f->seed, FV_STREAM_CAMERA, pixel * 2 + (uint64_t)f->eye, sample, (uint64_t)f->index);
}

/* ---- per-thread counters ---- */

/* Slots every technique shares, then slots a technique names for itself. */
enum {
    FV_KIT_RAYS = 0,  /* reported as "rays" */
    FV_KIT_NAN,       /* samples the guard dropped: "nan_samples" */
    FV_KIT_USER0,
    FV_KIT_USER1,
    FV_KIT_USER2,
    FV_KIT_USER3,
    FV_KIT_USER4,
    FV_KIT_USER5,
    FV_KIT_SLOTS = 8
};

/* One thread's counters fill exactly one cache line, so threads never write the same line. */
typedef struct fv_kit_thread_counts {
    _Alignas(64) uint64_t c[FV_KIT_SLOTS];
} fv_kit_thread_counts;

typedef struct fv_kit_counters {
    fv_kit_thread_counts t[FV_MAX_THREADS];
} fv_kit_counters;

/* Counters live on the heap (they are 16 KiB): create zeroed, destroy. */
fv_kit_counters *fv_kit_counters_create(void);
void fv_kit_counters_destroy(fv_kit_counters *k);
/* A frame's counters from a block its technique keeps (*keep, created on first use, zeroed on every
 * later one), so that a warmed-up frame allocates nothing (docs/threads.md, "No allocation in a
 * frame"); NULL when out of memory. The technique destroys *keep with its state. */
fv_kit_counters *fv_kit_counters_reuse(fv_kit_counters **keep);
static inline void fv_kit_count(fv_kit_counters *k, int thread, int slot, uint64_t v) { k->t[thread].c[slot] += v; }
uint64_t fv_kit_sum(const fv_kit_counters *k, int slot);
/* Adds "rays" and "nan_samples" to stats (the latter even when zero, so it is always reported). */
void fv_kit_report(const fv_kit_counters *k, fv_stats *stats);

/* ---- the NaN/Inf guard ---- */

/* A radiance estimate that is not finite is replaced by black and counted in *dropped, so one bad
 * path never poisons a pixel, a filter or a reference, and the stats say how many there were. */
static inline fv_vec3 fv_kit_guard(fv_vec3 L, uint64_t *dropped) { return fv_path_guard(L, dropped); }

/* ---- progress and cancel ---- */

/* A phase of a frame's work: reports base + span * fraction of the eye's work to the frame's
 * callback, and remembers a cancel. Start from a zeroed struct, call fv_kit_phase before each
 * phase, and pass fv_kit_progress_fn with it to fv_parallel_tiles. */
typedef struct fv_kit_progress {
    const fv_frame *frame;
    double base, span;
    bool cancelled;
} fv_kit_progress;

void fv_kit_phase(fv_kit_progress *p, const fv_frame *frame, double base, double span);
bool fv_kit_progress_fn(void *user, double fraction);
/* Reports the end of the phase; false (and FV_ERR_CANCELLED in err) when the render must stop. */
fv_status fv_kit_phase_end(fv_kit_progress *p, fv_error *err);

#endif
