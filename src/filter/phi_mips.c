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
        /* Zeroed: rows beyond a column's height are never written by the build. One float more: the
         * 4-wide read of the last pixel (see lookup). */
        m->img[k] = fv_calloc_array(3 * (size_t)m->grid[k].w * (size_t)m->grid[k].h + 1, sizeof(float));
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

/* Row j of level k from level k - 1, a cell at a time with the kernel's step (kernel/vp_map.h). */
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

/* floor(f) for f > -1 (lookups only see f >= -0.5): truncation, minus one for negative f. */
static inline int floor_small(float f)
{
    return (int)f - (f < 0.0f);
}

#if defined(__GNUC__)
/* Four floats from any float address (GCC and Clang vector extensions): a pixel's RGB and one float
 * of the next pixel (every level has one float of padding after its last pixel), so a tap is one
 * load and two vector operations. */
typedef float v4f __attribute__((vector_size(16), aligned(4), may_alias));
#define PX(p) (*(const v4f *)(const void *)(p))
#else
typedef struct v4f {
    float v[4];
} v4f;
#endif

/* acc + wgt times the bilinear lookup of level k at columns xa (weight 1 - tx) and xb (weight tx),
 * V already in [0, 1]. Same taps and weights as fv_grid_bilinear, and per channel the same
 * operations in the same order. */
static inline v4f lookup(const fv_phi_mips *m, int k, int xa, int xb, float tx, float V, float wgt, v4f acc)
{
    const float *img = m->img[k];
    const int *rows = m->rows[k];
    const float *rowsf = m->rowsf[k];
    const size_t stride = 3 * (size_t)m->w;
    for (int c = 0; c < 2; c++) {
        const int x = c ? xb : xa, n = rows[x];
        const float fy = V * rowsf[x] - 0.5f;
        int y0 = floor_small(fy), y1 = y0 + 1;
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
#if defined(__GNUC__)
        acc += w0 * PX(p0);
        acc += w1 * PX(p1);
#else
        for (int ch = 0; ch < 3; ch++) acc.v[ch] += w0 * p0[ch], acc.v[ch] += w1 * p1[ch];
#endif
    }
    return acc;
}

void fv_phi_mips_sample(const fv_phi_mips *m, float X, float V, float level, float out[3])
{
    /* Columns clamp: X outside [0, w] reads the edge column, as fv_grid_bilinear does. */
    const float wf = (float)m->w;
    X = X >= 0.0f ? (X <= wf ? X : wf) : 0.0f; /* also NaN -> 0 */
    if (m->wrap) {
        if (!(V >= 0.0f && V < 1.0f)) V -= floorf(V); /* one turn is the same angle */
        if (!(V >= 0.0f && V <= 1.0f)) V = 0.0f;      /* NaN or infinite */
    } else {
        V = V >= 0.0f ? (V <= 1.0f ? V : 1.0f) : 0.0f;
    }
    const float fx = X - 0.5f;
    const int x0 = floor_small(fx);
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
    v4f acc = {0};
    if (t > 0.0f) {
        acc = lookup(m, k, xa, xb, tx, V, 1.0f - t, acc);
        acc = lookup(m, k + 1, xa, xb, tx, V, t, acc);
    } else {
        acc = lookup(m, k, xa, xb, tx, V, 1.0f, acc);
    }
#if defined(__GNUC__)
    out[0] = acc[0], out[1] = acc[1], out[2] = acc[2];
#else
    out[0] = acc.v[0], out[1] = acc.v[1], out[2] = acc.v[2];
#endif
}
