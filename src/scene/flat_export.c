/* fovea — the host side of the kernel scene (scene/flat_export.h): flattens a committed fv_scene into
 * the index-based arrays of kernel/kscene.h and builds its BVHs with Embree's generic builder
 * (rtcBuildBVH: binned SAH, our callbacks allocate the nodes from its thread-local allocator),
 * then copies each tree into the GPU-friendly fv_knode layout kernel/kscene.h describes.
 *
 * Why Embree's builder and our own layout: the builder is fast, multi-threaded and well tested;
 * the layout is what a portable traversal wants (two child boxes per 64-byte node, leaves as
 * ranges of pre-transformed triangles, indices instead of pointers so a GPU copy needs no
 * fix-ups). Measured sizes and build times are in the test's output and the issue report.
 */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <embree3/rtcore.h>
#include <embree3/rtcore_builder.h>
#include "core/alloc.h"
#include "fovea/stats.h"
#include "kernel/ksdf_trace.h"
#include "scene/flat_export.h"
#include "scene/scene_impl.h"

/* Bottom-level leaves: at most four triangles (short leaves suit one-ray-per-thread GPU
 * traversal; the encoding allows FV_KLEAF_MAX). Top-level leaves: one instance each. */
#define LEAF_TRIS 4
#define LEAF_INST 1

struct fv_scene_export {
    fv_kscene k;
    fv_vec3 *vtx, *nrm;
    fv_vec2 *uv;
    uint32_t *tri_vtx;
    int32_t *tri_mat, *tri_light;
    fv_kobject *objs;
    fv_sdf_op *sdf_ops;
    fv_knode *nodes;
    int capnodes;
    fv_ktri *ktris;
    fv_kinst *inst_src;   /* the instances in a fixed order (static BVH, dynamic meshes, SDFs) */
    fv_vec3 *ilo, *ihi;   /* their world boxes at the snapshot's time */
    fv_kinst *inst;       /* the same in the top level's leaf order */
    fv_knode *tnodes;
    int ninst, ntnodes;
    RTCDevice dev;        /* the scene's Embree device (the builder runs on its threads) */
    bool has_dynamic;
    int *tri_obj;         /* while creating: each global triangle's object */
    fv_ktexture *tex;     /* the scene's textures as kernels read them (texels are the scene's) */
    fv_scene_export_stats stats;
};

/* ---- the builder's nodes (temporary, in the RTCBVH's memory) ---- */

typedef struct bnode {
    int leaf;             /* 0: inner, 1: leaf */
    int n;                /* leaf: primitives; inner: children */
    void *c[2];
    struct RTCBounds b[2];
    unsigned prim[];      /* leaf: primitive ids */
} bnode;

static void *cb_create_node(RTCThreadLocalAllocator a, unsigned count, void *user)
{
    (void)user;
    bnode *n = rtcThreadLocalAlloc(a, sizeof *n, 16);
    if (!n) return NULL;
    memset(n, 0, sizeof *n);
    n->n = (int)(count < 2 ? count : 2);
    return n;
}

static void cb_set_children(void *node, void **children, unsigned count, void *user)
{
    (void)user;
    bnode *n = node;
    for (unsigned i = 0; i < 2; i++) n->c[i] = i < count ? children[i] : NULL;
}

static void cb_set_bounds(void *node, const struct RTCBounds **bounds, unsigned count, void *user)
{
    (void)user;
    bnode *n = node;
    for (unsigned i = 0; i < 2 && i < count; i++) n->b[i] = *bounds[i];
}

static void *cb_create_leaf(RTCThreadLocalAllocator a, const struct RTCBuildPrimitive *prims, size_t count, void *user)
{
    (void)user;
    bnode *n = rtcThreadLocalAlloc(a, sizeof *n + count * sizeof(unsigned), 16);
    if (!n) return NULL;
    memset(n, 0, sizeof *n);
    n->leaf = 1;
    n->n = (int)count;
    for (size_t i = 0; i < count; i++) n->prim[i] = prims[i].primID;
    return n;
}

/* ---- flattening into fv_knode ---- */

typedef struct flat {
    fv_knode *nodes;      /* where this tree's nodes go; nodes[0] is its root */
    int base;             /* the absolute index of nodes[0] (child indices are absolute) */
    int nnode;
    unsigned *order;      /* primitive ids in leaf order */
    int norder;
    int first;            /* the absolute index of order[0] in the leaf array */
    int leaves, max_depth;
    bool bad;             /* a leaf too long to encode, or a missing node */
} flat;

