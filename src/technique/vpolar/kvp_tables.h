/* fovea — the tables a Visual-Polar frame makes for each gaze (Foveated Real-Time Path Tracing in
 * Visual-Polar Space, Sec. 3.2: the space is placed at the gaze every frame), as kernel code: an
 * entry or a cell at a time, so that the CPU (technique/vpolar/space.c, vp_pipeline.c) and the device
 * frame's kernels (technique/vpolar/vpolar_kernels.h) compute them with the same arithmetic.
 *
 *  - The radial table: what the map stage and the denoiser's reprojection look up by the distance
 *    from the gaze alone, an entry every `step` pixels: the column X, the φ-mip level (Sec. 3.4)
 *    and the foveated blur's sigma (Sec. 3.5).
 *  - The on-screen mask: the grid cells some screen pixel can see (a polar grid's corners reach
 *    beyond the screen wherever the gaze is), in two steps: a column's radii and bound, then each
 *    cell of the column against the screen.
 */
#ifndef FV_TECHNIQUE_VPOLAR_KVP_TABLES_H
#define FV_TECHNIQUE_VPOLAR_KVP_TABLES_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include "fovea/math.h"
#include "filter/kblur.h"
#include "technique/vpolar/kvp_space.h"

/* ---- the radial table ---- */

/* A view's radial table of n entries of three floats (column, mip level, blur sigma). The sigma is
 * Sec. 3.5's profile at the entry's eccentricity r / px_per_deg * scale (scale: the blur's fovea
 * stretching with the space, 1 when it does not), 0 everywhere without the blur. */
typedef struct fv_kvp_radial {
    fv_kvp_space space;
    fv_kvp_view view;
    float step; /* pixels between entries */
    int n;
    int blur;
    double px_per_deg, scale, fovea_deg, ramp_deg, sigma_px;
    float *table;
} fv_kvp_radial;

FV_HD static inline void fv_kvp_radial_entry(const fv_kvp_radial *t, int i)
{
    float *e = &t->table[3 * (size_t)i];
    fv_kvp_radial_coords(&t->space, &t->view, t->step, i, &e[0], &e[1]);
    const float r = (float)i * t->step;
    e[2] = t->blur ? (float)fv_kblur_sigma_at((double)r / t->px_per_deg * t->scale, t->fovea_deg, t->ramp_deg, t->sigma_px) : 0.0f;
}

/* ---- the on-screen mask ---- */

/* The angle of row y of an n-row column (its centre), as cosine and sine: a full-height row's are
 * tabulated once per grid (space.c, and the device frame's row table), the same values. */
FV_HD static inline void fv_kvp_row_angle(int y, int n, float *c, float *s)
{
    const float phi = 2.0f * FV_PI * ((float)y + 0.5f) / (float)n;
    *c = cosf(phi), *s = sinf(phi);
}

/* What the cells of column x share: the radius of their centres, the square of how far a centre may
 * lie off the screen widened by the reach, and whether every centre lies within that screen. */
typedef struct fv_kvp_onscreen_col {
    float rm, b2;
    int all;
} fv_kvp_onscreen_col;

/* Column x of n rows, for cells a lookup reaches from within reach pixels of the screen. It spans
 * the radii [r(x), r(x + 1)]; a cell of an n-row column spans 2 pi / n of angle, so every point of
 * it is within (r1 - r0) / 2 + pi r1 / n of its centre (radial half-width plus the arc, which is
 * longer than the chord). That bound, doubled for the neighbouring cells a bilinear tap reaches, is
 * how far the centre may be off the screen widened by reach. */
FV_HD static inline fv_kvp_onscreen_col fv_kvp_onscreen_column(const fv_kvp_space *s, const fv_kvp_view *v, float reach, int x, int n)
{
    const float r0 = fv_kvp_radius(s, v, (float)x), r1 = fv_kvp_radius(s, v, (float)x + 1.0f), rm = fv_kvp_radius(s, v, (float)x + 0.5f);
    const float bound = 2.0f * (0.5f * (r1 - r0) + FV_PI * r1 / (float)n);
    const float lo_x = -reach, lo_y = -reach, hi_x = (float)s->sw + reach, hi_y = (float)s->sh + reach;
    fv_kvp_onscreen_col c;
    c.rm = rm;
    c.b2 = bound * bound;
    c.all = v->gx - rm >= lo_x && v->gy - rm >= lo_y && v->gx + rm <= hi_x && v->gy + rm <= hi_y;
    return c;
}

/* Cell y (< n) of a column: 1 when some point of it lies within reach of the screen (conservative:
 * a cell marked 0 is never read by a lookup from the screen whose footprint stays within reach).
 * row_cs: the full-height rows' angles (fv_kvp_row_angle for h rows, 2 floats a row), NULL: each
 * cell's computed. */
FV_HD static inline uint8_t fv_kvp_onscreen_cell(const fv_kvp_space *s, const fv_kvp_view *v, float reach, const fv_kvp_onscreen_col *c, int n,
                                                 int h, int y, const float *row_cs)
{
    if (c->all) return 1;
    float cs, sn;
    if (n == h && row_cs)
        cs = row_cs[2 * y], sn = row_cs[2 * y + 1];
    else
        fv_kvp_row_angle(y, n, &cs, &sn);
    const float lo_x = -reach, lo_y = -reach, hi_x = (float)s->sw + reach, hi_y = (float)s->sh + reach;
    const float px = v->gx + c->rm * cs, py = v->gy + c->rm * sn;
    const float dx = px < lo_x ? lo_x - px : (px > hi_x ? px - hi_x : 0.0f);
    const float dy = py < lo_y ? lo_y - py : (py > hi_y ? py - hi_y : 0.0f);
    return dx * dx + dy * dy <= c->b2;
}

#endif
