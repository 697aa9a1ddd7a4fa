/* fovea — the sphere-tracing family's march as kernel code: one ray's step rule, written once for
 * the CPU's batched tracer (technique/sdf/march.c, eight lanes), the portable backend and CUDA.
 *
 * Sphere tracing (Polychronakis et al. 2023, Sec. 2.1, Fig. 2): a ray advances by the distance the
 * field returns, which never passes a surface, until that distance falls under the hit distance.
 * Over-relaxation (Keinert et al., "Enhanced Sphere Tracing", 2014; `sdf-relaxed`, and `relax` of
 * ipr/fipr) advances by relax x distance instead; when the unbounding spheres of two consecutive
 * points no longer overlap, the step may have jumped a surface, so the ray goes back to the safe
 * step from the previous point and continues unrelaxed.
 *
 * Termination, after the shader convention of the paper's scenes: a hit when the distance is under
 * max(eps, eps_k t) (eps_k: a fraction of a target sample's footprint per unit distance, the same
 * on every pyramid level); a miss when t passes t1; a ray still marching after max_steps
 * evaluations counts as a hit where it stands (grazing rays along silhouettes), or for a shadow ray
 * as not blocked. A camera ray whose point lies inside a solid (distance below minus the hit
 * distance: a pyramid start behind a surface) steps back by the distance until it reaches the
 * surface it entered by; a shadow ray there is blocked. (The paper's shader takes such a point for
 * a hit; stepping back is ours, docs/sdf-tracing.md: it only changes pixels the 3x3 minimum failed
 * to protect.)
 *
 * A lane's decision uses only its own ray's numbers, so whichever lane (or GPU thread) marches a
 * ray, and in whatever order, the result is the same bit for bit.
 */
#ifndef FV_TECHNIQUE_SDF_KMARCH_H
#define FV_TECHNIQUE_SDF_KMARCH_H

#include <stdbool.h>
#include <stdint.h>
#include "technique/sdf/ksdf_world.h"
#include "kernel/ksimt.h"

typedef struct fv_march_opts {
    int max_steps;  /* evaluations per ray (the paper's heat maps stop at 256) */
    float relax;    /* 1: plain sphere tracing; (1, 2): over-relaxation factor */
    bool wide;      /* CPU: eight lanes with the 8-wide field, or the scalar loop */
} fv_march_opts;

typedef struct fv_march_ray {
    fv_vec3 o, d;     /* d unit */
    float t0, t1;     /* where the march starts and gives up */
    float eps, eps_k; /* hit distance max(eps, eps_k * t) */
} fv_march_ray;

typedef struct fv_march_hit {
    float t;          /* where the ray stopped (a hit) */
    uint16_t steps;   /* field evaluations spent */
    uint8_t hit;      /* 1 hit, 0 miss */
    uint8_t exhausted;/* stopped by max_steps */
    int mat;          /* material of the nearest leaf at the hit */
} fv_march_hit;

/* The relaxation every shadow ray marches with, whatever the method's own: the same shadows for
 * every technique (a CPU choice: a quarter fewer shadow steps on the built-in scenes,
 * docs/sdf-tracing.md). */
#define FV_SDF_SHADOW_RELAX 1.6f

/* One ray in flight. */
typedef struct fv_kmarch_lane {
    int ray;          /* the caller's index of the ray, -1: idle */
    float t;          /* where the field is evaluated next */
    float t_prev;     /* the last point whose step was accepted, and its distance */
    float r_prev;
    float step;       /* the step taken from t_prev to t */
    float omega;      /* the relaxation in force (1 after a failed relaxed step) */
    int steps;
} fv_kmarch_lane;

/* Starts ray r (index i) in lane l; false when it needs no march (it starts past its end: *out is
 * then a miss of 0 steps). */
FV_HD static inline bool fv_kmarch_start(fv_kmarch_lane *l, const fv_march_ray *r, fv_march_hit *out, int i, float relax)
{
    if (!(r->t0 <= r->t1)) {
        out->t = INFINITY;
        out->steps = 0;
        out->hit = 0;
        out->exhausted = 0;
        out->mat = 0;
        return false;
    }
    l->ray = i;
    l->t = r->t0;
    l->t_prev = r->t0;
    l->r_prev = 0.0f;
    l->step = 0.0f;
    l->omega = relax;
    l->steps = 0;
    return true;
}

/* Takes the field's value d (material m) at the lane's point; true when the ray is done (result
 * in *out). */
FV_HD static inline bool fv_kmarch_advance(fv_kmarch_lane *l, const fv_march_ray *r, float d, int m, int max_steps, bool any_hit,
                                           fv_march_hit *out)
{
    l->steps++;
    float rad = fabsf(d);
    if (l->omega > 1.0f && l->step > 0.0f && (d < 0.0f || rad + l->r_prev < l->step)) {
        /* The relaxed step may have passed a surface: go back to the plain step from the last
         * accepted point and march unrelaxed from there (Keinert et al. 2014, Sec. 3). */
        l->omega = 1.0f;
        l->step = l->r_prev;
        l->t = l->t_prev + l->step;
    } else if (!any_hit && d < -fmaxf(r->eps, r->eps_k * l->t) && l->t + d >= 0.0f) {
        /* The point is inside a solid: a pyramid level's start (the 3x3 minimum of the depths one
         * level down) can still lie behind a convex surface. |d| never reaches past the surface,
         * so stepping back by it walks out to where the ray enters the solid, instead of taking
         * the point inside for a hit. */
        l->t += d;
        l->t_prev = l->t;
        l->r_prev = 0.0f;
        l->step = 0.0f;
        l->omega = 1.0f;
    } else {
        float eps = fmaxf(r->eps, r->eps_k * l->t);
        if (d < eps) {
            out->t = l->t;
            out->hit = 1;
            out->exhausted = 0;
            out->mat = m;
            out->steps = (uint16_t)l->steps;
            return true;
        }
        l->t_prev = l->t;
        l->r_prev = rad;
        l->step = l->omega * rad;
        /* A relaxed step past the end is not checked by the next point: take the plain one,
         * which is safe, to decide whether the ray really leaves. */
        if (l->omega > 1.0f && l->t + l->step > r->t1) l->step = rad;
        l->t += l->step;
    }
    if (l->t > r->t1) {
        out->t = INFINITY;
        out->hit = 0;
        out->exhausted = 0;
        out->mat = 0;
        out->steps = (uint16_t)l->steps;
        return true;
    }
    if (l->steps >= max_steps) {
        out->t = l->t;
        out->hit = any_hit ? 0 : 1;
        out->exhausted = 1;
        out->mat = m;
        out->steps = (uint16_t)l->steps;
        return true;
    }
    return false;
}

/* Marches one ray through the world's field, a point at a time (any_hit: stop at the first
 * surface, shadow rays: hit = blocked, an exhausted ray counts as not blocked). */
FV_HD static inline void fv_kmarch_one(const fv_ksdf_world *w, int max_steps, float relax, const fv_march_ray *r, bool any_hit,
                                       fv_march_hit *out)
{
    fv_kmarch_lane l;
    if (!fv_kmarch_start(&l, r, out, 0, relax)) return;
    for (;;) {
        FV_SIMT_STEP(FV_SIMT_MARCH);
        fv_vec3 p = fv_madd(r->o, r->d, l.t);
        int m = 0;
        float d = fv_ksdf_world_eval1(w, p.x, p.y, p.z, &m);
        if (fv_kmarch_advance(&l, r, d, m, max_steps, any_hit, out)) return;
    }
}

#endif
