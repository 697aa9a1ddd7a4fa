/* fovea — the sphere-tracing family's shading as kernel code (Polychronakis et al. 2023, Sec. 4.1:
 * the scenes without soft shadows and ambient occlusion): Lambert plus a Blinn-Phong lobe from each
 * point, spot or directional light, hard shadows by sphere tracing towards the light, normals from
 * the field's gradient. The CPU (technique/sdf/sdf_shade.c) batches the field evaluations of many hits
 * through these helpers; fv_ksdf_shade_one runs them for one hit, a point at a time (the portable
 * backend and CUDA). Both take the same steps in the same order (lights in the scene's order), so a
 * hit shades to the same bits either way.
 *
 * The material model is the scene's: `albedo` is the Lambert term, a GLOSSY material's `specular`
 * and GGX `roughness` alpha become the Blinn-Phong colour and exponent 2 / alpha^2 - 2 (the usual
 * match of the two lobes' widths); MIRROR and DIELECTRIC materials get a sharp lobe (alpha 0.05)
 * of their `specular` tint: no reflection or refraction rays, as in the paper's shaders. The lobe is
 * normalised ((n + 8) / 8 pi), so a diffuse scene shades exactly as `pt max_depth=1` (direct light
 * only) and the two can be compared. Area lights (emissive triangles) are not seen.
 */
#ifndef FV_TECHNIQUE_SDF_KSDF_SHADE_H
#define FV_TECHNIQUE_SDF_KSDF_SHADE_H

#include "technique/sdf/kmarch.h"

typedef struct fv_sdf_shade_opts {
    float ambient;  /* constant term: ambient x albedo (0: direct light only) */
    bool shadows;   /* trace shadow rays (off: every light is visible) */
} fv_sdf_shade_opts;

typedef struct fv_sdf_shade_counts {
    uint64_t shadow_rays, shadow_steps, normal_evals;
} fv_sdf_shade_counts;

typedef struct fv_ksdf_lobe {
    fv_vec3 albedo, spec;
    float exponent, norm;
    bool has_spec;
} fv_ksdf_lobe;

FV_HD static inline fv_ksdf_lobe fv_ksdf_lobe_of(const fv_material *m)
{
    fv_ksdf_lobe l;
    l.albedo = m->albedo;
    l.spec = fv_v3s(0.0f);
    l.exponent = 0.0f;
    l.norm = 0.0f;
    l.has_spec = false;
    if (m->type == FV_MAT_DIFFUSE) return l;
    float alpha = m->type == FV_MAT_GLOSSY ? fmaxf(m->roughness, 0.03f) : 0.05f;
    l.spec = m->specular;
    l.exponent = 2.0f / (alpha * alpha) - 2.0f;
    l.norm = (l.exponent + 8.0f) / (8.0f * FV_PI);
    l.has_spec = fv_max3(l.spec) > 0.0f;
    return l;
}

/* The four tetrahedron directions: their sum is zero, so sum_k k f(p + h k) = 4 h grad f + O(h^3)
 * from four evaluations instead of six central differences. */
FV_HD static inline fv_vec3 fv_ksdf_tet(int j)
{
    return j == 0 ? fv_v3(1, -1, -1) : j == 1 ? fv_v3(-1, -1, 1) : j == 2 ? fv_v3(-1, 1, -1) : fv_v3(1, 1, 1);
}

/* Where the march stopped and the hit distance there: the gradient's step (a coarse level's
 * normal is as smooth as its footprint) and the shadow rays' offset. */
FV_HD static inline float fv_ksdf_hit_distance(const fv_march_ray *r, float t) { return fmaxf(r->eps, r->eps_k * t); }

/* The unit normal from the field at pos + hd tet(j), j = 0..3; where the differences cancel (a
 * crease's exact middle), it faces the ray (direction d). */
FV_HD static inline fv_vec3 fv_ksdf_normal_of(const float val[4], fv_vec3 d)
{
    fv_vec3 g = fv_v3s(0.0f);
    for (int j = 0; j < 4; j++) g = fv_madd(g, fv_ksdf_tet(j), val[j]);
    float len = fv_length(g);
    return len > 0.0f && isfinite(len) ? fv_scale(g, 1.0f / len) : fv_neg(d);
}

/* The shadow ray from hit point pos (normal nrm, hit distance hd) towards light L in *s; false
 * when the light is behind the surface (it adds nothing, no ray). */
FV_HD static inline bool fv_ksdf_shadow_ray(const fv_ksdf_world *w, const fv_ksdf_light *L, fv_vec3 pos, fv_vec3 nrm, float hd,
                                            fv_march_ray *s)
{
    fv_vec3 o = fv_madd(pos, nrm, 2.0f * hd);
    fv_vec3 to = L->directional ? fv_scale(L->dir, -L->far) : fv_sub(L->pos, o);
    float dist = fv_length(to);
    if (!(dist > 0.0f) || fv_dot(nrm, to) <= 0.0f) return false;
    s->o = o;
    s->d = fv_scale(to, 1.0f / dist);
    s->t0 = 0.0f;
    s->t1 = dist;
    /* Nothing blocks the light beyond the world's box: a shadow ray stops where it leaves it (the
     * light may stand far outside), which spares the long tail of steps a ray leaving a large
     * surface at a shallow angle takes. */
    float b0, b1;
    if (fv_ksdf_world_clip(w, o, s->d, &b0, &b1) && b1 < s->t1) s->t1 = b1;
    s->eps = 0.5f * hd;
    s->eps_k = 0.0f;
    return true;
}