static void count_tree(const bnode *n, int depth, int *inner, int *leaves, int *max_depth)
{
    if (!n) return;
    if (n->leaf) {
        (*leaves)++;
        if (depth > *max_depth) *max_depth = depth;
        return;
    }
    (*inner)++;
    count_tree(n->c[0], depth + 1, inner, leaves, max_depth);
    count_tree(n->c[1], depth + 1, inner, leaves, max_depth);
}

static void set_box(fv_knode *k, int i, const struct RTCBounds *b)
{
    float *lo = i ? k->l1 : k->l0, *hi = i ? k->h1 : k->h0;
    lo[0] = b->lower_x;
    lo[1] = b->lower_y;
    lo[2] = b->lower_z;
    hi[0] = b->upper_x;
    hi[1] = b->upper_y;
    hi[2] = b->upper_z;
}

/* The child code of builder node n: a leaf's range, or the index of its copied node. */
static int32_t flatten(flat *f, const bnode *n, int depth)
{
    if (!n) return ~0; /* an empty leaf */
    if (n->leaf) {
        if (n->n > FV_KLEAF_MAX) {
            f->bad = true;
            return ~0;
        }
        uint32_t code = (uint32_t)(f->first + f->norder) * 8u + (uint32_t)n->n;
        for (int i = 0; i < n->n; i++) f->order[f->norder++] = n->prim[i];
        f->leaves++;
        if (depth > f->max_depth) f->max_depth = depth;
        return (int32_t)~code;
    }
    int idx = f->nnode++;
    set_box(&f->nodes[idx], 0, &n->b[0]);
    set_box(&f->nodes[idx], 1, &n->b[1]);
    f->nodes[idx].pad0 = f->nodes[idx].pad1 = 0;
    int32_t c0 = flatten(f, n->c[0], depth + 1);
    int32_t c1 = flatten(f, n->c[1], depth + 1);
    f->nodes[idx].c0 = c0;
    f->nodes[idx].c1 = c1;
    return f->base + idx;
}

/* Builds a BVH over prims[0..n) (reordered by the builder) and copies it to f->nodes (room for
 * max(1, inner nodes) needed: see count_tree) and f->order; root box `root_box` for a tree that
 * is a single leaf. *nodes_out: how many nodes were written. */
typedef struct build_in {
    struct RTCBuildPrimitive *prims;
    size_t n;
    unsigned leaf_size;
} build_in;

static fv_status embree_fail(RTCDevice dev, const char *what, fv_error *err)
{
    enum RTCError e = rtcGetDeviceError(dev);
    if (e == RTC_ERROR_OUT_OF_MEMORY) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building the %s BVH", what);
    return fv_error_set(err, FV_ERR_INTERNAL, "Embree's builder failed on the %s BVH (error %d)", what, (int)e);
}

/* Runs the builder; *bvh must be released by the caller, *root is in its memory. */
static fv_status run_builder(RTCDevice dev, const build_in *in, const char *what, RTCBVH *bvh, const bnode **root, fv_error *err)
{
    *bvh = rtcNewBVH(dev);
    if (!*bvh) return embree_fail(dev, what, err);
    struct RTCBuildArguments a = rtcDefaultBuildArguments();
    a.buildQuality = RTC_BUILD_QUALITY_MEDIUM; /* binned SAH, no spatial splits */
    a.maxBranchingFactor = 2;
    a.maxDepth = FV_KSTACK - 4;
    a.sahBlockSize = 1;
    a.minLeafSize = 1;
    a.maxLeafSize = in->leaf_size;
    a.traversalCost = 1.0f;
    a.intersectionCost = 1.0f;
    a.bvh = *bvh;
    a.primitives = in->prims;
    a.primitiveCount = in->n;
    a.primitiveArrayCapacity = in->n;
    a.createNode = cb_create_node;
    a.setNodeChildren = cb_set_children;
    a.setNodeBounds = cb_set_bounds;
    a.createLeaf = cb_create_leaf;
    *root = rtcBuildBVH(&a);
    if (!*root) return embree_fail(dev, what, err);
    return FV_OK;
}

