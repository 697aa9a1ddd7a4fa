/* fovea — BSDFs of the four material types, shared by every technique.
 *
 * All directions are in the local shading frame (z = shading normal) and point away from the
 * surface. For diffuse, mirror and glossy materials the caller orients the frame so that wo.z > 0
 * (surfaces are two-sided); for dielectrics it keeps the geometric orientation, so wo.z < 0 means
 * the ray arrives from inside the object.
 */
#ifndef FV_SCENE_BSDF_H
#define FV_SCENE_BSDF_H

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

static inline void fv_shading_make(const fv_material *m, fv_vec3 ng, fv_vec3 ns, fv_vec3 wo, fv_shading *sh)
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

static inline fv_vec3 fv_shading_to_local(const fv_shading *sh, fv_vec3 v) { return fv_to_local(v, sh->t, sh->b, sh->n); }
static inline fv_vec3 fv_shading_to_world(const fv_shading *sh, fv_vec3 v) { return fv_from_local(v, sh->t, sh->b, sh->n); }

/* True when the material has a non-delta lobe, i.e. light sampling (NEE) makes sense there. */
static inline bool fv_bsdf_is_smooth(const fv_material *m)
{
    return m->type == FV_MAT_DIFFUSE || m->type == FV_MAT_GLOSSY;
}

/* f(wo, wi) of the non-delta lobes (without the cosine) and, in *pdf, the density with which
 * fv_bsdf_sample would have produced wi. Zero for delta-only materials. */
fv_vec3 fv_bsdf_eval(const fv_material *m, fv_vec3 wo, fv_vec3 wi, float *pdf);

/* Samples wi given wo and three uniform numbers; false when the sample carries no energy. */
bool fv_bsdf_sample_dir(const fv_material *m, fv_vec3 wo, fv_transport mode, float u0, float u1, float u2,
                        fv_bsdf_sample *out);

/* Building blocks, exposed for tests and for techniques that need one lobe. */
float fv_fresnel_dielectric(float cos_i, float eta); /* eta = n_t / n_i, cos_i >= 0 */
float fv_ggx_d(float cos_h, float alpha);
float fv_ggx_g1(float cos_v, float alpha);
fv_vec3 fv_sample_cosine_hemisphere(float u0, float u1);

#endif
