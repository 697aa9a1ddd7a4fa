/* fovea — sample spaces: where the samples of one frame lie on the screen, as a regular grid that
 * can be traced, denoised and resampled like an image.
 *
 *  - Visual-Polar space (Foveated Real-Time Path Tracing in Visual-Polar Space, Sec. 3.2): columns
 *    are the distance ρ from the gaze, rows the angle φ around it. In the fovea ρ is linear and the
 *    columns are clipped to a triangle (column height proportional to ρ) so that the screen density
 *    is constant; beyond it every column is full height and ρ follows the acuity distribution, Eq. 2
 *    (screen to grid) and a least-squares polynomial inverse in the spirit of Eq. 3 (grid to screen).
 *    The largest ρ is the distance from the gaze to the farthest screen corner, so the grid, and the
 *    number of samples, is the same wherever the gaze is.
 *  - Log-polar space (Meng, Du, Zwicker, Varshney, "Kernel Foveated Rendering", 2018): a
 *    (W / sigma) x (H / sigma) grid, ρ = exp(L (u)^alpha) with L = log of the largest ρ.
 *  - Cartesian space: a uniform grid of the screen scaled by sqrt(1 - reduction) on both axes
 *    (reduction 0: the screen itself).
 *
 * Angles are "planar degrees" as in the paper's Eq. 2, a distance on the screen divided by the
 * pixels per degree at the gaze point (the display's viewing distance D in pixels times pi / 180).
 *
 * A space is built once per screen size (its grid never changes); a view places it for one frame's
 * gaze. Views are plain values, so a technique keeps last frame's view to reproject its history.
 */
#ifndef FV_TECHNIQUE_VPOLAR_SPACE_H
#define FV_TECHNIQUE_VPOLAR_SPACE_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include "filter/grid.h"
#include "fovea/gaze.h"
#include "fovea/status.h"
#include "technique/vpolar/kvp_space.h"

typedef enum fv_space_kind { FV_SPACE_CARTESIAN = 0, FV_SPACE_VPOLAR, FV_SPACE_LOGPOLAR } fv_space_kind;

typedef struct fv_space_opts {
    fv_space_kind kind;
    double reduction;    /* Visual-Polar and Cartesian: share of the screen's pixels not sampled,
                            [0, 1) for Cartesian, (0, 1) for Visual-Polar; 0.61 in the paper */
    double fovea_deg;    /* Visual-Polar: radius of the linear, clipped part (5.79: where V(e) of
                            Eq. 1 stops being flat) */
    int fit_degree;      /* Visual-Polar: degree of the polynomial inverse of Eq. 2 (2..10) */
    double lp_sigma;     /* log-polar: screen-to-grid size ratio per axis (> 1; 1.8 in Meng et al.) */
    double lp_alpha;     /* log-polar: kernel exponent (> 0; 4 in Meng et al.) */
} fv_space_opts;

void fv_space_opts_default(fv_space_kind kind, fv_space_opts *o);

typedef struct fv_space fv_space;

/* Builds the grid for a screen_w x screen_h image; px_per_deg is the display's pixels per degree at
 * the gaze point. Options out of range, a grid below 2x2 or above the film limits, or a reduction
 * too large for the fovea to keep one sample per pixel -> FV_ERR_INVALID naming the value. */
fv_status fv_space_create(const fv_space_opts *o, int screen_w, int screen_h, double px_per_deg, fv_space **out,
                          fv_error *err);
void fv_space_destroy(fv_space *s);

const fv_grid *fv_space_grid(const fv_space *s);
fv_space_kind fv_space_kind_of(const fv_space *s);
/* Samples in the grid (the valid rows of all columns). */
long fv_space_sample_count(const fv_space *s);
/* Visual-Polar: the fovea's share of the samples and its density in samples per screen pixel when
 * the gaze is at the screen's centre and at a corner (the lowest); the largest error of the fitted
 * inverse against the exact inverse of Eq. 2, in pixels, for the gaze at the centre. 0 for the
 * other kinds. */
typedef struct fv_space_info {
    double fovea_share, fovea_density_centre, fovea_density_corner, fit_error_px;
    double fovea_columns;  /* X at the fovea's edge */
} fv_space_info;
void fv_space_get_info(const fv_space *s, fv_space_info *out);
/* The fitted polynomial's coefficients, lowest order first (Visual-Polar; n = degree + 1). */
int fv_space_fit_coeffs(const fv_space *s, const double **coeffs);

/* A space placed for one gaze. */
typedef struct fv_space_view {
    const fv_space *space;
    float gx, gy;        /* gaze in pixels */
    float rho_max;       /* distance from the gaze to the farthest corner, pixels */
    float log_rho_max;   /* log-polar: L */
} fv_space_view;

fv_space_view fv_space_view_at(const fv_space *s, fv_gaze g);

/* Grid (X, V) continuous coordinates (filter/grid.h) to screen position in pixels. */
void fv_space_to_screen(const fv_space_view *v, float X, float V, float *px, float *py);
/* Screen position in pixels to grid (X, V); *phi_per_px (optional) receives how many rows of the
 * column one screen pixel spans along φ (the mip level is its log2; 0 for the Cartesian kind). */
void fv_space_from_screen(const fv_space_view *v, float px, float py, float *X, float *V, float *phi_per_px);
/* Screen radius (pixels from the gaze) of column coordinate X. */
float fv_space_radius(const fv_space_view *v, float X);

/* A radial table of one view, for the lookups that depend only on the distance from the gaze (the
 * map stage, the denoiser's reprojection): entry i, at table[i * stride], holds the column X at
 * distance i * step from the gaze (fv_space_from_screen along +x) and, next to it, the mip level
 * (log2 of the rows one pixel spans along φ, 0 below one row); n >= 2 entries. */
void fv_space_radial_table(const fv_space_view *v, float step, int n, int stride, float *table);

/* fv_space_turns and fv_space_table_x, the per-pixel steps of the lookups through such a table,
 * are kernel code: technique/vpolar/kvp_space.h. */

/* The flat form of the space (technique/vpolar/kvp_space.h) and of a view of it, for the kernels. */
const fv_kvp_space *fv_space_kernel(const fv_space *s);
static inline fv_kvp_view fv_space_kview(const fv_space_view *v)
{
    fv_kvp_view k = {v->gx, v->gy, v->rho_max, v->log_rho_max};
    return k;
}

/* For every grid cell (storage w * h, rows beyond a column's height 0): 1 when some point of the
 * cell lies within reach_px of the screen, reach_px plus the cell's own size (a bilinear lookup
 * from the screen reaches the neighbouring cells), 0 when the whole cell is farther off screen.
 * The test is conservative: a cell marked 0 is never read by a lookup from the screen whose
 * footprint stays within reach_px. Cartesian spaces: every cell is 1. Returns the count of 1s.
 * About ten flops per cell (per-column radii and a per-row angle table for full-height columns). */
long fv_space_onscreen_mask(const fv_space_view *v, float reach_px, uint8_t *mask);

/* The cumulative acuity of Eq. 2 continued as pi e^2 inside 5.79 degrees (they meet there): the
 * area-weighted acuity within e planar degrees of the gaze. Exposed for the tests. */
double fv_space_acuity_area(double e_deg);

#endif
