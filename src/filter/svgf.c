/* fovea — spatiotemporal variance-guided filtering (Schied et al., HPG 2017, Sec. 4; see svgf.h for
 * the algorithm and the contract). This file is the CPU implementation on an fv_grid.
 *
 * One frame is a few sweeps over the grid, each an OpenMP loop over rows; every pixel is computed
 * from its inputs alone, in a fixed order, so the result does not depend on the thread count:
 *  A. classify each pixel, demodulate, fetch and blend its history (Sec. 4.1), keep its features;
 *  B. depth gradient and variance: temporal, or the 7x7 spatial estimate (Sec. 4.2);
 *  C. per À-Trous pass (Sec. 4.3): the 3x3-prefiltered variance, then the pass itself, ping-ponging
 *     between two buffers; the first pass also writes the history;
 *  D. remodulate and store this frame's G-buffer as the next frame's history;
 *  E. fill the pixels that had no path (only when there are some).
 *
 * Speed: rows are processed in chunks of CHUNK pixels with the taps in the outer loop. For most
 * pixels a tap is a plain shift in memory (screen grids; in polar grids, between full-height
 * columns away from the clamped edges), so the inner loop runs over contiguous pixels and the
 * compiler vectorises it (omp simd) from buffers kept as one array per channel. The other pixels
 * (the fovea's short columns, the clamped edges) look their taps up as fv_grid_tap does, from a
 * per-chunk table, and run the same arithmetic on gathered loads. Each pixel adds its taps in the
 * same order either way, so the two paths give the same bits. The normal weight's cosine^128 is
 * seven squarings, unrolled and vectorised; other powers of two are squarings in a plain loop, other
 * exponents powf. The exponential is an inline approximation (exp_neg). Spans of a chunk with no
 * surface (background, rows beyond short columns) are skipped.
 *
 * Choices the paper leaves open, and why:
 *  - Depth gradient: per axis (along the column and across columns, through the grid's own taps) the
 *    smaller of the two one-sided differences to neighbouring surface pixels, then the larger of the
 *    two axes, times the tap's Euclidean distance in grid pixels (2^i sqrt(dx^2 + dy^2)). A central
 *    difference would straddle a silhouette and make the depth test of exactly the pixels next to
 *    it blind; on a smooth surface the one-sided differences agree with the central one.
 *  - Spatial variance (history shorter than 4 frames, counting this one): moments averaged over the
 *    7x7 neighbourhood with the depth and normal weights only. A luminance term would need a scale
 *    that linear radiance with no fixed exposure does not have, and the albedo is already divided
 *    out, so texture does not inflate the estimate.
 *  - History length: the renormalised bilinear average of the taps' lengths plus one, capped at
 *    LEN_MAX (beyond 1 / alpha it only feeds the counters).
 *  - History consistency uses this frame's depth for the position tolerance (5% of the distance: a
 *    point that moved further than that in one frame is a different point for the history).
 *  - Polar grids: a history coordinate X outside [0, w] is clamped to the edge columns (as the
 *    lookup clamps them) and V is wrapped; the consistency test decides. Screen grids refuse
 *    coordinates outside the image.
 *  - Non-finite input (colour, albedo, normal, depth or position of a sampled surface pixel) is
 *    treated like an unsampled pixel: one NaN would otherwise spread through the history forever.
 *  - Every pixel that is not a surface (background, holes, rows beyond their column's height) has a
 *    zero normal and zero values in the working buffers, so as a tap its weight is exactly 0 and
 *    the inner loops need no test.
 *
 * Memory: about 140 bytes per grid pixel, all allocated by fv_svgf_create; nothing is allocated per
 * frame (the per-chunk scratch is on the stack, about 4 KB).
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/svgf.h"

#define LEN_MAX 256.0f
#define MIN_ALBEDO 1e-3f
#define HIST_MIN_WEIGHT 0.01f
#define HIST_COS 0.9f           /* normals within ~25 degrees */
#define HIST_POS_REL 0.05f      /* position tolerance, fraction of the depth */
#define HIST_DEPTH_MIN 1e-3f
#define HIST_POS_ULP 1e-5f      /* plus this fraction of the coordinates' size: float rounding */
#define DEPTH_EPS_REL 1e-4f     /* depth differences this small relative to the depth are free */
#define LUM_EPS 1e-10f
#define VAR_TEMPORAL_LEN 4.0f
#define CHUNK 64
#define NTAP 24                 /* taps of the 5x5 kernel besides the centre */
#define NTAP7 48                /* the same for the 7x7 moments */
#define SQ_DEFAULT 7            /* sigma_normal 128 = 2^7: the case compiled with a constant */
/* Rows are dealt to the threads in interleaved blocks (still a static schedule): the fovea's short
 * columns make the first rows of a polar grid heavier, and halves would leave one thread waiting. */
#define ROWS_PER_BLOCK 8

/* The per-tap functions must be inlined into the loops marked omp simd, or nothing vectorises. */
#if defined(__GNUC__)
#define TAP_INLINE static inline __attribute__((always_inline))
#else
#define TAP_INLINE static inline
#endif

enum { KIND_NONE = 0, KIND_SURFACE = 1, KIND_HOLE = 2 };
enum { V_R, V_G, V_B, V_VAR, V_LUM, NVAL };

static const float k_b3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
static const float k_g3[3] = {0.25f, 0.5f, 0.25f};

