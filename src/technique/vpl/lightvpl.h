/* fovea — VPLs from light random walks: classic instant radiosity (Keller 1997), the `ir` and
 * `ir-low` baselines of Foveated Instant Radiosity (Sec. 4: the paper's IR and IR' with 2000 VPLs).
 *
 * Walks leave the lights by power and bounce with the shared light-path kernel
 * (transport/light_path.h); every diffuse or glossy vertex becomes a VPL, until `count` VPLs exist.
 * Walk w draws from its own stream (FV_STREAM_VPL, w, frame), so the set does not depend on the thread
 * count, and a new frame index gives a new set (the baselines regenerate every frame). A VPL at the
 * k-th vertex of a walk carries k-bounce indirect light; `bounces` limits k (bounces = 1 is light ->
 * y -> pixel, to compare with pt at max_depth 2).
 *
 * Power: walks are started with the full light power, then every VPL's flux is divided by the
 * number of walks started W, and turned into what the gather kernel expects: P = flux * albedo / pi
 * (the VPL reflects diffusely; Sec. 4: diffuse scenes). The last walk may be cut short when the
 * count is reached: the deeper vertices of one walk in W are lost (a bias of order 1/W of the last
 * bounce), which keeps the count exact as the paper's fixed VPL budget is.
 */
#ifndef FV_TECHNIQUE_VPL_LIGHTVPL_H
#define FV_TECHNIQUE_VPL_LIGHTVPL_H

#include <stdint.h>
#include "technique/vpl/vpl_gather.h"

/* Fills vpls[0..count) (map = -1); returns how many were made (fewer only when the scene emits
 * nothing or walks keep dying: after 100 x count walks without reaching the count). *walks receives
 * W, *rays the rays cast. */
int fv_vpl_from_light_walks(const fv_scene *s, uint64_t seed, uint64_t frame, int count, int bounces, fv_vpl_light *vpls,
                            int64_t *walks, uint64_t *rays);

#endif
