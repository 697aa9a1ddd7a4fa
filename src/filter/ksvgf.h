/* fovea — SVGF (filter/svgf.h: Schied et al., HPG 2017) as kernel code: each step of a frame as a
 * function of one pixel, over a flat description of the grid, the frame's buffers and the filter's
 * state (fv_ksvgf). The portable backend runs them over tiles on the CPU's threads
 * (technique/vpolar/vp_device.c), CUDA a thread per pixel; the CPU filter (filter/svgf.c) calls the
 * per-pixel steps that are not its vectorised sweeps (classification and history, remodulation,
 * hole fill, the counters) and shares the arithmetic of the others (the weights, the exponential,
 * the grid's taps), so those exist once.
 *
 * Bits: every pixel adds its taps in the order of fv_svgf's FV_SVGF_ISA_PLAIN build (svgf.h), with
 * the same float operations (no FMA: nvcc builds with --fmad=false), so a frame run through these
 * steps gives the same bits as fv_svgf_filter, history included (tests/unit/test_kernel_svgf.c).
 * One exception on a GPU: a sigma_normal that is not a power of two goes through powf, which CUDA
 * rounds differently from the C library (within 2 ulp); the default 128 is seven squarings, exact
 * everywhere.
 *
 * A frame, each step one launch over every pixel (x, y) of the w x h storage, in this order; a
 * step reads its neighbours' results of the step before, so no two may share a launch:
 *   1. fv_ksvgf_accumulate_pixel  classify, demodulate, fetch and blend the history;
 *   2. fv_ksvgf_variance_pixel    depth gradient and variance (reads step 1's neighbours);
 *   for pass = 0 .. iterations - 1:
 *   3. fv_ksvgf_prefilter_pixel   the 3x3-prefiltered variance of the pass's input;
 *   4. fv_ksvgf_atrous_pixel      the pass (val[pass & 1] -> val[1 - (pass & 1)]);
 *      or 3+4 in one launch: fv_ksvgf_prefilter_atrous_pixel (a pass reads the prefiltered
 *      variance of its own pixel only, so it can compute it; the same bits);
 *   5. fv_ksvgf_finish_pixel      remodulate into colour, this frame's history positions and ids
 *                                 (reads its own pixel only: may also run at the end of the last
 *                                 pass's launch, in the same thread);
 *   6. fv_ksvgf_hole_pixel        the pixels without a path (reads step 5's colours; only when
 *                                 a row count of holes is non-zero, but harmless otherwise);
 *   7. fv_ksvgf_count_row         one call per row (after step 1, any time): the row's counters,
 *                                 summed on the host by fv_ksvgf_sum_rows for fv_svgf_info.
 * Then the host swaps the current and previous feature buffers (fv_ksvgf_swap) for the next frame.
 */
#ifndef FV_FILTER_KSVGF_H
#define FV_FILTER_KSVGF_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "filter/demod.h"
#include "filter/grid.h"
#include "fovea/math.h"

#define FV_KSVGF_LEN_MAX 256.0f
#define FV_KSVGF_HIST_MIN_WEIGHT 0.01f
#define FV_KSVGF_HIST_COS 0.9f       /* normals within ~25 degrees */
#define FV_KSVGF_HIST_POS_REL 0.05f  /* position tolerance, fraction of the depth */
#define FV_KSVGF_HIST_DEPTH_MIN 1e-3f
#define FV_KSVGF_HIST_POS_ULP 1e-5f  /* plus this fraction of the coordinates' size: float rounding */
#define FV_KSVGF_DEPTH_EPS_REL 1e-4f /* depth differences this small relative to the depth are free */
#define FV_KSVGF_LUM_EPS 1e-10f
#define FV_KSVGF_VAR_TEMPORAL_LEN 4.0f
/* The B3 spline's 5 weights (1, 4, 6, 4, 1) / 16 and the 3x3 Gaussian's (1, 2, 1) / 4. */
#define FV_KSVGF_B3_0 (1.0f / 16)
#define FV_KSVGF_B3_1 (1.0f / 4)
#define FV_KSVGF_B3_2 (3.0f / 8)
#define FV_KSVGF_G3_0 0.25f
#define FV_KSVGF_G3_1 0.5f

