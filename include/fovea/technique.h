/* fovea — rendering methods: the reference path tracer, each foveated technique and each baseline,
 * found by name in a registry and driven through one interface.
 *
 * The CLI, the viewer and the benchmark harness drive every method through these calls only (via
 * the sequence driver, fovea/drive.h), so comparisons are fair: same scene, cameras, gaze and film.
 * A method keeps its temporal state (photon maps, history buffers) in its instance between frames.
 *
 * Lifetime: the scene must outlive every technique created on it, and must not be changed (except
 * by fv_scene_set_time between renders) while one renders. Thread-safety: one instance renders one
 * frame at a time; different instances on the same scene may render concurrently.
 *
 * The technique class is private to the library (docs/architecture.md says why): new methods are
 * added in src/technique/ and listed in its registry.
 */
#ifndef FOVEA_TECHNIQUE_H
#define FOVEA_TECHNIQUE_H

#include "fovea/export.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/params.h"
#include "fovea/scene.h"
#include "fovea/stats.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The registry, in a fixed order: name ("pt", "fpm", ...), one-line summary, and the parameter
 * help (lines "key=type (default): meaning"). NULL for i out of range. Static strings. */
FV_API int fv_technique_count(void);
FV_API const char *fv_technique_name(int i);
FV_API const char *fv_technique_summary(int i);
FV_API const char *fv_technique_params_help(int i);
/* Index of a method by name, -1 when unknown. */
FV_API int fv_technique_index(const char *name);
/* The key of method i's samples-per-pixel parameter ("spp" for pt), NULL when the method has no
 * such notion (or i is out of range). */
FV_API const char *fv_technique_spp_param(int i);
/* Whether method i spends less effort away from the gaze (its image depends on the gaze); false
 * for an index out of range. */
FV_API bool fv_technique_foveated(int i);
/* Frames method i renders before a still (or a sequence's first frame) is converged: `fovea
 * render` runs them unwritten at frame 0's views (fv_drive_opts.warmup). 0 for a method whose
 * first frame is already its steady state, and for an index out of range. */
FV_API int fv_technique_still_warmup(int i);
/* Frames of a sequence a method with state between frames needs before a frame matches the one
 * an uninterrupted sequence renders (a block of a sequence split over MPI ranks starts that many
 * frames early, docs/distributed.md). 0 for a method without such state or an index out of range. */
FV_API int fv_technique_sequence_warmup(int i);
/* Sets method `name`'s samples-per-pixel parameter to spp in params (what the CLI's --spp means
 * for every method). FV_ERR_INVALID, with a one-line message naming the parameter to use instead,
 * when the method has none; the message of fv_technique_create when the name is unknown. */
FV_API fv_status fv_technique_set_spp(const char *name, fv_params *params, int spp, fv_error *err);

typedef struct fv_technique fv_technique;

/* Creates method `name` on a committed scene with parameters (NULL: defaults; read, not kept).
 * Unknown name, unknown parameter key or bad value -> FV_ERR_INVALID naming it. Release with
 * fv_technique_destroy, before the scene. log (may be NULL) receives warnings. */
FV_API fv_status fv_technique_create(const char *name, const fv_scene *scene, const fv_params *params, const fv_log *log,
                                     fv_technique **out, fv_error *err);
/* Renders one eye of one frame into film (its size must match the frame's camera). Stats are
 * added to *stats (not cleared). FV_ERR_CANCELLED when the frame's progress callback asked so;
 * the film's contents are then undefined. */
FV_API fv_status fv_technique_render(fv_technique *t, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
/* The method's registry name (a static string). */
FV_API const char *fv_technique_name_of(const fv_technique *t);
/* NULL is ignored. */
FV_API void fv_technique_destroy(fv_technique *t);

#ifdef __cplusplus
}
#endif
#endif
