/* fovea — the image side of the inverted pyramid (Polychronakis et al. 2023, Sec. 3.1-3.2): the
 * levels' sizes, the 3x3 minimum filter that gives a ray its start, the Sobel edges of pass 2, the
 * probability of pass 3, and the colours of the diagnostic outputs. Pure functions on buffers,
 * tested by hand (tests/unit/test_sdf_family.c).
 *
 * Levels are counted from the tip: level 0 is the coarsest, level L-1 the target. They are built on
 * the sample grid (the film's pixels times the samples per pixel along each axis, so at 16 spp the
 * tip has one ray per pixel, which is where the paper's speed-up with super-sampling comes from).
 * Level k has one ray per f = 2^(L-1-k) x f block of target samples: ceil(W / f) x ceil(H / f)
 * rays, the last row and column covering what is left of an odd size; each ray passes through the
 * centre of the part of its block inside the grid.
 */
#ifndef FV_SDF_PYRAMID_H
#define FV_SDF_PYRAMID_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/math.h"

#define FV_PYRAMID_MAX_LEVELS 6

typedef struct fv_pyramid_level {
    int w, h;  /* rays */
    int f;     /* target samples per ray along each axis */
} fv_pyramid_level;

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

#endif
