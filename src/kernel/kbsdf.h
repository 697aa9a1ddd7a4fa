/* fovea — BSDFs of the four material types: Lambert, perfect mirror, Lambert + GGX microfacet
 * ("glossy"), smooth dielectric. Kernel code (FV_HD): the CPU techniques and the CUDA kernels
 * compile these same functions, so every device shades alike.
 *
 * All directions are in the local shading frame (z = shading normal) and point away from the
 * surface. For diffuse, mirror and glossy materials the caller orients the frame so that wo.z > 0
 * (surfaces are two-sided); for dielectrics it keeps the geometric orientation, so wo.z < 0 means
 * the ray arrives from inside the object.
 *
 * GGX follows Walter et al. 2007 ("Microfacet models for refraction through rough surfaces"):
 * D = a^2 / (pi (cos^2 h (a^2 - 1) + 1)^2), separable Smith G, Schlick's Fresnel with F0 = specular.
 * The dielectric uses the exact unpolarised Fresnel equations and picks reflection or refraction
 * with probability F, so each sample's weight is just the tint (times the radiance scaling).
 * Energy is not perfectly conserved for the glossy sum at grazing angles; kd + ks <= 1 is left to
 * the scene author.
 */
#ifndef FV_KERNEL_KBSDF_H
#define FV_KERNEL_KBSDF_H

#include <stdbool.h>
#include "fovea/scene.h"

/* Which quantity a path carries: camera paths carry radiance, light (photon) paths importance.
 * They differ only in the (eta_i/eta_t)^2 scaling of refraction (Veach 1997, Sec. 5.2). */
typedef enum fv_transport { FV_TRANSPORT_RADIANCE = 0, FV_TRANSPORT_IMPORTANCE } fv_transport;

typedef struct fv_bsdf_sample {
    fv_vec3 wi;
    fv_vec3 weight;  /* f * |cos(wi)| / pdf */
    float pdf;       /* solid-angle density; for delta lobes, the discrete lobe probability */
    bool delta;      /* sampled from a specular (delta) lobe */
} fv_bsdf_sample;

/* The local shading frame at a surface hit, for a ray arriving from direction wo (unit, pointing
 * away from the surface). Two-sided materials turn to face the arriving ray; dielectrics keep
 * their orientation so the BSDF can tell entering from leaving. A shading normal that faces away
 * from the view (interpolated normals can) is clamped to grazing. Every technique builds its
 * frames here, so they all treat surfaces alike. */
typedef struct fv_shading {
    fv_vec3 ng, n, t, b; /* oriented geometric normal, shading normal, tangents */
    fv_vec3 wo;          /* wo in the local frame */
} fv_shading;

FV_HD static inline void fv_shading_make(const fv_material *m, fv_vec3 ng, fv_vec3 ns, fv_vec3 wo, fv_shading *sh)
{
    if (m->type != FV_MAT_DIELECTRIC && fv_dot(wo, ng) < 0.0f) {
        ng = fv_neg(ng);
        ns = fv_neg(ns);
    }
    sh->ng = ng;
    sh->n = ns;
    fv_basis(ns, &sh->t, &sh->b);
    sh->wo = fv_to_local(wo, sh->t, sh->b, ns);
    if (m->type != FV_MAT_DIELECTRIC && sh->wo.z <= 0.0f) sh->wo.z = 1e-4f;
}

FV_HD static inline fv_vec3 fv_shading_to_local(const fv_shading *sh, fv_vec3 v) { return fv_to_local(v, sh->t, sh->b, sh->n); }
FV_HD static inline fv_vec3 fv_shading_to_world(const fv_shading *sh, fv_vec3 v) { return fv_from_local(v, sh->t, sh->b, sh->n); }

/* True when the material has a non-delta lobe, i.e. light sampling (NEE) makes sense there. */
FV_HD static inline bool fv_bsdf_is_smooth(const fv_material *m)
{
    return m->type == FV_MAT_DIFFUSE || m->type == FV_MAT_GLOSSY;
}

