/* fovea — the SDF family's sphere tracer (march.h). */
#include <math.h>
#include <string.h>
#include "technique/sdf/march.h"

/* One lane's ray in flight. */
typedef struct lane {
    int ray;          /* index in the batch, -1: idle */
    float t;          /* where the field is evaluated next */
    float t_prev;     /* the last point whose step was accepted, and its distance */
    float r_prev;
    float step;       /* the step taken from t_prev to t */
    float omega;      /* the relaxation in force (1 after a failed relaxed step) */
    int steps;
} lane;

/* Starts ray i in lane l; false when it needs no march (it starts past its end). */
static bool lane_start(lane *l, const fv_march_ray *r, fv_march_hit *out, int i, float relax)
{
    if (!(r->t0 <= r->t1)) {
        memset(out, 0, sizeof *out);
        out->t = INFINITY;
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
 * in *out). The decision uses only the ray's own numbers, so any lane gives the same answer. */
static bool lane_advance(lane *l, const fv_march_ray *r, float d, int m, int max_steps, bool any_hit, fv_march_hit *out)
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

static void march_scalar(const fv_sdf_world *w, const fv_march_opts *o, const fv_march_ray *rays, fv_march_hit *out, int n, bool any_hit)
{
    for (int i = 0; i < n; i++) {
        lane l;
        if (!lane_start(&l, &rays[i], &out[i], i, o->relax)) continue;
        const fv_march_ray *r = &rays[i];
        for (;;) {
            fv_vec3 p = fv_madd(r->o, r->d, l.t);
            int m = 0;
            float d = fv_sdf_world_eval1(w, p.x, p.y, p.z, &m);
            if (lane_advance(&l, r, d, m, o->max_steps, any_hit, &out[i])) break;
        }
    }
}

static void march_wide(const fv_sdf_world *w, const fv_march_opts *o, const fv_march_ray *rays, fv_march_hit *out, int n, bool any_hit)
{
    lane lanes[8];
    int next = 0, busy = 0;
    /* Fills lane k with the next ray that needs marching. */
#define REFILL(k)                                                                      \
    do {                                                                               \
        lanes[k].ray = -1;                                                             \
        while (next < n) {                                                             \
            int i_ = next++;                                                           \
            if (lane_start(&lanes[k], &rays[i_], &out[i_], i_, o->relax)) {            \
                busy++;                                                                \
                break;                                                                 \
            }                                                                          \
        }                                                                              \
    } while (0)
    for (int k = 0; k < 8; k++) REFILL(k);
    float x[8], y[8], z[8], d[8];
    int m[8];
    while (busy > 0) {
        int any = -1;
        for (int k = 0; k < 8; k++) {
            if (lanes[k].ray < 0) continue;
            const fv_march_ray *r = &rays[lanes[k].ray];
            x[k] = r->o.x + r->d.x * lanes[k].t;
            y[k] = r->o.y + r->d.y * lanes[k].t;
            z[k] = r->o.z + r->d.z * lanes[k].t;
            any = k;
        }
        for (int k = 0; k < 8; k++)
            if (lanes[k].ray < 0) x[k] = x[any], y[k] = y[any], z[k] = z[any];
        fv_sdf_world_eval8(w, x, y, z, d, m);
        for (int k = 0; k < 8; k++) {
            if (lanes[k].ray < 0) continue;
            int i = lanes[k].ray;
            if (lane_advance(&lanes[k], &rays[i], d[k], m[k], o->max_steps, any_hit, &out[i])) {
                busy--;
                REFILL(k);
            }
        }
    }
#undef REFILL
}

void fv_march(const fv_sdf_world *w, const fv_march_opts *o, const fv_march_ray *rays, fv_march_hit *out, int n, bool any_hit)
{
    if (o->wide) march_wide(w, o, rays, out, n, any_hit);
    else march_scalar(w, o, rays, out, n, any_hit);
}

void fv_march_eval_points(const fv_sdf_world *w, bool wide, const fv_vec3 *p, float *d, int n)
{
    int i = 0;
    if (wide) {
        for (; i + 8 <= n; i += 8) {
            float x[8], y[8], z[8];
            for (int k = 0; k < 8; k++) x[k] = p[i + k].x, y[k] = p[i + k].y, z[k] = p[i + k].z;
            fv_sdf_world_eval8(w, x, y, z, &d[i], NULL);
        }
    }
    for (; i < n; i++) d[i] = fv_sdf_world_eval1(w, p[i].x, p[i].y, p[i].z, NULL);
}
