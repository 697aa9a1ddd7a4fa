/* fovea — albedo demodulation, shared by the filters that smooth light rather than colour: SVGF
 * (filter/svgf.c) and fpm-guided's lattice fill and filter (technique/photon/guided.c).
 *
 * A pixel's colour c is divided by its first-hit albedo a, channel by channel, before filtering
 * and multiplied by it again after, so that texture and material colour are not blurred:
 *
 *   d(a) = (1, 1, 1)                     when every channel of a is below FV_DEMOD_MIN (a black
 *                                        surface: an emitter, a metal, black paint), whose colour
 *                                        is not proportional to its albedo: not demodulated;
 *   d(a) = max(a_k, FV_DEMOD_MIN) per k  otherwise.
 *
 * The floor matters at textured hits, where one channel of a texel can be 0 or nearly (a pure red
 * texel, dark wood whose blue is below 1e-3) while the others are not: a channel that was simply
 * not demodulated there (divided by 1) took its neighbours' filtered *light* as its *colour* when
 * multiplied back, e.g. the full blue light of the surroundings on a brown texel (issue 25). With
 * the floor the channel is remodulated by at most FV_DEMOD_MIN, so the colour it can gain is at most
 * 1e-3 of the light, and its own contribution to its neighbours' light is a_k / max(a_k, 1e-3) <= 1
 * times theirs. An albedo either black or at least 1e-3 in every channel keeps the exact factors of
 * the rule before (a, or 1).
 *
 * The callers pass what the surface reflects, not only its diffuse albedo: for a glossy surface the
 * albedo plus its specular colour (fv_bsdf_demod_reflectance, kernel/kbsdf.h), since its highlight is
 * not proportional to the diffuse albedo (a dark-tinted glossy panel divided by (0, 0.04, 0.02)
 * bled its highlight red and cyan into its surroundings: CesiumMilkTruck's windows).
 */
#ifndef FV_FILTER_DEMOD_H
#define FV_FILTER_DEMOD_H

#include "fovea/math.h"

#define FV_DEMOD_MIN 1e-3f

/* The demodulation factors d of albedo a (3 floats each); FV_HD: SVGF's kernels use it too. */
FV_HD static inline void fv_demod_factors(const float *a, float *d)
{
    if (a[0] < FV_DEMOD_MIN && a[1] < FV_DEMOD_MIN && a[2] < FV_DEMOD_MIN) {
        d[0] = d[1] = d[2] = 1.0f;
        return;
    }
    for (int k = 0; k < 3; k++) d[k] = a[k] < FV_DEMOD_MIN ? FV_DEMOD_MIN : a[k];
}

#endif
