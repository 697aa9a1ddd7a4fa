/* fovea — direct light for the instant-radiosity family (see direct.h). */
#include <math.h>
#include "scene/light.h"
#include "technique/vpl/direct.h"

fv_vec3 fv_vpl_direct_irradiance(const fv_scene *s, fv_vec3 p, fv_vec3 n, fv_vec3 ng, int area_samples, fv_rng *rng,
                                 uint64_t *rays)
{
    fv_vec3 e = fv_v3s(0.0f);
    const int nd = fv_light_delta_count(s);
    for (int i = 0; i < nd; i++) {
        const fv_light *l = fv_light_delta_at(s, i);
        fv_vec3 sun;
        if (fv_light_delta_directional(l, &sun)) { /* irradiance E from -sun, unblocked past the bounds */
            float c = -fv_dot(n, sun);
            if (c <= 0.0f) continue;
            fv_vec3 lo, hi;
            fv_scene_bounds(s, &lo, &hi);
            (*rays)++;
            if (!fv_scene_visible(s, FV_TRACE_ALL, p, ng, fv_madd(p, sun, -2.0f * fv_length(fv_sub(hi, lo)) - fv_length(fv_sub(p, lo)))))
                continue;
            e = fv_add(e, fv_scale(fv_light_delta_intensity(l, sun), c));
            continue;
        }
        fv_vec3 lp = fv_light_delta_pos(l);
        fv_vec3 d = fv_sub(lp, p);
        float d2 = fv_dot(d, d);
        if (!(d2 > 0.0f)) continue;
        fv_vec3 wi = fv_scale(d, 1.0f / sqrtf(d2));
        float c = fv_dot(n, wi);
        if (c <= 0.0f) continue;
        fv_vec3 I = fv_light_delta_intensity(l, fv_neg(wi));
        if (fv_max3(I) <= 0.0f) continue;
        (*rays)++;
        if (!fv_scene_visible(s, FV_TRACE_ALL, p, ng, lp)) continue;
        e = fv_add(e, fv_scale(I, c / d2));
    }
    if (area_samples <= 0 || fv_scene_light_count(s) == nd) return e;
    fv_vec3 area = fv_v3s(0.0f);
    for (int k = 0; k < area_samples; k++) {
        float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
        fv_light_sample ls;
        if (!fv_light_sample_li_area(s, p, u0, u1, u2, &ls) || !(ls.pdf > 0.0f)) continue;
        float c = fv_dot(n, ls.wi);
        if (c <= 0.0f) continue;
        (*rays)++;
        if (!fv_scene_visible(s, FV_TRACE_ALL, p, ng, fv_madd(p, ls.wi, ls.dist))) continue;
        area = fv_add(area, fv_scale(ls.li, c / ls.pdf));
    }
    return fv_add(e, fv_scale(area, 1.0f / (float)area_samples));
}
