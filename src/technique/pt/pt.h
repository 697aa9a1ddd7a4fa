/* fovea — the path tracing kernel, exposed so other techniques (Visual-Polar path tracing, the
 * baselines) reuse the same integrator instead of copying it. */
#ifndef FV_TECHNIQUE_PT_H
#define FV_TECHNIQUE_PT_H

#include "core/rng.h"
#include "fovea/technique.h"
#include "scene/scene_impl.h"

typedef struct fv_pt_options {
    int spp;
    int max_depth;
    int rr_depth;
} fv_pt_options;

/* What the first hit of a camera path saw, for the film's auxiliary buffers. */
typedef struct fv_pt_first_hit {
    bool hit;
    float t;
    fv_vec3 p, n, albedo;
    int obj;
} fv_pt_first_hit;

/* Reads spp, max_depth, rr_depth from params (marking them used). */
fv_status fv_pt_read_options(fv_params *p, fv_pt_options *opt, fv_error *err);

/* Radiance arriving at o from direction d (unit). first (optional) receives the first hit;
 * *rays (optional) is increased by the number of rays cast. */
fv_vec3 fv_pt_trace(const fv_scene *s, const fv_pt_options *opt, fv_vec3 o, fv_vec3 d, fv_rng *rng,
                    fv_pt_first_hit *first, uint64_t *rays);
/* The same when the first hit is already known (pre; pre_ok false: the ray missed), as for
 * camera rays traced in packets. */
fv_vec3 fv_pt_trace_from(const fv_scene *s, const fv_pt_options *opt, fv_vec3 o, fv_vec3 d, const fv_hit *pre, bool pre_ok, fv_rng *rng,
                         fv_pt_first_hit *first, uint64_t *rays);

#endif
