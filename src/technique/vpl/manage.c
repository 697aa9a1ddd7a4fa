/* fovea — the scene-free VPL bookkeeping of Foveated Instant Radiosity: Eq. 1, the CDF resampling
 * of Sec. 3.1, Eq. 2, the density grid and the selection of Alg. 4 lines 4-9 and Alg. 5, and the
 * interleaved tiles of Sec. 3.4. See manage.h for the contract of each function.
 *
 * Limits: one thread per call; scratch memory is taken per call (a CDF and a bitmap for
 * resampling, one ranking array for the selection) and, when it cannot be had, a slower path that
 * needs none gives the same result (resampling) or a documented degraded one (the selection runs
 * in index order).
 */
#include "technique/vpl/manage.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"

/* ---- Eq. 1 ---- */

/* NaN fails both comparisons and lands on 0, so a bad number still gives a point of the disc. */
static double unit_clamp(float x) { return x > 0.0f ? (x < 1.0f ? (double)x : 1.0) : 0.0; }

void fv_vpl_polar_sample(float u, float v, float *dx, float *dy)
{
    /* Foveated Instant Radiosity, Eq. 1: the square root makes the area below radius R grow as
     * R^2 like u, so equal steps of u cover equal areas of the disc. Double precision keeps
     * cos(pi/2) at 6e-17 rather than float's -4e-8. */
    double r = sqrt(unit_clamp(u));
    double t = 2.0 * FV_PI_D * unit_clamp(v);
    *dx = (float)(r * cos(t));
    *dy = (float)(r * sin(t));
}

/* ---- Sec. 3.1: resampling by a CDF ---- */

static double clean_weight(float w) { return isfinite(w) && w > 0.0f ? (double)w : 0.0; }

/* The smallest i with cdf[i] > x, for 0 <= x < cdf[count - 1]. A zero weight repeats its
 * predecessor's sum, so it can never be the smallest index above x: it is never drawn. */
