/* fovea — light paths from the lights (see light_path.h). */
#include <math.h>
#include "kernel/kbsdf.h"
#include "scene/light.h"
#include "transport/light_path.h"

bool fv_light_path_emit(const fv_scene *s, fv_rng *rng, int64_t count, fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux)
{
    float u[5];
    for (int k = 0; k < 5; k++) u[k] = fv_rng_next(rng);
    return fv_light_path_emit_u(s, u, count, o, d, flux);
}

bool fv_light_path_emit_u(const fv_scene *s, const float u[5], int64_t count, fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux)
{
    fv_vec3 power, n;
    if (!fv_light_sample_emission(s, u, o, d, &power, &n)) return false;
    if (fv_dot(n, n) > 0.0f) *o = fv_offset_point(s, *o, n, *d);
    *flux = fv_scale(power, 1.0f / (float)count);
    return true;
}

bool fv_light_path_scatter(const fv_scene *s, const fv_hit *h, fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux, fv_rng *rng,
                           fv_light_vertex_fn visit, void *ctx)
{
    fv_material mbuf;
    const fv_material *m = fv_hit_material(s, h, &mbuf);
    if (fv_bsdf_is_smooth(m)) visit(ctx, h, m, *d, *flux);
    fv_vec3 wo = fv_neg(*d);
    fv_shading sh;
    fv_shading_make(m, h->ng, h->ns, wo, &sh);
    fv_bsdf_sample bs;
    float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
    if (!fv_bsdf_sample_dir(m, sh.wo, FV_TRANSPORT_IMPORTANCE, u0, u1, u2, &bs)) return false;
    fv_vec3 wi = fv_shading_to_world(&sh, bs.wi);
    /* Reflection must leave on the side it arrived on, refraction cross (shading normals lie). */
    bool reflect = bs.wi.z * sh.wo.z > 0.0f;
    if ((fv_dot(wi, h->ng) * fv_dot(wo, h->ng) > 0.0f) != reflect) return false;
    /* Russian roulette on the change of power: the surviving walk keeps about the flux it had. */
    fv_vec3 nf = fv_mul(*flux, bs.weight);
    float before = fv_max3(fv_vmax(*flux, fv_neg(*flux))), after = fv_max3(fv_vmax(nf, fv_neg(nf)));
    float q = before > 0.0f ? fv_minf(1.0f, after / before) : 0.0f;
    if (!(fv_rng_next(rng) < q)) return false;
    *flux = fv_scale(nf, 1.0f / q);
    *o = fv_offset_point(s, h->p, h->ng, wi);
    *d = wi;
    return true;
}

void fv_light_path_trace(const fv_scene *s, fv_trace_set set, fv_vec3 o, fv_vec3 d, fv_vec3 flux, int depth, int max_depth,
                         fv_rng *rng, fv_light_vertex_fn visit, void *ctx, uint64_t *rays)
{
    for (; depth < max_depth; depth++) {
        fv_hit h;
        (*rays)++;
        if (!fv_scene_intersect(s, set, o, d, INFINITY, &h)) return;
        if (!fv_light_path_scatter(s, &h, &o, &d, &flux, rng, visit, ctx)) return;
    }
}
