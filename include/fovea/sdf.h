/* fovea — signed distance fields: a tree of primitives and operators, compiled for evaluation.
 *
 * The geometry of issue 11 (Polychronakis, Koulieris and Mania, "An Inverted Pyramid Acceleration
 * Structure Guiding Foveated Sphere Tracing for Implicit Surfaces in VR", EG 2023, Sec. 2.1 and
 * 3): sphere tracing steps along a ray by the distance the field returns, so every distance here
 * is a lower bound of the true distance to the surface (the field is 1-Lipschitz), never more.
 * docs/sdf.md gives the rules that keep each operator so.
 *
 * A field is described as a flat array of nodes (what a C caller or a scene loader fills) and one
 * root index. Primitives sit at the origin of their own frame; FV_SDF_TRANSFORM places them.
 * Parameters per kind (fields not listed are ignored but must still be finite):
 *
 *   SPHERE        p[0] radius > 0
 *   BOX           v[0] half extents, each > 0
 *   ROUND_BOX     v[0] half extents (of the rounded box) > 0, p[0] rounding radius, 0 < r <= min(v[0])
 *   TORUS         around the y axis: p[0] major radius > 0 (centre to tube centre), p[1] tube radius > 0
 *   CAPSULE       v[0], v[1] segment end points (may coincide), p[0] radius > 0
 *   CYLINDER      capped, along y: p[0] radius > 0, p[1] half height > 0
 *   CONE          capped, along y: p[0] radius at y = -h > 0, p[1] radius at y = +h >= 0 (0: a point),
 *                 p[2] half height h > 0
 *   PLANE         solid below dot(n, x) = h: v[0] normal n (unit within 1e-4), p[0] offset h
 *   HEIGHTFIELD   solid below y = p[0] + p[1] * fbm(p[2] * (x, z)): p[0] base height, p[1] amplitude >= 0,
 *                 p[2] frequency > 0, p[3] octaves (integer 1..8), p[4] seed (integer 0..2^24)
 *   UNION         a, b children: the nearer (a union of many children only evaluates those near the
 *                 point, with the same result: docs/sdf.md, "Unions of many shapes")
 *   SUBTRACT      a minus b
 *   INTERSECT     a and b
 *   SMOOTH_UNION  a, b children, p[0] blend width k > 0 (the surface grows by at most k/4)
 *   TRANSFORM     child a evaluated at S^-1 R^-1 (x - t): v[0] translation t, q rotation (unit within
 *                 1e-4), p[0] uniform scale > 0 (non-uniform scale would break the distance bound)
 *   REPEAT        child a repeated: v[0] period per axis (0: that axis is not repeated, else > 0),
 *                 v[1] per axis 0 (unlimited) or an integer n >= 1 (cells -n..n only); the child's
 *                 bounds must lie strictly inside one cell, [-period/2, period/2], on repeated axes
 *
 * Leaves carry `material` (>= 0, an index the caller interprets); an operator's material is its
 * nearer child's (UNION, SMOOTH_UNION), the child whose surface it is at that point (SUBTRACT:
 * b's where b cuts, INTERSECT: the farther child's).
 *
 * Bounds: the root must be bounded. A plane, a height field or an unlimited repetition is
 * unbounded; intersect it with a BOX (placed by a TRANSFORM) to bound it, which also clips the
 * surface there. fv_sdf_create refuses a tree whose root box is infinite or empty.
 *
 * Ownership: fv_sdf_create copies what it needs; the caller's nodes may be freed at once, the
 * handle is released with fv_sdf_destroy. Threads: evaluation (distance, normal, bounds) only
 * reads the handle, so any number of threads may evaluate one field at once.
 */
#ifndef FOVEA_SDF_H
#define FOVEA_SDF_H

#include "fovea/export.h"
#include "fovea/math.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum fv_sdf_kind {
    FV_SDF_SPHERE,
    FV_SDF_BOX,
    FV_SDF_ROUND_BOX,
    FV_SDF_TORUS,
    FV_SDF_CAPSULE,
    FV_SDF_CYLINDER,
    FV_SDF_CONE,
    FV_SDF_PLANE,
    FV_SDF_HEIGHTFIELD,
    FV_SDF_UNION,
    FV_SDF_SUBTRACT,
    FV_SDF_INTERSECT,
    FV_SDF_SMOOTH_UNION,
    FV_SDF_TRANSFORM,
    FV_SDF_REPEAT,
    FV_SDF_KIND_COUNT
} fv_sdf_kind;

typedef struct fv_sdf_node {
    fv_sdf_kind kind;
    float p[8];    /* scalar parameters, per kind above */
    fv_vec3 v[2];  /* vector parameters, per kind above */
    fv_quat q;     /* TRANSFORM's rotation; ignored (but must be finite) elsewhere */
    int a, b;      /* child node indices: a for TRANSFORM/REPEAT, a and b for the operators */
    int material;  /* leaves */
} fv_sdf_node;

/* Largest node count, and deepest nesting of the compiled tree (a node shared by several parents
 * is expanded once per use, so the compiled program may be longer than the node array). A chain
 * of UNIONs through child a (the left fold of a flat list, as the scene loader builds it) is one
 * n-ary union: its children are one level below it however many there are. */
#define FV_SDF_MAX_NODES 65536
#define FV_SDF_MAX_DEPTH 48

typedef struct fv_sdf fv_sdf;

/* Lower-case name of a kind ("sphere", "smooth_union", ...), or "unknown". */
FV_API const char *fv_sdf_kind_name(fv_sdf_kind kind);

/* Validates every node (also those the root does not reach) and compiles the tree under `root`.
 * FV_ERR_INVALID with a one-line message naming the node index and field: unknown kind, child out
 * of range or a cycle, a non-finite value, a size or radius <= 0, k <= 0, a non-unit quaternion or
 * normal, scale <= 0, a repeated child wider than its cell, an unbounded or empty root. */
FV_API fv_status fv_sdf_create(const fv_sdf_node *nodes, int count, int root, fv_sdf **out, fv_error *err);
FV_API void fv_sdf_destroy(fv_sdf *sdf);

/* A lower bound of the signed distance at p (negative inside); *material (may be NULL) gets the
 * material of the nearest leaf as the operators define it. */
FV_API float fv_sdf_distance(const fv_sdf *sdf, fv_vec3 p, int *material);

/* The unit gradient at p by central differences of step h (h <= 0: 1e-4 times the bounds'
 * diagonal); (0, 0, 0) where the differences cancel. */
FV_API fv_vec3 fv_sdf_normal(const fv_sdf *sdf, fv_vec3 p, float h);

/* A finite box holding the whole surface and the inside. */
FV_API void fv_sdf_bounds(const fv_sdf *sdf, fv_vec3 *lo, fv_vec3 *hi);

#ifdef __cplusplus
}
#endif
#endif
