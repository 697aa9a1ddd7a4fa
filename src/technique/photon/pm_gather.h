/* fovea — the camera side of photon mapping, shared by pm, pm-t and fpm: eye paths through
 * mirrors and glass to the first diffuse or glossy surface, and the density estimate there
 * (Foveated Photon Mapping, Eq. 3 and 5: a disc of radius gamma, sum f_r * flux / (pi gamma^2)).
 *
 * Direct light is not computed separately: like the paper, every technique estimates all the
 * light reflected by a diffuse or glossy surface from the photon maps (photons are stored from
 * their first hit on). Emitters seen directly, or through mirrors and glass, add their emission.
 */
#ifndef FV_TECHNIQUE_PHOTON_PM_GATHER_H
#define FV_TECHNIQUE_PHOTON_PM_GATHER_H

#include <stdbool.h>
#include "core/rng.h"
#include "scene/query.h"
#include "technique/photon/photon_map.h"

typedef struct fv_pm_hit {
    bool hit;            /* a diffuse or glossy surface was reached */
    fv_vec3 p, n;        /* position, shading normal facing the arriving ray */
    fv_vec3 ng;          /* geometric normal facing the arriving ray */
    fv_vec3 wo;          /* unit direction back along the arriving ray */
    int mat, obj;
    int prim;            /* the triangle, and the barycentrics u, v on it: the material's texture */
    float u, v;          /* is read there (query.h's fv_material_at) */
    bool dynamic;        /* on a dynamic object, or reached through one */
    fv_vec3 weight;      /* throughput of the mirror/glass chain before the surface */
    fv_vec3 emitted;     /* emission met along the chain (already weighted) */
    float first_t;       /* distance to the first surface (any material), +inf for none */
    fv_vec3 first_p, first_n;
    int first_obj;
    fv_vec3 albedo;      /* of the first surface, for the auxiliary buffers */
    fv_vec3 reflectance; /* of the first surface, what a filter demodulates by (fv_bsdf_demod_reflectance) */
} fv_pm_hit;

/* Follows a camera ray (o, d) through at most max_depth mirror/glass bounces, choosing between
 * reflection and refraction with the Fresnel probabilities drawn from rng. */
void fv_pm_eye_path(const fv_scene *s, fv_vec3 o, fv_vec3 d, int max_depth, fv_rng *rng, fv_pm_hit *out);
/* The same, but the first dielectric met is split rather than sampled: its reflection and its
 * refraction are both followed (each weighted by its Fresnel probability), the second into out[1]
 * (fpm-guided's fovea: the camera-ray noise through glass is pm's fovea error). Returns how many
 * of out are filled (1 or 2); emission met before the split is counted in out[0] only, so the
 * pixel's estimate is the sum of the two. */
int fv_pm_eye_path_split(const fv_scene *s, fv_vec3 o, fv_vec3 d, int max_depth, fv_rng *rng, fv_pm_hit out[2]);

/* Sum over the photons of m within r of x of f_r(x, wo, wi) * flux (not yet divided by pi r^2);
 * *u_sum (may be NULL) accumulates max(|flux r|, |flux g|, |flux b|) of the same photons (Eq. 4). */
fv_vec3 fv_pm_gather(const fv_scene *s, const fv_photon_map *m, const fv_pm_hit *x, float r, double *u_sum);

#endif
