/* fovea — eye paths and photon density estimates (see pm_gather.h). */
#include <math.h>
#include "kernel/kbsdf.h"
#include "scene/light.h"
#include "technique/photon/pm_gather.h"

static void eye_start(fv_pm_hit *out)
{
    out->hit = false;
    out->dynamic = false;
    out->weight = fv_v3s(1.0f);
    out->emitted = fv_v3s(0.0f);
    out->first_t = INFINITY;
    out->first_obj = -1;
    out->albedo = fv_v3s(0.0f);
    out->reflectance = fv_v3s(0.0f);
}

/* The two delta lobes of material m seen from wo (local frame), each with the weight it carries
 * when both are followed (its sampling weight times its probability): false when only one lobe
 * exists here (a mirror; a dielectric under total internal reflection or at F = 0). */
static bool two_lobes(const fv_material *m, fv_vec3 wo, fv_bsdf_sample *a, fv_bsdf_sample *b)
{
    if (m->type != FV_MAT_DIELECTRIC) return false;
    if (!fv_bsdf_sample_dir(m, wo, FV_TRANSPORT_RADIANCE, 0.0f, 0.5f, 0.5f, a) ||
        !fv_bsdf_sample_dir(m, wo, FV_TRANSPORT_RADIANCE, 0x1.fffffep-1f, 0.5f, 0.5f, b))
        return false;
    if (!(a->pdf < 1.0f && b->pdf < 1.0f) || a->wi.z * b->wi.z > 0.0f) return false;
    a->weight = fv_scale(a->weight, a->pdf);
    b->weight = fv_scale(b->weight, b->pdf);
    return true;
}

/* Follows the ray (o, d) from bounce `depth` on, out holding what came before. With split != NULL,
 * the first bounce off a dielectric follows both lobes: the second continues in *split (a copy of
 * out at that point), and *split_used says so. */
static void eye_walk(const fv_scene *s, fv_vec3 o, fv_vec3 d, int depth, int max_depth, fv_rng *rng, fv_pm_hit *out,
                     fv_pm_hit *split, bool *split_used)
{
    for (; depth <= max_depth; depth++) {
        fv_hit h;
        if (!fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h)) { /* escaped: the environment, if any */
            out->emitted = fv_add(out->emitted, fv_mul(out->weight, fv_light_env_radiance(s, d)));
            return;
        }
        fv_material mbuf;
        const fv_material *m = fv_hit_material(s, &h, &mbuf);
        fv_vec3 wo = fv_neg(d);
        if (depth == 0) {
            out->first_t = h.t;
            out->first_p = h.p;
            out->first_n = fv_dot(h.ns, wo) < 0.0f ? fv_neg(h.ns) : h.ns;
            out->first_obj = h.obj;
            out->albedo = fv_bsdf_is_smooth(m) ? m->albedo : m->specular;
            out->reflectance = fv_bsdf_demod_reflectance(m);
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
            out->prim = h.prim;
            out->u = h.u;
            out->v = h.v;
            out->obj = h.obj;
            return;
        }
        fv_bsdf_sample bs, b2;
        if (split && two_lobes(m, sh.wo, &bs, &b2)) {
            *split = *out;
            split->emitted = fv_v3s(0.0f); /* what came before counts once, in out */
            split->weight = fv_mul(out->weight, b2.weight);
            fv_vec3 wi2 = fv_shading_to_world(&sh, b2.wi);
            eye_walk(s, fv_offset_point(s, h.p, h.ng, wi2), wi2, depth + 1, max_depth, rng, split, NULL, NULL);
            *split_used = true;
            split = NULL;
        } else {
            float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
            if (!fv_bsdf_sample_dir(m, sh.wo, FV_TRANSPORT_RADIANCE, u0, u1, u2, &bs)) return;
        }
        fv_vec3 wi = fv_shading_to_world(&sh, bs.wi);
        out->weight = fv_mul(out->weight, bs.weight);
        o = fv_offset_point(s, h.p, h.ng, wi);
        d = wi;
    }
}

void fv_pm_eye_path(const fv_scene *s, fv_vec3 o, fv_vec3 d, int max_depth, fv_rng *rng, fv_pm_hit *out)
{
    eye_start(out);
    eye_walk(s, o, d, 0, max_depth, rng, out, NULL, NULL);
}

int fv_pm_eye_path_split(const fv_scene *s, fv_vec3 o, fv_vec3 d, int max_depth, fv_rng *rng, fv_pm_hit out[2])
{
    bool two = false;
    eye_start(&out[0]);
    eye_walk(s, o, d, 0, max_depth, rng, &out[0], &out[1], &two);
    return two ? 2 : 1;
}

/* max(|r|, |g|, |b|) as fmax(fabs(.), ...) of the flux's components: the same value without
 * libm calls (NaN components lose to the others, as in fmax). */
static inline float max_abs3(fv_vec3 v)
{
    float a = fabsf(v.x), b = fabsf(v.y), c = fabsf(v.z);
    float bc = c > b || isnan(b) ? c : b;
    return bc > a || isnan(a) ? bc : a;
}

fv_vec3 fv_pm_gather(const fv_scene *s, const fv_photon_map *m, const fv_pm_hit *x, float r, double *u_sum)
{
    fv_material mbuf;
    const fv_material *mat = fv_material_at(s, x->mat, x->obj, x->prim, x->u, x->v, &mbuf);
    fv_shading sh;
    fv_shading_make(mat, x->ng, x->n, x->wo, &sh);
    /* A diffuse surface's f_r is albedo / pi (the shading keeps wo above it): fv_bsdf_eval's value
     * for a photon from above, taken once, and applied to every photon the disc holds: on a curved
     * surface those that arrived from below this point's tangent plane are part of the flux
     * density the disc averages (photon_map.h, fv_photon_query_facing). */
    const bool diffuse = mat->type == FV_MAT_DIFFUSE;
    const fv_vec3 f_diffuse = fv_scale(mat->albedo, FV_INV_PI);
    fv_vec3 sum = fv_v3s(0.0f);
    double u = 0.0;
    fv_photon_query q;
    uint32_t idx[128];
    int k;
    fv_photon_query_begin(&q, m, x->p, r);
    /* Photons on another surface (the other side of a thin wall, a nearby perpendicular face)
     * would leak light: keep those whose surface faces the same way (the query tests it); then
     * the sums, each a loop of its own (short dependency chains, few registers). */
    fv_photon_query_facing(&q, sh.n);
    while ((k = fv_photon_query_next(&q, idx, 128)) > 0) {
        if (diffuse) {
            for (int j = 0; j < k; j++) sum = fv_add(sum, fv_mul(f_diffuse, m->p[idx[j]].flux));
        } else {
            for (int j = 0; j < k; j++) {
                const fv_photon *ph = &m->p[idx[j]];
                float pdf;
                fv_vec3 f = fv_bsdf_eval(mat, sh.wo, fv_shading_to_local(&sh, fv_neg(ph->dir)), &pdf);
                sum = fv_add(sum, fv_mul(f, ph->flux));
            }
        }
        if (u_sum)
            for (int j = 0; j < k; j++) u += max_abs3(m->p[idx[j]].flux);
    }
    if (u_sum) *u_sum += u;
    return sum;
}