/* What a denoiser divides a first hit's colour by (filter/demod.h): the light the surface reflects
 * per unit of light it receives, roughly, per channel. Diffuse: its albedo; glossy: albedo plus
 * specular colour (F0), as its highlight is the specular colour's, not the albedo's; a mirror or
 * glass: its specular tint. */
FV_HD static inline fv_vec3 fv_bsdf_demod_reflectance(const fv_material *m)
{
    if (m->type == FV_MAT_DIFFUSE) return m->albedo;
    if (m->type == FV_MAT_GLOSSY) return fv_add(m->albedo, m->specular);
    return m->specular;
}

/* ---- the lobes ---- */

FV_HD static inline fv_vec3 fv_sample_cosine_hemisphere(float u0, float u1)
{
    float r = sqrtf(u0), phi = 2.0f * FV_PI * u1;
    return fv_v3(r * cosf(phi), r * sinf(phi), sqrtf(fv_maxf(0.0f, 1.0f - u0)));
}

FV_HD static inline float fv_fresnel_dielectric(float cos_i, float eta)
{
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f; /* total internal reflection */
    float cos_t = sqrtf(1.0f - sin2_t);
    float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5f * (rs * rs + rp * rp);
}

FV_HD static inline float fv_ggx_d(float cos_h, float alpha)
{
    if (cos_h <= 0.0f) return 0.0f;
    float a2 = alpha * alpha, c2 = cos_h * cos_h;
    float d = c2 * (a2 - 1.0f) + 1.0f;
    return a2 / (FV_PI * d * d);
}

FV_HD static inline float fv_ggx_g1(float cos_v, float alpha)
{
    if (cos_v <= 0.0f) return 0.0f;
    float a2 = alpha * alpha;
    return 2.0f * cos_v / (cos_v + sqrtf(a2 + (1.0f - a2) * cos_v * cos_v));
}

FV_HD static inline fv_vec3 fv_bsdf_schlick(fv_vec3 f0, float c)
{
    float m = 1.0f - fv_clampf(c, 0.0f, 1.0f);
    float m5 = m * m * m * m * m;
    return fv_add(f0, fv_scale(fv_sub(fv_v3s(1.0f), f0), m5));
}

/* Probability of choosing the specular lobe of a glossy material: its share of reflectance,
 * kept away from 0 and 1 so neither lobe is starved. */
FV_HD static inline float fv_bsdf_glossy_spec_prob(const fv_material *m)
{
    float ld = fv_luminance(m->albedo), ls = fv_luminance(m->specular);
    if (ls <= 0.0f) return 0.0f;
    if (ld <= 0.0f) return 1.0f;
    return fv_clampf(ls / (ld + ls), 0.1f, 0.9f);
}

FV_HD static inline fv_vec3 fv_bsdf_glossy_eval(const fv_material *m, fv_vec3 wo, fv_vec3 wi, float *pdf)
{
    *pdf = 0.0f;
    if (wo.z <= 0.0f || wi.z <= 0.0f) return fv_v3s(0.0f);
    float ps = fv_bsdf_glossy_spec_prob(m);
    fv_vec3 h = fv_normalize(fv_add(wo, wi));
    float a = m->roughness;
    float d = fv_ggx_d(h.z, a), oh = fv_dot(wo, h);
    fv_vec3 spec = fv_scale(fv_bsdf_schlick(m->specular, oh), d * fv_ggx_g1(wo.z, a) * fv_ggx_g1(wi.z, a) / (4.0f * wo.z * wi.z));
    fv_vec3 f = fv_add(fv_scale(m->albedo, FV_INV_PI), spec);
    float pdf_spec = oh > 0.0f ? d * h.z / (4.0f * oh) : 0.0f;
    *pdf = ps * pdf_spec + (1.0f - ps) * wi.z * FV_INV_PI;
    return f;
}

/* f(wo, wi) of the non-delta lobes (without the cosine) and, in *pdf, the density with which
 * fv_bsdf_sample_dir would have produced wi. Zero for delta-only materials. */