/* The CPU's vectorised loops need these inlined (filter/svgf_impl.h). */
#if defined(__GNUC__) && !defined(__CUDACC__)
#define FV_KSVGF_INLINE static inline __attribute__((always_inline))
#else
#define FV_KSVGF_INLINE static inline
#endif

/* What a pixel is this frame (kind): never filtered / a surface / a hole to fill. */
enum { FV_KSVGF_NONE = 0, FV_KSVGF_SURFACE = 1, FV_KSVGF_HOLE = 2 };
/* fv_ksvgf_accumulate_pixel's result: the kinds, and a surface that found its history. */
enum { FV_KSVGF_SURFACE_HIST = 3 };
/* The working values of a pixel: demodulated rgb, variance, luminance. */
enum { FV_KSVGF_R, FV_KSVGF_G, FV_KSVGF_B, FV_KSVGF_VAR, FV_KSVGF_LUM, FV_KSVGF_NVAL };

/* Everything the steps read and write. Buffers are w * h pixels of the grid's storage (3 floats a
 * pixel where noted), on the device that runs the kernels; all zeroed at creation (pixels that are
 * never surfaces keep zero features and values, and weigh exactly 0 as taps). */
typedef struct fv_ksvgf {
    fv_grid g;                  /* w, h, col_h (device copy), wrap */
    /* options (filter/svgf.h, fv_svgf_opts) */
    float alpha_color, alpha_moments, sigma_depth, sigma_normal, sigma_lum;
    int iterations;
    int sq;                     /* sigma_normal = 2^sq (sq <= 16): squarings; -1: powf */
    int periph_x, periph_passes; /* fv_svgf_set_periphery: columns from periph_x get periph_passes passes */
    bool history;               /* this frame fetches history (a previous frame and prev_coord) */
    /* this frame's inputs (fv_svgf_frame) */
    float *color;               /* 3: in the noisy radiance, out (steps 5, 6) the filtered */
    const float *albedo, *normal, *depth, *position, *prev_coord; /* 3, 3, 1, 3, 2 */
    const uint32_t *id;
    const uint8_t *sampled, *active; /* NULL: every pixel */
    /* state */
    uint8_t *kind;
    uint8_t *found;             /* 1: a surface with history this frame; NULL: not kept (the CPU's
                                   filter counts as it goes; fv_ksvgf_count_row needs it) */
    float *surf;                /* 1 on a surface, else 0 (the prefilter's weights) */
    float *gvar, *grad;         /* the pass's prefiltered variance; the depth gradient */
    float *nx, *ny, *nz, *z, *m1, *m2, *len;   /* this frame's features, moments, history length */
    const float *pnx, *pny, *pnz, *pm1, *pm2, *plen; /* the previous frame's (fv_ksvgf_swap) */
    float *pz;                  /* the previous frame's depth (only swapped) */
    float *val[2][FV_KSVGF_NVAL]; /* ping-pong over the passes */
    float *hist_illum, *hist_pos; /* 3, 3: illumination after the first pass, positions */
    uint32_t *hist_id;
    long *row_surface, *row_hist, *row_holes; /* h each: step 7 */
    double *row_len;
} fv_ksvgf;

/* ---- arithmetic shared with the CPU sweeps (filter/svgf_impl.h) */

FV_HD FV_KSVGF_INLINE float fv_ksvgf_luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

/* The depth term's floor: differences below 1e-4 of the depth are rounding. */
FV_HD FV_KSVGF_INLINE float fv_ksvgf_depth_eps(float z) { return FV_KSVGF_DEPTH_EPS_REL * fabsf(z) + 1e-30f; }

