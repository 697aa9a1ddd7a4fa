/* fovea — the image side of the inverted pyramid (Polychronakis et al. 2023, Sec. 3.1-3.2): the
 * levels' sizes, the 3x3 minimum filter that gives a ray its start, the Sobel edges of pass 2, the
 * probability of pass 3, and the colours of the diagnostic outputs. Pure functions on buffers,
 * tested by hand (tests/unit/test_sdf_family.c).
 *
 * Levels are counted from the tip (level 0) to the target (L-1) on the sample grid; how they are
 * laid out: technique/sdf/kpyr.h. The host buffers below are the CPU pipeline's and the portable
 * backend's (the device backends keep their own, technique/sdf/sdf_device.c).
 */
#ifndef FV_SDF_PYRAMID_H
#define FV_SDF_PYRAMID_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/math.h"
#include "fovea/status.h"
#include "technique/sdf/kpyr.h"

/* fv_pyramid_level, fv_kpyr (a pyramid's shape and buffers) and the per-cell steps:
 * technique/sdf/kpyr.h. These are their whole-buffer forms and the host buffers. */

/* Fills level[0 .. levels-1] for a target grid of sw x sh samples. */
void fv_pyramid_levels(int sw, int sh, int levels, fv_pyramid_level *level);

/* Target-grid position (in samples, from the top-left corner) the ray (i, j) of a level passes
 * through: the centre of its block clipped to the grid. */
void fv_pyramid_centre(const fv_pyramid_level *l, int sw, int sh, int i, int j, float *sx, float *sy);

/* Start distance of a ray whose parent (one level down) is (pi, pj): the smallest depth of the
 * parent and its eight neighbours (Sec. 3.2.4), or the parent's own depth without the filter.
 * Depths are +inf where the parent's ray missed. */
float fv_pyramid_start(const float *depth, const fv_pyramid_level *parent, int pi, int pj, bool min_filter);

/* Sec. 3.2.2: Sobel on the depth image (w x h, +inf for a miss; a miss is treated as the farthest
 * finite depth times two, so silhouettes against the sky are edges), edge[i] = 1 where the
 * gradient's magnitude exceeds threshold x the pixel's depth (a relative threshold keeps the
 * ground's smooth recession from counting as an edge), else 0. Borders clamp. */
void fv_pyramid_sobel(const float *depth, int w, int h, float threshold, uint8_t *edge);

/* Sec. 3.2.3 with Eq. 1: the probability a target pixel is traced at the top level: 1 inside the
 * fovea, 0 beyond outer_deg, 1 on an edge, else p(w) = 0.90964 e^(-w / 2.9661) + 0.00792. */
double fv_pyramid_probability(double ecc_deg, double fovea_deg, double outer_deg, bool edge);

/* Diagnostic colours: steps per ray on a log scale from blue (1 step) through green to red
 * (256 and more), as the heat maps of Fig. 4; a level from red (the tip) through green to blue
 * (the target). */
fv_vec3 fv_pyramid_heat(float steps);
fv_vec3 fv_pyramid_level_colour(int level, int levels);

/* fipr's middle level kept between frames, per eye: the colours the pixels outside the mask are
 * reconstructed from, and the frame each was last shaded in (refreshed every 1, 2 or 4 frames). */
typedef struct fv_pyramid_history {
    int sw, sh;   /* the target grid it belongs to; another size starts afresh */
    float *color; /* 3 per middle-level ray */
    int *stamp;   /* frame index of the last shading, INT_MIN: never */
} fv_pyramid_history;

/* Makes k's host buffers fit a w x h film at S samples per pixel along each axis and L levels
 * (kept when they already do): depth and steps of levels 0 .. L-2, with fipr need, edge and mask,
 * with vis the shadow_reuse visibility of level L-2. FV_ERR_NOMEM (k emptied) when memory runs out. */
fv_status fv_pyramid_alloc(fv_kpyr *k, int w, int h, int S, int L, bool fipr, bool vis, fv_error *err);
void fv_pyramid_free(fv_kpyr *k);

/* Points k's history at hs, sized for k's middle level; a new size, or index 0 (a sequence's first
 * frame), starts without history (every stamp INT_MIN). */
fv_status fv_pyramid_history_attach(fv_pyramid_history *hs, fv_kpyr *k, int index, fv_error *err);
void fv_pyramid_history_free(fv_pyramid_history *hs);

#endif