static struct RTCBuildPrimitive *prims_alloc(size_t n)
{
    if (n > SIZE_MAX / sizeof(struct RTCBuildPrimitive) / 2) return NULL;
    /* The builder wants 32-byte aligned primitives (RTC_ALIGN(32)). */
    return aligned_alloc(32, (n ? n : 1) * sizeof(struct RTCBuildPrimitive));
}

static void prim_set(struct RTCBuildPrimitive *p, fv_vec3 lo, fv_vec3 hi, unsigned id)
{
    p->lower_x = lo.x;
    p->lower_y = lo.y;
    p->lower_z = lo.z;
    p->upper_x = hi.x;
    p->upper_y = hi.y;
    p->upper_z = hi.z;
    p->geomID = 0;
    p->primID = id;
}

/* A one-leaf tree gets a root node of its own (traversal always starts at a node): the leaf and
 * an empty second child. */
static void root_leaf_node(fv_knode *k, int32_t leaf, fv_vec3 lo, fv_vec3 hi)
{
    memset(k, 0, sizeof *k);
    struct RTCBounds b = {lo.x, lo.y, lo.z, 0.0f, hi.x, hi.y, hi.z, 0.0f};
    set_box(k, 0, &b);
    k->c0 = leaf;
    k->c1 = ~0;
}

/* ---- the bottom level ---- */

static void tri_box(const fv_scene_export *x, int g, fv_vec3 *lo, fv_vec3 *hi)
{
    const uint32_t *ix = &x->tri_vtx[3 * g];
    fv_vec3 a = x->vtx[ix[0]], b = x->vtx[ix[1]], c = x->vtx[ix[2]];
    *lo = fv_vmin(a, fv_vmin(b, c));
    *hi = fv_vmax(a, fv_vmax(b, c));
}

/* The BVH over triangles tris[0..n) (global ids), their leaf entries from ktris[first]; its root
 * node index in *root. */
static fv_status build_bottom(fv_scene_export *x, const int *tris, int n, int first, const char *what, int *root, fv_error *err)
{
    struct RTCBuildPrimitive *prims = prims_alloc((size_t)n);
    unsigned *order = fv_alloc_array((size_t)n, sizeof(unsigned));
    fv_status st = FV_OK;
    RTCBVH bvh = NULL;
    if (!prims || !order) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory building the %s BVH (%d triangles)", what, n);
        goto done;
    }
    fv_vec3 blo = fv_v3s(FLT_MAX), bhi = fv_v3s(-FLT_MAX);
    for (int i = 0; i < n; i++) {
        fv_vec3 lo, hi;
        tri_box(x, tris[i], &lo, &hi);
        prim_set(&prims[i], lo, hi, (unsigned)tris[i]);
        blo = fv_vmin(blo, lo);
        bhi = fv_vmax(bhi, hi);
    }
    build_in in = {prims, (size_t)n, LEAF_TRIS};
    const bnode *r = NULL;
    if ((st = run_builder(x->dev, &in, what, &bvh, &r, err)) != FV_OK) goto done;
    int inner = 0, leaves = 0, depth = 0;
    count_tree(r, 1, &inner, &leaves, &depth);
    if (depth > FV_KSTACK) {
        st = fv_error_set(err, FV_ERR_INTERNAL, "the %s BVH is %d levels deep, more than the traversal's %d", what, depth, FV_KSTACK);
        goto done;
    }
    int need = x->k.nnodes + (inner > 0 ? inner : 1);
    if (fv_grow((void **)&x->nodes, &x->capnodes, need, sizeof *x->nodes)) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory building the %s BVH (%d nodes)", what, inner);
        goto done;
    }
    flat f = {x->nodes + x->k.nnodes, x->k.nnodes, 0, order, 0, first, 0, 0, false};
    if (r->leaf) {
        int32_t leaf = flatten(&f, r, 1);
        root_leaf_node(&f.nodes[0], leaf, blo, bhi);
        f.nnode = 1;
    } else {
        flatten(&f, r, 1);
    }
    if (f.bad || f.norder != n) {
        st = fv_error_set(err, FV_ERR_INTERNAL, "the %s BVH came back malformed from Embree's builder", what);
        goto done;
    }
    *root = x->k.nnodes;
    x->k.nnodes += f.nnode;
    x->stats.nodes += f.nnode;
    x->stats.leaves += f.leaves;
    if (f.max_depth > x->stats.max_depth) x->stats.max_depth = f.max_depth;
    /* The leaf entries: triangles pre-transformed for the ray test. */
    for (int i = 0; i < n; i++) {
        int g = (int)order[i];
        const uint32_t *ix = &x->tri_vtx[3 * g];
        fv_vec3 a = x->vtx[ix[0]], e1 = fv_sub(x->vtx[ix[1]], a), e2 = fv_sub(x->vtx[ix[2]], a);
        fv_ktri *t = &x->ktris[first + i];
        t->v0[0] = a.x, t->v0[1] = a.y, t->v0[2] = a.z;
        t->e1[0] = e1.x, t->e1[1] = e1.y, t->e1[2] = e1.z;
        t->e2[0] = e2.x, t->e2[1] = e2.y, t->e2[2] = e2.z;
        int o = x->tri_obj[g];
        t->obj = o;
        t->prim = g - x->objs[o].first_tri;
        t->pad = 0;
    }