/* e^-x for x >= 0, inline (a call to expf per tap was a quarter of the CPU's frame): 2^t with
 * t = -x log2(e) split into an integer i and a fraction whose e^a, a in [-ln2 / 2, ln2 / 2], comes
 * from its Taylor series to the 5th power (truncation error below 2.5e-6, evaluated in Estrin's
 * form: half the dependent operations of Horner's), and 2^i through the exponent bits. Relative
 * error below 4e-6 for x < 10 and 5e-6 up to 87; exactly 1 at 0; exactly 0 from 87 on (where expf
 * is below 2e-38), for +inf and NaN. Branch-free, with the selects on integers (for x >= 0 the
 * bits order like the values), so that the CPU's loops over taps vectorise; the same bits on any
 * IEEE machine without FMA contraction. */
FV_HD FV_KSVGF_INLINE float fv_ksvgf_exp_neg(float x)
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

/* max(0, c)^sn: sq squarings when sn = 2^sq, else powf. (c + |c|) / 2 is max(c, 0) exactly in a
 * form that vectorises. */
FV_HD FV_KSVGF_INLINE float fv_ksvgf_normal_pow(float c, int sq, float sn)
{
    c = 0.5f * (c + fabsf(c));
    if (sq < 0) return powf(c, sn);
    for (int k = 0; k < sq; k++) c *= c;
    return c;
}

/* The B3 weight of tap column (or row) i of 5, and the 3x3 Gaussian's of i of 3. */
FV_HD FV_KSVGF_INLINE float fv_ksvgf_b3(int i) { return i == 2 ? FV_KSVGF_B3_2 : (i == 1 || i == 3) ? FV_KSVGF_B3_1 : FV_KSVGF_B3_0; }
FV_HD FV_KSVGF_INLINE float fv_ksvgf_g3(int i) { return i == 1 ? FV_KSVGF_G3_1 : FV_KSVGF_G3_0; }

/* The depth gradient along one axis: the smaller one-sided difference to a surface neighbour (qm,
 * qp: the taps on either side, -1 outside a screen grid; filter/svgf.c says why not a central
 * difference). */
FV_HD FV_KSVGF_INLINE float fv_ksvgf_axis_gradient(const uint8_t *kind, const float *z, long qm, long qp, float zc)
{
    float dm = qm >= 0 && kind[qm] == FV_KSVGF_SURFACE ? fabsf(zc - z[qm]) : INFINITY;
    float dp = qp >= 0 && kind[qp] == FV_KSVGF_SURFACE ? fabsf(z[qp] - zc) : INFINITY;
    float d = fminf(dm, dp);
    return isfinite(d) ? d : 0.0f;
}

/* The passes' tap distances in units of the step: 1, sqrt 2, 2, sqrt 5, sqrt 8 (d2 = 1, 2, 4, 5, 8). */
FV_HD FV_KSVGF_INLINE int fv_ksvgf_atrous_class(int d2) { return d2 == 1 ? 0 : d2 == 2 ? 1 : d2 == 4 ? 2 : d2 == 5 ? 3 : 4; }
FV_HD FV_KSVGF_INLINE float fv_ksvgf_atrous_dist(int c)
{
    return c == 0 ? 1.0f : c == 1 ? sqrtf(2.0f) : c == 2 ? 2.0f : c == 3 ? sqrtf(5.0f) : sqrtf(8.0f);
}

/* Host: sigma_normal's squarings (fv_ksvgf.sq): k when it is 2^k, k <= 16, else -1. */
static inline int fv_ksvgf_squarings(float sigma_normal)
{
    for (int k = 0; k <= 16; k++)
        if (sigma_normal == (float)(1 << k)) return k;
    return -1;
}

/* The columns pass `pass` filters: [0, cut); the others go through unchanged. */
FV_HD FV_KSVGF_INLINE int fv_ksvgf_pass_cut(const fv_ksvgf *k, int pass) { return pass < k->periph_passes ? k->g.w : k->periph_x; }

/* ---- 1. classification, demodulation, temporal accumulation */

/* The history at pixel p's prev_coord, blended from the consistent taps of a bilinear lookup
 * (filter/svgf.h, step 2): out = (r, g, b, m1, m2, length). False when there is none. */
