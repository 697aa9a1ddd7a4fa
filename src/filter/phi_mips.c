/* fovea — mipmaps along φ only, for mapping a polar sample grid to the screen (Koskela et al.,
 * Visual-Polar Sec. 3.4; see phi_mips.h for the contract).
 *
 * Halving a column of n rows into m = ceil(n / 2): row j of the new level covers the source span
 * [j n / m, (j + 1) n / m). Measured in units of 1 / (n m) of the circle, source row i covers
 * [i m, (i + 1) m) and new row j covers [j n, (j + 1) n), so the overlaps are integers:
 *  - n even (n = 2m): rows 2j and 2j + 1, half each;
 *  - n odd (n = 2m - 1, which includes n = 1 -> m = 1): rows 2j - 1, 2j, 2j + 1 with weights
 *    j, m and m - 1 - j out of n (the first is 0 for j = 0, the last 0 for j = m - 1), e.g. n = 5:
 *    (3, 2) / 5, (1, 3, 1) / 5, (2, 3) / 5.
 * Each level keeps the mean of every column. The integer weights need no floor or division per
 * pixel; a per-column reciprocal of n turns them into fractions.
 *
 * Sampling runs once per screen pixel (~1.8 M times a frame), so it repeats the bilinear addressing
 * of fv_grid_bilinear (filter/grid.h) with no division or modulo: X and V are brought into range
 * once, after which a row index can only be one step outside its column and wraps or clamps with a
 * compare. At level 0 it returns exactly what fv_grid_bilinear's taps and weights give.
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/phi_mips.h"

#define MAX_LEVELS FV_KPHI_MAX_LEVELS

struct fv_phi_mips {
    int levels;
    int w;
    bool wrap;
    fv_grid grid[MAX_LEVELS];   /* what fv_phi_mips_grid returns; level 0 is the caller's grid */
    int *rows[MAX_LEVELS];      /* rows of each column at level k (owned, never NULL) */
    float *rowsf[MAX_LEVELS];   /* the same as floats, for the lookup */
    float *inv_src[MAX_LEVELS]; /* level k >= 1: 1 / rows[k - 1][x], the unit of the odd weights */
    float *img[MAX_LEVELS];     /* 3 floats per pixel, grid[k].w * grid[k].h pixels */
};

void fv_phi_mips_destroy(fv_phi_mips *m)
{
    if (!m) return;
    for (int k = 0; k < MAX_LEVELS; k++) free(m->rows[k]), free(m->rowsf[k]), free(m->inv_src[k]), free(m->img[k]);
    free(m);
}