struct fv_svgf {
    fv_grid g;
    fv_svgf_opts o;
    int normal_squarings;   /* sigma_normal = 2^k, k <= 16: k; else -1 (powf) */
    int full_from;          /* polar grids: columns from here on all hold h rows */
    bool have_history;
    size_t n;
    uint8_t *kind;
    float *surf;            /* 1 on a surface pixel, else 0 (the variance prefilter's weights) */
    float *nx[2], *ny[2], *nz[2], *z[2]; /* normal and depth; [0] this frame, [1] the history */
    float *val[2][NVAL];    /* demodulated rgb, variance, luminance; ping-pong over the passes */
    float *gvar;            /* variance after the 3x3 prefilter, for the current pass */
    float *grad;            /* depth gradient magnitude */
    float *m1[2], *m2[2];   /* luminance moments; [0] this frame, [1] the history */
    float *len[2];          /* history length; 0: not a surface pixel (cannot serve as history) */
    float *hist_illum;      /* rgb after the first pass, for the next frame */
    float *hist_pos;        /* xyz */
    uint32_t *hist_id;
    long *row_surface, *row_hist, *row_holes;
    double *row_len;
};

void fv_svgf_opts_default(fv_svgf_opts *o)
{
    o->alpha_color = 0.2f;
    o->alpha_moments = 0.2f;
    o->iterations = 5;
    o->sigma_depth = 1.0f;
    o->sigma_normal = 128.0f;
    o->sigma_lum = 4.0f;
}

fv_status fv_svgf_opts_validate(const fv_svgf_opts *o, fv_error *err)
{
    if (!o) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no options");
    const struct {
        const char *name;
        float v;
    } alphas[2] = {{"alpha_color", o->alpha_color}, {"alpha_moments", o->alpha_moments}},
      sigmas[3] = {{"sigma_depth", o->sigma_depth}, {"sigma_normal", o->sigma_normal}, {"sigma_lum", o->sigma_lum}};
    for (int i = 0; i < 2; i++)
        if (!(alphas[i].v > 0.0f && alphas[i].v <= 1.0f))
            return fv_error_set(err, FV_ERR_INVALID, "SVGF: %s %g not in (0, 1]", alphas[i].name, (double)alphas[i].v);
    if (o->iterations < 0 || o->iterations > 10)
        return fv_error_set(err, FV_ERR_INVALID, "SVGF: iterations %d not in [0, 10]", o->iterations);
    for (int i = 0; i < 3; i++)
        if (!(sigmas[i].v > 0.0f && isfinite(sigmas[i].v)))
            return fv_error_set(err, FV_ERR_INVALID, "SVGF: %s %g must be positive and finite", sigmas[i].name,
                                (double)sigmas[i].v);
    return FV_OK;
}

/* ---- small helpers */

static inline int imin(int a, int b) { return a < b ? a : b; }
static inline int imax(int a, int b) { return a > b ? a : b; }

static inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

static inline float demod_albedo(float a) { return a < MIN_ALBEDO ? 1.0f : a; }

/* The denominator's floor of the depth term: differences below 1e-4 of the depth are rounding. */
static inline float depth_eps(float z) { return DEPTH_EPS_REL * fabsf(z) + 1e-30f; }

/* e^-x for x >= 0, inline (a call to expf per tap was a quarter of the frame): 2^t with
 * t = -x log2(e) split into an integer i and a fraction whose e^a, a in [-ln2 / 2, ln2 / 2], comes
 * from its Taylor series to the 5th power (truncation error below 2.5e-6, evaluated in Estrin's
 * form: half the dependent operations of Horner's), and 2^i through the exponent bits. Relative
 * error below 4e-6 for x < 10 and 5e-6 up to 87; exactly 1 at 0; exactly 0 from 87 on (where expf
 * is below 2e-38), for +inf and NaN. Branch-free, with the selects on integers (for x >= 0 the
 * bits order like the values), so that loops over taps vectorise. */
TAP_INLINE float exp_neg(float x)
{
    union { float f; int32_t i; } u = {x}, lim = {87.0f}, scale;
    int32_t in = u.i < lim.i;
    u.i = in ? u.i : lim.i;
    float t = -u.f * 1.44269504f;
    int32_t i = (int32_t)(t - 0.5f); /* t <= 0: truncation rounds t - 0.5 up, i in [-125, 0] */
    float a = (t - (float)i) * 0.693147181f, a2 = a * a;
    float p = (1.0f + a) + a2 * ((1.0f / 2 + a * (1.0f / 6)) + a2 * (1.0f / 24 + a * (1.0f / 120)));
    scale.i = in ? (i + 127) * (1 << 23) : 0;
    return p * scale.f;
}

/* max(0, c)^sigma_normal: sq squarings when sigma_normal = 2^sq, else powf. Called with the literal
 * SQ_DEFAULT in the hot loops so that the squarings unroll and the loop vectorises. (c + |c|) / 2
 * is max(c, 0) exactly in a form that vectorises. */
TAP_INLINE float normal_pow(float c, int sq, float sn)
{
    c = 0.5f * (c + fabsf(c));
    if (sq < 0) return powf(c, sn);
    for (int k = 0; k < sq; k++) c *= c;
    return c;
}

/* For the pixels [x0, x1) of row y: the run [*a, *b) whose tap (dx, dy) is the pixel x + *off (a
 * plain shift: fv_grid_tap reduces to it there). Pixels outside the run need fv_grid_tap on a polar
 * grid; on a screen grid their tap lies outside the image. An empty run is returned as a = b = x1.
 * (x0, x1 here are any span of a row, not necessarily a whole chunk.) */
static inline void tap_run(const fv_svgf *f, int y, int dx, int dy, int x0, int x1, int *a, int *b, long *off)
{
    const fv_grid *g = &f->g;
    int row, lo, hi;
    if (!g->wrap) {
        row = y + dy;
        lo = imax(x0, -dx);
        hi = imin(x1, g->w - dx);
        if (row < 0 || row >= g->h) lo = hi = x1;
    } else {
        /* Both columns full height: no remapping between heights, the row wraps modulo h. */
        row = fv_grid_wrap_row(y + dy, g->h);
        lo = imax(imax(x0, f->full_from), imax(f->full_from - dx, -dx));
        hi = imin(x1, g->w - dx);
    }
    if (lo >= hi) lo = hi = x1;
    *a = lo;
    *b = hi;
    *off = (long)row * g->w + dx;
}

