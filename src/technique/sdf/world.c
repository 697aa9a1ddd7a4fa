/* fovea — the SDF family's view of a scene (world.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
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

/* The flat form's program array: the static union's ops, then each moving object's. */
static fv_status flatten(fv_sdf_world *w, int nmoving, fv_error *err)
{
    int n = w->statics ? w->statics->count : 0;
    for (int i = 0; i < nmoving; i++) n += w->sdfs[i]->count;
    if (!w->ops || n > w->ops_cap) {
        free(w->ops);
        w->ops_cap = 0;
        w->ops = fv_alloc_array((size_t)(n > 0 ? n : 1), sizeof *w->ops);
        if (!w->ops) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        w->ops_cap = n > 0 ? n : 1;
    }
    int at = 0;
    if (w->statics) {
        memcpy(w->ops, w->statics->ops, (size_t)w->statics->count * sizeof *w->ops);
        at = w->statics->count;
    }
    for (int i = 0; i < nmoving; i++) {
        w->objs[i].first = at;
        w->objs[i].count = w->sdfs[i]->count;
        memcpy(w->ops + at, w->sdfs[i]->ops, (size_t)w->sdfs[i]->count * sizeof *w->ops);
        at += w->sdfs[i]->count;
    }
    w->k.ops = w->ops;
    w->k.nops = n;
    w->k.statics_count = w->statics ? w->statics->count : 0;
    return FV_OK;
}

fv_status fv_sdf_world_build(fv_sdf_world *w, const fv_scene *s, fv_error *err)
{
    memset(w, 0, sizeof *w);
    return fv_sdf_world_refresh(w, s, err);
}

fv_status fv_sdf_world_refresh(fv_sdf_world *w, const fv_scene *s, fv_error *err)
{
    int n = fv_scene_sdf_object_count(s);
    int nl = fv_light_delta_count(s);
    /* Kept: built for this scene, with its objects and lights (a committed scene's counts and
     * static objects do not change, so neither does the static union). */
    const bool keep = w->objs && w->scene == s && w->nsdf == n && w->nlights == nl;
    if (!keep) {
        fv_sdf_world_free(w);
        w->scene = s;
        if (n == 0) return fv_error_set(err, FV_ERR_INVALID, "the scene has no signed distance field object");
        w->objs = fv_calloc_array((size_t)n, sizeof *w->objs);
        w->sdfs = fv_calloc_array((size_t)n, sizeof *w->sdfs);
        w->lights = fv_calloc_array((size_t)(nl > 0 ? nl : 1), sizeof *w->lights);
        w->static_list = fv_calloc_array((size_t)n, sizeof *w->static_list);
        if (!w->objs || !w->sdfs || !w->lights || !w->static_list) {
            fv_sdf_world_free(w);
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        }
        w->nsdf = n;
        w->nlights = nl;
    }
    const fv_sdf **statics = w->static_list;
    memset(w->objs, 0, (size_t)n * sizeof *w->objs); /* as a fresh build has them */
    memset(w->sdfs, 0, (size_t)n * sizeof *w->sdfs);
    memset(&w->k, 0, sizeof w->k);
    fv_ksdf_world *k = &w->k;
    k->lo = fv_v3s(INFINITY);
    k->hi = fv_v3s(-INFINITY);
    int ns = 0, count = 0;
    for (int i = 0; i < fv_scene_object_count(s); i++) {
        if (fv_scene_object_kind(s, i) != FV_OBJECT_SDF) continue;
        fv_vec3 lo, hi;
        fv_scene_object_bounds(s, i, &lo, &hi);
        k->lo = fv_vmin(k->lo, lo);
        k->hi = fv_vmax(k->hi, hi);
        if (!fv_scene_object_dynamic(s, i)) {
            statics[ns++] = fv_scene_object_sdf(s, i);
            continue;
        }
        fv_ksdf_object *o = &w->objs[count];
        const fv_sdf *sdf = fv_scene_object_sdf(s, i);
        w->sdfs[count++] = sdf;
        o->lo = lo;
        o->hi = hi;
        fv_scene_object_world_to_local(s, i, &o->inv);
        float st = largest_stretch(&o->inv);
        /* a hair under 1/stretch: power iteration approaches the stretch from below */
        o->lip = st > 0.0f ? 0.999f / st : 0.0f;
        /* The world box holds the moved local box; a world point e from it is at least
         * e * (smallest stretch of inv) from the local box, where the field is >= c times that.
         * The smallest stretch is at least |det| / S^2 (S under-estimated by the same hair). */
        o->cull_c = st > 0.0f ? o->lip * fv_sdf_bound_c(sdf) * 0.998f * abs_det(&o->inv) / (st * st) : 0.0f;
    }
    fv_status status = FV_OK;
    if (ns == 1) w->statics = statics[0];
    else if (ns > 1 && w->merged) w->statics = w->merged; /* kept: the same static objects */
    else if (ns > 1 && (status = fv_sdf_union_create(statics, ns, &w->merged, err)) == FV_OK) w->statics = w->merged;
    else w->statics = NULL;
    if (status == FV_OK) status = flatten(w, count, err);
    if (status != FV_OK) {
        fv_sdf_world_free(w);
        return status;
    }
    k->objs = w->objs;
    k->count = count;
    float diag = fv_length(fv_sub(k->hi, k->lo));
    k->eps_abs = w->eps_abs = 1e-5f * diag;
    const float box[6] = {k->lo.x, k->lo.y, k->lo.z, k->hi.x, k->hi.y, k->hi.z};
    float mag = 0.0f;
    for (int i = 0; i < 6; i++) mag = fmaxf(mag, fabsf(box[i]));
    k->cull_margin = FV_SDF_WORLD_CULL_REL * 2.0f * mag;
    fv_vec3 pad = fv_v3s(1e-3f * diag);
    k->lo = fv_sub(k->lo, pad);
    k->hi = fv_add(k->hi, pad);
    for (int i = 0; i < nl; i++) {
        const fv_light *l = fv_light_delta_at(s, i);
        fv_vec3 dir = fv_v3s(0.0f);
        w->lights[i].light = *l;
        w->lights[i].pos = fv_light_delta_pos(l);
        w->lights[i].directional = fv_light_delta_directional(l, &dir);
        w->lights[i].dir = dir;
        w->lights[i].far = 2.0f * fv_length(fv_sub(k->hi, k->lo));
    }
    k->lights = w->lights;
    k->nlights = nl;
    k->mats = fv_scene_material(s, 0);
    k->nmat = fv_scene_material_count(s);
    return FV_OK;
}

