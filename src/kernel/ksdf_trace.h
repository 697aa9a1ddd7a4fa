/* fovea — sphere tracing one SDF object of a kernel scene (kernel/kscene.h), for the portable
 * traversal (kernel/ktraverse.h) on the CPU and on CUDA.
 *
 * The one sphere tracer of SDF objects, which the Embree user geometry (scene/scene_sdf.c) calls
 * too: clip to the field's padded box, walk out of the hit band when the ray starts inside it,
 * march at most FV_KSDF_TRACE_STEPS steps, refine FV_KSDF_REFINE times; the normal is
 * fv_sdf_normal's central differences and the material the nearest leaf's. The field is evaluated by the scalar build of
 * the one SDF kernel (sdf/kernel.h with FV_K_WIDE 0, host-and-device under nvcc), so on the CPU
 * every distance, and therefore every hit, is bit-identical to the Embree path's.
 *
 * Includes sdf/kernel.h, which defines static functions: a unit that includes this header must
 * not include another build of sdf/kernel.h.
 */
#ifndef FV_KERNEL_KSDF_TRACE_H
#define FV_KERNEL_KSDF_TRACE_H

#include <math.h>
#include <stdbool.h>
#include "core/ray_box.h"
#include "fovea/math.h"
#include "kernel/kscene.h"
#include "kernel/ksimt.h"

#ifdef FV_K_WIDE
#error "kernel/ksdf_trace.h builds the scalar SDF kernel: include it in a unit without another sdf/kernel.h"
#endif
#define FV_K_WIDE 0
#include "sdf/kernel.h"

/* A ray that needs more steps than this is reported as a miss. */
#define FV_KSDF_TRACE_STEPS 512
/* Newton-like steps along the ray after the hit, which put the point on the surface to float
 * precision for rays that are not grazing. */
#define FV_KSDF_REFINE 3

/* The object's field as the kernel evaluates it: a view of its ops in the shared program array. */
FV_HD static inline fv_sdf fv_ksdf_field(const fv_kscene *s, const fv_kobject *ob)
{
    fv_sdf f;
    f.ops = (fv_sdf_op *)(s->sdf_ops + ob->sdf_first); /* read only; the struct's field is not const */
    f.count = ob->sdf_count;
    f.lo = ob->lo;
    f.hi = ob->hi;
    f.normal_h = ob->sdf_normal_h;
    return f;
}

/* fv_sdf_distance: the field at object-space p, and the nearest leaf's material when mat is set. */
FV_HD static inline float fv_ksdf_distance(const fv_sdf *f, fv_vec3 p, int *mat)
{
    kf d;
    ki m;
    k_eval(f, p.x, p.y, p.z, &d, &m);
    if (mat) *mat = m;
    return d;
}

/* fv_sdf_normal with the default step: six scalar probes, the same values the eight-lane call
 * gives (sdf_eval.h: lane i of the wide build is bit-identical to the scalar one). */
FV_HD static inline fv_vec3 fv_ksdf_normal(const fv_sdf *f, fv_vec3 p)
{
    float h = f->normal_h;
    float dx0 = fv_ksdf_distance(f, fv_v3(p.x + h, p.y, p.z), 0), dx1 = fv_ksdf_distance(f, fv_v3(p.x - h, p.y, p.z), 0);
    float dy0 = fv_ksdf_distance(f, fv_v3(p.x, p.y + h, p.z), 0), dy1 = fv_ksdf_distance(f, fv_v3(p.x, p.y - h, p.z), 0);
    float dz0 = fv_ksdf_distance(f, fv_v3(p.x, p.y, p.z + h), 0), dz1 = fv_ksdf_distance(f, fv_v3(p.x, p.y, p.z - h), 0);
    fv_vec3 g = fv_v3(dx0 - dx1, dy0 - dy1, dz0 - dz1);
    float l = fv_length(g);
    return l > 0.0f && isfinite(l) ? fv_scale(g, 1.0f / l) : fv_v3(0.0f, 0.0f, 0.0f);
}

