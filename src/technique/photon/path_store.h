/* fovea — light photon paths traced once through the static objects and kept, each frame's photon
 * map made from them with only the paths a dynamic object may change traced again (fpm-guided,
 * docs/photon-mapping.md).
 *
 * pm-t (the paper's temporal strategy) keeps the static photons and corrects them with positive
 * and negative photons sent towards the dynamic objects from the lights; light that reaches a
 * dynamic object after a bounce is never corrected, and the negative photons add noise where they
 * cancel. Here every kept path remembers its segments. A path none of whose segments meets a
 * dynamic object's bounding sphere is the path the whole scene would give with the same random
 * numbers, so its photons are kept; the others are traced again through the whole scene, from the
 * same numbers. The frame's map is therefore exactly the map a full trace of the current scene
 * would give (bit for bit: tests/unit/test_fpm_guided.c), at the cost of the paths near the moving
 * objects.
 */
#ifndef FV_PHOTON_PATH_STORE_H
#define FV_PHOTON_PATH_STORE_H

#include "technique/photon/photon_trace.h"

typedef struct fv_path_store fv_path_store;

fv_status fv_path_store_create(fv_path_store **out, fv_error *err);
void fv_path_store_destroy(fv_path_store *p);

/* Traces job->count photon paths (fv_photon_emit, then the walk of transport/light_path.h) through
 * the static objects and keeps their photons and segments, replacing what the store held. The job
 * is remembered (its warp context must stay as it is while the store is used). */
fv_status fv_path_store_trace(fv_path_store *p, const fv_photon_job *job, uint64_t *rays, fv_error *err);
/* True once a trace has completed. */
bool fv_path_store_ready(const fv_path_store *p);
/* A factor on a path's flux from the numbers its emission used (multiple importance sampling of
 * two photon sets, guided.c). */
typedef float (*fv_path_scale_fn)(const void *ctx, const float u[5]);

/* This frame's photons appended to out (not cleared, not built): each kept path's own, or, for a
 * path that meets one of the spheres of dirs (the dynamic objects now; NULL: none), the photons of
 * the same path traced again through the whole scene at its current time; each path's flux times
 * scale(u) when scale is given. *retraced gets how many paths were traced again. */
fv_status fv_path_store_frame(fv_path_store *p, const fv_dyn_dirs *dirs, fv_path_scale_fn scale, const void *scale_ctx,
                              int threads, fv_photon_map *out, int64_t *retraced, uint64_t *rays, fv_error *err);

#endif
