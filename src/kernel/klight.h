/* fovea — the light table and what a path kernel asks of it: next-event estimation from a shading
 * point, the density of hitting an emitter by chance (for MIS), an emitter's radiance and the
 * environment's. Kernel code (FV_HD): the CPU scene (scene/light.c wraps these for fv_scene) and the
 * device scene (kernel/kscene.h, the same table copied to the GPU) sample lights with these same
 * functions.
 *
 * A light is picked with probability proportional to its emitted power (the table's cdf, built at
 * commit by scene.c). Area lights are sampled uniformly by area on the chosen triangle. The
 * environment is sampled by direction: a hemisphere about its up axis in proportion to the
 * hemisphere's mean luminance, then uniformly within it, so a uniform environment is sampled
 * uniformly over the sphere (density 1/(4 pi)). Spot lights fall off smoothly (smoothstep in cos)
 * between the inner and outer cone; point lights are isotropic. A directional light (desc.dir the
 * way its light travels, desc.intensity the irradiance E it gives a surface facing it) is a delta
 * light at infinity: sampled as arriving along -dir from a point beyond the scene, li = E.
 */
#ifndef FV_KERNEL_KLIGHT_H
#define FV_KERNEL_KLIGHT_H

#include <stdbool.h>
#include "fovea/scene.h"
#include "kernel/ktexture.h"

enum { FV_KLIGHT_DELTA = 0, FV_KLIGHT_TRIANGLE = 1, FV_KLIGHT_ENV = 2 };

/* One sampleable light: a delta light, an emissive triangle or the environment. Emissive objects
 * are static (fv_scene_animate_object refuses them), so a triangle's world vertices are fixed. */
typedef struct fv_light fv_light;
struct fv_light {
    int kind;            /* FV_KLIGHT_* */
    fv_light_desc desc;  /* delta light at the scene's current time */
    int delta;           /* delta light: its index in the scene's list as added */
    int obj, prim;       /* emissive triangle */
    fv_vec3 a, b, c;     /* emissive triangle: its world vertices */
    float area;
    fv_vec3 n;           /* unit geometric normal of the triangle */
    fv_vec3 emission;    /* its material's emission (times the texture at a point, below) */
    int emission_texture; /* its material's emission texture id in the table's tex (0: none) */
    fv_vec2 ta, tb, tc;  /* texture coordinates of a, b, c (with an emission texture) */
    fv_vec3 emission_mean; /* emission times the texture's mean over the triangle (untextured: emission) */
    bool two_sided;
    float power;         /* selection weight ~ emitted power */
};

/* A view of a light table: host memory for the CPU, device memory once copied to a GPU. */
typedef struct fv_klights {
    const struct fv_light *light; /* n entries: the delta lights that emit first, then triangles, then
                                     the environment */
    const float *cdf;             /* n + 1 entries, cdf[n] = 1 */
    int n;
    int ndelta;                   /* how many of light[] are delta lights */
    int env_light;                /* index of the environment in light[], -1: none */
    fv_env_desc env;
    float env_p_up;               /* probability of sampling the environment's upper hemisphere */
    fv_vec3 env_c;                /* the bounding sphere the environment's and directional lights' photons are aimed at */
    float env_r;
    const struct fv_ktexture *tex; /* the scene's textures (emission textures are read from them), ntex */
    int ntex;
} fv_klights;

typedef struct fv_light_sample {
    fv_vec3 wi;      /* unit direction from the shading point to the light */
    float dist;      /* distance to the sampled point (environment, directional: a point beyond the scene's bounds) */
    fv_vec3 li;      /* incident radiance (area, environment) or intensity / dist^2 (delta; directional: its irradiance) */
    float pdf;       /* solid-angle density including the light pick (area, environment); pick probability (delta) */
    bool delta;
} fv_light_sample;

/* The light u picks by power and its probability. */
FV_HD static inline int fv_klights_pick(const fv_klights *L, float u, float *pmf)
{
    int lo = 0, hi = L->n - 1;
    while (lo < hi) { /* first i with cdf[i+1] > u */
        int mid = (lo + hi) / 2;
        if (L->cdf[mid + 1] <= u) lo = mid + 1;
        else hi = mid;
    }
    *pmf = L->cdf[lo + 1] - L->cdf[lo];
    return lo;
}

/* A spot light's fall-off towards unit direction w_out (1 inside the inner cone). */
FV_HD static inline float fv_klight_spot_falloff(const fv_light_desc *d, fv_vec3 w_out)
{
    float c = fv_dot(w_out, d->dir);
    float ci = cosf(fv_radians(d->inner_deg)), co = cosf(fv_radians(d->outer_deg));
    if (c >= ci) return 1.0f;
    if (c <= co) return 0.0f;
    float t = (c - co) / (ci - co);
    return t * t * (3.0f - 2.0f * t);
}

