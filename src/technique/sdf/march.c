/* fovea — the SDF family's sphere tracer (march.h): the CPU's batches of rays, each ray stepped by
 * technique/sdf/kmarch.h, the rule the portable and CUDA backends run. */
#include <math.h>
#include "technique/sdf/march.h"

static void march_scalar(const fv_sdf_world *w, const fv_march_opts *o, const fv_march_ray *rays, fv_march_hit *out, int n, bool any_hit)
{
    for (int i = 0; i < n; i++) fv_kmarch_one(&w->k, o->max_steps, o->relax, &rays[i], any_hit, &out[i]);
}

static void march_wide(const fv_sdf_world *w, const fv_march_opts *o, const fv_march_ray *rays, fv_march_hit *out, int n, bool any_hit)
{
    fv_kmarch_lane lanes[8];
    int next = 0, busy = 0;
    /* Fills lane k with the next ray that needs marching. */
#define REFILL(k)                                                                      \
    do {                                                                               \
        lanes[k].ray = -1;                                                             \
        while (next < n) {                                                             \
            int i_ = next++;                                                           \
            if (fv_kmarch_start(&lanes[k], &rays[i_], &out[i_], i_, o->relax)) {            \
                busy++;                                                                \
                break;                                                                 \
            }                                                                          \
        }                                                                              \
    } while (0)
    for (int k = 0; k < 8; k++) REFILL(k);
    float x[8], y[8], z[8], d[8];
    int m[8];
    while (busy > 0) {
        int any = -1;
        for (int k = 0; k < 8; k++) {
            if (lanes[k].ray < 0) continue;
            const fv_march_ray *r = &rays[lanes[k].ray];
            x[k] = r->o.x + r->d.x * lanes[k].t;
            y[k] = r->o.y + r->d.y * lanes[k].t;
            z[k] = r->o.z + r->d.z * lanes[k].t;
            any = k;
        }
        for (int k = 0; k < 8; k++)
            if (lanes[k].ray < 0) x[k] = x[any], y[k] = y[any], z[k] = z[any];
        fv_sdf_world_eval8(w, x, y, z, d, m);
        for (int k = 0; k < 8; k++) {
            if (lanes[k].ray < 0) continue;
            int i = lanes[k].ray;
            if (fv_kmarch_advance(&lanes[k], &rays[i], d[k], m[k], o->max_steps, any_hit, &out[i])) {
                busy--;
                REFILL(k);
            }
        }
    }
#undef REFILL
}

void fv_march(const fv_sdf_world *w, const fv_march_opts *o, const fv_march_ray *rays, fv_march_hit *out, int n, bool any_hit)
{
    if (o->wide) march_wide(w, o, rays, out, n, any_hit);
    else march_scalar(w, o, rays, out, n, any_hit);
}

void fv_march_eval_points(const fv_sdf_world *w, bool wide, const fv_vec3 *p, float *d, int n)
{
    int i = 0;
    if (wide) {
        for (; i + 8 <= n; i += 8) {
            float x[8], y[8], z[8];
            for (int k = 0; k < 8; k++) x[k] = p[i + k].x, y[k] = p[i + k].y, z[k] = p[i + k].z;
            fv_sdf_world_eval8(w, x, y, z, &d[i], NULL);
        }
    }
    for (; i < n; i++) d[i] = fv_sdf_world_eval1(w, p[i].x, p[i].y, p[i].z, NULL);
}