/* The box the tracer clips to and a BVH bounds the field by: its bounds grown by four hit
 * distances eps, so a surface on the box's face (a plane clipped by its own bounding box) is still
 * reached from outside. */
FV_HD static inline void fv_sdf_padded_box(fv_vec3 field_lo, fv_vec3 field_hi, float eps, fv_vec3 *lo, fv_vec3 *hi)
{
    fv_vec3 pad = fv_v3s(4.0f * eps);
    *lo = fv_sub(field_lo, pad);
    *hi = fv_add(field_hi, pad);
}

/* Sphere-traces field f along o + t d for t in [tnear, tfar] (object space; d need not be unit),
 * hitting where the distance falls below eps (Polychronakis et al. 2023, Sec. 2.1: march by the
 * distance the field returns, which never overshoots); the hit's t in *thit. The one tracer of SDF
 * objects: Embree's user geometry (scene/scene_sdf.c) and the portable traversal call it. */
FV_HD static inline bool fv_sdf_trace_field(const fv_sdf *f, float eps, fv_vec3 o, fv_vec3 d, float tnear, float tfar, float *thit)
{
    fv_vec3 lo, hi;
    fv_sdf_padded_box(f->lo, f->hi, eps, &lo, &hi);
    float t0 = tnear, t1 = tfar;
    if (!fv_ray_box_clip(o, d, lo, hi, &t0, &t1)) return false;
    float dl = fv_length(d);
    if (!(dl > 0.0f) || !isfinite(dl)) return false;
    const float inv_dl = 1.0f / dl;

    float t = t0;
    float dist = fv_ksdf_distance(f, fv_madd(o, d, t), 0);
    /* A ray that starts on a surface (inside the hit band at its own origin, not where it enters
     * the box) is leaving that surface: walk out of the band before looking for hits, or it would
     * hit itself at t = tnear. Fields whose bound is loose (height fields, smooth unions) can
     * leave a ray offset by the scene's epsilon still inside the band. */
    int step = 0;
    if (t0 == tnear && fabsf(dist) < eps) {
        while (fabsf(dist) < eps) {
            FV_SIMT_STEP(FV_SIMT_MARCH);
            t += fmaxf(fabsf(dist), eps) * inv_dl;
            if (t > t1 || ++step >= FV_KSDF_TRACE_STEPS) return false;
            dist = fv_ksdf_distance(f, fv_madd(o, d, t), 0);
        }
    }
    /* side: +1 when marching outside the solid, -1 inside (a refracted ray), so side * dist is
     * the distance to the surface ahead either way, and < eps once the surface is reached or
     * crossed. */
    float side = dist >= 0.0f ? 1.0f : -1.0f;
    for (; step < FV_KSDF_TRACE_STEPS; step++) {
        FV_SIMT_STEP(FV_SIMT_MARCH);
        float ds = side * dist;
        if (ds < eps) {
            for (int k = 0; k < FV_KSDF_REFINE; k++) {
                t += ds * inv_dl;
                ds = side * fv_ksdf_distance(f, fv_madd(o, d, t), 0);
            }
            if (!(t >= tnear && t <= tfar)) return false;
            *thit = t;
            return true;
        }
        t += ds * inv_dl;
        if (t > t1) return false;
        dist = fv_ksdf_distance(f, fv_madd(o, d, t), 0);
    }
    return false;
}

/* The field of object ob of a kernel scene, traced as above. */
FV_HD static inline bool fv_ksdf_trace(const fv_kscene *s, const fv_kobject *ob, fv_vec3 o, fv_vec3 d, float tnear, float tfar,
                                       float *thit)
{
    const fv_sdf f = fv_ksdf_field(s, ob);
    return fv_sdf_trace_field(&f, ob->sdf_eps, o, d, tnear, tfar, thit);
}

/* The top level's box of object ob: its field's padded box. */
FV_HD static inline void fv_ksdf_padded_box(const fv_kobject *ob, fv_vec3 *lo, fv_vec3 *hi)
{
    fv_sdf_padded_box(ob->lo, ob->hi, ob->sdf_eps, lo, hi);
}

#endif
