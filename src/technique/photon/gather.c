/* fovea — eye paths and photon density estimates (see gather.h). */
#include <math.h>
#include "scene/bsdf.h"
#include "scene/light.h"
#include "technique/photon/gather.h"

void fv_pm_eye_path(const fv_scene *s, fv_vec3 o, fv_vec3 d, int max_depth, fv_rng *rng, fv_pm_hit *out)
{
    out->hit = false;
    out->dynamic = false;
    out->weight = fv_v3s(1.0f);
    out->emitted = fv_v3s(0.0f);
    out->first_t = INFINITY;
    out->first_obj = -1;
    out->albedo = fv_v3s(0.0f);
    for (int depth = 0; depth <= max_depth; depth++) {
        fv_hit h;
        if (!fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h)) { /* escaped: the environment, if any */
            out->emitted = fv_add(out->emitted, fv_mul(out->weight, fv_light_env_radiance(s, d)));
            return;
        }
        const fv_material *m = fv_scene_material(s, h.mat);
        fv_vec3 wo = fv_neg(d);
        if (depth == 0) {
            out->first_t = h.t;
            out->first_p = h.p;
            out->first_n = fv_dot(h.ns, wo) < 0.0f ? fv_neg(h.ns) : h.ns;
            out->first_obj = h.obj;
            out->albedo = fv_bsdf_is_smooth(m) ? m->albedo : m->specular;
        }
        if (fv_scene_object_dynamic(s, h.obj)) out->dynamic = true;
        if (fv_max3(m->emission) > 0.0f) out->emitted = fv_add(out->emitted, fv_mul(out->weight, fv_light_emitted(s, m, h.ng, wo)));
        fv_shading sh;
        fv_shading_make(m, h.ng, h.ns, wo, &sh);
        if (fv_bsdf_is_smooth(m)) {
            out->hit = true;
            out->p = h.p;
            out->n = sh.n;
            out->ng = sh.ng;
            out->wo = wo;
            out->mat = h.mat;
            out->obj = h.obj;
            return;
        }
        fv_bsdf_sample bs;
        float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
        if (!fv_bsdf_sample_dir(m, sh.wo, FV_TRANSPORT_RADIANCE, u0, u1, u2, &bs)) return;
        fv_vec3 wi = fv_shading_to_world(&sh, bs.wi);
        out->weight = fv_mul(out->weight, bs.weight);
        o = fv_offset_point(s, h.p, h.ng, wi);
        d = wi;
    }
}

typedef struct gather_ctx {
    const fv_material *m;
    fv_shading sh;
    fv_vec3 sum;
    double u;
} gather_ctx;

static void gather_one(void *user, const fv_photon *ph, float d2)
{
    (void)d2;
    gather_ctx *c = user;
    /* Photons on another surface (the other side of a thin wall, a nearby perpendicular face)
     * would leak light: keep those whose surface faces the same way. */
    if (fv_dot(ph->n, c->sh.n) <= 0.5f) return;
    fv_vec3 wi_l = fv_shading_to_local(&c->sh, fv_neg(ph->dir));
    if (wi_l.z <= 0.0f) return;
    float pdf;
    fv_vec3 f = fv_bsdf_eval(c->m, c->sh.wo, wi_l, &pdf);
    c->sum = fv_add(c->sum, fv_mul(f, ph->flux));
    c->u += fmax(fabs(ph->flux.x), fmax(fabs(ph->flux.y), fabs(ph->flux.z)));
}

fv_vec3 fv_pm_gather(const fv_scene *s, const fv_photon_map *m, const fv_pm_hit *x, float r, double *u_sum)
{
    gather_ctx c;
    c.m = fv_scene_material(s, x->mat);
    fv_shading_make(c.m, x->ng, x->n, x->wo, &c.sh);
    c.sum = fv_v3s(0.0f);
    c.u = 0.0;
    fv_photon_map_query(m, x->p, r, gather_one, &c);
    if (u_sum) *u_sum += c.u;
    return c.sum;
}