FV_HD static inline bool fv_ksvgf_history(const fv_ksvgf *k, size_t p, float out[6])
{
    const fv_grid *g = &k->g;
    const float *np = &k->normal[3 * p], *xp = &k->position[3 * p];
    const float depth = k->depth[p];
    const uint32_t id = k->id[p];
    float X = k->prev_coord[2 * p], V = k->prev_coord[2 * p + 1];
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
    float tol = FV_KSVGF_HIST_POS_REL * (depth > FV_KSVGF_HIST_DEPTH_MIN ? depth : FV_KSVGF_HIST_DEPTH_MIN) + FV_KSVGF_HIST_POS_ULP * big;
    float tol2 = tol * tol;
    float acc[6] = {0, 0, 0, 0, 0, 0}, wsum = 0.0f;
    for (int t = 0; t < 4; t++) {
        long q = idx[t];
        /* Length 0 marks every pixel that cannot serve as history: rows beyond the column's
         * height, no surface, no path, non-finite input. */
        if (!(wt[t] > 0.0f) || !(k->plen[q] > 0.0f) || k->hist_id[q] != id) continue;
        if (!(k->pnx[q] * np[0] + k->pny[q] * np[1] + k->pnz[q] * np[2] > FV_KSVGF_HIST_COS)) continue;
        const float *xq = &k->hist_pos[3 * q];
        float dx = xq[0] - xp[0], dy = xq[1] - xp[1], dz = xq[2] - xp[2];
        if (!(dx * dx + dy * dy + dz * dz < tol2)) continue;
        const float *c = &k->hist_illum[3 * q];
        acc[0] += wt[t] * c[0];
        acc[1] += wt[t] * c[1];
        acc[2] += wt[t] * c[2];
        acc[3] += wt[t] * k->pm1[q];
        acc[4] += wt[t] * k->pm2[q];
        acc[5] += wt[t] * k->plen[q];
        wsum += wt[t];
    }
    if (wsum < FV_KSVGF_HIST_MIN_WEIGHT) return false;
    for (int t = 0; t < 6; t++) out[t] = acc[t] / wsum;
    return true;
}

/* Pixel (x, y): its kind, features, demodulated value, moments and history length, blended with
 * its history when k->history and it has one. Returns FV_KSVGF_NONE, _HOLE, _SURFACE or
 * _SURFACE_HIST (kind[] holds _SURFACE for both). */
FV_HD static inline int fv_ksvgf_accumulate_pixel(const fv_ksvgf *k, int x, int y)
{
    const fv_grid *g = &k->g;
    const size_t p = (size_t)y * (size_t)g->w + (size_t)x;
    const float *np = &k->normal[3 * p];
    uint8_t kd = FV_KSVGF_NONE;
    if (y < fv_grid_col_h(g, x) && (!k->active || k->active[p])) {
        if (k->sampled && !k->sampled[p]) {
            kd = FV_KSVGF_HOLE;
        } else if (np[0] != 0.0f || np[1] != 0.0f || np[2] != 0.0f) {
            const float *c = &k->color[3 * p], *a = &k->albedo[3 * p], *xp = &k->position[3 * p];
            float all = c[0] + c[1] + c[2] + a[0] + a[1] + a[2] + np[0] + np[1] + np[2] + k->depth[p] + xp[0] + xp[1] + xp[2];
            kd = isfinite(all) ? FV_KSVGF_SURFACE : FV_KSVGF_HOLE;
        }
    }
    k->kind[p] = kd;
    if (k->found) k->found[p] = 0;
    if (kd != FV_KSVGF_SURFACE) {
        k->surf[p] = 0.0f;
        k->nx[p] = k->ny[p] = k->nz[p] = k->z[p] = 0.0f;
        for (int c = 0; c < FV_KSVGF_NVAL; c++) k->val[0][c][p] = 0.0f;
        k->m1[p] = k->m2[p] = k->len[p] = 0.0f;
        return kd;
    }
    const float *c = &k->color[3 * p];
    float il[3], d[3];
    fv_demod_factors(&k->albedo[3 * p], d);
    for (int ch = 0; ch < 3; ch++) il[ch] = c[ch] / d[ch];
    k->surf[p] = 1.0f;
    k->nx[p] = np[0], k->ny[p] = np[1], k->nz[p] = np[2], k->z[p] = k->depth[p];
    float l = fv_ksvgf_luminance(il[0], il[1], il[2]), m1 = l, m2 = l * l, n_len = 1.0f;
    float hst[6];
    int res = FV_KSVGF_SURFACE;
    if (k->history && fv_ksvgf_history(k, p, hst)) {
        n_len = hst[5] + 1.0f < FV_KSVGF_LEN_MAX ? hst[5] + 1.0f : FV_KSVGF_LEN_MAX;
        /* The new sample's weight: 1 / length (a plain mean) until that falls below alpha. */
        const float ac = k->alpha_color, am = k->alpha_moments;
        float inv = 1.0f / n_len, wc = ac > inv ? ac : inv, wm = am > inv ? am : inv;
        for (int ch = 0; ch < 3; ch++) il[ch] = hst[ch] + wc * (il[ch] - hst[ch]);
        m1 = hst[3] + wm * (m1 - hst[3]);
        m2 = hst[4] + wm * (m2 - hst[4]);
        l = fv_ksvgf_luminance(il[0], il[1], il[2]);
        res = FV_KSVGF_SURFACE_HIST;
        if (k->found) k->found[p] = 1;
    }
    k->val[0][FV_KSVGF_R][p] = il[0], k->val[0][FV_KSVGF_G][p] = il[1], k->val[0][FV_KSVGF_B][p] = il[2];
    k->val[0][FV_KSVGF_VAR][p] = 0.0f, k->val[0][FV_KSVGF_LUM][p] = l;
    k->m1[p] = m1;
    k->m2[p] = m2;
    k->len[p] = n_len;
    return res;
}

