/* fovea — the SDF family's shading (shade.h). */
#include <math.h>
#include <stdlib.h>
#include "core/alloc.h"
#include "technique/sdf/shade.h"

/* The four tetrahedron directions: their sum is zero, so sum_k k f(p + h k) = 4 h grad f + O(h^3)
 * from four evaluations instead of six central differences. */
static const float k_tet[4][3] = {{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};

typedef struct lobe {
    fv_vec3 albedo, spec;
    float exponent, norm;
    bool has_spec;
} lobe;

static lobe lobe_of(const fv_material *m)
{
    lobe l = {m->albedo, fv_v3s(0.0f), 0.0f, 0.0f, false};
    if (m->type == FV_MAT_DIFFUSE) return l;
    float alpha = m->type == FV_MAT_GLOSSY ? fmaxf(m->roughness, 0.03f) : 0.05f;
    l.spec = m->specular;
    l.exponent = 2.0f / (alpha * alpha) - 2.0f;
    l.norm = (l.exponent + 8.0f) / (8.0f * FV_PI);
    l.has_spec = fv_max3(l.spec) > 0.0f;
    return l;
}

fv_status fv_sdf_shade(const fv_sdf_world *w, const fv_march_opts *mo, const fv_sdf_shade_opts *so, const fv_march_ray *rays,
                       const fv_march_hit *hits, int n, const uint32_t *vis_in, uint32_t *vis_out, fv_vec3 *color, fv_vec3 *normal,
                       fv_sdf_shade_counts *counts, fv_error *err)
{
    int nh = 0;
    for (int i = 0; i < n; i++) nh += hits[i].hit;
    for (int i = 0; i < n; i++) {
        if (color) color[i] = fv_v3s(0.0f);
        if (normal) normal[i] = fv_v3s(0.0f);
        if (vis_out) vis_out[i] = FV_SDF_VIS_UNKNOWN;
    }
    /* visibility is known per light as one bit, for the first 31 lights */
    const bool bits = w->light_count <= 31;
    if (nh == 0) return FV_OK;
    int *idx = fv_alloc_array((size_t)nh, sizeof *idx);
    fv_vec3 *pt = fv_alloc_array((size_t)nh * 4, sizeof *pt);
    float *val = fv_alloc_array((size_t)nh * 4, sizeof *val);
    fv_vec3 *nrm = fv_alloc_array((size_t)nh, sizeof *nrm), *pos = fv_alloc_array((size_t)nh, sizeof *pos);
    float *hd = fv_alloc_array((size_t)nh, sizeof *hd);
    fv_march_ray *sray = fv_alloc_array((size_t)nh, sizeof *sray);
    fv_march_hit *shit = fv_alloc_array((size_t)nh, sizeof *shit);
    int *sidx = fv_alloc_array((size_t)nh, sizeof *sidx), *lit = fv_alloc_array((size_t)nh, sizeof *lit);
    uint32_t *vis = fv_calloc_array((size_t)nh, sizeof *vis);
    lobe *lobes = color ? fv_alloc_array((size_t)nh, sizeof *lobes) : NULL;
    fv_status st = FV_OK;
    if (!idx || !pt || !val || !nrm || !pos || !hd || !sray || !shit || !sidx || !lit || !vis || (color && !lobes)) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory shading %d hits", nh);
        goto done;
    }
    /* Normals: the gradient with a step of the ray's own hit distance, so a coarse level's
     * normal is as smooth as its footprint. */
    for (int i = 0, k = 0; i < n; i++) {
        if (!hits[i].hit) continue;
        const fv_march_ray *r = &rays[i];
        idx[k] = i;
        pos[k] = fv_madd(r->o, r->d, hits[i].t);
        hd[k] = fmaxf(r->eps, r->eps_k * hits[i].t);
        for (int j = 0; j < 4; j++) pt[4 * k + j] = fv_madd(pos[k], fv_v3(k_tet[j][0], k_tet[j][1], k_tet[j][2]), hd[k]);
        k++;
    }
    fv_march_eval_points(w, mo->wide, pt, val, nh * 4);
    counts->normal_evals += (uint64_t)nh * 4;
    for (int k = 0; k < nh; k++) {
        fv_vec3 g = fv_v3s(0.0f);
        for (int j = 0; j < 4; j++) g = fv_madd(g, fv_v3(k_tet[j][0], k_tet[j][1], k_tet[j][2]), val[4 * k + j]);
        float len = fv_length(g);
        /* where the differences cancel (a crease's exact middle), face the ray */
        nrm[k] = len > 0.0f && isfinite(len) ? fv_scale(g, 1.0f / len) : fv_neg(rays[idx[k]].d);
        const fv_material *m = fv_scene_material(w->scene, hits[idx[k]].mat);
        if (color) {
            color[idx[k]] = fv_scale(m->albedo, so->ambient);
            lobes[k] = lobe_of(m);
        }
        if (normal) normal[idx[k]] = nrm[k];
    }
    for (int li = 0; li < w->light_count; li++) {
        const fv_sdf_point_light *L = &w->lights[li];
        int ns = 0, nl = 0;
        for (int k = 0; k < nh; k++) {
            fv_vec3 o = fv_madd(pos[k], nrm[k], 2.0f * hd[k]);
            fv_vec3 to = L->directional ? fv_scale(L->dir, -L->far) : fv_sub(L->pos, o);
            float dist = fv_length(to);
            if (!(dist > 0.0f) || fv_dot(nrm[k], to) <= 0.0f) continue;
            uint32_t known = vis_in && bits ? vis_in[idx[k]] : FV_SDF_VIS_UNKNOWN;
            if (known != FV_SDF_VIS_UNKNOWN || !so->shadows) {
                /* the caller knows this point's visibility (ipr's shadow_reuse), or no shadows */
                if (!so->shadows || (known >> li & 1u)) lit[nl++] = k;
                continue;
            }
            fv_march_ray *s = &sray[ns];
            s->o = o;
            s->d = fv_scale(to, 1.0f / dist);
            s->t0 = 0.0f;
            s->t1 = dist;
            /* Nothing blocks the light beyond the world's box: a shadow ray stops where it leaves
             * it (the light may stand far outside), which spares the long tail of steps a ray
             * leaving a large surface at a shallow angle takes. */
            float b0, b1;
            if (fv_sdf_world_clip(w, o, s->d, &b0, &b1) && b1 < s->t1) s->t1 = b1;
            s->eps = 0.5f * hd[k];
            s->eps_k = 0.0f;
            sidx[ns++] = k;
        }
        if (so->shadows && ns > 0) {
            /* The same march for every technique, so shadows never differ between them:
             * over-relaxed (a CPU choice: a quarter fewer shadow steps on the built-in scenes,
             * docs/sdf-tracing.md), whatever the method's own relax. */
            fv_march_opts plain = *mo;
            plain.relax = 1.6f;
            fv_march(w, &plain, sray, shit, ns, true);
            counts->shadow_rays += (uint64_t)ns;
        }
        for (int s = 0; s < ns; s++) {
            counts->shadow_steps += shit[s].steps;
            if (!shit[s].hit) lit[nl++] = sidx[s];
        }
        for (int q = 0; q < nl; q++) {
            int k = lit[q], i = idx[k];
            if (bits) vis[k] |= 1u << li;
            if (!color) continue;
            fv_vec3 o = fv_madd(pos[k], nrm[k], 2.0f * hd[k]);
            fv_vec3 wi = L->directional ? fv_neg(L->dir) : fv_normalize(fv_sub(L->pos, o)), wo = fv_neg(rays[i].d);
            float cos_i = fv_dot(nrm[k], wi);
            fv_vec3 to = fv_sub(L->pos, pos[k]);
            float d2 = L->directional ? 1.0f : fv_dot(to, to); /* a directional light's I is its irradiance */
            if (!(cos_i > 0.0f) || !(d2 > 0.0f)) continue;
            fv_vec3 I = fv_light_delta_intensity(L->light, fv_neg(wi));
            const lobe lb = lobes[k];
            fv_vec3 f = fv_scale(lb.albedo, 1.0f / FV_PI);
            if (lb.has_spec) {
                fv_vec3 h = fv_normalize(fv_add(wi, wo));
                float ch = fmaxf(fv_dot(nrm[k], h), 0.0f);
                f = fv_add(f, fv_scale(lb.spec, lb.norm * powf(ch, lb.exponent)));
            }
            /* incident radiance first, as the light sampler gives it to every other method */
            fv_vec3 inc = fv_scale(I, 1.0f / d2);
            color[i] = fv_add(color[i], fv_scale(fv_mul(f, inc), cos_i));
        }
    }
    if (vis_out && bits)
        for (int k = 0; k < nh; k++) vis_out[idx[k]] = vis[k];
done:
    free(lit);
    free(vis);
    free(lobes);
    free(idx);
    free(pt);
    free(val);
    free(nrm);
    free(pos);
    free(hd);
    free(sray);
    free(shit);
    free(sidx);
    return st;
}
