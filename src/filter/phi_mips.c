/* fovea — mipmaps along φ only (Visual-Polar Sec. 3.4; see phi_mips.h).
 *
 * Level k+1's row j covers the angles [j, j + 1) / h_{k+1} of its column; the source rows of level
 * k overlapping that span are averaged with weights equal to the overlap, so odd heights need no
 * special case and every level keeps the column's mean. Each level is stored like the grid: h_k
 * rows (the tallest column) of w pixels.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/phi_mips.h"

#define MAX_LEVELS 24

struct fv_phi_mips {
    int levels;
    fv_grid grid[MAX_LEVELS];
    int *col_h[MAX_LEVELS];   /* level 0: the source grid's (not owned, may be NULL) */
    float *img[MAX_LEVELS];
};

fv_status fv_phi_mips_create(const fv_grid *g, int max_levels, fv_phi_mips **out, fv_error *err)
{
    *out = NULL;
    if (!g || g->w < 1 || g->h < 1) return fv_error_set(err, FV_ERR_INVALID, "φ mipmaps: empty grid");
    if (max_levels < 1) return fv_error_set(err, FV_ERR_INVALID, "φ mipmaps: max_levels %d must be at least 1", max_levels);
    if (max_levels > MAX_LEVELS) max_levels = MAX_LEVELS;
    fv_phi_mips *m = calloc(1, sizeof *m);
    if (!m) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    m->grid[0] = *g;
    m->levels = 1;
    for (;;) {
        int k = m->levels - 1;
        const fv_grid *pg = &m->grid[k];
        size_t n = (size_t)pg->w * pg->h;
        if (!(m->img[k] = fv_alloc_array(n, 3 * sizeof(float)))) break;
        int tallest = 0;
        for (int x = 0; x < pg->w; x++) tallest = fv_grid_col_h(pg, x) > tallest ? fv_grid_col_h(pg, x) : tallest;
        if (tallest <= 1 || m->levels == max_levels) {
            *out = m;
            return FV_OK;
        }
        int *ch = fv_alloc_array((size_t)pg->w, sizeof(int));
        if (!ch) break;
        int hmax = 1;
        for (int x = 0; x < pg->w; x++) {
            ch[x] = (fv_grid_col_h(pg, x) + 1) / 2;
            hmax = ch[x] > hmax ? ch[x] : hmax;
        }
        m->col_h[k + 1] = ch;
        m->grid[k + 1] = (fv_grid){pg->w, hmax, ch, pg->wrap};
        m->levels++;
    }
    fv_phi_mips_destroy(m);
    return fv_error_set(err, FV_ERR_NOMEM, "out of memory for φ mipmaps of a %dx%d grid", g->w, g->h);
}

void fv_phi_mips_destroy(fv_phi_mips *m)
{
    if (!m) return;
    for (int k = 0; k < MAX_LEVELS; k++) {
        free(m->img[k]);
        if (k > 0) free(m->col_h[k]);
    }
    free(m);
}

int fv_phi_mips_levels(const fv_phi_mips *m) { return m->levels; }
const fv_grid *fv_phi_mips_grid(const fv_phi_mips *m, int k) { return &m->grid[k]; }

typedef struct build_ctx {
    fv_phi_mips *m;
    int k; /* building level k from k - 1 */
} build_ctx;

static void build_columns(void *ctx, int64_t b, int64_t e, int thread)
{
    build_ctx *c = ctx;
    const fv_grid *sg = &c->m->grid[c->k - 1], *dg = &c->m->grid[c->k];
    const float *src = c->m->img[c->k - 1];
    float *dst = c->m->img[c->k];
    for (int64_t x = b; x < e; x++) {
        int hs = fv_grid_col_h(sg, (int)x), hd = fv_grid_col_h(dg, (int)x);
        /* In units of source rows, destination row j spans [j r, (j + 1) r) with r = hs / hd. */
        double r = (double)hs / hd;
        for (int j = 0; j < hd; j++) {
            double a = j * r, z = (j + 1) * r;
            float s[3] = {0, 0, 0};
            double wsum = 0.0;
            for (int i = (int)floor(a); i < hs && i < z; i++) {
                double wgt = fmin(z, i + 1.0) - fmax(a, (double)i);
                if (wgt <= 0.0) continue;
                const float *p = &src[3 * ((size_t)i * sg->w + (size_t)x)];
                s[0] += (float)wgt * p[0], s[1] += (float)wgt * p[1], s[2] += (float)wgt * p[2];
                wsum += wgt;
            }
            float inv = (float)(1.0 / wsum);
            float *o = &dst[3 * ((size_t)j * dg->w + (size_t)x)];
            o[0] = s[0] * inv, o[1] = s[1] * inv, o[2] = s[2] * inv;
        }
    }
}

void fv_phi_mips_build(fv_phi_mips *m, const float *rgb, int threads)
{
    memcpy(m->img[0], rgb, (size_t)m->grid[0].w * m->grid[0].h * 3 * sizeof(float));
    for (int k = 1; k < m->levels; k++) {
        build_ctx c = {m, k};
        fv_parallel_for(m->grid[k].w, 64, threads, build_columns, &c);
    }
}

static void sample_level(const fv_phi_mips *m, int k, float X, float V, float out[3])
{
    long idx[4];
    float wt[4];
    fv_grid_bilinear(&m->grid[k], X, V, idx, wt);
    const float *img = m->img[k];
    out[0] = out[1] = out[2] = 0.0f;
    for (int t = 0; t < 4; t++) {
        const float *p = &img[3 * idx[t]];
        out[0] += wt[t] * p[0], out[1] += wt[t] * p[1], out[2] += wt[t] * p[2];
    }
}

void fv_phi_mips_sample(const fv_phi_mips *m, float X, float V, float level, float out[3])
{
    float top = (float)(m->levels - 1);
    level = level > 0.0f ? (level < top ? level : top) : 0.0f; /* also maps NaN to 0 */
    int k = (int)level;
    float f = level - (float)k;
    sample_level(m, k, X, V, out);
    if (f > 0.0f && k + 1 < m->levels) {
        float b[3];
        sample_level(m, k + 1, X, V, b);
        for (int c = 0; c < 3; c++) out[c] += f * (b[c] - out[c]);
    }
}
