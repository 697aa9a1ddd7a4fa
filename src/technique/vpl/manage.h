/* fovea — the VPL bookkeeping of Foveated Instant Radiosity that needs no scene: the polar sampling
 * of the fovea (Eq. 1), resampling candidates by a CDF of their importance (Sec. 3.1), the
 * acceptance probability of an old VPL (Eq. 2), the density grid and the selection of valid VPLs
 * (Alg. 4 lines 4-9 and Alg. 5), and the interleaved tiles VPLs are assigned to (Sec. 3.4).
 *
 * Everything here works on plain arrays (positions, importances, uniform numbers drawn by the
 * caller), so each step is checked by hand in tests/unit/test_vpl_manage.c and the same inputs give
 * the same VPLs whatever the thread count.
 */
#ifndef FV_TECHNIQUE_VPL_MANAGE_H
#define FV_TECHNIQUE_VPL_MANAGE_H

#include <stdbool.h>
#include "core/rng.h"
#include "core/scratch.h"
#include "fovea/math.h"
#include "fovea/status.h"

/* ---- Eq. 1: uniform samples over the foveal disc ---- */

/* (u, v) in [0, 1)^2 -> a point of the unit disc: R = sqrt(u), theta = 2 pi v, (R cos, R sin).
 * u and v are clamped to [0, 1] (NaN counts as 0), so the point is always in the disc. */
void fv_vpl_polar_sample(float u, float v, float *dx, float *dy);

/* ---- Sec. 3.1: resampling by a CDF of importance ---- */

/* Draws `draws` times from the discrete distribution proportional to weights[0..count) (negative
 * or non-finite weights count as 0) with one fv_rng_next each, drops duplicates (the paper's
 * "separate check") and writes the distinct indices in the order first drawn to out (room for
 * min(draws, count)). Returns how many were written: 0 when every weight is 0 or count/draws <= 0,
 * and then the rng is not advanced (otherwise it is advanced exactly `draws` times). */
int fv_vpl_resample(const float *weights, int count, int draws, fv_rng *rng, int *out);
/* The same with its CDF from room, a scratch arena the caller keeps (core/scratch.h), so that a
 * warmed-up frame allocates nothing (docs/threads.md, "No allocation in a frame"). */
int fv_vpl_resample_in(const float *weights, int count, int draws, fv_rng *rng, int *out, fv_scratch *room);

/* ---- Eq. 2: may an old VPL stay? ---- */

/* C = imp_new / imp_old; 1 - cos(pi/2 C) when C <= 1, else 1. An old importance <= 0 (nothing to
 * compare with) gives 1 when imp_new > 0 and 0 otherwise; non-finite inputs give 0, and so does
 * imp_new <= 0 with imp_old > 0 (a negative C would otherwise give a positive 1 - cos). */
float fv_vpl_acceptance(float imp_new, float imp_old);

/* ---- the density grid of Alg. 5 ---- */

/* A uniform grid of cubic cells over [lo, hi] (resolution cells along the longest axis, at least
 * one along the others, as many as cover the box), counting the valid VPLs in each cell. A point
 * outside the box is clamped to the nearest cell, an infinite coordinate included; a point with a
 * NaN coordinate goes to cell 0. All functions accept a NULL grid (cell 0, count 0, no-op). */
typedef struct fv_density_grid fv_density_grid;

/* resolution outside [1, 256] or an empty/non-finite box -> FV_ERR_INVALID naming
 * `density_grid`; no memory -> FV_ERR_NOMEM. A box flat along some axes (lo == hi there) is valid,
 * one with lo > hi on any axis or lo == hi on all three is empty. */
fv_status fv_density_grid_create(fv_vec3 lo, fv_vec3 hi, int resolution, fv_density_grid **out, fv_error *err);
void fv_density_grid_destroy(fv_density_grid *g);
void fv_density_grid_clear(fv_density_grid *g);
int fv_density_grid_cell(const fv_density_grid *g, fv_vec3 p); /* row-major index, x fastest */
int fv_density_grid_cells(const fv_density_grid *g);           /* how many cells in all */
void fv_density_grid_dims(const fv_density_grid *g, int dims[3]); /* cells per axis */
int fv_density_grid_count_cell(const fv_density_grid *g, int cell); /* the count of one cell (0 outside) */
void fv_density_grid_add(fv_density_grid *g, fv_vec3 p, int delta); /* a count stays in [0, INT_MAX] */
int fv_density_grid_count(const fv_density_grid *g, fv_vec3 p);

