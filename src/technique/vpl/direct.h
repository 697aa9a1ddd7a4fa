/* fovea — direct light for the instant-radiosity family: what ir, ir-low and fir add alike to their
 * VPLs' indirect light (Foveated Instant Radiosity, Sec. 4.1: the methods share the direct term so
 * their errors differ only in the indirect one), and what fir's VPLs receive before their cone-traced
 * bounce (Sec. 3.4).
 *
 * Point and spot lights are exact: one shadow ray each (the paper's 1024^2 shadow maps, at
 * unlimited resolution). Area lights (emissive triangles) are sampled `area_samples` times with the
 * shared light sampler; a pick that lands on a delta light is dropped, since the delta lights were
 * counted exactly (the sampler's pick probability already divides the area samples, so the estimate
 * stays unbiased).
 */
#ifndef FV_TECHNIQUE_VPL_DIRECT_H
#define FV_TECHNIQUE_VPL_DIRECT_H

#include <stdint.h>
#include "core/rng.h"
#include "scene/query.h"

/* Irradiance at surface point p (unit normal n facing the side that is lit, geometric normal ng)
 * from every light, shadowed: sum of L cos / pdf. Multiply by albedo / pi for the radiance a diffuse
 * surface reflects. rng is read only for area lights; *rays counts the shadow rays. */
fv_vec3 fv_vpl_direct_irradiance(const fv_scene *s, fv_vec3 p, fv_vec3 n, fv_vec3 ng, int area_samples, fv_rng *rng,
                                 uint64_t *rays);

#endif
