/* fovea — the foveated Gaussian blur of Visual-Polar path tracing (Sec. 3.5): after mapping to the
 * screen, a Gaussian whose standard deviation grows with eccentricity removes the spatial aliasing
 * of the sparse periphery without blurring the fovea.
 *
 * The blur is separable (a horizontal then a vertical pass, as in the paper, for speed); each axis
 * is three box filters whose variances add up to sigma^2: the Gaussian's variance, a 2-D peak
 * 10-12% lower, at a cost that does not grow with sigma (blur.c). Each output pixel uses its own
 * sigma in every pass: exact variance for a constant sigma, a close approximation where sigma
 * varies slowly. Boxes are renormalised at the image border. Pixels with sigma below 0.05 are left
 * as they are by their own passes.
 */
#ifndef FV_FILTER_BLUR_H
#define FV_FILTER_BLUR_H

#include "fovea/status.h"

/* Sigma profile of Sec. 3.5: 0 up to fovea_deg, rising linearly to sigma_max at ramp_deg, held at
 * sigma_max beyond (the paper: 0 in the fovea, 6.8 pixels at 30 degrees at 1280x1440). */
double fv_blur_sigma_at(double e_deg, double fovea_deg, double ramp_deg, double sigma_max);

/* Blurs rgb (w * h * 3 floats) in place with the per-pixel sigma (w * h floats, pixels, >= 0).
 * threads 0 = all. Bad sizes, a NULL buffer or a negative or non-finite sigma -> FV_ERR_INVALID
 * (rgb unchanged); no scratch memory -> FV_ERR_NOMEM. */
fv_status fv_blur_variable(float *rgb, int w, int h, const float *sigma, int threads, fv_error *err);

#endif