done:
    if (bvh) rtcReleaseBVH(bvh);
    free(prims);
    free(order);
    return st;
}

/* ---- the top level ---- */

static void box_xform(const fv_xform *m, fv_vec3 lo, fv_vec3 hi, fv_vec3 *olo, fv_vec3 *ohi)
{
    *olo = fv_v3s(FLT_MAX);
    *ohi = fv_v3s(-FLT_MAX);
    for (int c = 0; c < 8; c++) {
        fv_vec3 p = fv_xform_point(m, fv_v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z));
        *olo = fv_vmin(*olo, p);
        *ohi = fv_vmax(*ohi, p);
    }
}

/* The union of a node's two boxes: a bottom BVH's bounds from its root. */
static void node_bounds(const fv_knode *k, fv_vec3 *lo, fv_vec3 *hi)
{
    *lo = fv_v3(k->l0[0], k->l0[1], k->l0[2]);
    *hi = fv_v3(k->h0[0], k->h0[1], k->h0[2]);
    if (k->c1 != ~0) {
        *lo = fv_vmin(*lo, fv_v3(k->l1[0], k->l1[1], k->l1[2]));
        *hi = fv_vmax(*hi, fv_v3(k->h1[0], k->h1[1], k->h1[2]));
    }
}

/* Instance boxes at the objects' current transforms, then the top-level BVH over them. */
static fv_status build_top(fv_scene_export *x, fv_error *err)
{
    x->k.ntnodes = 0;
    if (x->ninst == 0) return FV_OK;
    fv_vec3 blo = fv_v3s(FLT_MAX), bhi = fv_v3s(-FLT_MAX);
    for (int i = 0; i < x->ninst; i++) {
        const fv_kinst *in = &x->inst_src[i];
        const fv_kobject *ob = in->obj >= 0 ? &x->objs[in->obj] : NULL;
        fv_vec3 lo, hi;
        if (in->kind == FV_KINST_SDF) fv_ksdf_padded_box(ob, &lo, &hi);
        else node_bounds(&x->nodes[in->root], &lo, &hi);
        if (ob && ob->dynamic) box_xform(&ob->xf, lo, hi, &lo, &hi);
        x->ilo[i] = lo;
        x->ihi[i] = hi;
        blo = fv_vmin(blo, lo);
        bhi = fv_vmax(bhi, hi);
    }
    struct RTCBuildPrimitive *prims = prims_alloc((size_t)x->ninst);
    unsigned *order = fv_alloc_array((size_t)x->ninst, sizeof(unsigned));
    fv_status st = FV_OK;
    RTCBVH bvh = NULL;
    if (!prims || !order) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory building the top-level BVH (%d instances)", x->ninst);
        goto done;
    }
    for (int i = 0; i < x->ninst; i++) prim_set(&prims[i], x->ilo[i], x->ihi[i], (unsigned)i);
    build_in in = {prims, (size_t)x->ninst, LEAF_INST};
    const bnode *r = NULL;
    if ((st = run_builder(x->dev, &in, "top-level", &bvh, &r, err)) != FV_OK) goto done;
    int inner = 0, leaves = 0, depth = 0;
    count_tree(r, 1, &inner, &leaves, &depth);
    if (depth > FV_KSTACK || inner > x->ninst) { /* room: ninst nodes, at least one */
        st = fv_error_set(err, FV_ERR_INTERNAL, "the top-level BVH came back malformed from Embree's builder");
        goto done;
    }
    flat f = {x->tnodes, 0, 0, order, 0, 0, 0, 0, false};
    if (r->leaf) {
        int32_t leaf = flatten(&f, r, 1);
        root_leaf_node(&f.nodes[0], leaf, blo, bhi);
        f.nnode = 1;
    } else {
        flatten(&f, r, 1);
    }
    if (f.bad || f.norder != x->ninst) {
        st = fv_error_set(err, FV_ERR_INTERNAL, "the top-level BVH came back malformed from Embree's builder");
        goto done;
    }
    for (int i = 0; i < x->ninst; i++) x->inst[i] = x->inst_src[order[i]];
    x->k.ntnodes = f.nnode;
    x->stats.tnodes = f.nnode;
