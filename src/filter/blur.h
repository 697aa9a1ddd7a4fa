/* fovea — the foveated Gaussian blur of Visual-Polar path tracing (Sec. 3.5): after mapping to the
 * screen, a Gaussian whose standard deviation grows with eccentricity removes the spatial aliasing
 * of the sparse periphery without blurring the fovea.
 *
 * The blur is separable (a horizontal then a vertical pass, as in the paper, for speed); each output
 * pixel uses its own sigma in both passes, so the result is exact for a constant sigma and a close
 * approximation where sigma varies slowly. Kernels are truncated at 3 sigma (taps at whole-pixel
 * distances d <= 3 sigma) and renormalised at the image border. Sigma is first rounded to a grid
 * fine enough not to matter: multiples of 1/32 pixel up to 2 pixels, then 32 steps per octave (at
 * most 1/64 pixel or 1.6% off; the paper's 6.8 becomes 6.75). A pixel whose kernel keeps only its
 * centre tap (sigma below about 1/3 pixel, so every sigma below 0.05) is left unchanged, bit for bit.
 */
#ifndef FV_FILTER_BLUR_H
#define FV_FILTER_BLUR_H

#include <stddef.h>
#include "core/scratch.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" { /* C++ (a .cu file, the CUDA simulator) may build a blur table too */
#endif

/* Sigma profile of Sec. 3.5: 0 up to fovea_deg, rising linearly to sigma_max at ramp_deg, held at
 * sigma_max beyond (the paper: 0 in the fovea, 6.8 pixels at 30 degrees at 1280x1440). A NaN
 * eccentricity gets 0; ramp_deg <= fovea_deg makes the profile a step at fovea_deg. */
double fv_blur_sigma_at(double e_deg, double fovea_deg, double ramp_deg, double sigma_max);

/* Blurs rgb (w * h * 3 floats) in place with the per-pixel sigma (w * h floats, pixels, >= 0).
 * threads 0 = all; the result does not depend on it. Bad sizes, a NULL buffer or a negative or
 * non-finite sigma -> FV_ERR_INVALID (rgb unchanged); no scratch memory -> FV_ERR_NOMEM. */
fv_status fv_blur_variable(float *rgb, int w, int h, const float *sigma, int threads, fv_error *err);
/* The same with its temporaries (the row costs, the kernels, each slab's rows) from room, a
 * scratch arena its caller keeps (core/scratch.h): once room has grown to what a call needs, a
 * call allocates nothing (docs/threads.md, "No allocation in a frame"). The same bytes. */
fv_status fv_blur_variable_in(float *rgb, int w, int h, const float *sigma, int threads, fv_scratch *room, fv_error *err);

/* The kernels fv_blur_variable uses, for the kernels' passes (filter/kblur.h, fv_kblur_table):
 * on a w x h image whose largest sigma is smax, *nq kernels of *nk floats in all; fill writes
 * kernel q at k + off[q] (off: nq ints, k: nk floats). */
void fv_blur_table_size(float smax, int w, int h, int *nq, size_t *nk);
void fv_blur_table_fill(int w, int h, int nq, int *off, float *k);

#ifdef __cplusplus
}
#endif
#endif
