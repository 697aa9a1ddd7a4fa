/* fovea — rays through a kernel scene (kernel/kscene.h): closest hit, any hit, visibility. Written
 * once for the CPU and for CUDA (every function FV_HD static inline), with the semantics of the
 * Embree queries of scene/query.h, so a GPU backend and the CPU agree on what a ray hits:
 * fv_kscene_intersect fills fv_hit exactly as scene.c's fill_hit does.
 *
 * Traversal is iterative with a fixed stack of FV_KSTACK entries (the exporter refuses deeper
 * BVHs), no recursion, no allocation. A node holds both children's boxes: the slab test
 * (precomputed inverse direction) runs on both, a hit leaf is intersected at once, nearer leaf
 * first; of two hit inner children the nearer is entered and the farther pushed with its entry
 * distance, skipped when popped beyond the closest hit so far. The top level is the same loop
 * over tnodes; each instance runs the bottom loop with the ray in its object space (t is kept:
 * the direction is transformed, not normalised, as Embree does for instances).
 *
 * Triangles: Moeller-Trumbore on the stored (v0, e1, e2), t in (0, tmax], u, v >= 0, u + v <= 1
 * inclusive, so a ray through a shared edge finds at least one of its triangles except where
 * rounding splits them (measured against Embree in tests/unit/test_traverse.c).
 */
#ifndef FV_KERNEL_KTRAVERSE_H
#define FV_KERNEL_KTRAVERSE_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include "fovea/math.h"
#include "kernel/khit.h"
#include "kernel/kscene.h"
#include "kernel/ksdf_trace.h"
#include "kernel/ksimt.h"

/* A box test's far distance is scaled up by 1 + 2 gamma(3) so rounding in the slab arithmetic
 * never loses a box that a ray only touches (a wall's flat box, a triangle in a box face). */
#define FV_KBOX_ROUND 1.0000004f

/* The closest hit so far. */
typedef struct fv_kbest {
    float t, u, v;
    int32_t tri;  /* ktris index; -1: an SDF hit or none */
    int32_t obj;  /* object hit; -1: none */
} fv_kbest;

FV_HD static inline fv_vec3 fv_kinv_dir(fv_vec3 d)
{
    /* 1/0 = inf is what the slab test wants: that slab is then all or nothing. */
    return fv_v3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
}

/* Slab test of box [lo, hi] against o + t inv^-1, t in [0, tmax]; the entry distance in *tn. A
 * NaN slab (an origin on a plane parallel to the ray) is ignored by fv_minf/fv_maxf. */
FV_HD static inline bool fv_kbox(const float *lo, const float *hi, fv_vec3 o, fv_vec3 inv, float tmax, float *tn)
{
    float x0 = (lo[0] - o.x) * inv.x, x1 = (hi[0] - o.x) * inv.x;
    float y0 = (lo[1] - o.y) * inv.y, y1 = (hi[1] - o.y) * inv.y;
    float z0 = (lo[2] - o.z) * inv.z, z1 = (hi[2] - o.z) * inv.z;
    float a = fv_maxf(fv_maxf(fv_minf(x0, x1), fv_minf(y0, y1)), fv_maxf(fv_minf(z0, z1), 0.0f));
    float b = fv_minf(fv_minf(fv_maxf(x0, x1), fv_maxf(y0, y1)), fv_minf(fv_maxf(z0, z1), tmax));
    *tn = a;
    return a <= b * FV_KBOX_ROUND;
}

