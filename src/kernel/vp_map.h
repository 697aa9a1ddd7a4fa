/* fovea — the mipmaps along φ and the map stage of Visual-Polar path tracing (Sec. 3.4) as kernel
 * code: one cell of a level built from the level below (filter/phi_mips.c has the weights), a
 * trilinear lookup along φ, and one screen pixel of the map from the sample space. The CPU's
 * phi_mips.c builds its levels with the cell function and samples with fv_kphi_sample (its
 * fv_phi_mips_sample is this lookup); the portable backend and CUDA run these a cell or pixel at
 * a time.
 */
#ifndef FV_KERNEL_VP_MAP_H
#define FV_KERNEL_VP_MAP_H

#include <math.h>
#include <stddef.h>
#include "fovea/film.h"
#include "fovea/math.h"
#include "kernel/vp_space.h"

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

/* The grid cell nearest (X, V) whose first hit a screen pixel's auxiliary buffers take (the map
 * stage): column clamped to [0, w), row to its column's rows. col_h NULL: every column h rows. */
FV_HD static inline long fv_kvp_nearest_cell(const int *col_h, int w, int h, float X, float V)
{
    int gx = (int)X;
    gx = gx < 0 ? 0 : (gx >= w ? w - 1 : gx);
    const int nr = col_h ? col_h[gx] : h;
    int gy = (int)(V * (float)nr);
    gy = gy < 0 ? 0 : (gy >= nr ? nr - 1 : gy);
    return (long)gy * w + gx;
}

/* One frame of the map stage: the space and its view, the grid's buffers (first hits) and column
 * heights, its φ-mipmaps (built), the frame's radial table (three floats an entry: column, mip
 * level, blur sigma) and where the blur's sigma goes (one float per screen pixel). */
typedef struct fv_kvp_map_frame {
    fv_kvp_space space;
    fv_kvp_view view;
    const int *col_h;
    fv_kvp_gbuf g;
    fv_kphi_mips mips;
    const float *lut;
    int nlut;
    float inv_step;
    int polar;        /* Visual-Polar or log-polar: coordinates from the table */
    int identity;     /* a Cartesian grid the size of the screen: a copy */
    float *sigma;     /* NULL: no blur */
} fv_kvp_map_frame;

/* Screen pixel (x, y)'s grid coordinates and mip level, and the blur's sigma stored. */
FV_HD static inline void fv_kvp_map_coords(const fv_kvp_map_frame *m, int x, int y, float *X, float *V, float *level)
{
    const float px = (float)x + 0.5f, py = (float)y + 0.5f;
    const size_t pix = (size_t)y * (size_t)m->space.sw + (size_t)x;
    if (m->polar) {
        float sigma;
        fv_kvp_table_coords(m->lut, m->nlut, m->inv_step, px - m->view.gx, py - m->view.gy, X, V, level, &sigma);
        if (m->sigma) m->sigma[pix] = sigma;
        return;
    }
    /* The Cartesian grid: level 0, its blur (if any) from the table */
    if (m->sigma) {
        const float dx = px - m->view.gx, dy = py - m->view.gy;
        m->sigma[pix] = fv_space_table_x(m->lut + 2, 3, m->nlut, m->inv_step, sqrtf(dx * dx + dy * dy));
    }
    *level = 0.0f;
    *X = *V = 0.0f;
    if (!m->identity) fv_kvp_cartesian_from_screen(&m->space, px, py, X, V);
}

/* The film's first-hit buffers of screen pixel pix from grid cell near. */
FV_HD static inline void fv_kvp_map_aux(const fv_kvp_map_frame *m, size_t pix, long near, const fv_film_views *out)
{
    const fv_kvp_gbuf *g = &m->g;
    const bool hit = g->id[near] != 0;
    fv_film_store_first_hit(out, pix, hit, g->depth[near], fv_v3(g->position[3 * near], g->position[3 * near + 1], g->position[3 * near + 2]),
                            fv_v3(g->normal[3 * near], g->normal[3 * near + 1], g->normal[3 * near + 2]),
                            fv_v3(g->albedo[3 * near], g->albedo[3 * near + 1], g->albedo[3 * near + 2]), hit ? (int)g->id[near] - 1 : 0);
}

/* Screen pixel pix's colour from the sample space at (X, V, level) (Sec. 3.4) and its first-hit
 * buffers from the nearest cell. */
FV_HD static inline void fv_kvp_map_out(const fv_kvp_map_frame *m, size_t pix, float X, float V, float level, const fv_film_views *out)
{
    const bool aux = out->depth || out->normal || out->albedo || out->position || out->id;
    if (m->identity) {
        for (int c = 0; c < 3; c++) out->color[3 * pix + c] = m->g.color[3 * pix + c];
        if (aux) fv_kvp_map_aux(m, pix, (long)pix, out);
        return;
    }
    fv_kphi_sample(&m->mips, X, V, level, &out->color[3 * pix]);
    if (aux) fv_kvp_map_aux(m, pix, fv_kvp_nearest_cell(m->col_h, m->space.gw, m->space.gh, X, V), out);
}

/* The map stage at screen pixel (x, y). */
FV_HD static inline void fv_kvp_map_pixel(const fv_kvp_map_frame *m, int x, int y, const fv_film_views *out)
{
    float X, V, level;
    fv_kvp_map_coords(m, x, y, &X, &V, &level);
    fv_kvp_map_out(m, (size_t)y * (size_t)m->space.sw + (size_t)x, X, V, level, out);
}

#endif
