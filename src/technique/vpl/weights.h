/* fovea — foveated weights of voxels (Foveated Instant Radiosity, Alg. 2) and foveated importance of
 * VPLs (Alg. 3).
 *
 * Alg. 2: an occupied voxel's weight is its visibility from the viewpoint times the acuity where it
 * projects. Visibility is read from the first-hit buffer (the depth buffer the paper renders anyway):
 * the voxel's centre projects to a pixel, and the voxel is visible when the surface that pixel sees
 * is no nearer than the centre less one cell diagonal. FoveatedAcuity (the paper's acuity sampling
 * map after Stengel et al., [42]) is 1 within the foveal radius R of the gaze and R / d at distance
 * d > R beyond it: the minimum angle of resolution grows linearly with eccentricity, so acuity
 * falls as its inverse; outside the image the weight is 0.
 *
 * Alg. 3: a VPL's importance is the weighted sum of the foveated weights of the first voxels hit by
 * rays in a fixed set of directions over its hemisphere (ray casting, not cone tracing, as Sec. 3.2
 * argues). The set is a spherical Fibonacci spiral over the hemisphere, each direction weighted by
 * its cosine, the weights summing to 1: the importance is then the cosine-weighted fraction of the
 * VPL's view that falls on what the fovea sees, in [0, 1].
 */
#ifndef FV_TECHNIQUE_VPL_WEIGHTS_H
#define FV_TECHNIQUE_VPL_WEIGHTS_H

#include "fovea/camera.h"
#include "technique/vpl/gbuffer.h"
#include "technique/vpl/voxels.h"

#define FV_VPL_MAX_DIRECTIONS 1024

/* The fixed directions of Alg. 3 in a local frame (z = the normal) and their weights. */
typedef struct fv_vpl_dirs {
    int count;
    fv_vec3 d[FV_VPL_MAX_DIRECTIONS];
    float w[FV_VPL_MAX_DIRECTIONS];
} fv_vpl_dirs;

/* count in [1, FV_VPL_MAX_DIRECTIONS]. */
void fv_vpl_dirs_make(int count, fv_vpl_dirs *out);

/* The acuity of a point d pixels from the gaze with foveal radius R pixels: 1 for d <= R, R / d beyond. */
static inline float fv_vpl_acuity(float d, float R) { return d <= R ? 1.0f : R / d; }

/* Alg. 2: weight[c] for every level-0 cell c of the grid (0 for empty or hidden cells), seen by
 * camera cam whose first-hit buffer is gb, gaze at pixel (gx, gy), foveal radius R pixels.
 * Runs inside a region the caller opened, called by every thread of its team (fv_team_for):
 * adds how many cells got a weight > 0 to *count (shared); ends with the team's barrier. */
void fv_vpl_foveated_weights_team(const fv_voxels *v, const fv_camera_basis *cam, const fv_gbuffer *gb, float gx, float gy,
                                  float R, float *weight, int *count);

/* Alg. 3: the importance of a VPL at p with unit normal n (rays start one cell off the surface). */
float fv_vpl_importance(const fv_voxels *v, const float *weight, const fv_vpl_dirs *dirs, fv_vec3 p, fv_vec3 n);

#endif