/* The span [*lo, *hi) of the chunk [x0, x1) (pixel x0 at index p0) from its first to its last
 * surface pixel; false when the chunk has none. Only the span is filtered (the fovea's short columns leave most of a chunk's row
 * beyond their heights, and a background stays out of the loops). */
static inline bool surface_span(const uint8_t *kind, size_t p0, int x0, int x1, int *lo, int *hi)
{
    int a = x0, b = x1;
    while (a < b && kind[p0 + (a - x0)] != KIND_SURFACE) a++;
    while (b > a && kind[p0 + (b - 1 - x0)] != KIND_SURFACE) b--;
    *lo = a, *hi = b;
    return a < b;
}

/* The pixels of a chunk that are not in a tap's run (polar grids: short columns, clamped edges) take
 * their taps through this table: for each column offset, where fv_grid_tap(x, y, dx, .) starts. The
 * same-angle mapping between columns of different heights is an integer division, done once per
 * column offset here rather than once per tap. */
typedef struct chunk_cols {
    int x[7][CHUNK], row[7][CHUNK], n[7][CHUNK];
    bool ready;     /* built for the current chunk (only chunks that need it build it) */
} chunk_cols;

static void chunk_columns(const fv_grid *g, int y, int x0, int nc, int step, int ncols, chunk_cols *cc)
{
    const int half = ncols / 2;
    for (int i = 0; i < ncols; i++)
        for (int k = 0; k < nc; k++) {
            int x = x0 + k, xx = x + (i - half) * step;
            xx = xx < 0 ? 0 : (xx >= g->w ? g->w - 1 : xx);
            int hs = fv_grid_col_h(g, x), hd = fv_grid_col_h(g, xx), row = y;
            if (hs != hd) row = (int)(((long)y * 2 + 1) * hd / (2L * hs));
            cc->x[i][k] = xx, cc->row[i][k] = row, cc->n[i][k] = hd;
        }
    cc->ready = true;
}

/* fv_grid_tap(g, x0 + k, y, (ci - ncols / 2) * step, dy) on a polar grid, from the table. */
static inline int chunk_tap(const fv_grid *g, const chunk_cols *cc, int ci, int k, int dy)
{
    int n = cc->n[ci][k], yy = cc->row[ci][k] + dy;
    if (yy < 0 || yy >= n) yy = fv_grid_wrap_row(yy, n);
    return yy * g->w + cc->x[ci][k];
}

/* Fills fq[x - x0] for the pixels of [s0, s1) outside the run [a, b): their taps. Their centres may
 * be no surface: the tap is then still a valid pixel and weighs 0. */
static inline void fallback_taps(const fv_grid *g, const chunk_cols *cc, int ci, int dy, int x0, int s0, int s1, int a,
                                 int b, int *fq)
{
    for (int x = s0; x < a; x++) fq[x - x0] = chunk_tap(g, cc, ci, x - x0, dy);
    for (int x = b; x < s1; x++) fq[x - x0] = chunk_tap(g, cc, ci, x - x0, dy);
}

/* ---- create / destroy */

/* Every float buffer with its length in floats per pixel, for allocation and release in one place. */
static int float_buffers(fv_svgf *f, float ***ptr, int *per_pixel)
{
    int k = 0;
#define BUF(p, m) (ptr[k] = &(p), per_pixel[k] = (m), k++)
    BUF(f->surf, 1);
    BUF(f->gvar, 1);
    BUF(f->grad, 1);
    BUF(f->hist_illum, 3);
    BUF(f->hist_pos, 3);
    for (int i = 0; i < 2; i++) {
        BUF(f->nx[i], 1);
        BUF(f->ny[i], 1);
        BUF(f->nz[i], 1);
        BUF(f->z[i], 1);
        BUF(f->m1[i], 1);
        BUF(f->m2[i], 1);
        BUF(f->len[i], 1);
        for (int c = 0; c < NVAL; c++) BUF(f->val[i][c], 1);
    }
#undef BUF
    return k;
}

#define MAX_BUFFERS 40

static void free_buffers(fv_svgf *f)
{
    float **ptr[MAX_BUFFERS];
    int pp[MAX_BUFFERS];
    int nb = float_buffers(f, ptr, pp);
    for (int i = 0; i < nb; i++) free(*ptr[i]);
    free(f->kind), free(f->hist_id);
    free(f->row_surface), free(f->row_hist), free(f->row_holes), free(f->row_len);
}