done:
    if (bvh) rtcReleaseBVH(bvh);
    free(prims);
    free(order);
    return st;
}

/* ---- create, update, destroy ---- */

static void copy_xforms(fv_scene_export *x, const fv_scene *s)
{
    for (int i = 0; i < s->nobj; i++) {
        x->objs[i].xf = s->objs[i].xf;
        x->objs[i].inv = s->objs[i].inv;
    }
}

static size_t export_bytes(const fv_scene_export *x)
{
    const fv_kscene *k = &x->k;
    return (size_t)k->nvtx * sizeof(fv_vec3) + (size_t)k->nnrm * sizeof(fv_vec3) + (size_t)k->nuv * sizeof(fv_vec2) +
           (size_t)k->ntri_vtx * sizeof(uint32_t) + (size_t)k->ntri * 2 * sizeof(int32_t) + (size_t)k->nobj * sizeof(fv_kobject) +
           (size_t)k->nsdf_ops * sizeof(fv_sdf_op) + (size_t)k->nnodes * sizeof(fv_knode) + (size_t)k->nktris * sizeof(fv_ktri) +
           (size_t)x->ninst * sizeof(fv_kinst) + (size_t)(x->ninst > 0 ? x->ninst : 1) * sizeof(fv_knode);
}

/* The arrays of the meshes, objects and fields, before any BVH. */
static fv_status copy_arrays(fv_scene_export *x, const fv_scene *s, fv_error *err)
{
    long long nv = 0, nn = 0, nu = 0, nt = 0, nops = 0;
    for (int i = 0; i < s->nobj; i++) {
        const fv_object *o = &s->objs[i];
        if (o->sdf) {
            nops += o->sdf->count;
            continue;
        }
        nv += o->nv;
        nt += o->nt;
        if (o->nrm) nn += o->nv;
        if (o->uv) nu += o->nv;
    }
    /* Leaf codes hold first * 8 + count in 31 bits. */
    if (nt >= (1ll << 28) || nv > INT32_MAX || nops > INT32_MAX)
        return fv_error_set(err, FV_ERR_INVALID, "scene too large to export: %lld triangles (at most %lld)", nt, (1ll << 28) - 1);
    x->vtx = fv_alloc_array((size_t)nv, sizeof *x->vtx);
    x->nrm = fv_alloc_array((size_t)nn, sizeof *x->nrm);
    x->uv = fv_alloc_array((size_t)nu, sizeof *x->uv);
    x->tri_vtx = fv_alloc_array((size_t)nt, 3 * sizeof *x->tri_vtx);
    x->tri_mat = fv_alloc_array((size_t)nt, sizeof *x->tri_mat);
    x->tri_light = fv_alloc_array((size_t)nt, sizeof *x->tri_light);
    x->ktris = fv_alloc_array((size_t)nt, sizeof *x->ktris);
    x->objs = fv_calloc_array((size_t)s->nobj, sizeof *x->objs);
    x->sdf_ops = fv_alloc_array((size_t)nops, sizeof *x->sdf_ops);
    if (!x->vtx || !x->nrm || !x->uv || !x->tri_vtx || !x->tri_mat || !x->tri_light || !x->ktris || !x->objs || !x->sdf_ops)
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory exporting the scene (%lld triangles)", nt);
    int v = 0, n = 0, u = 0, t = 0, op = 0;
    for (int i = 0; i < s->nobj; i++) {
        const fv_object *o = &s->objs[i];
        fv_kobject *k = &x->objs[i];
        k->first_tri = t;
        k->vtx_off = v;
        k->nrm_off = k->uv_off = -1;
        k->dynamic = o->dynamic;
        k->is_sdf = o->sdf != NULL;
        k->sdf_first = op;
        k->root = -1;
        k->xf = o->xf;
        k->inv = o->inv;
        k->lo = o->lo;
        k->hi = o->hi;
        if (o->sdf) {
            k->sdf_count = o->sdf->count;
            k->sdf_eps = o->sdf_eps;
            k->sdf_normal_h = o->sdf->normal_h;
            memcpy(x->sdf_ops + op, o->sdf->ops, (size_t)o->sdf->count * sizeof *x->sdf_ops);
            op += o->sdf->count;
            continue;
        }
        k->ntri = o->nt;
        k->nvtx = o->nv;
        memcpy(x->vtx + v, o->pos, (size_t)o->nv * sizeof *x->vtx);
        if (o->nrm) {
            k->nrm_off = n;
            memcpy(x->nrm + n, o->nrm, (size_t)o->nv * sizeof *x->nrm);
            n += o->nv;
        }
        if (o->uv) {
            k->uv_off = u;
            memcpy(x->uv + u, o->uv, (size_t)o->nv * sizeof *x->uv);
            u += o->nv;
        }
        for (int j = 0; j < o->nt; j++) {
            for (int c = 0; c < 3; c++) x->tri_vtx[3 * (t + j) + c] = (uint32_t)v + o->idx[3 * j + c];
            x->tri_mat[t + j] = o->mat[j];
            x->tri_light[t + j] = s->tri_light && s->tri_light[i] ? s->tri_light[i][j] : -1;
        }
        v += o->nv;
        t += o->nt;
    }
    fv_kscene *k = &x->k;
    k->vtx = x->vtx, k->nvtx = v;
    k->nrm = x->nrm, k->nnrm = n;
    k->uv = x->uv, k->nuv = u;
    k->tri_vtx = x->tri_vtx, k->ntri_vtx = 3 * t;
    k->tri_mat = x->tri_mat, k->tri_light = x->tri_light, k->ntri = t;
    k->objs = x->objs, k->nobj = s->nobj;
    k->sdf_ops = x->sdf_ops, k->nsdf_ops = op;
    k->ktris = x->ktris, k->nktris = t;
    k->mats = s->mats, k->nmat = s->nmat;
    /* The light table is the scene's own: set_time moves its delta lights in place. */
    k->lights = s->klights;
    if (s->ntex > 0) {
        if (!(x->tex = fv_calloc_array((size_t)s->ntex, sizeof *x->tex))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory exporting the scene");
        for (int i = 0; i < s->ntex; i++) {
            x->tex[i].w = s->tex[i].w;
            x->tex[i].h = s->tex[i].h;
            x->tex[i].rgb = s->tex[i].rgb;
        }
    }
    k->tex = x->tex, k->ntex = s->ntex;
    k->lights.tex = x->tex, k->lights.ntex = s->ntex; /* emission textures, read by light samples */
    k->eps = s->eps;
    k->time = s->time;
    return FV_OK;
}

fv_status fv_scene_export_create(const fv_scene *s, fv_scene_export **out, fv_error *err)
{
    *out = NULL;
    if (!s || !s->committed) return fv_error_set(err, FV_ERR_INVALID, "cannot export a scene that is not committed");
    double t0 = fv_time_ms();
    fv_scene_export *x = calloc(1, sizeof *x);
    if (!x) return fv_error_set(err, FV_ERR_NOMEM, "out of memory exporting the scene");
    x->dev = s->dev;
    fv_status st = copy_arrays(x, s, err);
    int *tris = NULL;
    if (st != FV_OK) goto fail;

    /* The instances: the static meshes' BVH, each dynamic mesh, each field. */
    int nstatic = 0;
    x->ninst = 0;
    for (int i = 0; i < s->nobj; i++) {
        if (s->objs[i].sdf || s->objs[i].dynamic) x->ninst++;
        else nstatic += s->objs[i].nt;
        if (s->objs[i].dynamic) x->has_dynamic = true;
    }
    if (nstatic > 0) x->ninst++;
    x->inst_src = fv_alloc_array((size_t)x->ninst, sizeof *x->inst_src);
    x->inst = fv_alloc_array((size_t)x->ninst, sizeof *x->inst);
    x->ilo = fv_alloc_array((size_t)x->ninst, sizeof *x->ilo);
    x->ihi = fv_alloc_array((size_t)x->ninst, sizeof *x->ihi);
    x->tnodes = fv_calloc_array((size_t)(x->ninst > 0 ? x->ninst : 1), sizeof *x->tnodes);
    tris = fv_alloc_array((size_t)x->k.ntri, sizeof *tris);
    x->tri_obj = fv_alloc_array((size_t)x->k.ntri, sizeof *x->tri_obj);
    if (!x->inst_src || !x->inst || !x->ilo || !x->ihi || !x->tnodes || !tris || !x->tri_obj) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory exporting the scene (%d instances)", x->ninst);
        goto fail;
    }
    for (int i = 0; i < s->nobj; i++)
        for (int j = 0; j < x->objs[i].ntri; j++) x->tri_obj[x->objs[i].first_tri + j] = i;

    /* Leaf entries: the static triangles first, then each dynamic mesh's. */
    int ni = 0, first = 0;
    if (nstatic > 0) {
        int n = 0;
        for (int i = 0; i < s->nobj; i++) {
            const fv_kobject *k = &x->objs[i];
            if (k->is_sdf || k->dynamic) continue;
            for (int j = 0; j < k->ntri; j++) tris[n++] = k->first_tri + j;
        }
        int root;
        if ((st = build_bottom(x, tris, n, first, "static", &root, err)) != FV_OK) goto fail;
        fv_kinst in = {FV_KINST_STATIC, -1, root, 0};
        x->inst_src[ni++] = in;
        first += n;
    }
    for (int i = 0; i < s->nobj; i++) {
        fv_kobject *k = &x->objs[i];
        if (k->is_sdf) {
            fv_kinst in = {FV_KINST_SDF, i, -1, 0};
            x->inst_src[ni++] = in;
            continue;
        }
        if (!k->dynamic) continue;
        for (int j = 0; j < k->ntri; j++) tris[j] = k->first_tri + j;
        char what[FV_NAME_MAX + 16];
        snprintf(what, sizeof what, "object '%s'", s->objs[i].name);
        if ((st = build_bottom(x, tris, k->ntri, first, what, &k->root, err)) != FV_OK) goto fail;
        fv_kinst in = {FV_KINST_DYNAMIC, i, k->root, 0};
        x->inst_src[ni++] = in;
        first += k->ntri;
    }
    free(tris);
    tris = NULL;
    free(x->tri_obj);
    x->tri_obj = NULL;
    x->k.nodes = x->nodes;
    if ((st = build_top(x, err)) != FV_OK) goto fail;
    x->k.inst = x->inst;
    x->k.ninst = x->ninst;
    x->k.tnodes = x->tnodes;
    x->stats.triangles = x->k.ntri;
    x->stats.instances = x->ninst;
    x->stats.bytes = export_bytes(x);
    x->stats.build_ms = fv_time_ms() - t0;
    *out = x;
    return FV_OK;
fail:
    free(tris);
    fv_scene_export_destroy(x);
    return st;
}

