/* fovea — the light a pixel receives from a set of virtual point lights: the shading kernel of ir,
 * ir-low and fir (Foveated Instant Radiosity, Sec. 3.4; Keller's instant radiosity).
 *
 * A VPL at y with unit normal n_y and power P lights a diffuse point x (normal n_x) with
 *     P * cos_y * cos_x / max(|x - y|^2, c^2) * V(x, y)          (times albedo(x) / pi, by the caller)
 * where cos_y = n_y . (x - y)/|x - y| and cos_x = n_x . (y - x)/|x - y| (both clamped at 0), and c is
 * the clamp distance: the paper's "clamped geometry term" (0.03 for every method, Sec. 4.1) read as
 * c = 0.03 x the radius of the scene's bounding sphere, so 1/d^2 cannot blow up next to a VPL
 * (the bias this costs is the energy of the clamped region, the same for all three methods).
 *
 * What P means is the producer's business: a light-walk VPL carries its flux times its albedo / pi
 * (ir), a fir VPL its radiosity / pi times the area it stands for (Sec. 3.4, uniform density).
 *
 * Visibility V is either exact (shadow rays to the VPLs, eight per Embree packet) or read from each
 * VPL's depth cube map (cubemap.h: 1 or 0, or 2x2 percentage-closer).
 */
#ifndef FV_TECHNIQUE_VPL_VPL_GATHER_H
#define FV_TECHNIQUE_VPL_VPL_GATHER_H

#include <math.h>
#include <stdint.h>
#include "technique/vpl/cubemap.h"
#include "scene/query.h"

typedef struct fv_vpl_light {
    fv_vec3 p;     /* on its surface */
    fv_vec3 n;     /* unit, the side it lights */
    fv_vec3 power; /* see above */
    int map;       /* its cube map in the pool, or -1 (rays) */
} fv_vpl_light;

typedef struct fv_vpl_gather {
    const fv_scene *scene;
    const fv_vpl_light *vpls;
    const fv_cubemaps *maps; /* NULL: exact shadow rays */
    fv_cube_filter filter;
    float clamp2;            /* c^2 */
} fv_vpl_gather;

/* The unshadowed term of VPL v at x (unit normal n): P cos_y cos_x / max(d^2, c^2) into *c; false
 * (and *c untouched) when x and v do not face each other. */
static inline bool fv_vpl_term(const fv_vpl_gather *g, const fv_vpl_light *v, fv_vec3 x, fv_vec3 n, fv_vec3 *c)
{
    const fv_vec3 d = fv_sub(v->p, x);
    const float d2 = fv_dot(d, d);
    const float cx = fv_dot(n, d), cy = -fv_dot(v->n, d);
    if (cx <= 0.0f || cy <= 0.0f || !(d2 > 0.0f)) return false;
    *c = fv_scale(v->power, cx * cy / (d2 * fmaxf(d2, g->clamp2))); /* the two cosines carry 1/d each */
    return true;
}

/* The clamp distance c of a scene: `clamp` times the radius of its bounding sphere. */
float fv_vpl_clamp_distance(const fv_scene *s, float clamp);

/* Sum over the VPLs list[0..count) (list NULL: VPLs 0..count-1) of P cos_y cos_x / max(d^2, c^2) V at
 * point x with unit normal n (geometric normal ng, for the shadow rays' offset). *rays counts shadow
 * rays, *lookups cube-map lookups. */
fv_vec3 fv_vpl_gather_at(const fv_vpl_gather *g, fv_vec3 x, fv_vec3 n, fv_vec3 ng, const int *list, int count,
                         uint64_t *rays, uint64_t *lookups);

#endif