/* Moeller-Trumbore: o + t d against the triangle, t in (0, tmax]. */
FV_HD static inline bool fv_ktri_hit(const fv_ktri *tr, fv_vec3 o, fv_vec3 d, float tmax, float *t, float *u, float *v)
{
    fv_vec3 e1 = fv_v3(tr->e1[0], tr->e1[1], tr->e1[2]), e2 = fv_v3(tr->e2[0], tr->e2[1], tr->e2[2]);
    fv_vec3 pv = fv_cross(d, e2);
    float det = fv_dot(e1, pv);
    if (!(det != 0.0f)) return false;
    float id = 1.0f / det;
    fv_vec3 tv = fv_sub(o, fv_v3(tr->v0[0], tr->v0[1], tr->v0[2]));
    float uu = fv_dot(tv, pv) * id;
    if (!(uu >= 0.0f && uu <= 1.0f)) return false;
    fv_vec3 qv = fv_cross(tv, e1);
    float vv = fv_dot(d, qv) * id;
    if (!(vv >= 0.0f && uu + vv <= 1.0f)) return false;
    float tt = fv_dot(e2, qv) * id;
    if (!(tt > 0.0f && tt <= tmax)) return false;
    *t = tt;
    *u = uu;
    *v = vv;
    return true;
}

/* The leaf code c (< 0) as its first entry and count. */
FV_HD static inline void fv_kleaf(int32_t c, int *first, int *count)
{
    uint32_t v = ~(uint32_t)c;
    *first = (int)(v >> 3);
    *count = (int)(v & 7u);
}

/* A bottom-level leaf: its triangles against the ray; with any, true at the first hit. */
FV_HD static inline bool fv_kleaf_tris(const fv_kscene *s, int32_t c, fv_vec3 o, fv_vec3 d, bool any, fv_kbest *b)
{
    int first, count;
    fv_kleaf(c, &first, &count);
    for (int i = first; i < first + count; i++) {
        float t, u, v;
        if (!fv_ktri_hit(&s->ktris[i], o, d, b->t, &t, &u, &v)) continue;
        if (any) return true;
        b->t = t;
        b->u = u;
        b->v = v;
        b->tri = i;
        b->obj = s->ktris[i].obj;
    }
    return false;
}

/* The walk's state: the farther children put aside, with their entry distances. */
typedef struct fv_kwalk {
    int32_t node[FV_KSTACK];
    float t[FV_KSTACK];
    int sp;
} fv_kwalk;

/* Node n's two children against the ray (inverse direction inv, up to tmax): whether each box is
 * hit, in the order to visit them (the nearer first), with their indices and entry distances. */
FV_HD static inline void fv_knode_children(const fv_knode *n, fv_vec3 o, fv_vec3 inv, float tmax, bool *ha, bool *hb, int32_t *ca,
                                           int32_t *cb, float *ta, float *tb)
{
    *ha = fv_kbox(n->l0, n->h0, o, inv, tmax, ta);
    *hb = fv_kbox(n->l1, n->h1, o, inv, tmax, tb);
    *ca = n->c0;
    *cb = n->c1;
    if (*ha && *hb && *tb < *ta) { /* nearer child first */
        int32_t c = *ca;
        *ca = *cb;
        *cb = c;
        float t = *ta;
        *ta = *tb;
        *tb = t;
    }
}

/* The next inner node to visit once a node's leaves were intersected (ha, hb: the inner children
 * still to enter, nearer first): the nearer, putting the farther aside; with neither, the next one
 * put aside that is still nearer than the closest hit tbest. False when the walk is over. */
FV_HD static inline bool fv_kwalk_next(fv_kwalk *w, bool ha, bool hb, int32_t ca, int32_t cb, float tb, float tbest, int32_t *ni)
{
    if (ha && hb) {
        if (w->sp < FV_KSTACK) {
            w->node[w->sp] = cb;
            w->t[w->sp] = tb;
            w->sp++;
        }
        *ni = ca;
        return true;
    }
    if (ha || hb) {
        *ni = ha ? ca : cb;
        return true;
    }
    while (w->sp > 0) {
        w->sp--;
        if (w->t[w->sp] <= tbest) {
            *ni = w->node[w->sp];
            return true;
        }
    }
    return false;
}

/* One bottom-level BVH from node `root` with the ray in its space. Closest hit into *b, or with
 * any, true at the first hit. */