/* Radiant intensity of delta light l towards unit direction w (spot fall-off applied); a
 * directional light's irradiance E whatever w (fv_light_delta_intensity, the SDF family's shading). */
FV_HD static inline fv_vec3 fv_klight_delta_intensity(const struct fv_light *l, fv_vec3 w)
{
    if (l->desc.type == FV_LIGHT_DIRECTIONAL) return l->desc.intensity;
    float fall = l->desc.type == FV_LIGHT_SPOT ? fv_klight_spot_falloff(&l->desc, w) : 1.0f;
    return fv_scale(l->desc.intensity, fall);
}

/* The point uniform by area that two uniform numbers pick on a triangle, as its weights on the
 * vertices a, b, c (b's and c's are a hit's barycentrics u, v). */
FV_HD static inline void fv_klight_triangle_bary(float u0, float u1, float w[3])
{
    float su = sqrtf(u0);
    w[0] = 1.0f - su;
    w[1] = u1 * su;
    w[2] = 1.0f - w[0] - w[1];
}

FV_HD static inline fv_vec3 fv_klight_triangle_at(const struct fv_light *l, const float w[3])
{
    return fv_add(fv_add(fv_scale(l->a, w[0]), fv_scale(l->b, w[1])), fv_scale(l->c, w[2]));
}

/* A point uniform by area on an emissive triangle. */
FV_HD static inline fv_vec3 fv_klight_triangle_point(const struct fv_light *l, float u0, float u1)
{
    float w[3];
    fv_klight_triangle_bary(u0, u1, w);
    return fv_klight_triangle_at(l, w);
}

/* Emitted radiance of triangle light l at the point with vertex weights w: its emission, times
 * its emission texture there when it has one (the same lookup as a hit's material). */
FV_HD static inline fv_vec3 fv_klight_triangle_emission(const fv_klights *L, const struct fv_light *l, const float w[3])
{
    const fv_ktexture *t = fv_ktexture_id(L->tex, L->ntex, l->emission_texture);
    if (!t) return l->emission;
    fv_vec2 st = {w[0] * l->ta.x + w[1] * l->tb.x + w[2] * l->tc.x, w[0] * l->ta.y + w[1] * l->tb.y + w[2] * l->tc.y};
    return fv_mul(l->emission, fv_ktexture_sample(t, st));
}

/* ---- the environment ---- */

/* Its radiance seen looking towards unit direction w: a gradient from the horizon to the zenith
 * above, to the ground below. */
FV_HD static inline fv_vec3 fv_kenv_radiance(const fv_env_desc *e, fv_vec3 w)
{
    float t = fv_dot(w, e->up);
    if (t >= 0.0f) return fv_add(e->horizon, fv_scale(fv_sub(e->zenith, e->horizon), fv_minf(t, 1.0f)));
    return fv_add(e->horizon, fv_scale(fv_sub(e->ground, e->horizon), fv_minf(-t, 1.0f)));
}

/* Density of fv_kenv_sample_dir over the sphere of directions. */
FV_HD static inline float fv_kenv_dir_pdf(const fv_klights *L, fv_vec3 w)
{
    float p = fv_dot(w, L->env.up) >= 0.0f ? L->env_p_up : 1.0f - L->env_p_up;
    return p / (2.0f * FV_PI);
}

/* A hemisphere by u0 (in proportion to its mean luminance), then a uniform direction in it: the
 * height t along up is uniform in [0, 1] (Archimedes), the azimuth 2 pi u1. */
FV_HD static inline fv_vec3 fv_kenv_sample_dir(const fv_klights *L, float u0, float u1, float *pdf)
{
    float p = L->env_p_up, t;
    if (u0 < p) {
        t = u0 / p;
        *pdf = p / (2.0f * FV_PI);
    } else {
        t = -(u0 - p) / (1.0f - p);
        *pdf = (1.0f - p) / (2.0f * FV_PI);
    }
    t = fv_clampf(t, -1.0f, 1.0f);
    float r = sqrtf(fv_maxf(0.0f, 1.0f - t * t)), phi = 2.0f * FV_PI * u1;
    fv_vec3 a, b;
    fv_basis(L->env.up, &a, &b);
    return fv_normalize(fv_from_local(fv_v3(r * cosf(phi), r * sinf(phi), t), a, b, L->env.up));
}

/* The radius of the sphere that stands for the environment where a light must be a place, and of
 * the disc its photons leave: just outside the bounding sphere. */
FV_HD static inline float fv_kenv_radius(const fv_klights *L) { return 1.001f * L->env_r; }

/* The environment's radiance arriving along -w (what a ray escaping along unit w carries); zero
 * when the table has none. */