/* ---- 2. depth gradient and variance */

/* The depth gradient of surface pixel (x, y): per axis the smaller one-sided difference, then the
 * larger of the two axes (filter/svgf.c). */
FV_HD static inline float fv_ksvgf_gradient(const fv_ksvgf *k, int x, int y, float zc)
{
    const fv_grid *g = &k->g;
    float gx = fv_ksvgf_axis_gradient(k->kind, k->z, fv_grid_tap(g, x, y, -1, 0), fv_grid_tap(g, x, y, 1, 0), zc);
    float gy = fv_ksvgf_axis_gradient(k->kind, k->z, fv_grid_tap(g, x, y, 0, -1), fv_grid_tap(g, x, y, 0, 1), zc);
    return gx > gy ? gx : gy;
}

/* Pixel (x, y): grad and val[0] variance of a surface pixel, the temporal variance when its history
 * is at least 4 frames long, else the 7x7 estimate of the moments with the depth and normal weights
 * (taps row by row, the centre first with weight 1). */
FV_HD static inline void fv_ksvgf_variance_pixel(const fv_ksvgf *k, int x, int y)
{
    const fv_grid *g = &k->g;
    const size_t p = (size_t)y * (size_t)g->w + (size_t)x;
    if (k->kind[p] != FV_KSVGF_SURFACE) return;
    const float zc = k->z[p];
    const float gr = fv_ksvgf_gradient(k, x, y, zc);
    k->grad[p] = gr;
    float *var = k->val[0][FV_KSVGF_VAR];
    float tv = k->m2[p] - k->m1[p] * k->m1[p];
    var[p] = tv > 0.0f ? tv : 0.0f;
    if (k->len[p] >= FV_KSVGF_VAR_TEMPORAL_LEN) return;
    const float zs = k->sigma_depth * gr, ze = fv_ksvgf_depth_eps(zc);
    const float nxp = k->nx[p], nyp = k->ny[p], nzp = k->nz[p];
    float a1 = k->m1[p], a2 = k->m2[p], aw = 1.0f;
    for (int j = 0; j < 7; j++)
        for (int i = 0; i < 7; i++) {
            if (i == 3 && j == 3) continue;
            const long q = fv_grid_tap(g, x, y, i - 3, j - 3);
            if (q < 0) continue;
            const float rz = 1.0f / (zs * sqrtf((float)((i - 3) * (i - 3) + (j - 3) * (j - 3))) + ze);
            float wn = fv_ksvgf_normal_pow(nxp * k->nx[q] + nyp * k->ny[q] + nzp * k->nz[q], k->sq, k->sigma_normal);
            float wt = wn * fv_ksvgf_exp_neg(fabsf(zc - k->z[q]) * rz);
            a1 += wt * k->m1[q];
            a2 += wt * k->m2[q];
            aw += wt;
        }
    float mean1 = a1 / aw, mean2 = a2 / aw, sv = mean2 - mean1 * mean1;
    var[p] = sv > 0.0f ? sv : 0.0f;
}