FV_HD static inline bool fv_kblas(const fv_kscene *s, int root, fv_vec3 o, fv_vec3 d, bool any, fv_kbest *b)
{
    const fv_vec3 inv = fv_kinv_dir(d);
    fv_kwalk w;
    w.sp = 0;
    int32_t ni = root;
    for (;;) {
        bool ha, hb;
        int32_t ca, cb;
        float ta, tb;
        FV_SIMT_STEP(FV_SIMT_TRAVERSE);
        fv_knode_children(&s->nodes[ni], o, inv, b->t, &ha, &hb, &ca, &cb, &ta, &tb);
        if (ha && ca < 0) {
            if (fv_kleaf_tris(s, ca, o, d, any, b)) return true;
            ha = false;
        }
        if (hb && cb < 0) {
            if (fv_kleaf_tris(s, cb, o, d, any, b)) return true;
            hb = false;
        }
        if (!fv_kwalk_next(&w, ha, hb, ca, cb, tb, b->t, &ni)) return false;
    }
}

/* The ray in the object space of instance object ob (unchanged for a static one). */
FV_HD static inline void fv_kto_object(const fv_kobject *ob, fv_vec3 o, fv_vec3 d, fv_vec3 *oo, fv_vec3 *od)
{
    if (ob && ob->dynamic) {
        *oo = fv_xform_point(&ob->inv, o);
        *od = fv_xform_vector(&ob->inv, d);
    } else {
        *oo = o;
        *od = d;
    }
}

/* A top-level leaf: its instances. */
FV_HD static inline bool fv_kleaf_inst(const fv_kscene *s, int32_t c, fv_vec3 o, fv_vec3 d, bool any, fv_kbest *b)
{
    int first, count;
    fv_kleaf(c, &first, &count);
    for (int i = first; i < first + count; i++) {
        const fv_kinst *in = &s->inst[i];
        const fv_kobject *ob = in->obj >= 0 ? &s->objs[in->obj] : (const fv_kobject *)0;
        fv_vec3 oo, od;
        fv_kto_object(ob, o, d, &oo, &od);
        if (in->kind == FV_KINST_SDF) {
            float t;
            if (!fv_ksdf_trace(s, ob, oo, od, 0.0f, b->t, &t)) continue;
            if (any) return true;
            b->t = t;
            b->u = b->v = 0.0f;
            b->tri = -1;
            b->obj = in->obj;
        } else if (fv_kblas(s, in->root, oo, od, any, b)) {
            return true;
        }
    }
    return false;
}

/* The top level: closest hit into *b (b->t the limit), or with any, true at the first hit. */
FV_HD static inline bool fv_ktlas(const fv_kscene *s, fv_vec3 o, fv_vec3 d, bool any, fv_kbest *b)
{
    if (s->ntnodes <= 0) return false;
    const fv_vec3 inv = fv_kinv_dir(d);
    fv_kwalk w;
    w.sp = 0;
    int32_t ni = 0;
    for (;;) {
        bool ha, hb;
        int32_t ca, cb;
        float ta, tb;
        FV_SIMT_STEP(FV_SIMT_TRAVERSE);
        fv_knode_children(&s->tnodes[ni], o, inv, b->t, &ha, &hb, &ca, &cb, &ta, &tb);
        if (ha && ca < 0) {
            if (fv_kleaf_inst(s, ca, o, d, any, b)) return true;
            ha = false;
        }
        /* The closest hit may have moved nearer than the second box. */
        if (hb && cb < 0) {
            if (tb <= b->t && fv_kleaf_inst(s, cb, o, d, any, b)) return true;
            hb = false;
        }
        if (!fv_kwalk_next(&w, ha, hb, ca, cb, tb, b->t, &ni)) return false;
    }
}

/* Closest hit along o + t d, t in (0, tmax] (d need not be unit), over every object at the
 * snapshot's time; *hit as scene.c's fill_hit makes it. */