FV_HD static inline fv_vec3 fv_bsdf_eval(const fv_material *m, fv_vec3 wo, fv_vec3 wi, float *pdf)
{
    switch (m->type) {
    case FV_MAT_DIFFUSE:
        if (wo.z <= 0.0f || wi.z <= 0.0f) break;
        *pdf = wi.z * FV_INV_PI;
        return fv_scale(m->albedo, FV_INV_PI);
    case FV_MAT_GLOSSY:
        return fv_bsdf_glossy_eval(m, wo, wi, pdf);
    default:
        break;
    }
    *pdf = 0.0f;
    return fv_v3s(0.0f);
}

FV_HD static inline bool fv_bsdf_sample_dielectric(const fv_material *m, fv_vec3 wo, fv_transport mode, float u, fv_bsdf_sample *out)
{
    bool entering = wo.z > 0.0f;
    float eta = entering ? m->ior : 1.0f / m->ior; /* n_t / n_i */
    float cos_o = fabsf(wo.z);
    float F = fv_fresnel_dielectric(cos_o, eta);
    out->delta = true;
    if (u < F) {
        out->wi = fv_v3(-wo.x, -wo.y, wo.z);
        out->pdf = F;
        out->weight = m->specular;
        return true;
    }
    float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    float cos_t = sqrtf(fv_maxf(0.0f, 1.0f - sin2_t));
    /* Snell: wi = -wo / eta + (cos_o / eta - cos_t) n, with n on wo's side. */
    float sgn = entering ? 1.0f : -1.0f;
    out->wi = fv_normalize(fv_v3(-wo.x / eta, -wo.y / eta, -sgn * cos_t));
    out->pdf = 1.0f - F;
    float scale = mode == FV_TRANSPORT_RADIANCE ? 1.0f / (eta * eta) : 1.0f;
    out->weight = fv_scale(m->specular, scale);
    return true;
}

/* Samples wi given wo and three uniform numbers; false when the sample carries no energy. */
FV_HD static inline bool fv_bsdf_sample_dir(const fv_material *m, fv_vec3 wo, fv_transport mode, float u0, float u1, float u2,
                        fv_bsdf_sample *out)
{
    switch (m->type) {
    case FV_MAT_DIFFUSE:
        if (wo.z <= 0.0f) return false;
        out->wi = fv_sample_cosine_hemisphere(u0, u1);
        out->pdf = out->wi.z * FV_INV_PI;
        out->weight = m->albedo;
        out->delta = false;
        return out->pdf > 0.0f;
    case FV_MAT_MIRROR:
        if (wo.z <= 0.0f) return false;
        out->wi = fv_v3(-wo.x, -wo.y, wo.z);
        out->pdf = 1.0f;
        out->weight = m->specular;
        out->delta = true;
        return true;
    case FV_MAT_GLOSSY: {
        if (wo.z <= 0.0f) return false;
        float ps = fv_bsdf_glossy_spec_prob(m);
        if (u2 < ps) {
            float a2 = m->roughness * m->roughness;
            float t2 = a2 * u0 / fv_maxf(1e-12f, 1.0f - u0); /* tan^2 of the half-vector angle */
            float ch = 1.0f / sqrtf(1.0f + t2), sh = sqrtf(fv_maxf(0.0f, 1.0f - ch * ch));
            float phi = 2.0f * FV_PI * u1;
            fv_vec3 h = fv_v3(sh * cosf(phi), sh * sinf(phi), ch);
            out->wi = fv_sub(fv_scale(h, 2.0f * fv_dot(wo, h)), wo);
        } else {
            out->wi = fv_sample_cosine_hemisphere(u0, u1);
        }
        if (out->wi.z <= 0.0f) return false;
        fv_vec3 f = fv_bsdf_glossy_eval(m, wo, out->wi, &out->pdf);
        if (!(out->pdf > 0.0f)) return false;
        out->weight = fv_scale(f, out->wi.z / out->pdf);
        out->delta = false;
        return true;
    }
    case FV_MAT_DIELECTRIC:
        return fv_bsdf_sample_dielectric(m, wo, mode, u0, out);
    }
    return false;
}

#endif