fv_status fv_svgf_create(const fv_grid *grid, const fv_svgf_opts *o, fv_svgf **out, fv_error *err)
{
    if (!out) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no output handle");
    *out = NULL;
    fv_svgf_opts def;
    if (!o) {
        fv_svgf_opts_default(&def);
        o = &def;
    }
    fv_status s = fv_svgf_opts_validate(o, err);
    if (s != FV_OK) return s;
    if (!grid || grid->w < 1 || grid->h < 1)
        return fv_error_set(err, FV_ERR_INVALID, "SVGF: grid size %dx%d", grid ? grid->w : 0, grid ? grid->h : 0);
    if (grid->col_h)
        for (int x = 0; x < grid->w; x++)
            if (grid->col_h[x] < 1 || grid->col_h[x] > grid->h)
                return fv_error_set(err, FV_ERR_INVALID, "SVGF: column %d has %d rows, not in [1, %d]", x, grid->col_h[x],
                                    grid->h);
    /* Pixel indices are ints in the inner loops (what the vectoriser can gather with). */
    if ((long long)grid->w * grid->h > INT32_MAX)
        return fv_error_set(err, FV_ERR_INVALID, "SVGF: grid %dx%d is too large", grid->w, grid->h);
    fv_svgf *f = calloc(1, sizeof *f);
    if (!f) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the SVGF filter");
    f->g = *grid;
    f->o = *o;
    f->n = (size_t)grid->w * (size_t)grid->h;
    f->normal_squarings = -1;
    for (int k = 0; k <= 16; k++)
        if (o->sigma_normal == (float)(1 << k)) f->normal_squarings = k;
    f->full_from = grid->w;
    while (f->full_from > 0 && fv_grid_col_h(grid, f->full_from - 1) == grid->h) f->full_from--;
    /* Zeroed memory: the pixels that are never surfaces keep zero features and values. */
    size_t n = f->n, h = (size_t)grid->h;
    float **ptr[MAX_BUFFERS];
    int pp[MAX_BUFFERS];
    int nb = float_buffers(f, ptr, pp);
    bool ok = true;
    for (int i = 0; i < nb && ok; i++) ok = (*ptr[i] = fv_calloc_array(n, pp[i] * sizeof(float))) != NULL;
    ok = ok && (f->kind = fv_calloc_array(n, 1)) != NULL;
    ok = ok && (f->hist_id = fv_calloc_array(n, sizeof(uint32_t))) != NULL;
    ok = ok && (f->row_surface = fv_calloc_array(h, sizeof(long))) != NULL;
    ok = ok && (f->row_hist = fv_calloc_array(h, sizeof(long))) != NULL;
    ok = ok && (f->row_holes = fv_calloc_array(h, sizeof(long))) != NULL;
    ok = ok && (f->row_len = fv_calloc_array(h, sizeof(double))) != NULL;
    if (!ok) {
        free_buffers(f);
        free(f);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for SVGF buffers of a %dx%d grid", grid->w, grid->h);
    }
    *out = f;
    return FV_OK;
}

void fv_svgf_destroy(fv_svgf *f)
{
    if (!f) return;
    free_buffers(f);
    free(f);
}

void fv_svgf_reset(fv_svgf *f)
{
    if (f) f->have_history = false;
}

/* ---- A. classification, demodulation, temporal accumulation */

/* The history at prev_coord (X, V), blended from the consistent taps of a bilinear lookup:
 * out = (r, g, b, m1, m2, length). False when there is none. */
static bool fetch_history(const fv_svgf *f, const float *pc, const float *np, const float *xp, float depth, uint32_t id,
                          float out[6])
{
    const fv_grid *g = &f->g;
    float X = pc[0], V = pc[1];
    if (!isfinite(X) || !isfinite(V)) return false;
    if (!g->wrap) {
        if (X < 0.0f || X > (float)g->w || V < 0.0f || V > 1.0f) return false;
    } else {
        /* Columns clamp (the lookup would clamp them anyway; this keeps floorf's result in int
         * range), rows wrap. */
        X = X < 0.0f ? 0.0f : (X > (float)g->w ? (float)g->w : X);
        if (V < 0.0f || V >= 1.0f) V -= floorf(V);
    }
    long idx[4];
    float wt[4];
    fv_grid_bilinear(g, X, V, idx, wt);
    float ax = fabsf(xp[0]), ay = fabsf(xp[1]), az = fabsf(xp[2]), big = ax > ay ? ax : ay;
    big = big > az ? big : az;
    float tol = HIST_POS_REL * (depth > HIST_DEPTH_MIN ? depth : HIST_DEPTH_MIN) + HIST_POS_ULP * big;
    float tol2 = tol * tol;
    const float *pnx = f->nx[1], *pny = f->ny[1], *pnz = f->nz[1], *plen = f->len[1];
    float acc[6] = {0, 0, 0, 0, 0, 0}, wsum = 0.0f;
    for (int k = 0; k < 4; k++) {
        long q = idx[k];
        /* Length 0 marks every pixel that cannot serve as history: rows beyond the column's
         * height, no surface, no path, non-finite input. */
        if (!(wt[k] > 0.0f) || !(plen[q] > 0.0f) || f->hist_id[q] != id) continue;
        if (!(pnx[q] * np[0] + pny[q] * np[1] + pnz[q] * np[2] > HIST_COS)) continue;
        const float *xq = &f->hist_pos[3 * q];
        float dx = xq[0] - xp[0], dy = xq[1] - xp[1], dz = xq[2] - xp[2];
        if (!(dx * dx + dy * dy + dz * dz < tol2)) continue;
        const float *c = &f->hist_illum[3 * q];
        acc[0] += wt[k] * c[0];
        acc[1] += wt[k] * c[1];
        acc[2] += wt[k] * c[2];
        acc[3] += wt[k] * f->m1[1][q];
        acc[4] += wt[k] * f->m2[1][q];
        acc[5] += wt[k] * plen[q];
        wsum += wt[k];
    }
    if (wsum < HIST_MIN_WEIGHT) return false;
    for (int k = 0; k < 6; k++) out[k] = acc[k] / wsum;
    return true;
}