static int cdf_search(const double *cdf, int count, double x)
{
    int lo = 0, hi = count - 1;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (cdf[mid] > x) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

/* The same index without a CDF: the prefix sums are formed in the same order and precision, so
 * the answer is bit for bit the binary search's. */
static int linear_search(const float *weights, int count, double x)
{
    double acc = 0.0;
    int last = 0;
    for (int i = 0; i < count; i++) {
        double w = clean_weight(weights[i]);
        if (w <= 0.0) continue;
        acc += w;
        last = i;
        if (acc > x) return i;
    }
    return last; /* not reached while x < total; a positive weight either way */
}

int fv_vpl_resample(const float *weights, int count, int draws, fv_rng *rng, int *out)
{
    return fv_vpl_resample_in(weights, count, draws, rng, out, NULL);
}

int fv_vpl_resample_in(const float *weights, int count, int draws, fv_rng *rng, int *out, fv_scratch *room)
{
    if (count <= 0 || draws <= 0) return 0;
    double total = 0.0;
    for (int i = 0; i < count; i++) total += clean_weight(weights[i]);
    if (!(total > 0.0)) return 0;

    /* One block: the CDF, then one bit per index for the duplicate check. */
    size_t words = ((size_t)count + 63) / 64;
    double *cdf = NULL;
    uint64_t *seen = NULL;
    if ((size_t)count < SIZE_MAX / sizeof(double) - words) {
        if (room) fv_scratch_begin(room);
        cdf = room ? fv_scratch_take(room, (size_t)count + words, sizeof(double)) : fv_alloc_array((size_t)count + words, sizeof(double));
        if (cdf) {
            double acc = 0.0;
            for (int i = 0; i < count; i++) {
                acc += clean_weight(weights[i]);
                cdf[i] = acc;
            }
            seen = (uint64_t *)(cdf + count);
            memset(seen, 0, words * sizeof *seen);
        }
    }

    int n = 0;
    for (int d = 0; d < draws; d++) {
        /* fv_rng_next < 1, so x < total: every draw finds an index. */
        double x = (double)fv_rng_next(rng) * total;
        int i = cdf ? cdf_search(cdf, count, x) : linear_search(weights, count, x);
        bool dup = false;
        if (seen) {
            uint64_t bit = 1ull << (i & 63);
            dup = (seen[i >> 6] & bit) != 0;
            seen[i >> 6] |= bit;
        } else {
            for (int k = 0; k < n && !dup; k++) dup = out[k] == i;
        }
        /* Foveated Instant Radiosity, Sec. 3.1: a candidate drawn twice would be one light
         * counted twice, so repeats are dropped and only the first draw keeps its place. */
        if (!dup) out[n++] = i;
    }
    if (!room) free(cdf);
    return n;
}

/* ---- Eq. 2 ---- */

float fv_vpl_acceptance(float imp_new, float imp_old)
{
    if (!isfinite(imp_new) || !isfinite(imp_old)) return 0.0f;
    /* No earlier importance to compare with: any current importance is an increase. */
    if (imp_old <= 0.0f) return imp_new > 0.0f ? 1.0f : 0.0f;
    /* A negative ratio would give 1 - cos of a negative angle, which is positive: a light that
     * is now worth nothing must not be kept by that accident. */
    if (imp_new <= 0.0f) return 0.0f;
    double c = (double)imp_new / (double)imp_old;
    /* Foveated Instant Radiosity, Eq. 2: an old VPL that did not lose importance always stays;
     * one that lost some stays with a probability that falls off to 0 as its importance does. */
    if (c >= 1.0) return 1.0f;
    return (float)(1.0 - cos(0.5 * FV_PI_D * c));
}

/* ---- the density grid ---- */

struct fv_density_grid {
    fv_vec3 lo;
    double inv_h; /* cells per world unit */
    int dims[3];
    int *counts;
};

fv_status fv_density_grid_create(fv_vec3 lo, fv_vec3 hi, int resolution, fv_density_grid **out, fv_error *err)
{
    *out = NULL;
    if (resolution < 1 || resolution > 256)
        return fv_error_set(err, FV_ERR_INVALID, "density_grid: resolution %d outside [1, 256]", resolution);
    const double l[3] = {lo.x, lo.y, lo.z}, u[3] = {hi.x, hi.y, hi.z};
    double longest = 0.0;
    bool ok = true;
    for (int a = 0; a < 3; a++) {
        ok = ok && isfinite(l[a]) && isfinite(u[a]) && l[a] <= u[a];
        if (ok && u[a] - l[a] > longest) longest = u[a] - l[a];
    }
    if (!ok || !(longest > 0.0))
        return fv_error_set(err, FV_ERR_INVALID, "density_grid: box (%g, %g, %g)..(%g, %g, %g) is empty or not finite",
                            l[0], l[1], l[2], u[0], u[1], u[2]);

    fv_density_grid *g = calloc(1, sizeof *g);
    if (!g) return fv_error_set(err, FV_ERR_NOMEM, "density_grid: out of memory");
    double h = longest / (double)resolution;
    g->lo = lo;
    g->inv_h = 1.0 / h;
    for (int a = 0; a < 3; a++) {
        /* Enough cubes to cover the axis; the slack keeps 5.0000001 cells at 5 (the last cell
         * takes what rounding leaves over, as points past it are clamped anyway). */
        int n = (int)ceil((u[a] - l[a]) / h - 1e-3);
        g->dims[a] = n < 1 ? 1 : (n > resolution ? resolution : n);
    }
    g->counts = fv_calloc_array((size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2], sizeof *g->counts);
    if (!g->counts) {
        fv_status st = fv_error_set(err, FV_ERR_NOMEM, "density_grid: out of memory for a %dx%dx%d grid", g->dims[0], g->dims[1], g->dims[2]);
        fv_density_grid_destroy(g);
        return st;
    }
    *out = g;
    return FV_OK;
}

void fv_density_grid_destroy(fv_density_grid *g)
{
    if (!g) return;
    free(g->counts);
    free(g);
}

int fv_density_grid_cells(const fv_density_grid *g) { return g ? g->dims[0] * g->dims[1] * g->dims[2] : 0; }

void fv_density_grid_dims(const fv_density_grid *g, int dims[3])
{
    for (int a = 0; a < 3; a++) dims[a] = g ? g->dims[a] : 0;
}

int fv_density_grid_count_cell(const fv_density_grid *g, int cell)
{
    return g && cell >= 0 && cell < fv_density_grid_cells(g) ? g->counts[cell] : 0;
}

void fv_density_grid_clear(fv_density_grid *g)
{
    if (g) memset(g->counts, 0, (size_t)fv_density_grid_cells(g) * sizeof *g->counts);
}

/* The cell along one axis; the comparisons come before the cast, so an infinite coordinate is
 * clamped instead of overflowing the int. */
static int axis_cell(double f, int n)
{
    if (!(f >= 1.0)) return 0;
    if (f >= (double)n) return n - 1;
    return (int)f;
}

int fv_density_grid_cell(const fv_density_grid *g, fv_vec3 p)
{
    if (!g || isnan(p.x) || isnan(p.y) || isnan(p.z)) return 0;
    int i = axis_cell(((double)p.x - g->lo.x) * g->inv_h, g->dims[0]);
    int j = axis_cell(((double)p.y - g->lo.y) * g->inv_h, g->dims[1]);
    int k = axis_cell(((double)p.z - g->lo.z) * g->inv_h, g->dims[2]);
    return i + g->dims[0] * (j + g->dims[1] * k);
}

void fv_density_grid_add(fv_density_grid *g, fv_vec3 p, int delta)
{
    if (!g) return;
    int *c = &g->counts[fv_density_grid_cell(g, p)];
    long long v = (long long)*c + delta;
    *c = v < 0 ? 0 : (v > INT_MAX ? INT_MAX : (int)v);
}

int fv_density_grid_count(const fv_density_grid *g, fv_vec3 p) { return g ? g->counts[fv_density_grid_cell(g, p)] : 0; }

/* ---- Alg. 4 lines 4-9 and Alg. 5 ---- */

typedef struct fv_ranked {
    double score;
    int idx;
} fv_ranked;

/* Imp + 1 / (vd + C) of Alg. 5 line 15: the second term favours sparse cells. A NaN (from a NaN
 * importance or C) becomes -infinity so the sort has a total order and such a VPL loses every
 * comparison it could win. */
static double score_of(float imp, int vd, float c)
{
    double s = (double)imp + 1.0 / ((double)vd + (double)c);
    return isnan(s) ? -INFINITY : s;
}

/* Ties go to the lower index in both orders, so equal scores give the same selection on every
 * platform whatever qsort does with equal keys. */
static int cmp_ascending(const void *a, const void *b)
{
    const fv_ranked *x = a, *y = b;
    if (x->score != y->score) return x->score < y->score ? -1 : 1;
    return (x->idx > y->idx) - (x->idx < y->idx);
}

static int cmp_descending(const void *a, const void *b)
{
    const fv_ranked *x = a, *y = b;
    if (x->score != y->score) return x->score > y->score ? -1 : 1;
    return (x->idx > y->idx) - (x->idx < y->idx);
}

int fv_vpl_select(const fv_vpl_select_in *in, const fv_vpl_select_opts *opt, fv_density_grid *grid, bool *keep_old,
                  bool *take_cand, int *kept_reused, int *kept_left)
{
    const int n_old = in->n_old > 0 ? in->n_old : 0;
    const int n_cand = in->n_cand > 0 ? in->n_cand : 0;
    const int total = opt->total > 0 ? opt->total : 0;
    const float c = opt->density_c;
    for (int i = 0; i < n_old; i++) keep_old[i] = false;
    for (int i = 0; i < n_cand; i++) take_cand[i] = false;
    int selected = 0, reused = 0, left_kept = 0;

    /* Alg. 4 line 4 (VPLSelectionOld): reuse is what keeps consecutive frames alike, so the old
     * VPLs that pass Eq. 2 come first and fill the grid before any candidate is looked at. */
    for (int i = 0; i < n_old && selected < total; i++) {
        if (!(in->old_u[i] < fv_vpl_acceptance(in->old_imp_new[i], in->old_imp_prev[i]))) continue;
        keep_old[i] = true;
        fv_density_grid_add(grid, in->old_pos[i], 1);
        selected++, reused++;
    }
    const int n_left = n_old - reused;

    /* Alg. 5 lines 2-6: left VPLs weakest first, candidates strongest first, so pair i sets the
     * i-th weakest survivor against the i-th best newcomer. The left VPLs are ranked by their
     * current importance, the one measured for this frame's fovea like the candidates'. */
    fv_ranked *rank = NULL;
    if (n_left + n_cand > 0 && selected < total) {
        if (opt->room) fv_scratch_begin(opt->room);
        rank = opt->room ? fv_scratch_take(opt->room, (size_t)n_left + (size_t)n_cand, sizeof *rank)
                         : fv_alloc_array((size_t)n_left + (size_t)n_cand, sizeof *rank);
        if (rank) {
            for (int i = 0, m = 0; i < n_old; i++) {
                if (keep_old[i]) continue;
                rank[m].score = score_of(in->old_imp_new[i], fv_density_grid_count(grid, in->old_pos[i]), c);
                rank[m++].idx = i;
            }
            for (int i = 0; i < n_cand; i++) {
                rank[n_left + i].score = score_of(in->cand_imp[i], fv_density_grid_count(grid, in->cand_pos[i]), c);
                rank[n_left + i].idx = i;
            }
            qsort(rank, (size_t)n_left, sizeof *rank, cmp_ascending);
            qsort(rank + n_left, (size_t)n_cand, sizeof *rank, cmp_descending);
        }
    }

    /* Alg. 5 lines 7-20, with every one of the N pairs (the paper's loop stops at N - 1). The
     * densities are read now, not taken from the ranking: each selection raises its cell's
     * count, which is what stops one dense cell from taking every candidate. Without the
     * ranking array (no memory) both lists are walked in index order. */
    const int N = n_left < n_cand ? n_left : n_cand;
    int i = 0;
    for (int cursor = -1; i < N && selected < total; i++) {
        int l, k;
        if (rank) {
            l = rank[i].idx;
            k = rank[n_left + i].idx;
        } else {
            /* Past the cursor keep_old still holds step 1's flags, so this finds the next left one. */
            do cursor++;
            while (keep_old[cursor]);
            l = cursor;
            k = i;
        }
        int vd_l = fv_density_grid_count(grid, in->old_pos[l]);
        int vd_c = fv_density_grid_count(grid, in->cand_pos[k]);
        if (score_of(in->old_imp_new[l], vd_l, c) < score_of(in->cand_imp[k], vd_c, c) && vd_c < opt->density_limit) {
            take_cand[k] = true;
            fv_density_grid_add(grid, in->cand_pos[k], 1);
        } else {
            keep_old[l] = true;
            fv_density_grid_add(grid, in->old_pos[l], 1);
            left_kept++;
        }
        selected++;
    }

    /* Alg. 5 lines 21-28: the candidates no pair consumed fill what room is left, best first,
     * a full cell skipped rather than ending the loop. Left VPLs past N are dropped (i == N here
     * unless `total` was reached, and then nothing more is taken). */
    for (int j = N; j < n_cand && selected < total; j++) {
        int k = rank ? rank[n_left + j].idx : j;
        if (fv_density_grid_count(grid, in->cand_pos[k]) >= opt->density_limit) continue;
        take_cand[k] = true;
        fv_density_grid_add(grid, in->cand_pos[k], 1);
        selected++;
    }
    if (!opt->room) free(rank);
    if (kept_reused) *kept_reused = reused;
    if (kept_left) *kept_left = left_kept;
    return selected;
}

/* ---- Sec. 3.4: interleaved tiles ---- */

#define FV_TILES_ON_STACK 1024

/* How many VPLs tile t holds, counted afresh: the path for a tile count whose table could not
 * be allocated. */
static int tile_load(const int *tile, int count, int t)
{
    int n = 0;
    for (int i = 0; i < count; i++) n += tile[i] == t;
    return n;
}

void fv_vpl_assign_tiles(int *tile, int count, int tiles)
{
    if (tiles <= 0 || count <= 0) return;
    int stack[FV_TILES_ON_STACK];
    int *load = tiles <= FV_TILES_ON_STACK ? stack : fv_alloc_array((size_t)tiles, sizeof *load);
    if (load) {
        memset(load, 0, (size_t)tiles * sizeof *load);
        for (int i = 0; i < count; i++)
            if (tile[i] >= 0 && tile[i] < tiles) load[tile[i]]++;
    }
    /* Foveated Instant Radiosity, Sec. 3.4: an old VPL keeps its tile so a tile's light does not
     * jump between frames; a new one goes where it evens out the per-tile counts. */
    for (int i = 0; i < count; i++) {
        if (tile[i] >= 0 && tile[i] < tiles) continue;
        int best = 0, best_n = INT_MAX;
        for (int t = 0; t < tiles; t++) {
            int n = load ? load[t] : tile_load(tile, count, t);
            if (n < best_n) best = t, best_n = n;
        }
        tile[i] = best;
        if (load) load[best]++;
    }
    if (load != stack) free(load);
}
