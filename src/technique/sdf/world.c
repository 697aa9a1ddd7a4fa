/* fovea — the SDF family's view of a scene (world.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/ray_box.h"
#include "sdf/sdf_eval.h"
#include "technique/sdf/world.h"

/* The largest singular value of a 3x3 linear map, by power iteration on M^T M (converges in a
 * few steps for the rotation-and-scale maps of rigid animation). */
static float largest_stretch(const fv_xform *x)
{
    double a[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            a[i][j] = 0.0;
            for (int k = 0; k < 3; k++) a[i][j] += (double)x->m[k][i] * (double)x->m[k][j];
        }
    double v[3] = {1.0, 0.7, 0.4}, lambda = 0.0;
    for (int it = 0; it < 64; it++) {
        double u[3];
        for (int i = 0; i < 3; i++) u[i] = a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2];
        double n = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        if (!(n > 0.0)) break;
        lambda = n;
        for (int i = 0; i < 3; i++) v[i] = u[i] / n;
    }
    return (float)sqrt(lambda);
}

/* |det| of the linear part: with the largest stretch S, the smallest is at least |det| / S^2
 * (the product of the three singular values is |det|, the other two are at most S). */
static float abs_det(const fv_xform *x)
{
    double d = (double)x->m[0][0] * ((double)x->m[1][1] * x->m[2][2] - (double)x->m[1][2] * x->m[2][1]) -
               (double)x->m[0][1] * ((double)x->m[1][0] * x->m[2][2] - (double)x->m[1][2] * x->m[2][0]) +
               (double)x->m[0][2] * ((double)x->m[1][0] * x->m[2][1] - (double)x->m[1][1] * x->m[2][0]);
    return (float)fabs(d);
}

