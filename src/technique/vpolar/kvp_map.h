/* fovea — the map stage of Visual-Polar path tracing (Sec. 3.4) as kernel code: one screen pixel
 * of the map from the sample space, read through the φ-mipmaps (filter/kphi.h). The CPU, the
 * portable backend and CUDA run it a pixel at a time.
 */
#ifndef FV_TECHNIQUE_VPOLAR_KVP_MAP_H
#define FV_TECHNIQUE_VPOLAR_KVP_MAP_H

#include <math.h>
#include <stddef.h>
#include "fovea/film.h"
#include "fovea/math.h"
#include "filter/kphi.h"
#include "technique/vpolar/kvp_space.h"

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