static void sweep_accumulate(fv_svgf *f, const fv_svgf_frame *fr, bool history, int nt)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const float ac = f->o.alpha_color, am = f->o.alpha_moments;
    float *const *v = f->val[0];
    #pragma omp parallel for schedule(static, ROWS_PER_BLOCK) num_threads(nt)
    for (int y = 0; y < h; y++) {
        long n_surface = 0, n_hist = 0, n_holes = 0;
        double len_sum = 0.0;
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            const float *np = &fr->normal[3 * p];
            uint8_t k = KIND_NONE;
            if (y < fv_grid_col_h(g, x)) {
                if (fr->sampled && !fr->sampled[p]) {
                    k = KIND_HOLE;
                } else if (np[0] != 0.0f || np[1] != 0.0f || np[2] != 0.0f) {
                    const float *c = &fr->color[3 * p], *a = &fr->albedo[3 * p], *xp = &fr->position[3 * p];
                    float all = c[0] + c[1] + c[2] + a[0] + a[1] + a[2] + np[0] + np[1] + np[2] + fr->depth[p] + xp[0] +
                                xp[1] + xp[2];
                    k = isfinite(all) ? KIND_SURFACE : KIND_HOLE;
                }
            }
            f->kind[p] = k;
            if (k != KIND_SURFACE) {
                n_holes += k == KIND_HOLE;
                f->surf[p] = 0.0f;
                f->nx[0][p] = f->ny[0][p] = f->nz[0][p] = f->z[0][p] = 0.0f;
                for (int c = 0; c < NVAL; c++) v[c][p] = 0.0f;
                f->m1[0][p] = f->m2[0][p] = f->len[0][p] = 0.0f;
                continue;
            }
            n_surface++;
            const float *c = &fr->color[3 * p], *a = &fr->albedo[3 * p];
            float il[3];
            for (int ch = 0; ch < 3; ch++) il[ch] = c[ch] / demod_albedo(a[ch]);
            f->surf[p] = 1.0f;
            f->nx[0][p] = np[0], f->ny[0][p] = np[1], f->nz[0][p] = np[2], f->z[0][p] = fr->depth[p];
            float l = luminance(il[0], il[1], il[2]), m1 = l, m2 = l * l, n_len = 1.0f;
            float hst[6];
            if (history && fetch_history(f, &fr->prev_coord[2 * p], np, &fr->position[3 * p], fr->depth[p], fr->id[p], hst)) {
                n_len = hst[5] + 1.0f < LEN_MAX ? hst[5] + 1.0f : LEN_MAX;
                /* The new sample's weight: 1 / length (a plain mean) until that falls below alpha. */
                float inv = 1.0f / n_len, wc = ac > inv ? ac : inv, wm = am > inv ? am : inv;
                for (int ch = 0; ch < 3; ch++) il[ch] = hst[ch] + wc * (il[ch] - hst[ch]);
                m1 = hst[3] + wm * (m1 - hst[3]);
                m2 = hst[4] + wm * (m2 - hst[4]);
                l = luminance(il[0], il[1], il[2]);
                n_hist++;
                len_sum += n_len;
            }
            v[V_R][p] = il[0], v[V_G][p] = il[1], v[V_B][p] = il[2], v[V_VAR][p] = 0.0f, v[V_LUM][p] = l;
            f->m1[0][p] = m1;
            f->m2[0][p] = m2;
            f->len[0][p] = n_len;
        }
        f->row_surface[y] = n_surface;
        f->row_hist[y] = n_hist;
        f->row_holes[y] = n_holes;
        f->row_len[y] = len_sum;
    }
}

/* ---- B. depth gradient and variance */

/* Along one axis: the smaller one-sided difference to a surface neighbour (see the top of the file). */
static inline float axis_gradient(const fv_svgf *f, long qm, long qp, float zc)
{
    const float *z = f->z[0];
    float dm = qm >= 0 && f->kind[qm] == KIND_SURFACE ? fabsf(zc - z[qm]) : INFINITY;
    float dp = qp >= 0 && f->kind[qp] == KIND_SURFACE ? fabsf(z[qp] - zc) : INFINITY;
    float d = fminf(dm, dp);
    return isfinite(d) ? d : 0.0f;
}

/* One tap of the 7x7 moments estimate, pixel p (chunk slot k) taking pixel q. */
TAP_INLINE void moments_tap(const fv_svgf *f, size_t p, int q, int k, float rz, int sq, float sn, float *a1, float *a2,
                               float *aw)
{
    const float *nx = f->nx[0], *ny = f->ny[0], *nz = f->nz[0], *z = f->z[0];
    float wn = normal_pow(nx[p] * nx[q] + ny[p] * ny[q] + nz[p] * nz[q], sq, sn);
    float wt = wn * exp_neg(fabsf(z[p] - z[q]) * rz);
    a1[k] += wt * f->m1[0][q];
    a2[k] += wt * f->m2[0][q];
    aw[k] += wt;
}

