/* fovea — a sparse lattice of shaded pixels filled in at full resolution, edge-aware (fpm-guided's
 * periphery, docs/photon-mapping.md).
 *
 * Where acuity is low the expensive estimate (a photon gather) is made only at every step-th pixel
 * of every step-th row; every other pixel takes the mean of the known pixels at the corners of its
 * lattice cell, each weighted bilinearly and by how much its surface agrees with the pixel's (the
 * first-hit normal and position every pixel has anyway). So edges stay where the geometry puts
 * them, at full resolution, and no block structure appears. A pixel none of whose corners agree
 * (a thin object between lattice points) is reported, for the caller to shade itself.
 */
#ifndef FV_FILTER_LATTICE_H
#define FV_FILTER_LATTICE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "fovea/status.h"
#include "filter/atrous.h"

typedef struct fv_lattice_opts {
    int step;             /* lattice spacing in pixels (>= 1); the lattice is x % step == 0 && y % step == 0 */
    const uint8_t *level; /* optional per pixel: its cell is step << level[i] wide (coarser where acuity is
                             lower; NULL: level 0 everywhere); its corners are multiples of that */
    float normal_power;   /* weight max(0, n . n_q)^power */
    float sigma_position; /* weight exp(-|p - p_q|^2 / sigma^2), scene units; <= 0: no position term */
} fv_lattice_opts;

/* Fills every pixel with known[i] == 0 and (skip NULL or skip[i] == 0) of rgb (w*h*3) from the
 * known pixels at its cell's lattice corners, guided by normal and position (3 floats per pixel;
 * a zero normal marks a pixel without surface, which neither gives nor takes). Each pixel left
 * unfilled (no corner with weight) gets need[i] = 1 and keeps its value; all others get
 * need[i] = 0. Returns how many need shading. Known pixels off the lattice are not used. */
long fv_lattice_fill(float *rgb, const uint8_t *known, const uint8_t *skip, const float *normal, const float *position, int w,
                     int h, const fv_lattice_opts *o, uint8_t *need);

/* Filters the lattice's known pixels among themselves with `iterations` passes of the À-Trous
 * filter (filter/atrous.h), as an image of ceil(w/step) x ceil(h/step) pixels, before the fill: the
 * periphery is denoised at the resolution it was estimated at. Only pixels with filter_mask[i] != 0
 * are written back (others still guide and feed the filter). sigma_position, workspace (may be NULL)
 * and threads as for fv_atrous_opts. */
fv_status fv_lattice_filter(float *rgb, const uint8_t *known, const uint8_t *filter_mask, const float *normal,
                            const float *position, int w, int h, int step, int iterations, fv_atrous *workspace, int threads,
                            float sigma_position, fv_error *err);

/* Both as steps of a caller's parallel region (docs/threads.md): called by every thread of the
 * team with the same arguments, each ends with the team's barrier, neither opens a region nor
 * allocates; same results bit for bit. fv_lattice_fill_team adds its count to *missing (shared,
 * zeroed before the region). fv_lattice_filter_team takes ao (iterations, sigma_position;
 * ao->workspace prepared with fv_atrous_prepare for at least the lattice's ceil(w/step) x
 * ceil(h/step)) and scratch of fv_lattice_scratch_floats(w, h, step) floats, the caller's, kept
 * from frame to frame. */
void fv_lattice_fill_team(float *rgb, const uint8_t *known, const uint8_t *skip, const float *normal, const float *position,
                          int w, int h, const fv_lattice_opts *o, uint8_t *need, long *missing);
size_t fv_lattice_scratch_floats(int w, int h, int step);
void fv_lattice_filter_team(float *rgb, const uint8_t *known, const uint8_t *filter_mask, const float *normal,
                            const float *position, int w, int h, int step, const fv_atrous_opts *ao, float *scratch);

#endif