/* ---- Alg. 4 lines 4-9 and Alg. 5: which VPLs are valid this frame ---- */

typedef struct fv_vpl_select_opts {
    int total;         /* TOTALNUMBER: at most this many valid VPLs in all */
    int density_limit; /* DENSITYLIMIT: a candidate is taken only while its cell holds fewer VPLs */
    float density_c;   /* C of the score Imp + 1 / (vd + C); > 0 keeps the term finite */
    fv_scratch *room;  /* the ranking's scratch, kept by the caller (core/scratch.h); NULL: allocated for the call */
} fv_vpl_select_opts;

typedef struct fv_vpl_select_in {
    /* the previous frame's valid VPLs after UpdateVPLs (Alg. 4 line 3; dropped ones not listed) */
    int n_old;
    const fv_vec3 *old_pos;
    const float *old_imp_prev; /* Imp_p: importance last frame */
    const float *old_imp_new;  /* Imp_pn: importance now */
    const float *old_u;        /* one uniform number in [0, 1) each, for Eq. 2 */
    /* the new candidates (Sec. 3.1, already resampled and distinct) */
    int n_cand;
    const fv_vec3 *cand_pos;
    const float *cand_imp;
} fv_vpl_select_in;

/* The selection, in this order:
 *  1. VPLSelectionOld (Alg. 4 line 4): old VPL i is reusable when old_u[i] < Eq. 2 of
 *     (old_imp_new[i], old_imp_prev[i]); reusable VPLs are kept (at most `total`, in index order)
 *     and counted in `grid` (which the caller passes cleared).
 *  2. VPLSelectionCandidates (Alg. 5) on the left (not kept in step 1) old VPLs and the
 *     candidates. The density vd of a VPL is the count in its cell of the VPLs selected so far
 *     (read when the VPL is looked at, so the grid fills as VPLs are selected: the paper's
 *     gDensity of lines 2-4 read once would let one cell take every candidate); it is a count,
 *     compared with density_limit as a count. Imp is cand_imp for a candidate and old_imp_new
 *     (measured for this frame, like the candidates') for a left VPL; a NaN score counts as
 *     -infinity. The left VPLs are sorted ascending and the candidates descending by the score
 *     Imp + 1 / (vd + C) with the densities after step 1 (ties: lower index first). Then for i < N = min(n_left, n_cand) (the paper's loop runs to
 *     N - 1; we compare every pair): the i-th left l and the i-th candidate c are compared with
 *     their current densities; c is taken when score(l) < score(c) and vd_c < density_limit,
 *     otherwise l is kept; the one taken is added to the grid. Left VPLs past N are dropped.
 *  3. The remaining candidates (sorted positions N and on; one that lost its pair is not tried
 *     again), in sorted order, are taken while fewer than `total` VPLs are
 *     selected and their current vd < density_limit (lines 21-28).
 * No step selects more than `total` VPLs in all (a pair is skipped once `total` is reached).
 * total <= 0 selects nothing; density_limit <= 0 takes no candidate. The grid is not cleared here:
 * counts already in it count as selected VPLs of their cells. If the ranking scratch (one
 * double and one int per left VPL and candidate) cannot be allocated, steps 2 and 3 walk both
 * lists in index order instead of sorted order (a degraded but valid selection, never a crash).
 * kept_reused and kept_left may be NULL; grid must not be.
 * Outputs: keep_old[n_old] and take_cand[n_cand] flags; *kept_reused receives the count of step 1,
 * *kept_left the old VPLs kept in step 2. Returns the number selected in all. */
int fv_vpl_select(const fv_vpl_select_in *in, const fv_vpl_select_opts *opt, fv_density_grid *grid, bool *keep_old,
                  bool *take_cand, int *kept_reused, int *kept_left);

/* ---- Sec. 3.4: interleaved tiles ---- */

/* Assigns each VPL whose tile[i] is < 0 (new ones) to the tile with the fewest VPLs at that moment
 * (ties: the lowest tile index), leaving tile[i] >= 0 as it is (old VPLs keep their tile). Tiles
 * are numbered [0, tiles). tile[i] >= tiles is treated as new. tiles <= 0 leaves tile as it is. */
void fv_vpl_assign_tiles(int *tile, int count, int tiles);

#endif