void fv_sdf_world_free(fv_sdf_world *w)
{
    fv_sdf_destroy(w->merged);
    free(w->objs);
    free(w->sdfs);
    free(w->lights);
    free(w->ops);
    free(w->static_list);
    memset(w, 0, sizeof *w);
}

void fv_sdf_world_eval8(const fv_sdf_world *w, const float *x, const float *y, const float *z, float *d, int *mat)
{
    const fv_ksdf_world *k = &w->k;
    if (k->count == 0) { /* static objects only: one field */
        fv_sdf_distance8(w->statics, x, y, z, d, mat);
        return;
    }
    float best[8], od[8], lx[8], ly[8], lz[8];
    int bm[8], om[8];
    if (w->statics) {
        fv_sdf_distance8(w->statics, x, y, z, best, bm);
    } else {
        for (int i = 0; i < 8; i++) best[i] = INFINITY, bm[i] = 0;
    }
    for (int i = 0; i < k->count; i++) {
        const fv_ksdf_object *o = &k->objs[i];
        bool all_far = true;
        for (int l = 0; l < 8; l++) all_far = all_far && fv_ksdf_far_from(k, o, x[l], y[l], z[l], best[l]);
        if (all_far) continue;
        for (int l = 0; l < 8; l++) fv_ksdf_to_local(&o->inv, x[l], y[l], z[l], &lx[l], &ly[l], &lz[l]);
        fv_sdf_distance8(w->sdfs[i], lx, ly, lz, od, om);
        for (int l = 0; l < 8; l++) {
            float v = od[l] * o->lip;
            if (v < best[l]) best[l] = v, bm[l] = om[l];
        }
    }
    for (int l = 0; l < 8; l++) {
        d[l] = best[l];
        if (mat) mat[l] = bm[l];
    }
}

float fv_sdf_world_eval1(const fv_sdf_world *w, float x, float y, float z, int *mat) { return fv_ksdf_world_eval1(&w->k, x, y, z, mat); }

bool fv_sdf_world_clip(const fv_sdf_world *w, fv_vec3 o, fv_vec3 d, float *t0, float *t1) { return fv_ksdf_world_clip(&w->k, o, d, t0, t1); }
