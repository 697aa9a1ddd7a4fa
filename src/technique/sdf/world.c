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

fv_status fv_sdf_world_build(fv_sdf_world *w, const fv_scene *s, fv_error *err)
{
    memset(w, 0, sizeof *w);
    w->scene = s;
    int n = fv_scene_sdf_object_count(s);
    if (n == 0) return fv_error_set(err, FV_ERR_INVALID, "the scene has no signed distance field object");
    int nl = fv_light_delta_count(s);
    w->objs = fv_calloc_array((size_t)n, sizeof *w->objs);
    w->lights = fv_calloc_array((size_t)(nl > 0 ? nl : 1), sizeof *w->lights);
    if (!w->objs || !w->lights) {
        fv_sdf_world_free(w);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    w->lo = fv_v3s(INFINITY);
    w->hi = fv_v3s(-INFINITY);
    for (int i = 0, k = 0; i < fv_scene_object_count(s); i++) {
        if (fv_scene_object_kind(s, i) != FV_OBJECT_SDF) continue;
        fv_sdf_world_object *o = &w->objs[k++];
        o->sdf = fv_scene_object_sdf(s, i);
        o->moved = fv_scene_object_dynamic(s, i);
        o->inv = fv_xform_identity();
        o->lip = 1.0f;
        if (o->moved) {
            fv_scene_object_world_to_local(s, i, &o->inv);
            float st = largest_stretch(&o->inv);
            /* a hair under 1/stretch: power iteration approaches the stretch from below */
            o->lip = st > 0.0f ? 0.999f / st : 0.0f;
        }
        fv_scene_object_bounds(s, i, &o->lo, &o->hi);
        w->lo = fv_vmin(w->lo, o->lo);
        w->hi = fv_vmax(w->hi, o->hi);
    }
    w->count = n;
    float diag = fv_length(fv_sub(w->hi, w->lo));
    w->eps_abs = 1e-5f * diag;
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
    free(w->objs);
    free(w->lights);
    memset(w, 0, sizeof *w);
}

/* Distance from p to the box when outside it, -inf inside (where it bounds nothing). */
static inline float box_distance(fv_vec3 lo, fv_vec3 hi, float x, float y, float z)
{
    float dx = fmaxf(fmaxf(lo.x - x, x - hi.x), 0.0f);
    float dy = fmaxf(fmaxf(lo.y - y, y - hi.y), 0.0f);
    float dz = fmaxf(fmaxf(lo.z - z, z - hi.z), 0.0f);
    float d2 = dx * dx + dy * dy + dz * dz;
    return d2 > 0.0f ? sqrtf(d2) : -INFINITY;
}

static inline void to_local(const fv_xform *m, float x, float y, float z, float *lx, float *ly, float *lz)
{
    *lx = m->m[0][0] * x + m->m[0][1] * y + m->m[0][2] * z + m->m[0][3];
    *ly = m->m[1][0] * x + m->m[1][1] * y + m->m[1][2] * z + m->m[1][3];
    *lz = m->m[2][0] * x + m->m[2][1] * y + m->m[2][2] * z + m->m[2][3];
}

void fv_sdf_world_eval8(const fv_sdf_world *w, const float *x, const float *y, const float *z, float *d, int *mat)
{
    if (w->count == 1 && !w->objs[0].moved) {
        fv_sdf_distance8(w->objs[0].sdf, x, y, z, d, mat);
        return;
    }
    float best[8], box[8], od[8], lx[8], ly[8], lz[8];
    int bm[8], om[8];
    for (int k = 0; k < 8; k++) best[k] = INFINITY, bm[k] = 0;
    for (int i = 0; i < w->count; i++) {
        const fv_sdf_world_object *o = &w->objs[i];
        bool any = false;
        for (int k = 0; k < 8; k++) {
            box[k] = w->count > 1 ? box_distance(o->lo, o->hi, x[k], y[k], z[k]) : -INFINITY;
            any |= box[k] < best[k];
        }
        if (!any) continue; /* no lane can get nearer: the value would be >= box >= best */
        const float *px = x, *py = y, *pz = z;
        if (o->moved) {
            for (int k = 0; k < 8; k++) to_local(&o->inv, x[k], y[k], z[k], &lx[k], &ly[k], &lz[k]);
            px = lx, py = ly, pz = lz;
        }
        fv_sdf_distance8(o->sdf, px, py, pz, od, om);
        for (int k = 0; k < 8; k++) {
            float v = o->moved ? od[k] * o->lip : od[k];
            v = fmaxf(v, box[k]);
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
    if (w->count == 1 && !w->objs[0].moved) return fv_sdf_distance1(w->objs[0].sdf, x, y, z, mat);
    float best = INFINITY;
    int bm = 0;
    for (int i = 0; i < w->count; i++) {
        const fv_sdf_world_object *o = &w->objs[i];
        float box = w->count > 1 ? box_distance(o->lo, o->hi, x, y, z) : -INFINITY;
        if (!(box < best)) continue;
        float lx = x, ly = y, lz = z;
        if (o->moved) to_local(&o->inv, x, y, z, &lx, &ly, &lz);
        int om = 0;
        float v = fv_sdf_distance1(o->sdf, lx, ly, lz, &om);
        if (o->moved) v = v * o->lip;
        v = fmaxf(v, box);
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