static void sweep_variance(fv_svgf *f, int nt)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const uint8_t *kind = f->kind;
    const float sd = f->o.sigma_depth, sn = f->o.sigma_normal;
    const int sq = f->normal_squarings;
    float *var = f->val[0][V_VAR], *grad = f->grad;
    const float *m1 = f->m1[0], *m2 = f->m2[0], *len = f->len[0];
    /* The 48 taps of the 7x7 window, the distance classes of their squared distances
     * (1, 2, 4, 5, 8, 9, 10, 13, 18). */
    int di[NTAP7], dj[NTAP7], cls[NTAP7];
    const int d2s[9] = {1, 2, 4, 5, 8, 9, 10, 13, 18};
    float dist[9];
    for (int c = 0; c < 9; c++) dist[c] = sqrtf((float)d2s[c]);
    for (int j = 0, t = 0; j < 7; j++)
        for (int i = 0; i < 7; i++) {
            if (i == 3 && j == 3) continue;
            int d2 = (i - 3) * (i - 3) + (j - 3) * (j - 3);
            di[t] = i - 3, dj[t] = j - 3;
            for (int c = 0; c < 9; c++)
                if (d2s[c] == d2) cls[t] = c;
            t++;
        }
    #pragma omp parallel for schedule(static, ROWS_PER_BLOCK) num_threads(nt)
    for (int y = 0; y < h; y++) {
        float a1[CHUNK], a2[CHUNK], aw[CHUNK], rz[9][CHUNK];
        int fq[CHUNK];
        chunk_cols cc;
        for (int x0 = 0; x0 < w; x0 += CHUNK) {
            const int x1 = imin(x0 + CHUNK, w), nc = x1 - x0;
            const size_t p0 = (size_t)y * w + x0;
            /* Every pixel's depth gradient (each reads only its neighbours' depths) and temporal
             * variance; the 7x7 estimate below replaces the variance of the young ones. */
            bool young = false;
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                if (kind[p] != KIND_SURFACE) continue;
                const int x = x0 + k;
                const float zc = f->z[0][p];
                float gx = axis_gradient(f, fv_grid_tap(g, x, y, -1, 0), fv_grid_tap(g, x, y, 1, 0), zc);
                float gy = axis_gradient(f, fv_grid_tap(g, x, y, 0, -1), fv_grid_tap(g, x, y, 0, 1), zc);
                grad[p] = gx > gy ? gx : gy;
                float tv = m2[p] - m1[p] * m1[p];
                var[p] = tv > 0.0f ? tv : 0.0f;
                young = young || len[p] < VAR_TEMPORAL_LEN;
            }
            int s0, s1;
            if (!young || !surface_span(kind, p0, x0, x1, &s0, &s1)) continue;
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                float zs = sd * grad[p], ze = depth_eps(f->z[0][p]);
                for (int c = 0; c < 9; c++) rz[c][k] = 1.0f / (zs * dist[c] + ze);
                a1[k] = m1[p], a2[k] = m2[p], aw[k] = 1.0f; /* the centre, weight 1 */
            }
            cc.ready = false;
            for (int t = 0; t < NTAP7; t++) {
                int a, b;
                long off;
                tap_run(f, y, di[t], dj[t], s0, s1, &a, &b, &off);
                const float *rzc = rz[cls[t]];
                if (sq == SQ_DEFAULT) {
                    #pragma omp simd
                    for (int x = a; x < b; x++)
                        moments_tap(f, p0 + (x - x0), (int)off + x, x - x0, rzc[x - x0], SQ_DEFAULT, sn, a1, a2, aw);
                } else {
                    for (int x = a; x < b; x++)
                        moments_tap(f, p0 + (x - x0), (int)off + x, x - x0, rzc[x - x0], sq, sn, a1, a2, aw);
                }
                if (!g->wrap || (a == s0 && b == s1)) continue;
                if (!cc.ready) chunk_columns(g, y, x0, nc, 1, 7, &cc);
                fallback_taps(g, &cc, di[t] + 3, dj[t], x0, s0, s1, a, b, fq);
                for (int r = 0; r < 2; r++) {
                    const int lo = r ? b : s0, hi = r ? s1 : a;
                    if (sq == SQ_DEFAULT) {
                        #pragma omp simd
                        for (int x = lo; x < hi; x++)
                            moments_tap(f, p0 + (x - x0), fq[x - x0], x - x0, rzc[x - x0], SQ_DEFAULT, sn, a1, a2, aw);
                    } else {
                        for (int x = lo; x < hi; x++)
                            moments_tap(f, p0 + (x - x0), fq[x - x0], x - x0, rzc[x - x0], sq, sn, a1, a2, aw);
                    }
                }
            }
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                if (kind[p] != KIND_SURFACE || len[p] >= VAR_TEMPORAL_LEN) continue;
                float mean1 = a1[k] / aw[k], mean2 = a2[k] / aw[k], sv = mean2 - mean1 * mean1;
                var[p] = sv > 0.0f ? sv : 0.0f;
            }
        }
    }
}

/* ---- C. the À-Trous passes */

/* The variance that guides the luminance weight, prefiltered with a 3x3 Gaussian over the surface
 * neighbours (Sec. 4.3: one pixel's variance estimate is itself noisy). */
static void sweep_prefilter(fv_svgf *f, const float *var, int nt)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const uint8_t *kind = f->kind;
    const float *surf = f->surf;
    float *gvar = f->gvar;
    #pragma omp parallel for schedule(static, ROWS_PER_BLOCK) num_threads(nt)
    for (int y = 0; y < h; y++) {
        float av[CHUNK], aw[CHUNK];
        int fq[CHUNK];
        chunk_cols cc;
        for (int x0 = 0; x0 < w; x0 += CHUNK) {
            const int x1 = imin(x0 + CHUNK, w), nc = x1 - x0;
            const size_t p0 = (size_t)y * w + x0;
            int s0, s1;
            if (!surface_span(kind, p0, x0, x1, &s0, &s1)) {
                memset(&gvar[p0], 0, (size_t)nc * sizeof(float));
                continue;
            }
            for (int k = 0; k < nc; k++) av[k] = aw[k] = 0.0f;
            cc.ready = false;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    const float kk = k_g3[i] * k_g3[j];
                    int a, b;
                    long off;
                    tap_run(f, y, i - 1, j - 1, s0, s1, &a, &b, &off);
                    #pragma omp simd
                    for (int x = a; x < b; x++) {
                        av[x - x0] += kk * var[off + x];
                        aw[x - x0] += kk * surf[off + x];
                    }
                    if (!g->wrap || (a == s0 && b == s1)) continue;
                    if (!cc.ready) chunk_columns(g, y, x0, nc, 1, 3, &cc);
                    fallback_taps(g, &cc, i, j - 1, x0, s0, s1, a, b, fq);
                    for (int r = 0; r < 2; r++) {
                        const int lo = r ? b : s0, hi = r ? s1 : a;
                        #pragma omp simd
                        for (int x = lo; x < hi; x++) {
                            av[x - x0] += kk * var[fq[x - x0]];
                            aw[x - x0] += kk * surf[fq[x - x0]];
                        }
                    }
                }
            /* Not a surface: aw may be 0 (no surface around), and the value is never read. */
            for (int k = 0; k < nc; k++) gvar[p0 + k] = kind[p0 + k] == KIND_SURFACE ? av[k] / aw[k] : 0.0f;
        }
    }
}