FV_HD static inline fv_vec3 fv_klights_env_radiance(const fv_klights *L, fv_vec3 w)
{
    return L->env_light >= 0 ? fv_kenv_radiance(&L->env, w) : fv_v3s(0.0f);
}

/* Solid-angle density with which fv_klights_sample_li picks direction w on the environment,
 * including the light pick; 0 when the table has none. */
FV_HD static inline float fv_klights_env_pdf(const fv_klights *L, fv_vec3 w)
{
    if (L->env_light < 0) return 0.0f;
    return (L->cdf[L->env_light + 1] - L->cdf[L->env_light]) * fv_kenv_dir_pdf(L, w);
}

/* ---- emitters hit by chance, and next-event estimation ---- */

/* Radiance emitted by a surface of material m with geometric normal ng toward unit w. */
FV_HD static inline fv_vec3 fv_klight_emitted(const fv_material *m, fv_vec3 ng, fv_vec3 w)
{
    float c = fv_dot(ng, w);
    if (c > 0.0f || (m->two_sided_emission && c < 0.0f)) return m->emission;
    return fv_v3s(0.0f);
}

/* Samples incident light at p with three uniform numbers; false when nothing was sampled (no
 * light, or the point is behind a one-sided emitter). Visibility is NOT tested. */
FV_HD static inline bool fv_klights_sample_li(const fv_klights *L, fv_vec3 p, float u0, float u1, float u2, fv_light_sample *out)
{
    if (L->n == 0) return false;
    float pmf;
    const struct fv_light *l = &L->light[fv_klights_pick(L, u0, &pmf)];
    if (!(pmf > 0.0f)) return false;
    if (l->kind == FV_KLIGHT_DELTA && l->desc.type == FV_LIGHT_DIRECTIONAL) {
        out->wi = fv_neg(l->desc.dir);
        out->dist = 2.0f * (fv_kenv_radius(L) + fv_length(fv_sub(p, L->env_c)));
        out->li = l->desc.intensity;
        out->pdf = pmf;
        out->delta = true;
        return true;
    }
    if (l->kind == FV_KLIGHT_DELTA) {
        fv_vec3 d = fv_sub(l->desc.pos, p);
        float d2 = fv_dot(d, d);
        if (!(d2 > 0.0f)) return false;
        out->dist = sqrtf(d2);
        out->wi = fv_scale(d, 1.0f / out->dist);
        float fall = l->desc.type == FV_LIGHT_SPOT ? fv_klight_spot_falloff(&l->desc, fv_neg(out->wi)) : 1.0f;
        if (fall <= 0.0f) return false;
        out->li = fv_scale(l->desc.intensity, fall / d2);
        out->pdf = pmf;
        out->delta = true;
        return true;
    }
    if (l->kind == FV_KLIGHT_ENV) {
        float pdf_w;
        out->wi = fv_kenv_sample_dir(L, u1, u2, &pdf_w);
        out->li = fv_kenv_radiance(&L->env, out->wi);
        /* a point beyond everything: the shadow ray then tests the whole way out */
        out->dist = 2.0f * (fv_kenv_radius(L) + fv_length(fv_sub(p, L->env_c)));
        out->pdf = pmf * pdf_w;
        out->delta = false;
        return fv_max3(out->li) > 0.0f;
    }
    float bw[3];
    fv_klight_triangle_bary(u1, u2, bw);
    fv_vec3 q = fv_klight_triangle_at(l, bw);
    fv_vec3 d = fv_sub(q, p);
    float d2 = fv_dot(d, d);
    if (!(d2 > 0.0f)) return false;
    out->dist = sqrtf(d2);
    out->wi = fv_scale(d, 1.0f / out->dist);
    float cos_l = fv_dot(l->n, out->wi); /* emitter faces p when negative */
    if (!(cos_l < 0.0f || (l->two_sided && cos_l > 0.0f))) return false;
    out->li = fv_klight_triangle_emission(L, l, bw);
    out->pdf = pmf * d2 / (fabsf(cos_l) * l->area);
    out->delta = false;
    return true;
}

/* Solid-angle density with which fv_klights_sample_li would pick the point hit_p (geometric normal
 * hit_ng) on emissive triangle light li (-1: not a light, density 0) seen from p along unit w. */
FV_HD static inline float fv_klights_pdf_li(const fv_klights *L, int li, fv_vec3 p, fv_vec3 hit_p, fv_vec3 hit_ng, fv_vec3 w)
{
    if (li < 0) return 0.0f;
    const struct fv_light *l = &L->light[li];
    float pmf = L->cdf[li + 1] - L->cdf[li];
    fv_vec3 d = fv_sub(hit_p, p);
    float cos_l = fabsf(fv_dot(hit_ng, w));
    if (!(cos_l > 0.0f)) return 0.0f;
    return pmf * fv_dot(d, d) / (cos_l * l->area);
}

#endif
