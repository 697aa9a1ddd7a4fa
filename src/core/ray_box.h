/* fovea — the slab test: where a ray crosses an axis-aligned box. Shared by the SDF user geometry
 * (scene/scene_sdf.c), which clips each ray to a field's box before sphere-tracing it, and the
 * sphere tracers of the SDF family (technique/sdf/world.c); kernel code too (kernel/ksdf_trace.h). */
#ifndef FV_CORE_RAY_BOX_H
#define FV_CORE_RAY_BOX_H

#include <stdbool.h>
#include "fovea/math.h"

/* Narrows [*t0, *t1] to the part of o + t d (d need not be unit) inside [lo, hi]; false when
 * nothing is left. A ray parallel to a slab is inside it everywhere or nowhere. */
FV_HD static inline bool fv_ray_box_clip(fv_vec3 o, fv_vec3 d, fv_vec3 lo, fv_vec3 hi, float *t0, float *t1)
{
    const float oa[3] = {o.x, o.y, o.z}, da[3] = {d.x, d.y, d.z}, la[3] = {lo.x, lo.y, lo.z}, ha[3] = {hi.x, hi.y, hi.z};
    float a = *t0, b = *t1;
    for (int k = 0; k < 3; k++) {
        if (da[k] == 0.0f) {
            if (oa[k] < la[k] || oa[k] > ha[k]) return false;
            continue;
        }
        float inv = 1.0f / da[k];
        float ta = (la[k] - oa[k]) * inv, tb = (ha[k] - oa[k]) * inv;
        if (ta > tb) {
            float s = ta;
            ta = tb;
            tb = s;
        }
        if (ta > a) a = ta;
        if (tb < b) b = tb;
    }
    *t0 = a;
    *t1 = b;
    return a <= b;
}

#endif
