/* fovea — the mipmaps along φ of Visual-Polar path tracing (Sec. 3.4) as kernel code: one cell of
 * a level built from the level below (filter/phi_mips.c has the weights) and a trilinear lookup
 * along φ. The CPU's phi_mips.c builds its levels with the cell function and samples with
 * fv_kphi_sample (its fv_phi_mips_sample is this lookup); the portable backend and CUDA run them a
 * cell at a time, and the map stage (technique/vpolar/kvp_map.h) samples with it.
 */
#ifndef FV_FILTER_KPHI_H
#define FV_FILTER_KPHI_H

#include <math.h>
#include <stddef.h>
#include "fovea/math.h"

#define FV_KPHI_MAX_LEVELS 32 /* a column of up to INT_MAX rows needs at most 32 levels */

/* A chain of φ-mipmaps (host memory on the CPU and the portable backend, device memory on CUDA):
 * level k has w columns of rows[k][x] rows, its pixels 3 floats each on a w-wide storage (one float
 * of padding after the last pixel); inv_src[k][x] = 1 / rows[k - 1][x] for k >= 1. */
typedef struct fv_kphi_mips {
    int levels, w;
    int wrap;                                 /* polar grid: rows wrap */
    const int *rows[FV_KPHI_MAX_LEVELS];
    const float *rowsf[FV_KPHI_MAX_LEVELS];   /* rows as floats */
    const float *inv_src[FV_KPHI_MAX_LEVELS];
    float *img[FV_KPHI_MAX_LEVELS];
} fv_kphi_mips;

/* Cell (x, j) of level k >= 1 from level k - 1; a cell beyond its column's rows is left alone. */
FV_HD static inline void fv_kphi_halve_cell(const fv_kphi_mips *m, int k, int x, int j)
{
    const int md = m->rows[k][x];
    if (j >= md) return;
    const size_t stride = 3 * (size_t)m->w;
    const float *s = m->img[k - 1] + 2 * (size_t)j * stride + 3 * (size_t)x; /* row 2j of the source */
    float *o = m->img[k] + (size_t)j * stride + 3 * (size_t)x;
    if (m->rows[k - 1][x] == 2 * md) {
        for (int c = 0; c < 3; c++) o[c] = 0.5f * (s[c] + s[stride + c]);
    } else {
        /* Zero weights are skipped, not multiplied: the rows they name may not exist, and a
         * non-finite neighbour must not leak in through 0 * inf. */
        const float wa = (float)j, wb = (float)md, wc = (float)(md - 1 - j), u = m->inv_src[k][x];
        for (int c = 0; c < 3; c++) {
            float sum = wb * s[c];
            if (j > 0) sum += wa * s[c - stride];
            if (j < md - 1) sum += wc * s[c + stride];
            o[c] = sum * u;
        }
    }
}

/* floor(f) for f > -1 (lookups only see f >= -0.5): truncation, minus one for negative f. */
FV_HD static inline int fv_kphi_floor_small(float f)
{
    return (int)f - (f < 0.0f);
}

/* acc + wgt times the bilinear lookup of level k at columns xa (weight 1 - tx) and xb (weight tx),
 * V already in [0, 1]: fv_grid_bilinear's taps and weights. */
FV_HD static inline void fv_kphi_lookup(const fv_kphi_mips *m, int k, int xa, int xb, float tx, float V, float wgt, float acc[3])
{
    const float *img = m->img[k];
    const size_t stride = 3 * (size_t)m->w;
    for (int c = 0; c < 2; c++) {
        const int x = c ? xb : xa, n = m->rows[k][x];
        const float fy = V * m->rowsf[k][x] - 0.5f;
        int y0 = fv_kphi_floor_small(fy), y1 = y0 + 1;
        const float ty = fy - (float)y0, wc = wgt * (c ? tx : 1.0f - tx);
        /* V in [0, 1] puts fy in [-0.5, n - 0.5]: y0 in [-1, n - 1], y1 in [0, n] */
        if (m->wrap) {
            y0 = y0 < 0 ? n - 1 : y0;
            y1 = y1 >= n ? 0 : y1;
        } else {
            y0 = y0 < 0 ? 0 : y0;
            y1 = y1 >= n ? n - 1 : y1;
        }
        const float w0 = wc * (1.0f - ty), w1 = wc * ty;
        const float *p0 = img + (size_t)y0 * stride + 3 * (size_t)x, *p1 = img + (size_t)y1 * stride + 3 * (size_t)x;
        for (int ch = 0; ch < 3; ch++) acc[ch] += w0 * p0[ch];
        for (int ch = 0; ch < 3; ch++) acc[ch] += w1 * p1[ch];
    }
}

/* Colour at continuous (X, V) and fractional level, as fv_phi_mips_sample (filter/phi_mips.h):
 * bilinear in the two nearest levels, blended linearly; X clamps to the edge columns, V wraps on a
 * polar grid and clamps on a screen grid, a NaN reads level 0 at the edge. */
FV_HD static inline void fv_kphi_sample(const fv_kphi_mips *m, float X, float V, float level, float out[3])
{
    const float wf = (float)m->w;
    X = X >= 0.0f ? (X <= wf ? X : wf) : 0.0f; /* also NaN -> 0 */
    if (m->wrap) {
        if (!(V >= 0.0f && V < 1.0f)) V -= floorf(V); /* one turn is the same angle */
        if (!(V >= 0.0f && V <= 1.0f)) V = 0.0f;      /* NaN or infinite */
    } else {
        V = V >= 0.0f ? (V <= 1.0f ? V : 1.0f) : 0.0f;
    }
    const float fx = X - 0.5f;
    const int x0 = fv_kphi_floor_small(fx);
    const float tx = fx - (float)x0;
    const int xa = x0 < 0 ? 0 : x0, xb = x0 + 1 < m->w ? x0 + 1 : m->w - 1;
    int k = 0;
    float t = 0.0f;
    if (level > 0.0f) { /* NaN -> level 0 */
        const float top = (float)(m->levels - 1);
        if (level < top) {
            k = (int)level;
            t = level - (float)k;
        } else {
            k = m->levels - 1;
        }
    }
    float acc[3] = {0.0f, 0.0f, 0.0f};
    if (t > 0.0f) {
        fv_kphi_lookup(m, k, xa, xb, tx, V, 1.0f - t, acc);
        fv_kphi_lookup(m, k + 1, xa, xb, tx, V, t, acc);
    } else {
        fv_kphi_lookup(m, k, xa, xb, tx, V, 1.0f, acc);
    }
    out[0] = acc[0], out[1] = acc[1], out[2] = acc[2];
}

#endif