fv_status fv_scene_export_update(fv_scene_export *x, const fv_scene *s, fv_error *err)
{
    if (!s->committed || s->nobj != x->k.nobj) return fv_error_set(err, FV_ERR_INVALID, "export update: not the scene it was made from");
    if (s->time == x->k.time) return FV_OK;
    x->k.time = s->time;
    if (!x->has_dynamic) return FV_OK; /* nothing moves: the snapshot stands for every time */
    double t0 = fv_time_ms();
    copy_xforms(x, s);
    fv_status st = build_top(x, err);
    x->stats.update_ms = fv_time_ms() - t0;
    return st;
}

const fv_kscene *fv_scene_export_view(const fv_scene_export *x) { return &x->k; }

void fv_scene_export_stats_get(const fv_scene_export *x, fv_scene_export_stats *out) { *out = x->stats; }

void fv_scene_export_destroy(fv_scene_export *x)
{
    if (!x) return;
    free(x->tex);
    free(x->vtx);
    free(x->nrm);
    free(x->uv);
    free(x->tri_vtx);
    free(x->tri_mat);
    free(x->tri_light);
    free(x->objs);
    free(x->sdf_ops);
    free(x->nodes);
    free(x->ktris);
    free(x->inst_src);
    free(x->ilo);
    free(x->ihi);
    free(x->inst);
    free(x->tnodes);
    free(x->tri_obj);
    free(x);
}
