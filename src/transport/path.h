/* fovea — the path tracing kernel shared by every technique that traces camera paths: `pt` (the
 * reference), the trace stage of `vpolar` and its baselines, and any family that needs a path
 * traced estimate. One integrator, so the reference and the foveated methods never drift apart.
 * The estimator is kernel/kpath_impl.h, the same source as the GPU's (kernel/kpt.h); its options
 * and first-hit record are kernel/kpath.h.
 */
#ifndef FV_TRANSPORT_PATH_H
#define FV_TRANSPORT_PATH_H

#include <stdbool.h>
#include <stdint.h>
#include "core/rng.h"
#include "fovea/params.h"
#include "kernel/kpath.h"
#include "scene/query.h"

/* Reads spp (16), max_depth (8), rr_depth (3) from params, marking them used. */
fv_status fv_path_read_opts(fv_params *p, fv_path_opts *opt, fv_error *err);

/* Radiance arriving at o from direction d (unit). first (optional) receives the first hit;
 * *rays (optional) is increased by the number of rays cast. */
fv_vec3 fv_path_trace(const fv_scene *s, const fv_path_opts *opt, fv_vec3 o, fv_vec3 d, fv_rng *rng, fv_path_first_hit *first,
                      uint64_t *rays);
/* The same when the first hit is already known (pre; pre_ok false: the ray missed), as for
 * camera rays traced in packets. */
fv_vec3 fv_path_trace_from(const fv_scene *s, const fv_path_opts *opt, fv_vec3 o, fv_vec3 d, const fv_hit *pre, bool pre_ok,
                           fv_rng *rng, fv_path_first_hit *first, uint64_t *rays);

#endif