/* ---- 3, 4. the À-Trous passes */

/* The prefiltered variance of surface pixel (x, y) for pass `pass`: the 3x3 Gaussian of the pass's
 * input variance over the surface neighbours (Sec. 4.3), column by column. */
FV_HD static inline float fv_ksvgf_prefilter_value(const fv_ksvgf *k, int pass, int x, int y)
{
    const fv_grid *g = &k->g;
    const float *var = k->val[pass & 1][FV_KSVGF_VAR];
    float av = 0.0f, aw = 0.0f;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            const long q = fv_grid_tap(g, x, y, i - 1, j - 1);
            if (q < 0) continue;
            const float kk = fv_ksvgf_g3(i) * fv_ksvgf_g3(j);
            av += kk * var[q];
            aw += kk * k->surf[q];
        }
    return av / aw;
}

/* Pixel (x, y) of pass `pass`'s prefilter into gvar (0 off a surface). Only the columns the pass
 * filters need it. */
FV_HD static inline void fv_ksvgf_prefilter_pixel(const fv_ksvgf *k, int pass, int x, int y)
{
    const size_t p = (size_t)y * (size_t)k->g.w + (size_t)x;
    if (x >= fv_ksvgf_pass_cut(k, pass)) return;
    k->gvar[p] = k->kind[p] == FV_KSVGF_SURFACE ? fv_ksvgf_prefilter_value(k, pass, x, y) : 0.0f;
}

/* Pixel (x, y) of pass `pass` (taps 2^pass apart), from val[pass & 1] to val[1 - (pass & 1)]: the
 * centre, then the 24 taps row by row, each weighted by the B3 kernel, the normals, the depth and
 * the luminance; the variance filtered alongside with the squared weights. A column the pass does
 * not filter (fv_svgf_set_periphery) goes through unchanged. The first pass also writes the
 * history's illumination. The prefiltered variance is read at the pixel alone: from gvar
 * (fv_ksvgf_atrous_pixel, after a prefilter launch), or computed here (fused: one launch a pass). */
