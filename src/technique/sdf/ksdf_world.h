/* fovea — the sphere-tracing family's world (technique/sdf/world.h) as kernel code: the union of a
 * scene's SDF objects as one field, its box and its delta lights, in flat, index-based arrays, the
 * same on the CPU (host memory) and on a GPU (after technique/sdf/sdf_device.c copies it array by array).
 *
 * The field is evaluated as technique/sdf/world.c always has: the static objects' merged union
 * first, then each moving object in its own space (the point moved back by its inverse transform,
 * its distance scaled by lip so it stays a lower bound), skipped when its box proves it cannot be
 * nearer than what was found. fv_ksdf_world_eval1 is the one scalar evaluation of the world: the
 * CPU's scalar path (fv_sdf_world_eval1), the portable backend and CUDA all call it, and the CPU's
 * eight-lane evaluation (world.c) uses the same skip test and transform below, so its lanes give the
 * same values bit for bit.
 *
 * Includes kernel/ksdf_trace.h (the scalar build of sdf/kernel.h): see the rule there.
 */
#ifndef FV_TECHNIQUE_SDF_KSDF_WORLD_H
#define FV_TECHNIQUE_SDF_KSDF_WORLD_H

#include <math.h>
#include <stdbool.h>
#include "core/ray_box.h"
#include "fovea/math.h"
#include "kernel/klight.h"
#include "kernel/ksdf_trace.h"

/* Relative rounding margin of the moving objects' skip test (as FV_K_CULL_REL, sdf/kernel.h). */
#define FV_SDF_WORLD_CULL_REL 2.44140625e-4f

/* A moving SDF object: its program in the world's ops, and how to reach its space. */
typedef struct fv_ksdf_object {
    int32_t first, count; /* ops [first, first + count) of fv_ksdf_world.ops */
    fv_xform inv;         /* world to the object's space */
    float lip;            /* 1 / the largest stretch of inv: world distance >= lip * local distance */
    float cull_c;         /* outside the world box, lip * local distance >= cull_c * distance to it */
    fv_vec3 lo, hi;       /* world box */
} fv_ksdf_object;

/* A point, spot or directional light as the family shades it. */
typedef struct fv_ksdf_light {
    fv_light light;   /* the scene's light record (its desc at the scene's current time) */
    fv_vec3 pos;
    int32_t directional; /* light along dir, from beyond the world's box (pos unused) */
    fv_vec3 dir;
    float far;        /* directional: a distance that leaves the world's box from anywhere in it */
} fv_ksdf_light;

typedef struct fv_ksdf_world {
    const fv_sdf_op *ops;      /* nops: the static union's program, then each moving object's */
    int nops;
    int statics_count;         /* the static union is ops [0, statics_count); 0: none */
    const fv_ksdf_object *objs;/* count: the moving objects, in scene order */
    int count;
    fv_vec3 lo, hi;            /* box around every object, padded by a few hit distances */
    float eps_abs;             /* smallest hit distance: 1e-5 of the box diagonal */
    float cull_margin;         /* the rounding margin of skipping a moving object, without the point's part */
    const fv_ksdf_light *lights; /* nlights */
    int nlights;
    const fv_material *mats;   /* nmat: the scene's materials */
    int nmat;
} fv_ksdf_world;

/* Distance from p to the box (0 inside). */
FV_HD static inline float fv_ksdf_box_distance(fv_vec3 lo, fv_vec3 hi, float x, float y, float z)
{
    float dx = fmaxf(fmaxf(lo.x - x, x - hi.x), 0.0f);
    float dy = fmaxf(fmaxf(lo.y - y, y - hi.y), 0.0f);
    float dz = fmaxf(fmaxf(lo.z - z, z - hi.z), 0.0f);
    return sqrtf(dx * dx + dy * dy + dz * dz);
}

FV_HD static inline void fv_ksdf_to_local(const fv_xform *m, float x, float y, float z, float *lx, float *ly, float *lz)
{
    *lx = m->m[0][0] * x + m->m[0][1] * y + m->m[0][2] * z + m->m[0][3];
    *ly = m->m[1][0] * x + m->m[1][1] * y + m->m[1][2] * z + m->m[1][3];
    *lz = m->m[2][0] * x + m->m[2][1] * y + m->m[2][2] * z + m->m[2][3];
}

/* True when moving object o cannot be nearer than best at p: outside its box its distance is at
 * least cull_c times the distance to the box, so beyond best plus the rounding margin (kernel.h's
 * argument for FV_OP_CULL) the union keeps best and its material. */
FV_HD static inline bool fv_ksdf_far_from(const fv_ksdf_world *w, const fv_ksdf_object *o, float x, float y, float z, float best)
{
    float m = w->cull_margin + FV_SDF_WORLD_CULL_REL * (fabsf(x) + fabsf(y) + fabsf(z));
    return o->cull_c * fv_ksdf_box_distance(o->lo, o->hi, x, y, z) > fmaxf(best + m, 0.0f);
}

/* The program ops [first, first + count) as a field k_eval runs (only ops and count are read). */
FV_HD static inline fv_sdf fv_ksdf_world_program(const fv_ksdf_world *w, int first, int count)
{
    fv_sdf f;
    f.ops = (fv_sdf_op *)(w->ops + first); /* read only; the struct's field is not const */
    f.count = count;
    f.lo = f.hi = fv_v3s(0.0f);
    f.c = 0.0f;
    f.upper = 0;
    f.mag = 0.0f;
    f.normal_h = 0.0f;
    return f;
}

/* The world's field at one point, with the nearest leaf's material when mat is set. */
FV_HD static inline float fv_ksdf_world_eval1(const fv_ksdf_world *w, float x, float y, float z, int *mat)
{
    float best = INFINITY;
    int bm = 0;
    if (w->statics_count > 0) {
        const fv_sdf f = fv_ksdf_world_program(w, 0, w->statics_count);
        best = fv_ksdf_distance(&f, fv_v3(x, y, z), &bm);
    }
    for (int i = 0; i < w->count; i++) {
        const fv_ksdf_object *o = &w->objs[i];
        if (fv_ksdf_far_from(w, o, x, y, z, best)) continue;
        float lx, ly, lz;
        fv_ksdf_to_local(&o->inv, x, y, z, &lx, &ly, &lz);
        int om = 0;
        const fv_sdf f = fv_ksdf_world_program(w, o->first, o->count);
        float v = fv_ksdf_distance(&f, fv_v3(lx, ly, lz), &om) * o->lip;
        if (v < best) best = v, bm = om;
    }
    if (mat) *mat = bm;
    return best;
}

/* Clips the ray o + t d (d unit) to the world's box: false when it misses the box. */
FV_HD static inline bool fv_ksdf_world_clip(const fv_ksdf_world *w, fv_vec3 o, fv_vec3 d, float *t0, float *t1)
{
    *t0 = 0.0f;
    *t1 = INFINITY;
    return fv_ray_box_clip(o, d, w->lo, w->hi, t0, t1);
}

/* Material id m (a leaf's, always in the table; the first one otherwise, so nothing reads
 * outside it). */
FV_HD static inline const fv_material *fv_ksdf_material(const fv_ksdf_world *w, int m)
{
    return &w->mats[m >= 0 && m < w->nmat ? m : 0];
}

#endif
