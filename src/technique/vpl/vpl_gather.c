/* fovea — the VPL shading kernel (see vpl_gather.h). */
#include <math.h>
#include "technique/vpl/vpl_gather.h"

float fv_vpl_clamp_distance(const fv_scene *s, float clamp)
{
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    return clamp * 0.5f * fv_length(fv_sub(hi, lo));
}

fv_vec3 fv_vpl_gather_at(const fv_vpl_gather *g, fv_vec3 x, fv_vec3 n, fv_vec3 ng, const int *list, int count,
                         uint64_t *rays, uint64_t *lookups)
{
    fv_vec3 sum = fv_v3s(0.0f);
    /* Shadow rays wait in a packet of eight; what they would add waits beside them. */
    fv_vec3 q[8], add[8];
    bool active[8], vis[8];
    int lanes = 0;
    for (int k = 0; k < count; k++) {
        const fv_vpl_light *v = &g->vpls[list ? list[k] : k];
        fv_vec3 c;
        if (!fv_vpl_term(g, v, x, n, &c)) continue;
        if (g->maps) {
            (*lookups)++;
            float vis1 = fv_cubemaps_visibility(g->maps, v->map, x, g->filter);
            if (vis1 > 0.0f) sum = fv_madd(sum, c, vis1);
            continue;
        }
        q[lanes] = v->p;
        add[lanes] = c;
        active[lanes] = true;
        if (++lanes == 8) {
            *rays += (uint64_t)fv_scene_visible8(g->scene, x, ng, q, active, vis);
            for (int i = 0; i < 8; i++)
                if (vis[i]) sum = fv_add(sum, add[i]);
            lanes = 0;
        }
    }
    if (lanes) {
        for (int i = lanes; i < 8; i++) active[i] = false;
        *rays += (uint64_t)fv_scene_visible8(g->scene, x, ng, q, active, vis);
        for (int i = 0; i < lanes; i++)
            if (vis[i]) sum = fv_add(sum, add[i]);
    }
    return sum;
}
