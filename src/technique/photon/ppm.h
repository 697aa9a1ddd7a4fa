/* fovea — the radius schedule of `ppm`, stochastic progressive photon mapping in the probabilistic
 * formulation of Knaus & Zwicker (ACM TOG 2011, Sec. 4.3, Eq. 15): pass i gathers with
 *     r_i^2 = r_1^2 * prod_{k=1}^{i-1} (k + alpha) / (k + 1),
 * so the variance each pass adds shrinks slowly enough (alpha in (0, 1)) that the average of the
 * passes' estimates converges while its bias, which the radius drives, goes to zero.
 * Kept apart from ppm.c so the schedule is tested with hand-worked numbers.
 */
#ifndef FV_PHOTON_PPM_H
#define FV_PHOTON_PPM_H

/* r_{i+1}^2 from r_i^2 (pass i counted from 1). */
static inline double fv_ppm_next_r2(double r2, double alpha, int i) { return r2 * ((double)i + alpha) / ((double)i + 1.0); }

#endif