/* What visible light L adds at pos seen from wo: false (nothing) where it grazes or coincides. */
FV_HD static inline bool fv_ksdf_light_term(const fv_ksdf_light *L, const fv_ksdf_lobe *lb, fv_vec3 pos, fv_vec3 nrm, float hd, fv_vec3 wo,
                                            fv_vec3 *term)
{
    fv_vec3 o = fv_madd(pos, nrm, 2.0f * hd);
    fv_vec3 wi = L->directional ? fv_neg(L->dir) : fv_normalize(fv_sub(L->pos, o));
    float cos_i = fv_dot(nrm, wi);
    fv_vec3 to = fv_sub(L->pos, pos);
    float d2 = L->directional ? 1.0f : fv_dot(to, to); /* a directional light's I is its irradiance */
    if (!(cos_i > 0.0f) || !(d2 > 0.0f)) return false;
    fv_vec3 I = fv_klight_delta_intensity(&L->light, fv_neg(wi));
    fv_vec3 f = fv_scale(lb->albedo, 1.0f / FV_PI);
    if (lb->has_spec) {
        fv_vec3 h = fv_normalize(fv_add(wi, wo));
        float ch = fmaxf(fv_dot(nrm, h), 0.0f);
        f = fv_add(f, fv_scale(lb->spec, lb->norm * powf(ch, lb->exponent)));
    }
    /* incident radiance first, as the light sampler gives it to every other method */
    fv_vec3 inc = fv_scale(I, 1.0f / d2);
    *term = fv_scale(fv_mul(f, inc), cos_i);
    return true;
}

/* Which lights reach a shaded point: bit l for light l (scenes with up to 31 delta lights), or
 * FV_SDF_VIS_UNKNOWN (also for a miss). ipr's shadow_reuse passes it from a level to the next. */
#define FV_SDF_VIS_UNKNOWN 0xffffffffu

/* Shades one marched camera ray: its radiance (black for a miss) and, in *normal, the unit normal
 * (zero for a miss); the costs are added to *c. known: the lights already known to reach the hit
 * (shadow_reuse; FV_SDF_VIS_UNKNOWN: none known, trace the shadow rays); *vis_out (when not NULL)
 * receives which lights reach it. The visibility is kept as bits only with at most 31 lights, as
 * the CPU's batched shading keeps it (technique/sdf/sdf_shade.c). */
FV_HD static inline fv_vec3 fv_ksdf_shade_vis(const fv_ksdf_world *w, const fv_march_opts *mo, const fv_sdf_shade_opts *so,
                                              const fv_march_ray *r, const fv_march_hit *h, uint32_t known, uint32_t *vis_out,
                                              fv_sdf_shade_counts *c, fv_vec3 *normal)
{
    *normal = fv_v3s(0.0f);
    if (vis_out) *vis_out = FV_SDF_VIS_UNKNOWN;
    if (!h->hit) return fv_v3s(0.0f);
    const bool bits = w->nlights <= 31;
    if (!bits) known = FV_SDF_VIS_UNKNOWN;
    const fv_vec3 pos = fv_madd(r->o, r->d, h->t);
    const float hd = fv_ksdf_hit_distance(r, h->t);
    float val[4];
    for (int j = 0; j < 4; j++) {
        fv_vec3 q = fv_madd(pos, fv_ksdf_tet(j), hd);
        val[j] = fv_ksdf_world_eval1(w, q.x, q.y, q.z, 0);
    }
    c->normal_evals += 4;
    const fv_vec3 nrm = fv_ksdf_normal_of(val, r->d);
    *normal = nrm;
    const fv_material *m = fv_ksdf_material(w, h->mat);
    const fv_ksdf_lobe lb = fv_ksdf_lobe_of(m);
    fv_vec3 colour = fv_scale(m->albedo, so->ambient);
    uint32_t vis = 0;
    for (int li = 0; li < w->nlights; li++) {
        const fv_ksdf_light *L = &w->lights[li];
        fv_march_ray s;
        if (!fv_ksdf_shadow_ray(w, L, pos, nrm, hd, &s)) continue;
        if (known != FV_SDF_VIS_UNKNOWN || !so->shadows) {
            /* the caller knows this point's visibility (shadow_reuse), or no shadows */
            if (so->shadows && !(known >> li & 1u)) continue;
        } else {
            fv_march_hit sh;
            fv_kmarch_one(w, mo->max_steps, FV_SDF_SHADOW_RELAX, &s, true, &sh);
            c->shadow_rays++;
            c->shadow_steps += sh.steps;
            if (sh.hit) continue;
        }
        if (bits) vis |= 1u << li;
        fv_vec3 term;
        if (fv_ksdf_light_term(L, &lb, pos, nrm, hd, fv_neg(r->d), &term)) colour = fv_add(colour, term);
    }
    if (vis_out && bits) *vis_out = vis;
    return colour;
}

/* Shades one marched camera ray, tracing every shadow ray (fv_ksdf_shade_vis knowing nothing). */
FV_HD static inline fv_vec3 fv_ksdf_shade_one(const fv_ksdf_world *w, const fv_march_opts *mo, const fv_sdf_shade_opts *so,
                                              const fv_march_ray *r, const fv_march_hit *h, fv_sdf_shade_counts *c, fv_vec3 *normal)
{
    return fv_ksdf_shade_vis(w, mo, so, r, h, FV_SDF_VIS_UNKNOWN, NULL, c, normal);
}

#endif
