/* fovea — a committed scene as a kernel sees it: flat, index-based arrays and a two-level BVH,
 * the same on the CPU (host memory, scene/flat_export.c builds it) and on a GPU (device memory after
 * a CUDA backend copies it field by field). Plain data, no functions; traversal is
 * kernel/ktraverse.h.
 *
 * Every pointer comes with the count that gives its length (the comment beside it names the
 * count and the element type), so a backend can deep-copy the struct without knowing the scene.
 * Indices, never pointers, link the arrays, so the copy needs no fix-ups.
 *
 * BVH layout (why): a binary BVH whose node holds BOTH children's boxes and indices (fv_knode,
 * 64 bytes = four 16-byte loads, one cache line). One node fetch tests two boxes, the traversal
 * descends into the nearer child and pushes the farther one, and no node is fetched only to learn
 * that its box is missed. A child index >= 0 is an inner node; < 0 is a leaf, ~c = first * 8 +
 * count, naming `count` (0..7, 0: empty) consecutive entries of the leaf's primitive array: ktris
 * for the bottom level (triangles pre-transformed to v0, e1, e2, 48 bytes, so a leaf's
 * triangles are read in order without gathering vertices), inst for the top level.
 * Measured (tests/unit/test_traverse.c, binned SAH, leaves of at most 4): city, 180,906
 * triangles: 90,423 nodes (5.8 MB), 90,424 leaves (about 2 triangles each), depth 24, 20.4 MB
 * for the whole snapshot, built in 90-160 ms on 2 cores; cornell: 32 triangles, 16 nodes, 17
 * leaves. On one CPU core this loop traces about a third as many rays as Embree's SIMD BVH
 * (0.7 vs 2.3 Mrays/s in city); it is written for one ray per GPU thread.
 *
 * Two levels: bottom-level BVHs over object-space triangles in `nodes` (the static meshes' BVH
 * first, then one per dynamic mesh, each never rebuilt), and a small top-level BVH `tnodes` over
 * the instances (the static BVH with identity, each dynamic mesh at its current transform, each
 * SDF object as one leaf instance whose box is its field's padded box), rebuilt when time moves.
 */
#ifndef FV_KERNEL_KSCENE_H
#define FV_KERNEL_KSCENE_H

#include <stdint.h>
#include "fovea/math.h"
#include "fovea/scene.h"
#include "kernel/klight.h"
#include "kernel/ktexture.h"
#include "sdf/program.h"

/* Depth bound of every BVH (the exporter refuses a deeper one): the traversal stack's size. */
#define FV_KSTACK 64
/* Most primitives in one leaf the child encoding can name (3 bits of count). */
#define FV_KLEAF_MAX 7

/* A BVH2 node: child 0's box (l0, h0) and index c0, child 1's (l1, h1) and c1. */
typedef struct fv_knode {
    float l0[3];
    int32_t c0;
    float h0[3];
    int32_t c1;
    float l1[3];
    int32_t pad0;
    float h1[3];
    int32_t pad1;
} fv_knode;

/* A triangle as the ray test reads it, in its object's space: v0, e1 = v1 - v0, e2 = v2 - v0,
 * with the object and its triangle index (fv_hit.obj, fv_hit.prim) in the spare lanes. */
typedef struct fv_ktri {
    float v0[3];
    int32_t obj;
    float e1[3];
    int32_t prim;
    float e2[3];
    int32_t pad;
} fv_ktri;

/* The kinds of top-level instance. */
enum { FV_KINST_STATIC = 0, FV_KINST_DYNAMIC = 1, FV_KINST_SDF = 2 };

/* A top-level leaf entry. The ray is moved into object space by objs[obj].inv when the object is
 * dynamic (a static instance's space is the world's). */
typedef struct fv_kinst {
    int32_t kind; /* FV_KINST_* */
    int32_t obj;  /* the object (dynamic mesh, SDF); -1 for the static meshes' BVH */
    int32_t root; /* meshes: the BVH's root in nodes[]; SDF: -1 */
    int32_t pad;
} fv_kinst;

/* One object of the scene, index = fv_hit.obj = the scene's object index. */
typedef struct fv_kobject {
    int32_t first_tri, ntri; /* its triangles: [first_tri, first_tri + ntri) of tri_vtx/tri_mat/tri_light */
    int32_t vtx_off, nvtx;   /* its vertices: [vtx_off, vtx_off + nvtx) of vtx */
    int32_t nrm_off;         /* its vertex normals: vertex g's is nrm[nrm_off + g - vtx_off]; -1: none */
    int32_t uv_off;          /* its UVs: vertex g's is uv[uv_off + g - vtx_off]; -1: none */
    int32_t dynamic;         /* 1: moves (xf, inv follow the scene's time) */
    int32_t is_sdf;          /* 1: a signed distance field (ntri = nvtx = 0) */
    int32_t sdf_first, sdf_count; /* its compiled program: [sdf_first, sdf_first + sdf_count) of sdf_ops */
    float sdf_eps;           /* sphere tracing's hit distance (fv_object.sdf_eps) */
    float sdf_normal_h;      /* the normal's central-difference step (fv_sdf.normal_h) */
    int32_t root;            /* dynamic mesh: its BVH's root in nodes[]; -1 otherwise */
    int32_t pad;
    fv_xform xf, inv;        /* object -> world at the snapshot's time, and its inverse */
    fv_vec3 lo, hi;          /* object-space bounds (an SDF's field bounds, unpadded) */
} fv_kobject;

typedef struct fv_kscene {
    const fv_vec3 *vtx;      /* nvtx fv_vec3: object-space vertex positions of every mesh object */
    int nvtx;
    const fv_vec3 *nrm;      /* nnrm fv_vec3: unit vertex normals of the objects that have them (or 0) */
    int nnrm;
    const fv_vec2 *uv;       /* nuv fv_vec2: texture coordinates of the objects that have them */
    int nuv;
    const uint32_t *tri_vtx; /* ntri_vtx = 3 ntri uint32_t: each triangle's three global vertex indices */
    int ntri_vtx;
    const int32_t *tri_mat;  /* ntri int32_t: material id per global triangle (first_tri + prim) */
    const int32_t *tri_light;/* ntri int32_t: index in the scene's light table, -1: not emissive */
    int ntri;
    const fv_kobject *objs;  /* nobj fv_kobject: per object */
    int nobj;
    const fv_sdf_op *sdf_ops;/* nsdf_ops fv_sdf_op: every SDF object's compiled program, one after another */
    int nsdf_ops;
    const fv_knode *nodes;   /* nnodes fv_knode: the bottom-level BVHs (static meshes from node 0) */
    int nnodes;
    const fv_ktri *ktris;    /* nktris fv_ktri: triangles in leaf order (nktris = ntri) */
    int nktris;
    const fv_kinst *inst;    /* ninst fv_kinst: top-level instances in leaf order */
    int ninst;
    const fv_knode *tnodes;  /* ntnodes fv_knode: the top-level BVH, root tnodes[0]; 0 nodes: empty scene */
    int ntnodes;
    const fv_material *mats; /* nmat fv_material: the scene's materials (its own array, not a copy) */
    int nmat;
    fv_klights lights;       /* the light table (kernel/klight.h): light[n], cdf[n + 1], the environment */
    const fv_ktexture *tex;  /* ntex fv_ktexture: texture id i is tex[i - 1]; each one's rgb holds 3 w h floats */
    int ntex;
    float eps;               /* the scene's ray offset (fv_scene_ray_eps) */
    double time;             /* the scene time the snapshot stands at */
} fv_kscene;

#endif
