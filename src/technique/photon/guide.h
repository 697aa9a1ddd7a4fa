/* fovea — photon guiding towards what the focus region gathers (fpm-guided, docs/photon-mapping.md,
 * "fpm-guided").
 *
 * Foveated Photon Mapping (Sec. 3.2) puts more photons where the viewer looks by tracing paths
 * from the eye and copying a light photon's flux onto them; that flux says nothing about the
 * irradiance where they land, which is why fpm's fovea is biased (docs/results.md). Here the light
 * photons themselves are aimed: a photon's emission is drawn from the light with five uniform
 * numbers (fv_light_sample_emission), and the guide draws the light-pick number and the two that
 * choose the direction from a piecewise-constant density q over a grid of cells instead, q learnt
 * from pilot photons: how many of their deposits fell in the cells the focus region's gather discs
 * touch. The photon's flux is divided by q, so E[flux] is what uniform numbers give: the map stays
 * an unbiased estimate everywhere, only denser where the focus region gathers. A share of q stays
 * uniform (`1 - alpha`), so no photon path the pilot missed has zero density.
 *
 * Deterministic for a seed and independent of the thread count (the pilot counts are integers).
 */
#ifndef FV_PHOTON_GUIDE_H
#define FV_PHOTON_GUIDE_H

#include <stdbool.h>
#include <stdint.h>
#include "scene/query.h"
#include "technique/photon/photon_trace.h"

/* ---- the cells a set of gather discs touch ---- */

/* A set of cells of a uniform grid (edge `cell`, unbounded: cells are hashed). */
typedef struct fv_focus_cells fv_focus_cells;

fv_status fv_focus_cells_create(fv_focus_cells **out, fv_error *err);
void fv_focus_cells_destroy(fv_focus_cells *f);
/* Empties the set and sets the grid's cell edge (> 0). */
void fv_focus_cells_reset(fv_focus_cells *f, float cell);
/* Adds every cell the box around the disc (x, r) overlaps (r <= cell: at most 8). */
fv_status fv_focus_cells_add(fv_focus_cells *f, fv_vec3 x, float r, fv_error *err);
bool fv_focus_cells_contains(const fv_focus_cells *f, fv_vec3 p);
int fv_focus_cells_count(const fv_focus_cells *f);
float fv_focus_cells_cell(const fv_focus_cells *f);
/* The share of a's cells that are also in b (1 when a is empty); both must share the cell edge,
 * else 0. */
double fv_focus_cells_overlap(const fv_focus_cells *a, const fv_focus_cells *b);

/* ---- the guide ---- */

typedef struct fv_photon_guide fv_photon_guide;

/* alpha in [0, 1): the share of photons the learnt cells get; the rest are drawn uniformly. */
fv_status fv_photon_guide_create(double alpha, fv_photon_guide **out, fv_error *err);
void fv_photon_guide_destroy(fv_photon_guide *g);

/* Learns q from `job->count` pilot photons (uniform numbers, random stream job->stream, traced
 * through `set` like the map they guide): a cell's weight is the number of their deposits inside
 * `focus`. With no such deposit q stays uniform. job->warp is ignored. */
fv_status fv_photon_guide_learn(fv_photon_guide *g, const fv_photon_job *job, fv_trace_set set, const fv_focus_cells *focus,
                                uint64_t *rays, fv_error *err);
/* Makes q uniform again for scene s (what a fresh guide has). */
void fv_photon_guide_reset(fv_photon_guide *g, const fv_scene *s);
/* The warp for fv_photon_job (ctx: the guide); the guide must have been learnt or reset for the
 * scene the job traces. */
float fv_photon_guide_warp(const void *ctx, fv_rng *rng, float u[5]);
/* q at emission numbers u (relative to uniform numbers: 1 everywhere for a uniform guide). */
float fv_photon_guide_density(const fv_photon_guide *g, const float u[5]);
/* The share of the pilot's deposits that fell in the focus cells (0 before learning). */
double fv_photon_guide_focus_share(const fv_photon_guide *g);

#endif