FV_HD static inline bool fv_kscene_intersect(const fv_kscene *s, fv_vec3 o, fv_vec3 d, float tmax, fv_hit *hit)
{
    fv_kbest b;
    b.t = tmax;
    b.u = b.v = 0.0f;
    b.tri = -1;
    b.obj = -1;
    fv_ktlas(s, o, d, false, &b);
    if (b.obj < 0) return false;

    const fv_kobject *ob = &s->objs[b.obj];
    fv_vec3 ng;
    int prim = 0;
    if (ob->is_sdf) {
        /* The gradient where the object-space ray meets the field (the Embree callback's normal);
         * at a crease's exact middle, where the differences cancel, it faces the ray. */
        fv_vec3 oo, od;
        fv_kto_object(ob, o, d, &oo, &od);
        const fv_sdf f = fv_ksdf_field(s, ob);
        ng = fv_ksdf_normal(&f, fv_madd(oo, od, b.t));
        if (!(fv_dot(ng, ng) > 0.0f)) ng = fv_neg(od);
    } else {
        const fv_ktri *tr = &s->ktris[b.tri];
        ng = fv_cross(fv_v3(tr->e1[0], tr->e1[1], tr->e1[2]), fv_v3(tr->e2[0], tr->e2[1], tr->e2[2]));
        prim = tr->prim;
    }
    /* From here statement for statement fill_hit. */
    if (ob->dynamic) ng = fv_xform_normal(&ob->inv, ng);
    hit->ng = fv_normalize(ng);
    hit->ns = hit->ng;
    hit->t = b.t;
    hit->p = fv_madd(o, d, b.t);
    hit->obj = b.obj;
    hit->u = b.u;
    hit->v = b.v;
    if (ob->is_sdf) {
        hit->prim = 0;
        hit->u = hit->v = 0.0f;
        const fv_sdf f = fv_ksdf_field(s, ob);
        int m = 0;
        fv_ksdf_distance(&f, ob->dynamic ? fv_xform_point(&ob->inv, hit->p) : hit->p, &m);
        hit->mat = m;
        return true;
    }
    int g = ob->first_tri + prim;
    hit->prim = prim;
    hit->mat = s->tri_mat[g];
    if (ob->nrm_off >= 0) {
        const uint32_t *ix = &s->tri_vtx[3 * g];
        const fv_vec3 *nv = s->nrm + ob->nrm_off - ob->vtx_off;
        fv_vec3 n = fv_add(fv_add(fv_scale(nv[ix[0]], 1.0f - b.u - b.v), fv_scale(nv[ix[1]], b.u)), fv_scale(nv[ix[2]], b.v));
        if (ob->dynamic) n = fv_xform_normal(&ob->inv, n);
        float len = fv_length(n);
        if (len > 1e-6f) hit->ns = fv_scale(n, 1.0f / len);
        if (fv_dot(hit->ns, hit->ng) < 0.0f) hit->ns = fv_neg(hit->ns);
    }
    return true;
}

/* Any hit along o + t d, t in (0, tmax]. */
FV_HD static inline bool fv_kscene_occluded(const fv_kscene *s, fv_vec3 o, fv_vec3 d, float tmax)
{
    fv_kbest b;
    b.t = tmax;
    b.u = b.v = 0.0f;
    b.tri = -1;
    b.obj = -1;
    return fv_ktlas(s, o, d, true, &b);
}

/* fv_offset_point: a point just off the surface on the side of direction d. */
FV_HD static inline fv_vec3 fv_kscene_offset_point(const fv_kscene *s, fv_vec3 p, fv_vec3 ng, fv_vec3 d)
{
    float e = s->eps;
    return fv_madd(p, ng, fv_dot(ng, d) >= 0.0f ? e : -e);
}

/* fv_scene_visible (all objects): nothing blocks surface point p (normal ng) from q, q excluded. */
FV_HD static inline bool fv_kscene_visible(const fv_kscene *s, fv_vec3 p, fv_vec3 ng, fv_vec3 q)
{
    fv_vec3 o = fv_kscene_offset_point(s, p, ng, fv_sub(q, p));
    fv_vec3 d = fv_sub(q, o);
    float len = fv_length(d);
    if (!(len > 2.0f * s->eps)) return true;
    return !fv_kscene_occluded(s, o, fv_scale(d, 1.0f / len), len - s->eps);
}

#endif
