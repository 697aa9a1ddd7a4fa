/* fovea — the path tracing kernel, written once (see kernel/kpath.h for its data).
 *
 * Next-event estimation at every non-delta vertex, combined with BSDF sampling by multiple
 * importance sampling (balance heuristic, Veach 1997 ch. 9) for area lights; delta lights are
 * sampled only by NEE, delta lobes only by the BSDF. Russian roulette from `rr_depth` on, with
 * survival probability max(throughput) capped at 0.95. A ray leaving the scene carries the
 * environment light (when the scene has one), weighted by MIS against its light sampling like an
 * area light's emission.
 *
 * Not a normal header: each inclusion defines one function, FV_PATH_FN, on one kind of scene, so
 * the CPU's Embree scene (transport/path.c) and the flat scene of the portable and CUDA backends
 * (kernel/kpt.h) run the very same estimator and draw the same random numbers in the same order.
 * The includer defines, before including it:
 *   FV_PATH_FN                      the function's name
 *   FV_PATH_QUAL                    its qualifiers (`static`, `FV_HD static inline`)
 *   FV_PATH_SCENE                   the scene type
 *   FV_PATH_INTERSECT(s, o, d, h)   closest hit along o + t d, t in (eps, inf): bool, fills fv_hit h
 *   FV_PATH_MATERIAL(s, h, buf)     the material at hit h (const fv_material *)
 *   FV_PATH_LIGHTS(s)               the light table (const fv_klights *)
 *   FV_PATH_LIGHT_OF(s, h)          the table index of the emissive triangle h hit, -1: none
 *   FV_PATH_VISIBLE(s, p, ng, q)    the shadow ray of scene/query.h's fv_scene_visible
 *   FV_PATH_OFFSET(s, p, ng, d)     fv_offset_point
 * and fv_hit, fv_material, the BSDFs (kernel/kbsdf.h), the light kernels (kernel/klight.h) and the
 * path types (kernel/kpath.h) must be visible. The macros are undefined at the end.
 */
#include "kernel/ksimt.h" /* guarded: the probes of the bounce loop */

/* Radiance arriving at o from direction d (unit). pre, when not NULL, is the first hit already
 * traced (pre_ok false: the ray missed), as for camera rays traced in packets. first (optional)
 * receives the first hit; *rays (optional) is increased by the number of rays cast. */
FV_PATH_QUAL fv_vec3 FV_PATH_FN(const FV_PATH_SCENE *s, const fv_path_opts *opt, fv_vec3 o, fv_vec3 d, const fv_hit *pre, bool pre_ok,
                               fv_rng *rng, fv_path_first_hit *first, uint64_t *rays)
{
    fv_vec3 L = fv_v3s(0.0f), beta = fv_v3s(1.0f);
    bool delta_prev = true;
    float pdf_prev = 1.0f;
    fv_vec3 p_prev = o;
    uint64_t nrays = 0;
    for (int depth = 1; depth <= opt->max_depth; depth++) {
        FV_SIMT_STEP(FV_SIMT_BOUNCE);
        fv_hit h;
        nrays++;
        if (depth == 1 && pre) h = *pre;
        if (depth == 1 && pre ? !pre_ok : !FV_PATH_INTERSECT(s, o, d, &h)) {
            fv_vec3 le = fv_klights_env_radiance(FV_PATH_LIGHTS(s), d);
            if (fv_max3(le) > 0.0f) {
                float w = delta_prev ? 1.0f : fv_path_mis(pdf_prev, fv_klights_env_pdf(FV_PATH_LIGHTS(s), d));
                L = fv_add(L, fv_mul(beta, fv_scale(le, w)));
            }
            break;
        }
        fv_material mbuf;
        const fv_material *m = FV_PATH_MATERIAL(s, &h, &mbuf);
        fv_vec3 wo = fv_neg(d);
        if (depth == 1 && first) {
            first->hit = true;
            first->t = h.t;
            first->p = h.p;
            first->n = h.ns;
            first->obj = h.obj;
            first->albedo = m->type == FV_MAT_DIFFUSE || m->type == FV_MAT_GLOSSY ? m->albedo : m->specular;
            first->reflectance = fv_bsdf_demod_reflectance(m);
        }
        if (fv_max3(m->emission) > 0.0f) {
            fv_vec3 le = fv_klight_emitted(m, h.ng, wo);
            float w = 1.0f;
            if (!delta_prev) w = fv_path_mis(pdf_prev, fv_klights_pdf_li(FV_PATH_LIGHTS(s), FV_PATH_LIGHT_OF(s, &h), p_prev, h.p, h.ng, d));
            L = fv_add(L, fv_mul(beta, fv_scale(le, w)));
        }
        fv_shading sh;
        fv_shading_make(m, h.ng, h.ns, wo, &sh);

        if (fv_bsdf_is_smooth(m)) {
            fv_light_sample ls;
            float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
            if (fv_klights_sample_li(FV_PATH_LIGHTS(s), h.p, u0, u1, u2, &ls) && fv_dot(ls.wi, sh.ng) > 0.0f) {
                float pdf_b;
                fv_vec3 f = fv_bsdf_eval(m, sh.wo, fv_shading_to_local(&sh, ls.wi), &pdf_b);
                float cosv = fabsf(fv_dot(ls.wi, sh.n));
                if (fv_max3(f) > 0.0f) {
                    nrays++;
                    if (FV_PATH_VISIBLE(s, h.p, sh.ng, fv_madd(h.p, ls.wi, ls.dist))) {
                        /* At the last vertex BSDF sampling does not continue, so light sampling
                         * is the only strategy for these paths and takes the full weight. */
                        float w = ls.delta || depth == opt->max_depth ? 1.0f : fv_path_mis(ls.pdf, pdf_b);
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
        o = FV_PATH_OFFSET(s, h.p, h.ng, wi);
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

#undef FV_PATH_FN
#undef FV_PATH_QUAL
#undef FV_PATH_SCENE
#undef FV_PATH_INTERSECT
#undef FV_PATH_MATERIAL
#undef FV_PATH_LIGHTS
#undef FV_PATH_LIGHT_OF
#undef FV_PATH_VISIBLE
#undef FV_PATH_OFFSET