/* The sums of one pass over a chunk, and the per-pixel terms of its weights. */
typedef struct pass_acc {
    float r[CHUNK], g[CHUNK], b[CHUNK], v[CHUNK], w[CHUNK];
    float inv_l[CHUNK];
    float rz[5][CHUNK];
} pass_acc;

/* The buffers a pass reads. */
typedef struct pass_src {
    const float *nx, *ny, *nz, *z;
    const float *r, *g, *b, *v, *l;
} pass_src;

/* One tap of a pass, pixel p (chunk slot k) taking pixel q with kernel weight kw. */
TAP_INLINE void atrous_tap(const pass_src *s, size_t p, int q, int k, float kw, const float *rz, int sq, float sn,
                              pass_acc *acc)
{
    float wn = normal_pow(s->nx[p] * s->nx[q] + s->ny[p] * s->ny[q] + s->nz[p] * s->nz[q], sq, sn);
    float e = fabsf(s->z[p] - s->z[q]) * rz[k] + fabsf(s->l[p] - s->l[q]) * acc->inv_l[k];
    float wt = kw * wn * exp_neg(e);
    acc->r[k] += wt * s->r[q];
    acc->g[k] += wt * s->g[q];
    acc->b[k] += wt * s->b[q];
    acc->v[k] += wt * wt * s->v[q];
    acc->w[k] += wt;
}

/* One pass with taps `step` apart from val[src] to val[1 - src]; the first also writes the history. */
static void sweep_atrous(fv_svgf *f, int step, int src, bool write_hist, int nt)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const uint8_t *kind = f->kind;
    const float sd = f->o.sigma_depth, sn = f->o.sigma_normal, sl = f->o.sigma_lum;
    const int sq = f->normal_squarings;
    float *const *dst = f->val[1 - src];
    const float *grad = f->grad, *gvar = f->gvar;
    const pass_src s = {f->nx[0], f->ny[0], f->nz[0], f->z[0], f->val[src][V_R], f->val[src][V_G],
                        f->val[src][V_B], f->val[src][V_VAR], f->val[src][V_LUM]};
    /* The taps around the centre: kernel weight, offsets, and the distance class (1, sqrt 2, 2,
     * sqrt 5, sqrt 8 times the step). */
    float kw[NTAP];
    int cls[NTAP], di[NTAP], dj[NTAP];
    const float dist[5] = {1.0f, sqrtf(2.0f), 2.0f, sqrtf(5.0f), sqrtf(8.0f)};
    for (int j = 0, t = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            if (i == 2 && j == 2) continue;
            int d2 = (i - 2) * (i - 2) + (j - 2) * (j - 2);
            kw[t] = k_b3[i] * k_b3[j];
            cls[t] = d2 == 1 ? 0 : d2 == 2 ? 1 : d2 == 4 ? 2 : d2 == 5 ? 3 : 4;
            di[t] = (i - 2) * step, dj[t] = (j - 2) * step;
            t++;
        }
    const float wc = k_b3[2] * k_b3[2];
    #pragma omp parallel for schedule(static, ROWS_PER_BLOCK) num_threads(nt)
    for (int y = 0; y < h; y++) {
        pass_acc acc;
        int fq[CHUNK];
        chunk_cols cc;
        for (int x0 = 0; x0 < w; x0 += CHUNK) {
            const int x1 = imin(x0 + CHUNK, w), nc = x1 - x0;
            const size_t p0 = (size_t)y * w + x0;
            int s0, s1;
            if (!surface_span(kind, p0, x0, x1, &s0, &s1)) {
                for (int c = 0; c < NVAL; c++) memset(&dst[c][p0], 0, (size_t)nc * sizeof(float));
                continue;
            }
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                acc.inv_l[k] = 1.0f / (sl * sqrtf(gvar[p]) + LUM_EPS);
                /* 1 / (sigma_depth |grad z| |p - q| + eps) for the five distances. */
                float zs = sd * grad[p] * (float)step, ze = depth_eps(s.z[p]);
                for (int c = 0; c < 5; c++) acc.rz[c][k] = 1.0f / (zs * dist[c] + ze);
                acc.r[k] = wc * s.r[p], acc.g[k] = wc * s.g[p], acc.b[k] = wc * s.b[p];
                acc.v[k] = wc * wc * s.v[p], acc.w[k] = wc;
            }
            cc.ready = false;
            for (int t = 0; t < NTAP; t++) {
                int a, b;
                long off;
                tap_run(f, y, di[t], dj[t], s0, s1, &a, &b, &off);
                const float *rz = acc.rz[cls[t]];
                if (sq == SQ_DEFAULT) {
                    #pragma omp simd
                    for (int x = a; x < b; x++)
                        atrous_tap(&s, p0 + (x - x0), (int)off + x, x - x0, kw[t], rz, SQ_DEFAULT, sn, &acc);
                } else {
                    for (int x = a; x < b; x++) atrous_tap(&s, p0 + (x - x0), (int)off + x, x - x0, kw[t], rz, sq, sn, &acc);
                }
                if (!g->wrap || (a == s0 && b == s1)) continue;
                if (!cc.ready) chunk_columns(g, y, x0, nc, step, 5, &cc);
                fallback_taps(g, &cc, di[t] / step + 2, dj[t], x0, s0, s1, a, b, fq);
                for (int r = 0; r < 2; r++) {
                    const int lo = r ? b : s0, hi = r ? s1 : a;
                    if (sq == SQ_DEFAULT) {
                        #pragma omp simd
                        for (int x = lo; x < hi; x++)
                            atrous_tap(&s, p0 + (x - x0), fq[x - x0], x - x0, kw[t], rz, SQ_DEFAULT, sn, &acc);
                    } else {
                        for (int x = lo; x < hi; x++)
                            atrous_tap(&s, p0 + (x - x0), fq[x - x0], x - x0, kw[t], rz, sq, sn, &acc);
                    }
                }
            }
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                if (kind[p] != KIND_SURFACE) {
                    for (int c = 0; c < NVAL; c++) dst[c][p] = 0.0f;
                    continue;
                }
                /* Divisions, not a reciprocal: a mean of equal values then comes out exactly equal. */
                float ws = acc.w[k], r = acc.r[k] / ws, gg = acc.g[k] / ws, b = acc.b[k] / ws;
                dst[V_R][p] = r, dst[V_G][p] = gg, dst[V_B][p] = b;
                dst[V_VAR][p] = acc.v[k] / (ws * ws);
                dst[V_LUM][p] = luminance(r, gg, b);
                if (write_hist) f->hist_illum[3 * p] = r, f->hist_illum[3 * p + 1] = gg, f->hist_illum[3 * p + 2] = b;
            }
        }
    }
}

