/* fovea — the reprojection of Visual-Polar path tracing's denoiser history (Sec. 3.3, "Temporal
 * accumulation") as kernel code: a grid sample's first hit projected into the previous frame's
 * camera, and the screen position mapped into the previous frame's sample space (through that
 * view's radial table on a polar space, directly on a Cartesian one), where SVGF fetches its
 * history. The CPU pipeline runs the two halves in two vectorised loops; the portable backend and
 * CUDA a sample at a time.
 */
#ifndef FV_TECHNIQUE_VPOLAR_KVP_REPROJECT_H
#define FV_TECHNIQUE_VPOLAR_KVP_REPROJECT_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include "fovea/camera.h"
#include "technique/vpolar/kvp_space.h"

/* Where grid cell i's first hit was on the previous frame's screen (*qx, *qy); false when the cell
 * had no path or surface, is off screen (onscreen, NULL: every cell is on), or its hit was behind
 * the previous camera or outside its screen. */
FV_HD static inline bool fv_kvp_reproject_screen(const fv_kvp_gbuf *g, const uint8_t *onscreen, const fv_camera_basis *prev, int sw, int sh,
                                                 long i, float *qx, float *qy)
{
    if (!g->sampled[i] || g->id[i] == 0 || (onscreen && !onscreen[i])) return false;
    const fv_vec3 x = fv_v3(g->position[3 * i], g->position[3 * i + 1], g->position[3 * i + 2]);
    if (!fv_camera_project_point(prev, x, qx, qy)) return false;
    return !(*qx < 0.0f || *qy < 0.0f || *qx > (float)sw || *qy > (float)sh);
}

/* One frame of the reprojection: the grid's buffers, the previous camera, and the previous view
 * with its radial table (polar spaces; three floats an entry, fv_kvp_table_coords). */
typedef struct fv_kvp_reproject_frame {
    fv_kvp_space space;
    fv_kvp_gbuf g;
    const uint8_t *onscreen;
    fv_camera_basis prev_cam;
    fv_kvp_view prev_view;
    const float *prev_lut;
    int nlut;
    float inv_step;
} fv_kvp_reproject_frame;

/* Grid cell i's history coordinate in the previous frame's grid into pc[0..1]; NaN when it has none. */
FV_HD static inline void fv_kvp_reproject_sample(const fv_kvp_reproject_frame *f, long i, float *pc)
{
    float qx, qy;
    pc[0] = pc[1] = NAN;
    if (!fv_kvp_reproject_screen(&f->g, f->onscreen, &f->prev_cam, f->space.sw, f->space.sh, i, &qx, &qy)) return;
    if (f->space.kind == FV_KVP_CARTESIAN)
        fv_kvp_cartesian_from_screen(&f->space, qx, qy, &pc[0], &pc[1]);
    else
        fv_kvp_table_coords(f->prev_lut, f->nlut, f->inv_step, qx - f->prev_view.gx, qy - f->prev_view.gy, &pc[0], &pc[1], NULL, NULL);
}

#endif