FV_HD static inline void fv_ksvgf_atrous_core(const fv_ksvgf *k, int pass, int x, int y, bool fused)
{
    const fv_grid *g = &k->g;
    const size_t p = (size_t)y * (size_t)g->w + (size_t)x;
    const int src = pass & 1, step = 1 << pass;
    float *const *dst = k->val[1 - src];
    const float *r = k->val[src][FV_KSVGF_R], *gg = k->val[src][FV_KSVGF_G], *b = k->val[src][FV_KSVGF_B];
    const float *v = k->val[src][FV_KSVGF_VAR], *l = k->val[src][FV_KSVGF_LUM];
    const bool surface = k->kind[p] == FV_KSVGF_SURFACE;
    if (x >= fv_ksvgf_pass_cut(k, pass)) {
        for (int c = 0; c < FV_KSVGF_NVAL; c++) dst[c][p] = k->val[src][c][p];
        if (pass == 0 && surface)
            for (int c = 0; c < 3; c++) k->hist_illum[3 * p + c] = k->val[src][FV_KSVGF_R + c][p];
        return;
    }
    if (!surface) {
        for (int c = 0; c < FV_KSVGF_NVAL; c++) dst[c][p] = 0.0f;
        return;
    }
    const float wc = FV_KSVGF_B3_2 * FV_KSVGF_B3_2;
    const float gv = fused ? fv_ksvgf_prefilter_value(k, pass, x, y) : k->gvar[p];
    const float inv_l = 1.0f / (k->sigma_lum * sqrtf(gv) + FV_KSVGF_LUM_EPS);
    const float zs = k->sigma_depth * k->grad[p] * (float)step, ze = fv_ksvgf_depth_eps(k->z[p]);
    const float nxp = k->nx[p], nyp = k->ny[p], nzp = k->nz[p], zp = k->z[p], lp = l[p];
    float ar = wc * r[p], ag = wc * gg[p], ab = wc * b[p], avr = wc * wc * v[p], aw = wc;
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            if (i == 2 && j == 2) continue;
            const long q = fv_grid_tap(g, x, y, (i - 2) * step, (j - 2) * step);
            if (q < 0) continue;
            const float kw = fv_ksvgf_b3(i) * fv_ksvgf_b3(j);
            const float rz = 1.0f / (zs * fv_ksvgf_atrous_dist(fv_ksvgf_atrous_class((i - 2) * (i - 2) + (j - 2) * (j - 2))) + ze);
            float wn = fv_ksvgf_normal_pow(nxp * k->nx[q] + nyp * k->ny[q] + nzp * k->nz[q], k->sq, k->sigma_normal);
            float e = fabsf(zp - k->z[q]) * rz + fabsf(lp - l[q]) * inv_l;
            float wt = kw * wn * fv_ksvgf_exp_neg(e);
            ar += wt * r[q];
            ag += wt * gg[q];
            ab += wt * b[q];
            avr += wt * wt * v[q];
            aw += wt;
        }
    /* Divisions, not a reciprocal: a mean of equal values then comes out exactly equal. */
    const float rr = ar / aw, rg = ag / aw, rb = ab / aw;
    dst[FV_KSVGF_R][p] = rr, dst[FV_KSVGF_G][p] = rg, dst[FV_KSVGF_B][p] = rb;
    dst[FV_KSVGF_VAR][p] = avr / (aw * aw);
    dst[FV_KSVGF_LUM][p] = fv_ksvgf_luminance(rr, rg, rb);
    if (pass == 0)
        for (int c = 0; c < 3; c++) k->hist_illum[3 * p + c] = dst[FV_KSVGF_R + c][p];
}

/* The pass after its prefilter launch (fv_ksvgf_prefilter_pixel over every pixel first). */
FV_HD static inline void fv_ksvgf_atrous_pixel(const fv_ksvgf *k, int pass, int x, int y) { fv_ksvgf_atrous_core(k, pass, x, y, false); }

/* Prefilter and pass in one launch: the same bits as the two launches, gvar not used. */
FV_HD static inline void fv_ksvgf_prefilter_atrous_pixel(const fv_ksvgf *k, int pass, int x, int y)
{
    fv_ksvgf_atrous_core(k, pass, x, y, true);
}

/* ---- 5. remodulation and this frame's history */

/* Pixel (x, y): a surface pixel's filtered value (val[iterations & 1]) times its demodulation
 * factors into colour; its position and id (and with no pass its illumination) into the history. */
FV_HD static inline void fv_ksvgf_finish_pixel(const fv_ksvgf *k, int x, int y)
{
    const size_t p = (size_t)y * (size_t)k->g.w + (size_t)x;
    if (k->kind[p] != FV_KSVGF_SURFACE) return;
    float *const *v = k->val[k->iterations & 1];
    const float il[3] = {v[FV_KSVGF_R][p], v[FV_KSVGF_G][p], v[FV_KSVGF_B][p]};
    float d[3];
    fv_demod_factors(&k->albedo[3 * p], d);
    for (int ch = 0; ch < 3; ch++) k->color[3 * p + ch] = il[ch] * d[ch];
    for (int ch = 0; ch < 3; ch++) {
        if (k->iterations == 0) k->hist_illum[3 * p + ch] = il[ch];
        k->hist_pos[3 * p + ch] = k->position[3 * p + ch];
    }
    k->hist_id[p] = k->id[p];
}

/* ---- 6. holes */