/* ---- D. remodulation and the history of the next frame */

static void sweep_finish(fv_svgf *f, const fv_svgf_frame *fr, int cur, bool copy_hist, int nt)
{
    const int w = f->g.w, h = f->g.h;
    float *const *v = f->val[cur];
    #pragma omp parallel for schedule(static, ROWS_PER_BLOCK) num_threads(nt)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            if (f->kind[p] != KIND_SURFACE) continue;
            const float il[3] = {v[V_R][p], v[V_G][p], v[V_B][p]};
            const float *a = &fr->albedo[3 * p];
            for (int ch = 0; ch < 3; ch++) fr->color[3 * p + ch] = il[ch] * demod_albedo(a[ch]);
            if (copy_hist) memcpy(&f->hist_illum[3 * p], il, sizeof il);
            memcpy(&f->hist_pos[3 * p], &fr->position[3 * p], 3 * sizeof(float));
            f->hist_id[p] = fr->id[p];
        }
}

/* ---- E. holes: the B3-weighted mean of the filtered surface pixels at the smallest spacing that
 * reaches any, no edge-stopping (the hole's own features are unknown). */

static void sweep_holes(fv_svgf *f, float *color, int nt)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const uint8_t *kind = f->kind;
    const int max_step = f->o.iterations > 1 ? 1 << (f->o.iterations - 1) : 1;
    #pragma omp parallel for schedule(static, ROWS_PER_BLOCK) num_threads(nt)
    for (int y = 0; y < h; y++) {
        if (!f->row_holes[y]) continue;
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            if (kind[p] != KIND_HOLE) continue;
            float s[3] = {0, 0, 0}, ws = 0.0f;
            for (int step = 1; step <= max_step && ws == 0.0f; step *= 2)
                for (int j = 0; j < 5; j++)
                    for (int i = 0; i < 5; i++) {
                        long q = fv_grid_tap(g, x, y, (i - 2) * step, (j - 2) * step);
                        if (q < 0 || kind[q] != KIND_SURFACE) continue;
                        float k = k_b3[i] * k_b3[j];
                        s[0] += k * color[3 * q];
                        s[1] += k * color[3 * q + 1];
                        s[2] += k * color[3 * q + 2];
                        ws += k;
                    }
            for (int ch = 0; ch < 3; ch++) color[3 * p + ch] = ws > 0.0f ? s[ch] / ws : 0.0f;
        }
    }
}

/* ---- the frame */

static void swap_buffers(float *b[2])
{
    float *t = b[0];
    b[0] = b[1];
    b[1] = t;
}

fv_status fv_svgf_filter(fv_svgf *f, const fv_svgf_frame *fr, int threads, fv_svgf_info *info, fv_error *err)
{
    if (!f) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no filter");
    if (!fr) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no frame buffers");
    const struct {
        const char *name;
        const void *p;
    } need[6] = {{"color", fr->color}, {"albedo", fr->albedo}, {"normal", fr->normal},
                 {"depth", fr->depth}, {"position", fr->position}, {"id", fr->id}};
    for (int i = 0; i < 6; i++)
        if (!need[i].p) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no %s buffer", need[i].name);
    const int nt = fv_thread_count(threads);
    const bool history = f->have_history && fr->prev_coord;

    sweep_accumulate(f, fr, history, nt);
    sweep_variance(f, nt);
    int cur = 0;
    for (int it = 0; it < f->o.iterations; it++) {
        sweep_prefilter(f, f->val[cur][V_VAR], nt);
        sweep_atrous(f, 1 << it, cur, it == 0, nt);
        cur = 1 - cur;
    }
    sweep_finish(f, fr, cur, f->o.iterations == 0, nt);

    long n_surface = 0, n_hist = 0, n_holes = 0;
    double len_sum = 0.0;
    for (int y = 0; y < f->g.h; y++) {
        n_surface += f->row_surface[y];
        n_hist += f->row_hist[y];
        n_holes += f->row_holes[y];
        len_sum += f->row_len[y];
    }
    if (n_holes) sweep_holes(f, fr->color, nt);

    /* This frame's features, moments and lengths become the history (the working values need no
     * swap: sweep A rewrites val[0] whole every frame). */
    swap_buffers(f->nx);
    swap_buffers(f->ny);
    swap_buffers(f->nz);
    swap_buffers(f->z);
    swap_buffers(f->m1);
    swap_buffers(f->m2);
    swap_buffers(f->len);
    f->have_history = true;
    if (info) {
        info->history_fraction = n_surface ? (double)n_hist / (double)n_surface : 0.0;
        info->mean_history = n_hist ? len_sum / (double)n_hist : 0.0;
    }
    return FV_OK;
}