fv_status fv_phi_mips_create(const fv_grid *g, int max_levels, fv_phi_mips **out, fv_error *err)
{
    if (!out) return fv_error_set(err, FV_ERR_INVALID, "phi mipmaps: no output handle");
    *out = NULL;
    if (!g) return fv_error_set(err, FV_ERR_INVALID, "phi mipmaps: no grid");
    if (g->w < 1 || g->h < 1) return fv_error_set(err, FV_ERR_INVALID, "phi mipmaps: grid size %dx%d", g->w, g->h);
    if (max_levels < 1)
        return fv_error_set(err, FV_ERR_INVALID, "phi mipmaps: max_levels %d must be at least 1", max_levels);
    for (int x = 0; g->col_h && x < g->w; x++)
        if (g->col_h[x] < 1 || g->col_h[x] > g->h)
            return fv_error_set(err, FV_ERR_INVALID, "phi mipmaps: column %d has %d rows, not in [1, %d]", x, g->col_h[x],
                                g->h);

    fv_phi_mips *m = calloc(1, sizeof *m);
    if (!m) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for phi mipmaps");
    m->w = g->w;
    m->wrap = g->wrap;
    m->grid[0] = *g;
    m->rows[0] = fv_alloc_array((size_t)g->w, sizeof(int));
    if (!m->rows[0]) goto nomem;
    int tallest = 0;
    for (int x = 0; x < g->w; x++) {
        m->rows[0][x] = fv_grid_col_h(g, x);
        tallest = m->rows[0][x] > tallest ? m->rows[0][x] : tallest;
    }
    m->levels = 1;
    /* A level is added while some column still has more than one row. */
    while (m->levels < max_levels && m->levels < MAX_LEVELS && tallest > 1) {
        const int k = m->levels;
        if (!(m->rows[k] = fv_alloc_array((size_t)g->w, sizeof(int)))) goto nomem;
        if (!(m->inv_src[k] = fv_alloc_array((size_t)g->w, sizeof(float)))) goto nomem;
        tallest = 0;
        for (int x = 0; x < g->w; x++) {
            const int n = m->rows[k - 1][x];
            m->rows[k][x] = (n + 1) / 2;
            m->inv_src[k][x] = 1.0f / (float)n;
            tallest = m->rows[k][x] > tallest ? m->rows[k][x] : tallest;
        }
        m->grid[k] = (fv_grid){g->w, tallest, m->rows[k], g->wrap};
        m->levels++;
    }
    for (int k = 0; k < m->levels; k++) {
        if (!(m->rowsf[k] = fv_alloc_array((size_t)g->w, sizeof(float)))) goto nomem;
        for (int x = 0; x < g->w; x++) m->rowsf[k][x] = (float)m->rows[k][x];
        /* Zeroed: rows beyond a column's height are never written by the build. */
        m->img[k] = fv_calloc_array(3 * (size_t)m->grid[k].w * (size_t)m->grid[k].h, sizeof(float));
        if (!m->img[k]) goto nomem;
    }
    *out = m;
    return FV_OK;
nomem:
    fv_phi_mips_destroy(m);
    return fv_error_set(err, FV_ERR_NOMEM, "out of memory for phi mipmaps of a %dx%d grid", g->w, g->h);
}

int fv_phi_mips_levels(const fv_phi_mips *m) { return m ? m->levels : 0; }

const fv_grid *fv_phi_mips_grid(const fv_phi_mips *m, int k)
{
    return m && k >= 0 && k < m->levels ? &m->grid[k] : NULL;
}

/* Row j of level k from level k - 1, a cell at a time with the kernel's step (filter/kphi.h). */
static void halve_row(const fv_kphi_mips *km, int k, int j)
{
    for (int x = 0; x < km->w; x++) fv_kphi_halve_cell(km, k, x, j);
}

void fv_phi_mips_kernel(const fv_phi_mips *m, fv_kphi_mips *out)
{
    memset(out, 0, sizeof *out);
    out->levels = m->levels;
    out->w = m->w;
    out->wrap = m->wrap;
    for (int k = 0; k < m->levels; k++) {
        out->rows[k] = m->rows[k];
        out->rowsf[k] = m->rowsf[k];
        out->inv_src[k] = m->inv_src[k];
        out->img[k] = m->img[k];
    }
}

void fv_phi_mips_build(fv_phi_mips *m, const float *rgb, int threads)
{
    if (!m || !rgb) return;
    const size_t stride = 3 * (size_t)m->w;
    const int h0 = m->grid[0].h;
    fv_kphi_mips km;
    fv_phi_mips_kernel(m, &km);
fv_region_begin();
#pragma omp parallel num_threads(fv_thread_count(threads))
    {
#pragma omp for schedule(static)
        for (int y = 0; y < h0; y++) memcpy(m->img[0] + y * stride, rgb + y * stride, stride * sizeof(float));
        /* Each level reads the one before: the implicit barrier of every loop orders them. Rows
         * near the top hold more columns (a triangular grid), hence dynamic chunks. */
        for (int k = 1; k < m->levels; k++) {
#pragma omp for schedule(dynamic, 8)
            for (int j = 0; j < m->grid[k].h; j++) halve_row(&km, k, j);
        }
    }
fv_region_end();
}

/* The map stage samples through the kernel (filter/kphi.h); this is the same lookup for host
 * callers, so there is one implementation of it. */
void fv_phi_mips_sample(const fv_phi_mips *m, float X, float V, float level, float out[3])
{
    fv_kphi_mips km;
    fv_phi_mips_kernel(m, &km);
    fv_kphi_sample(&km, X, V, level, out);
}