/* Pixel (x, y) when it is a hole: the B3-weighted mean of the filtered surface pixels' colours
 * among its 5x5 taps 1 apart, or if none 2, 4, ... up to 2^(iterations - 1) apart (at least 1);
 * none: black. No edge-stopping: the hole's own features are unknown. */
FV_HD static inline void fv_ksvgf_hole_pixel(const fv_ksvgf *k, int x, int y)
{
    const fv_grid *g = &k->g;
    const size_t p = (size_t)y * (size_t)g->w + (size_t)x;
    if (k->kind[p] != FV_KSVGF_HOLE) return;
    const int max_step = k->iterations > 1 ? 1 << (k->iterations - 1) : 1;
    const float *color = k->color;
    float s[3] = {0, 0, 0}, ws = 0.0f;
    for (int step = 1; step <= max_step && ws == 0.0f; step *= 2)
        for (int j = 0; j < 5; j++)
            for (int i = 0; i < 5; i++) {
                const long q = fv_grid_tap(g, x, y, (i - 2) * step, (j - 2) * step);
                if (q < 0 || k->kind[q] != FV_KSVGF_SURFACE) continue;
                const float kk = fv_ksvgf_b3(i) * fv_ksvgf_b3(j);
                s[0] += kk * color[3 * q];
                s[1] += kk * color[3 * q + 1];
                s[2] += kk * color[3 * q + 2];
                ws += kk;
            }
    for (int ch = 0; ch < 3; ch++) k->color[3 * p + ch] = ws > 0.0f ? s[ch] / ws : 0.0f;
}

/* ---- 7. the counters */

/* Row y's surface pixels, those with history, holes, and the sum of the history lengths (in x
 * order, in double), into the row arrays; needs kind, found and len of step 1. */
FV_HD static inline void fv_ksvgf_count_row(const fv_ksvgf *k, int y)
{
    const size_t p0 = (size_t)y * (size_t)k->g.w;
    long n_surface = 0, n_hist = 0, n_holes = 0;
    double len_sum = 0.0;
    for (int x = 0; x < k->g.w; x++) {
        const size_t p = p0 + (size_t)x;
        n_holes += k->kind[p] == FV_KSVGF_HOLE;
        if (k->kind[p] != FV_KSVGF_SURFACE) continue;
        n_surface++;
        if (!k->found[p]) continue;
        n_hist++;
        len_sum += k->len[p];
    }
    k->row_surface[y] = n_surface, k->row_hist[y] = n_hist, k->row_holes[y] = n_holes, k->row_len[y] = len_sum;
}

/* Host: the rows' counters summed in row order: history_fraction and mean_history of fv_svgf_info;
 * returns the number of holes (0: step 6 has nothing to do). */
static inline long fv_ksvgf_sum_rows(int h, const long *row_surface, const long *row_hist, const long *row_holes, const double *row_len,
                                     double *history_fraction, double *mean_history)
{
    long n_surface = 0, n_hist = 0, n_holes = 0;
    double len_sum = 0.0;
    for (int y = 0; y < h; y++) {
        n_surface += row_surface[y];
        n_hist += row_hist[y];
        n_holes += row_holes[y];
        len_sum += row_len[y];
    }
    *history_fraction = n_surface ? (double)n_hist / (double)n_surface : 0.0;
    *mean_history = n_hist ? len_sum / (double)n_hist : 0.0;
    return n_holes;
}

/* Host, after a frame: this frame's features, moments and lengths become the previous frame's (the
 * working values need no swap: step 1 rewrites val[0] whole every frame). */
static inline void fv_ksvgf_swap(fv_ksvgf *k)
{
    float *t;
#define FV_KSVGF_SWAP(cur, prev) (t = k->cur, k->cur = (float *)k->prev, k->prev = t)
    FV_KSVGF_SWAP(nx, pnx);
    FV_KSVGF_SWAP(ny, pny);
    FV_KSVGF_SWAP(nz, pnz);
    FV_KSVGF_SWAP(z, pz);
    FV_KSVGF_SWAP(m1, pm1);
    FV_KSVGF_SWAP(m2, pm2);
    FV_KSVGF_SWAP(len, plen);
#undef FV_KSVGF_SWAP
}

#endif
