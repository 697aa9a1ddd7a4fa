/* fovea — the light photon maps of the temporal strategy (pm-t, the paper's PM^t after its
 * ref. [43]), shared by pm-t, fpm and fpm-guided: the static map M_ls traced once through the
 * static objects and kept for every frame, the dynamic map M_ld (positive and negative photons
 * towards the dynamic objects, photon_trace.h) traced every frame.
 *
 * Moving lights relight static surfaces, so with them M_ls is retraced every frame.
 */
#ifndef FV_TECHNIQUE_PHOTON_PM_TEMPORAL_H
#define FV_TECHNIQUE_PHOTON_PM_TEMPORAL_H

#include <math.h>
#include <stdbool.h>
#include "fovea/stats.h"
#include "technique/photon/photon_trace.h"

typedef struct fv_pmt_maps {
    fv_photon_map ls, ld;
    bool ls_done;         /* M_ls holds this scene's static photons */
    bool lights_move;     /* the scene's lights move: M_ls is retraced every frame */
    fv_dyn_dirs *dirs;
} fv_pmt_maps;

fv_status fv_pmt_maps_init(fv_pmt_maps *m, const fv_scene *s, fv_error *err);
void fv_pmt_maps_free(fv_pmt_maps *m);

/* This frame's light photons: n_light photons (job->count is ignored), dyn_fraction of them towards the dynamic objects
 * when the scene has any (M_ld, every frame), the rest static (M_ls, traced when missing or when
 * the lights move). job->stream and job->frame are set here. Both maps are built into grids of
 * `cell`. Adds "light_photons" and "dynamic_photons" to stats and the rays cast to *rays. A
 * cancelled trace leaves no half map behind. */
fv_status fv_pmt_maps_update(fv_pmt_maps *m, const fv_photon_job *job, double n_light, double dyn_fraction, float cell, fv_stats *stats,
                             uint64_t *rays, fv_error *err);

/* Eq. 4's k: how much of M_ld's estimate joins M_ls's at a pixel, from the u sums of the dynamic
 * (num) and static (den) photons gathered there, W = min(num / den, 1) smoothed as 3W^2 - 2W^3.
 * The estimate is then sum(M_ls) + k sum(M_ld) (our reading of Eq. 3-5, pm.c). */
static inline float fv_pmt_blend_k(double num, double den)
{
    double w = den > 0.0 ? fmin(num / den, 1.0) : (num > 0.0 ? 1.0 : 0.0);
    return (float)(3.0 * w * w - 2.0 * w * w * w);
}

#endif