fv_status fv_sdf_world_build(fv_sdf_world *w, const fv_scene *s, fv_error *err)
{
    memset(w, 0, sizeof *w);
    w->scene = s;
    int n = fv_scene_sdf_object_count(s);
    if (n == 0) return fv_error_set(err, FV_ERR_INVALID, "the scene has no signed distance field object");
    int nl = fv_light_delta_count(s);
    w->objs = fv_calloc_array((size_t)n, sizeof *w->objs);
    w->lights = fv_calloc_array((size_t)(nl > 0 ? nl : 1), sizeof *w->lights);
    const fv_sdf **statics = fv_calloc_array((size_t)n, sizeof *statics);
    if (!w->objs || !w->lights || !statics) {
        free(statics);
        fv_sdf_world_free(w);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    w->lo = fv_v3s(INFINITY);
    w->hi = fv_v3s(-INFINITY);
    int ns = 0;
    for (int i = 0; i < fv_scene_object_count(s); i++) {
        if (fv_scene_object_kind(s, i) != FV_OBJECT_SDF) continue;
        fv_vec3 lo, hi;
        fv_scene_object_bounds(s, i, &lo, &hi);
        w->lo = fv_vmin(w->lo, lo);
        w->hi = fv_vmax(w->hi, hi);
        if (!fv_scene_object_dynamic(s, i)) {
            statics[ns++] = fv_scene_object_sdf(s, i);
            continue;
        }
        fv_sdf_world_object *o = &w->objs[w->count++];
        o->sdf = fv_scene_object_sdf(s, i);
        o->lo = lo;
        o->hi = hi;
        fv_scene_object_world_to_local(s, i, &o->inv);
        float st = largest_stretch(&o->inv);
        /* a hair under 1/stretch: power iteration approaches the stretch from below */
        o->lip = st > 0.0f ? 0.999f / st : 0.0f;
        /* The world box holds the moved local box; a world point e from it is at least
         * e * (smallest stretch of inv) from the local box, where the field is >= c times that.
         * The smallest stretch is at least |det| / S^2 (S under-estimated by the same hair). */
        o->cull_c = st > 0.0f ? o->lip * fv_sdf_bound_c(o->sdf) * 0.998f * abs_det(&o->inv) / (st * st) : 0.0f;
    }
    fv_status status = FV_OK;
    if (ns == 1) w->statics = statics[0];
    else if (ns > 1 && (status = fv_sdf_union_create(statics, ns, &w->merged, err)) == FV_OK) w->statics = w->merged;
    free(statics);
    if (status != FV_OK) {
        fv_sdf_world_free(w);
        return status;
    }
    float diag = fv_length(fv_sub(w->hi, w->lo));
    w->eps_abs = 1e-5f * diag;
    const float box[6] = {w->lo.x, w->lo.y, w->lo.z, w->hi.x, w->hi.y, w->hi.z};
    float mag = 0.0f;
    for (int k = 0; k < 6; k++) mag = fmaxf(mag, fabsf(box[k]));
    w->cull_margin = FV_SDF_WORLD_CULL_REL * 2.0f * mag;
    fv_vec3 pad = fv_v3s(1e-3f * diag);
    w->lo = fv_sub(w->lo, pad);
    w->hi = fv_add(w->hi, pad);
    for (int i = 0; i < nl; i++) {
        const fv_light *l = fv_light_delta_at(s, i);
        w->lights[i].light = l;
        w->lights[i].pos = fv_light_delta_pos(l);
        w->lights[i].directional = fv_light_delta_directional(l, &w->lights[i].dir);
        w->lights[i].far = 2.0f * fv_length(fv_sub(w->hi, w->lo));
    }
    w->light_count = nl;
    return FV_OK;
}

void fv_sdf_world_free(fv_sdf_world *w)
{
    fv_sdf_destroy(w->merged);
    free(w->objs);
    free(w->lights);
    memset(w, 0, sizeof *w);
}

/* Distance from p to the box (0 inside). */
static inline float box_distance(fv_vec3 lo, fv_vec3 hi, float x, float y, float z)
{
    float dx = fmaxf(fmaxf(lo.x - x, x - hi.x), 0.0f);
    float dy = fmaxf(fmaxf(lo.y - y, y - hi.y), 0.0f);
    float dz = fmaxf(fmaxf(lo.z - z, z - hi.z), 0.0f);
    return sqrtf(dx * dx + dy * dy + dz * dz);
}

static inline void to_local(const fv_xform *m, float x, float y, float z, float *lx, float *ly, float *lz)
{
    *lx = m->m[0][0] * x + m->m[0][1] * y + m->m[0][2] * z + m->m[0][3];
    *ly = m->m[1][0] * x + m->m[1][1] * y + m->m[1][2] * z + m->m[1][3];
    *lz = m->m[2][0] * x + m->m[2][1] * y + m->m[2][2] * z + m->m[2][3];
}

/* True when moving object o cannot be nearer than best at p: outside its box its distance is at
 * least cull_c times the distance to the box, so beyond best plus the rounding margin (kernel.h's
 * argument for FV_OP_CULL) the union keeps best and its material. */
static inline bool far_from(const fv_sdf_world *w, const fv_sdf_world_object *o, float x, float y, float z, float best)
{
    float m = w->cull_margin + FV_SDF_WORLD_CULL_REL * (fabsf(x) + fabsf(y) + fabsf(z));
    return o->cull_c * box_distance(o->lo, o->hi, x, y, z) > fmaxf(best + m, 0.0f);
}

void fv_sdf_world_eval8(const fv_sdf_world *w, const float *x, const float *y, const float *z, float *d, int *mat)
{
    if (w->count == 0) { /* static objects only: one field */
        fv_sdf_distance8(w->statics, x, y, z, d, mat);
        return;
    }
    float best[8], od[8], lx[8], ly[8], lz[8];
    int bm[8], om[8];
    if (w->statics) {
        fv_sdf_distance8(w->statics, x, y, z, best, bm);
    } else {
        for (int k = 0; k < 8; k++) best[k] = INFINITY, bm[k] = 0;
    }
    for (int i = 0; i < w->count; i++) {
        const fv_sdf_world_object *o = &w->objs[i];
        bool all_far = true;
        for (int k = 0; k < 8; k++) all_far = all_far && far_from(w, o, x[k], y[k], z[k], best[k]);
        if (all_far) continue;
        for (int k = 0; k < 8; k++) to_local(&o->inv, x[k], y[k], z[k], &lx[k], &ly[k], &lz[k]);
        fv_sdf_distance8(o->sdf, lx, ly, lz, od, om);
        for (int k = 0; k < 8; k++) {
            float v = od[k] * o->lip;
            if (v < best[k]) best[k] = v, bm[k] = om[k];
        }
    }
    for (int k = 0; k < 8; k++) {
        d[k] = best[k];
        if (mat) mat[k] = bm[k];
    }
}

float fv_sdf_world_eval1(const fv_sdf_world *w, float x, float y, float z, int *mat)
{
    if (w->count == 0) return fv_sdf_distance1(w->statics, x, y, z, mat);
    float best = INFINITY;
    int bm = 0;
    if (w->statics) best = fv_sdf_distance1(w->statics, x, y, z, &bm);
    for (int i = 0; i < w->count; i++) {
        const fv_sdf_world_object *o = &w->objs[i];
        if (far_from(w, o, x, y, z, best)) continue;
        float lx, ly, lz;
        to_local(&o->inv, x, y, z, &lx, &ly, &lz);
        int om = 0;
        float v = fv_sdf_distance1(o->sdf, lx, ly, lz, &om) * o->lip;
        if (v < best) best = v, bm = om;
    }
    if (mat) *mat = bm;
    return best;
}

bool fv_sdf_world_clip(const fv_sdf_world *w, fv_vec3 o, fv_vec3 d, float *t0, float *t1)
{
    *t0 = 0.0f;
    *t1 = INFINITY;
    return fv_ray_box_clip(o, d, w->lo, w->hi, t0, t1);
}
