/* fovea — the eye model's geometry and the papers' acuity models as kernel code (FV_HD): where a
 * pixel lies from the gaze, its eccentricity, its region (fovea, transition, periphery), the
 * transition's blend weight, and the acuity functions foveated methods spend effort by. The public
 * functions of fovea/gaze.h (gaze/eye.c, gaze/acuity.c) are these, so a GPU kernel and the CPU
 * classify pixels and weigh them identically.
 *
 * Foveated Photon Mapping, Eq. 7 gives the foveal radius in pixels as tan(e_f) * b * PPI with b the
 * pupil-to-lens distance; it is read as a viewing distance D in pixels and used both ways
 * (eccentricity = atan(d / D) for a pixel d pixels from the gaze point), so radii given in degrees
 * and eccentricities measured in degrees always agree. Eq. 6 gives the transition's blend weight.
 * Foveated Instant Radiosity (Sec. 5) gives the radius as 25% of the image width instead
 * (FV_FOVEA_WIDTH). Double precision, as the CPU has always computed them.
 */
#ifndef FV_KERNEL_KEYE_H
#define FV_KERNEL_KEYE_H

#include <math.h>
#include "fovea/gaze.h"

#define FV_MM_PER_INCH 25.4

/* The viewing distance D in pixels: from the horizontal field of view when the model has one, else
 * the pupil-to-lens distance times the pixel density. */
FV_HD static inline double fv_keye_view_dist_px(const fv_eye_model *m)
{
    if (m->fov_x_deg > 0.0f) return 0.5 * m->width / tan(0.5 * m->fov_x_deg * FV_PI_D / 180.0);
    return (double)m->eye_dist_mm / FV_MM_PER_INCH * m->ppi;
}

FV_HD static inline double fv_keye_fovea_radius_px(const fv_eye_model *m)
{
    if (m->mode == FV_FOVEA_WIDTH) return (double)m->fovea_frac * m->width;
    return tan(m->fovea_deg * FV_PI_D / 180.0) * fv_keye_view_dist_px(m);
}

FV_HD static inline double fv_keye_transition_radius_px(const fv_eye_model *m)
{
    if (m->mode == FV_FOVEA_WIDTH) return (double)m->transition_frac * m->width;
    return tan(m->transition_deg * FV_PI_D / 180.0) * fv_keye_view_dist_px(m);
}

/* Distance in pixels from film position (px, py) to the gaze point. */
FV_HD static inline double fv_keye_gaze_dist_px(const fv_eye_model *m, fv_gaze g, double px, double py)
{
    return hypot(px - (double)g.x * m->width, py - (double)g.y * m->height);
}

FV_HD static inline double fv_keye_eccentricity_deg(const fv_eye_model *m, fv_gaze g, double px, double py)
{
    return atan(fv_keye_gaze_dist_px(m, g, px, py) / fv_keye_view_dist_px(m)) * 180.0 / FV_PI_D;
}

/* The region of a point d pixels from the gaze, given the two radii. */
FV_HD static inline fv_region fv_keye_classify(double d, double rf, double rt)
{
    return d <= rf ? FV_REGION_FOVEA : d <= rt ? FV_REGION_TRANSITION : FV_REGION_PERIPHERY;
}

/* Eq. 6: 0 in the fovea, 1 in the periphery, linear across the transition. */
FV_HD static inline double fv_keye_blend(const fv_eye_model *m, fv_gaze g, double px, double py)
{
    double d = fv_keye_gaze_dist_px(m, g, px, py);
    double rf = fv_keye_fovea_radius_px(m), rt = fv_keye_transition_radius_px(m);
    if (d <= rf) return 0.0;
    if (d >= rt || rt <= rf) return 1.0;
    return (d - rf) / (rt - rf);
}

/* ---- acuity models, each the paper's equation as printed (tests/unit/test_gaze.c) ---- */

/* Visual-Polar, Eq. 1: 60 cycles/degree up to 5.79 degrees, then 449.4 / (0.3 e + 1)^2. The two
 * branches meet at 5.79 (449.4 / 2.737^2 = 60.0). */
FV_HD static inline double fv_kacuity_v(double e)
{
    if (e <= 5.79) return 60.0;
    double k = 0.3 * e + 1.0;
    return 449.4 / (k * k);
}

/* Visual-Polar, Eq. 2. */
FV_HD static inline double fv_kacuity_cdf(double d)
{
    double k = 0.3 * d + 1.0;
    return (1.0 / k + log(k)) * 166.4 * FV_PI_D - 612.3;
}

/* Visual-Polar, Eq. 3 (Horner form of 25.09 p^4 + 0.1680 p^3 + 27.61 p^2 + 23.87 p + 3.232). */
FV_HD static inline double fv_kacuity_cdf_inv_fit(double p)
{
    return (((25.09 * p + 0.1680) * p + 27.61) * p + 23.87) * p + 3.232;
}

/* Inverted-pyramid sphere tracing, Eq. 1 with its three zones (Sec. 3, third pass). */
FV_HD static inline double fv_kacuity_hyperbolic(double w, double fovea_deg, double outer_deg)
{
    if (w <= fovea_deg) return 1.0;
    if (outer_deg > 0.0 && w > outer_deg) return 0.0;
    double p = 0.90964 * exp(-w / 2.9661) + 0.00792;
    return p > 1.0 ? 1.0 : p;
}

/* Linear fall-off from 1 at e0 to min_value at e1. */
FV_HD static inline double fv_kacuity_linear(double e, double e0, double e1, double min_value)
{
    if (e <= e0) return 1.0;
    if (e >= e1 || e1 <= e0) return min_value;
    return 1.0 + (min_value - 1.0) * (e - e0) / (e1 - e0);
}

#endif
