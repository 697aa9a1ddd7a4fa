/* fovea — the path tracing kernel (see path.h).
 *
 * Next-event estimation at every non-delta vertex, combined with BSDF sampling by multiple
 * importance sampling (balance heuristic, Veach 1997 ch. 9) for area lights; delta lights are
 * sampled only by NEE, delta lobes only by the BSDF. Russian roulette from `rr_depth` on, with
 * survival probability max(throughput) capped at 0.95. A ray leaving the scene carries the
 * environment light (when the scene has one), weighted by MIS against its light sampling like an
 * area light's emission.
 */
#include "core/params_read.h"
#include "scene/bsdf.h"
#include "scene/light.h"
#include "transport/path.h"

static float mis_weight(float a, float b) { return a / (a + b); }

fv_vec3 fv_path_trace(const fv_scene *s, const fv_path_opts *opt, fv_vec3 o, fv_vec3 d, fv_rng *rng,
                    fv_path_first_hit *first, uint64_t *rays)
{
    return fv_path_trace_from(s, opt, o, d, NULL, false, rng, first, rays);
}

fv_vec3 fv_path_trace_from(const fv_scene *s, const fv_path_opts *opt, fv_vec3 o, fv_vec3 d, const fv_hit *pre, bool pre_ok, fv_rng *rng,
                         fv_path_first_hit *first, uint64_t *rays)
{
    fv_vec3 L = fv_v3s(0.0f), beta = fv_v3s(1.0f);
    bool delta_prev = true;
    float pdf_prev = 1.0f;
    fv_vec3 p_prev = o;
    uint64_t nrays = 0;
    for (int depth = 1; depth <= opt->max_depth; depth++) {
        fv_hit h;
        nrays++;
        if (depth == 1 && pre) h = *pre;
        if (depth == 1 && pre ? !pre_ok : !fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h)) {
            fv_vec3 le = fv_light_env_radiance(s, d);
            if (fv_max3(le) > 0.0f) {
                float w = delta_prev ? 1.0f : mis_weight(pdf_prev, fv_light_env_pdf(s, d));
                L = fv_add(L, fv_mul(beta, fv_scale(le, w)));
            }
            break;
        }
        fv_material mbuf;
        const fv_material *m = fv_hit_material(s, &h, &mbuf);
        fv_vec3 wo = fv_neg(d);
        if (depth == 1 && first) {
            first->hit = true;
            first->t = h.t;
            first->p = h.p;
            first->n = h.ns;
            first->obj = h.obj;
            first->albedo = m->type == FV_MAT_DIFFUSE || m->type == FV_MAT_GLOSSY ? m->albedo : m->specular;
        }
        if (fv_max3(m->emission) > 0.0f) {
            fv_vec3 le = fv_light_emitted(s, m, h.ng, wo);
            float w = 1.0f;
            if (!delta_prev) w = mis_weight(pdf_prev, fv_light_pdf_li(s, h.obj, h.prim, p_prev, h.p, h.ng, d));
            L = fv_add(L, fv_mul(beta, fv_scale(le, w)));
        }
        fv_shading sh;
        fv_shading_make(m, h.ng, h.ns, wo, &sh);

        if (fv_bsdf_is_smooth(m)) {
            fv_light_sample ls;
            float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
            if (fv_light_sample_li(s, h.p, u0, u1, u2, &ls) && fv_dot(ls.wi, sh.ng) > 0.0f) {
                float pdf_b;
                fv_vec3 f = fv_bsdf_eval(m, sh.wo, fv_shading_to_local(&sh, ls.wi), &pdf_b);
                float cosv = fabsf(fv_dot(ls.wi, sh.n));
                if (fv_max3(f) > 0.0f) {
                    nrays++;
                    if (fv_scene_visible(s, FV_TRACE_ALL, h.p, sh.ng, fv_madd(h.p, ls.wi, ls.dist))) {
                        /* At the last vertex BSDF sampling does not continue, so light sampling
                         * is the only strategy for these paths and takes the full weight. */
                        float w = ls.delta || depth == opt->max_depth ? 1.0f : mis_weight(ls.pdf, pdf_b);
                        L = fv_add(L, fv_mul(beta, fv_scale(fv_mul(f, ls.li), cosv * w / ls.pdf)));
                    }
                }
            }
        } else {
            /* keep the random stream aligned across material types */
            rng->dim += 3;
        }
        if (depth == opt->max_depth) break;

        fv_bsdf_sample bs;
        float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
        if (!fv_bsdf_sample_dir(m, sh.wo, FV_TRANSPORT_RADIANCE, u0, u1, u2, &bs)) break;
        fv_vec3 wi = fv_shading_to_world(&sh, bs.wi);
        /* Reflection must leave on the geometric side it arrived on (and refraction cross it);
         * shading normals can disagree, which would leak light through surfaces. */
        bool reflect = bs.wi.z * sh.wo.z > 0.0f;
        if ((fv_dot(wi, h.ng) * fv_dot(wo, h.ng) > 0.0f) != reflect) break;
        beta = fv_mul(beta, bs.weight);
        delta_prev = bs.delta;
        pdf_prev = bs.pdf;
        p_prev = h.p;
        o = fv_offset_point(s, h.p, h.ng, wi);
        d = wi;
        if (depth >= opt->rr_depth) {
            float q = fv_minf(0.95f, fv_max3(beta));
            if (!(fv_rng_next(rng) < q)) break;
            beta = fv_scale(beta, 1.0f / q);
        } else {
            rng->dim++;
        }
    }
    if (rays) *rays += nrays;
    return L;
}

fv_status fv_path_read_opts(fv_params *p, fv_path_opts *opt, fv_error *err)
{
    fv_status s;
    if ((s = fv_params_int(p, "spp", 16, 1, 1 << 20, &opt->spp, err)) != FV_OK) return s;
    if ((s = fv_params_int(p, "max_depth", 8, 1, 1024, &opt->max_depth, err)) != FV_OK) return s;
    if ((s = fv_params_int(p, "rr_depth", 3, 1, 1024, &opt->rr_depth, err)) != FV_OK) return s;
    return FV_OK;
}
