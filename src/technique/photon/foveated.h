/* fovea — foveated photon tracing and temporal photon management (Foveated Photon Mapping,
 * Alg. 1 line 9, Sec. 3.1, Fig. 2, and Alg. 2, Sec. 3.2).
 *
 * Foveated photon paths start at the eye and pass through pixels of the focus region (fovea and
 * transition). Mirrors and glass redirect them by the laws of reflection and refraction; at a
 * diffuse or glossy hit the nearest light photon decides: if its flux is positive the path goes on
 * in the reverse of that photon's incident direction (towards where its light came from), if it
 * is negative, or there is none, the path stops there. Russian roulette ends paths; a path that
 * would exceed the maximum depth is removed whole. The photon at the path's end takes the flux of
 * its nearest light photon and hands it back along the path as ordinary photon transport would
 * (times the albedo of each diffuse vertex, times the mirror/glass weights in between). Each
 * foveated photon records `nextf` (the next one along the path) and `nearl` (its nearest positive
 * light photon).
 *
 * Static paths (no vertex on a dynamic object, every nearest light photon from M_ls) go to M_fs and
 * are remembered per pixel (fbp); the others go to M_fd, which is rebuilt every frame. fbm counts
 * the paths a pixel still needs. Between frames, Alg. 2 carries each focus pixel's paths over from
 * the pixel it came from (back-projection with the current camera, projection with the previous
 * one) when it shows a static diffuse surface, and deletes them otherwise; paths of pixels that
 * left the focus region are deleted too, so memory stays bounded. Limits: one eye (the right eye is
 * reprojected by the technique); N is fixed at the first frame.
 */
#ifndef FV_PHOTON_FOVEATED_H
#define FV_PHOTON_FOVEATED_H

#include "fovea/camera.h"
#include "fovea/gaze.h"
#include "technique/photon/photon_map.h"
#include "scene/query.h"

#define FV_FOV_MAX_DEPTH 16

typedef struct fv_fov_photon {
    fv_photon p;
    int32_t nextf;   /* index of the next foveated photon along the path, -1 at its end */
    int32_t nearl;   /* index of the nearest light photon with positive flux in its map */
    uint8_t nearl_map; /* 0: M_ls, 1: M_ld */
} fv_fov_photon;

typedef struct fv_fov_stats {
    long paths_traced, paths_stored_static, paths_dynamic, paths_failed, paths_reused, paths_deleted;
    long photons_static, photons_dynamic;
} fv_fov_stats;

typedef struct fv_foveated fv_foveated;

/* For an image of width x height; n_paths = N paths per focus pixel; max_depth <= 16. */
fv_status fv_foveated_create(int width, int height, int n_paths, int max_depth, fv_foveated **out, fv_error *err);
void fv_foveated_destroy(fv_foveated *f);

/* Alg. 2: carries the paths over from the previous frame. Call every frame before tracing; with
 * prev == NULL (the first frame, or fpm's tpm=false) every old path is deleted and all are traced
 * anew. */
fv_status fv_foveated_manage(fv_foveated *f, const fv_scene *s, const fv_camera *cam, const fv_camera *prev,
                             const fv_eye_model *eye, fv_gaze gaze, int threads, fv_fov_stats *st, fv_error *err);

/* Alg. 1 line 9: traces the paths fbm asks for and rebuilds the grids of M_fs and M_fd with cell
 * size `cell`. light maps are M_ls and M_ld (built); radius bounds the nearest-photon search. */
fv_status fv_foveated_trace(fv_foveated *f, const fv_scene *s, const fv_camera *cam, const fv_photon_map *m_ls,
                            const fv_photon_map *m_ld, float radius, float cell, uint64_t seed, int frame, int threads,
                            fv_fov_stats *st, fv_error *err);

const fv_photon_map *fv_foveated_static_map(const fv_foveated *f);  /* M_fs */
const fv_photon_map *fv_foveated_dynamic_map(const fv_foveated *f); /* M_fd */


/* Live static paths and the pool's capacity (memory stays bounded: the tests watch these). */
void fv_foveated_pool(const fv_foveated *f, int *live, int *capacity);

/* Eq. 1: eta = sumFlux(light photons, r_i) / sumFlux(light + foveated photons, r_i). We sum what
 * the pixels of the region r_i actually gather (light[i], fov[i]: the luminance of the light and
 * foveated photons' flux gathered at pixel i, through mirrors and glass too), over the pixels with
 * mask[i] set: the photons that illuminate the region, counted as often as they are used. Negative
 * sums are left out. 1 when there is no foveated flux. */
double fv_foveated_eta(const float *light, const float *fov, const uint8_t *mask, size_t n);

#endif
