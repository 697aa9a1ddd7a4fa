/* fovea — how filters address the images they work on: a plain screen image, or a polar sample
 * grid (Visual-Polar or log-polar space) whose columns may hold fewer rows than the image and whose
 * rows wrap around.
 *
 * Storage is always h rows of w pixels, row-major, pixel (x, y) at index y * w + x. In a polar grid
 * a column x is one radius ρ and its rows are the angles φ: column x holds col_h[x] valid rows
 * (1..h); rows at or beyond col_h[x] are unused (the triangular clipping of the fovea, Visual-Polar
 * Sec. 3.2). Every column spans the full circle whatever its height, so row y of column x sits at
 * the normalised angle v = (y + 0.5) / col_h[x] in [0, 1).
 *
 * Edge handling (Visual-Polar Sec. 3.3): polar grids wrap on φ (rows) and clamp to the edge on ρ
 * (columns). Screen grids do not wrap; a filter tap outside the image is skipped and a resampling
 * tap clamps to the edge.
 *
 * Continuous coordinates: X in [0, w] along the columns (column x covers [x, x + 1), centre x + 0.5)
 * and V in [0, 1) along a column (row y of column x covers [y, y + 1) / col_h[x]). For a screen grid
 * V = Y / h with Y the continuous row coordinate.
 *
 * Plain C marked FV_HD: the same functions serve the CPU filters and the device kernels
 * (filter/ksvgf.h), which nvcc compiles for the GPU.
 */
#ifndef FV_FILTER_GRID_H
#define FV_FILTER_GRID_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include "fovea/math.h"

typedef struct fv_grid {
    int w, h;           /* storage size */
    const int *col_h;   /* NULL: every column has h rows; else rows of column x, 1..h (not owned) */
    bool wrap;          /* true: polar grid (rows wrap, columns clamp); false: screen grid */
} fv_grid;

FV_HD static inline int fv_grid_col_h(const fv_grid *g, int x) { return g->col_h ? g->col_h[x] : g->h; }

FV_HD static inline bool fv_grid_valid(const fv_grid *g, int x, int y)
{
    return x >= 0 && x < g->w && y >= 0 && y < fv_grid_col_h(g, x);
}

FV_HD static inline int fv_grid_wrap_row(int y, int n)
{
    int r = y % n;
    return r < 0 ? r + n : r;
}

/* The filter tap dx columns and dy rows away from pixel (x, y), as a pixel index, or -1 when the
 * tap falls outside a screen grid. In a polar grid the tap column is clamped to [0, w), the tap
 * starts from the row of that column at the same angle as (x, y) (columns differ in height) and the
 * row offset wraps around the column. */
FV_HD static inline long fv_grid_tap(const fv_grid *g, int x, int y, int dx, int dy)
{
    if (!g->wrap) {
        int xx = x + dx, yy = y + dy;
        if (xx < 0 || xx >= g->w || yy < 0 || yy >= g->h) return -1;
        return (long)yy * g->w + xx;
    }
    int xx = x + dx;
    xx = xx < 0 ? 0 : (xx >= g->w ? g->w - 1 : xx);
    int yy = y;
    if (g->col_h) {
        int hs = g->col_h[x], hd = g->col_h[xx];
        if (hs != hd) yy = (int)(((long)y * 2 + 1) * hd / (2L * hs)); /* same angle, other height */
    }
    yy = fv_grid_wrap_row(yy + dy, fv_grid_col_h(g, xx));
    return (long)yy * g->w + xx;
}

/* The four taps and weights of a bilinear lookup at continuous (X, V): two columns (clamped), and
 * in each column the two rows around V, wrapped on a polar grid and clamped on a screen grid.
 * Weights sum to 1 (some taps may coincide at the edges). */
FV_HD static inline void fv_grid_bilinear(const fv_grid *g, float X, float V, long idx[4], float wt[4])
{
    float fx = X - 0.5f;
    int x0 = (int)floorf(fx);
    float tx = fx - (float)x0;
    for (int c = 0; c < 2; c++) {
        int xc = x0 + c;
        xc = xc < 0 ? 0 : (xc >= g->w ? g->w - 1 : xc);
        int n = fv_grid_col_h(g, xc);
        float fy = V * (float)n - 0.5f;
        int y0 = (int)floorf(fy);
        float ty = fy - (float)y0;
        int y1 = y0 + 1;
        if (g->wrap) {
            y0 = fv_grid_wrap_row(y0, n);
            y1 = fv_grid_wrap_row(y1, n);
        } else {
            y0 = y0 < 0 ? 0 : (y0 >= n ? n - 1 : y0);
            y1 = y1 < 0 ? 0 : (y1 >= n ? n - 1 : y1);
        }
        float wc = c ? tx : 1.0f - tx;
        idx[2 * c] = (long)y0 * g->w + xc;
        idx[2 * c + 1] = (long)y1 * g->w + xc;
        wt[2 * c] = wc * (1.0f - ty);
        wt[2 * c + 1] = wc * ty;
    }
}

/* Continuous (X, V) of the centre of pixel (x, y). */
FV_HD static inline void fv_grid_centre(const fv_grid *g, int x, int y, float *X, float *V)
{
    *X = (float)x + 0.5f;
    *V = ((float)y + 0.5f) / (float)fv_grid_col_h(g, x);
}

#endif
