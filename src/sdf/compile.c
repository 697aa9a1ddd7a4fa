/* fovea — validating an SDF node tree and compiling it into the evaluators' program
 * (include/fovea/sdf.h, sdf_impl.h; the field of Polychronakis et al. 2023, Sec. 2.1).
 *
 * Bounds are carried up the tree with a constant c in [0, 1] such that, outside the box B,
 * d(p) >= c dist(p, B). The box alone suffices for union, intersection and transforms; c is what
 * lets a smooth union grow its children's box by the amount its blend can move the surface
 * (k / (4c)) — a child known only to be a lower bound (c small, c = 0 for repetition) would need an
 * unbounded margin. The rules and their derivations are in docs/sdf.md.
 */
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "sdf/sdf_impl.h"

/* Program length cap: shared nodes are expanded per use, so a small DAG can ask for a lot. */
#define FV_SDF_MAX_OPS (1 << 20)

typedef struct box3 {
    float lo[3], hi[3];
    float c;    /* d >= c dist(p, box) outside the box */
    bool upper; /* d <= the distance to the box's farthest point (a surface lies in the box) */
    float mag;  /* magnitude of the coordinates and constants the node's evaluation works with */
} box3;

/* A union with at least this many children a box test can skip is compiled as a culled chain
 * (sdf_impl.h); smaller ones keep the plain fold, where the tests cost about what they save
 * (sdf-temple's union of six, four of them cullable, rendered 20% slower culled). */
#define FV_SDF_CULL_MIN 8

typedef struct compiler {
    const fv_sdf_node *nodes;
    int count;
    unsigned char *on_path; /* cycle detection */
    fv_sdf_op *ops;
    int n_ops, cap;
    fv_error *err;
    int max_ops; /* FV_SDF_MAX_OPS for a tree; a merge of compiled fields only adds their lengths */
} compiler;

static const char *const kind_names[FV_SDF_KIND_COUNT] = {
    "sphere", "box", "round_box", "torus", "capsule", "cylinder", "cone", "plane", "heightfield",
    "union", "subtract", "intersect", "smooth_union", "transform", "repeat"};

const char *fv_sdf_kind_name(fv_sdf_kind kind)
{
    return (int)kind >= 0 && kind < FV_SDF_KIND_COUNT ? kind_names[kind] : "unknown";
}

static const char axis_name[3] = {'x', 'y', 'z'};
static float v3_get(fv_vec3 v, int i) { return i == 0 ? v.x : (i == 1 ? v.y : v.z); }
static bool is_integer(float x) { return floorf(x) == x; }

/* ---- validation of one node ---- */

#define REFUSE(...) return fv_error_set(err, FV_ERR_INVALID, __VA_ARGS__)

static fv_status check_positive(int i, const char *kind, const char *field, float v, fv_error *err)
{
    if (!(v > 0.0f)) REFUSE("sdf node %d (%s): %s %g must be > 0", i, kind, field, v);
    return FV_OK;
}

static fv_status check_child(int i, const char *kind, char which, int child, int count, fv_error *err)
{
    if (child < 0 || child >= count)
        REFUSE("sdf node %d (%s): child %c = %d is not a node index (0..%d)", i, kind, which, child, count - 1);
    return FV_OK;
}

static fv_status check_node(const fv_sdf_node *nodes, int count, int i, fv_error *err)
{
    const fv_sdf_node *n = &nodes[i];
    if ((int)n->kind < 0 || n->kind >= FV_SDF_KIND_COUNT) REFUSE("sdf node %d: unknown kind %d", i, (int)n->kind);
    const char *kn = kind_names[n->kind];
    for (int k = 0; k < 8; k++)
        if (!isfinite(n->p[k])) REFUSE("sdf node %d (%s): p[%d] is not finite", i, kn, k);
    for (int k = 0; k < 2; k++)
        for (int a = 0; a < 3; a++)
            if (!isfinite(v3_get(n->v[k], a))) REFUSE("sdf node %d (%s): v[%d].%c is not finite", i, kn, k, axis_name[a]);
    const float qc[4] = {n->q.x, n->q.y, n->q.z, n->q.w};
    for (int k = 0; k < 4; k++)
        if (!isfinite(qc[k])) REFUSE("sdf node %d (%s): q.%c is not finite", i, kn, "xyzw"[k]);
    fv_status st = FV_OK;
    bool leaf = n->kind <= FV_SDF_HEIGHTFIELD;
    if (leaf && n->material < 0) REFUSE("sdf node %d (%s): material %d must be >= 0", i, kn, n->material);
    switch (n->kind) {
    case FV_SDF_SPHERE: return check_positive(i, kn, "p[0] radius", n->p[0], err);
    case FV_SDF_BOX:
    case FV_SDF_ROUND_BOX:
        for (int a = 0; a < 3 && st == FV_OK; a++) {
            if (!(v3_get(n->v[0], a) > 0.0f))
                REFUSE("sdf node %d (%s): v[0].%c half extent %g must be > 0", i, kn, axis_name[a], v3_get(n->v[0], a));
        }
        if (n->kind == FV_SDF_ROUND_BOX) {
            if ((st = check_positive(i, kn, "p[0] rounding radius", n->p[0], err))) return st;
            if (n->p[0] > fv_min3(n->v[0]))
                REFUSE("sdf node %d (%s): p[0] rounding radius %g exceeds the smallest half extent %g", i, kn, n->p[0],
                       fv_min3(n->v[0]));
        }
        return FV_OK;
    case FV_SDF_TORUS:
        if ((st = check_positive(i, kn, "p[0] major radius", n->p[0], err))) return st;
        return check_positive(i, kn, "p[1] tube radius", n->p[1], err);
    case FV_SDF_CAPSULE: return check_positive(i, kn, "p[0] radius", n->p[0], err);
    case FV_SDF_CYLINDER:
        if ((st = check_positive(i, kn, "p[0] radius", n->p[0], err))) return st;
        return check_positive(i, kn, "p[1] half height", n->p[1], err);
    case FV_SDF_CONE:
        if ((st = check_positive(i, kn, "p[0] bottom radius", n->p[0], err))) return st;
        if (n->p[1] < 0.0f) REFUSE("sdf node %d (%s): p[1] top radius %g must be >= 0", i, kn, n->p[1]);
        return check_positive(i, kn, "p[2] half height", n->p[2], err);
    case FV_SDF_PLANE:
        if (fabsf(fv_length(n->v[0]) - 1.0f) > 1e-4f)
            REFUSE("sdf node %d (%s): v[0] normal has length %g, not 1", i, kn, fv_length(n->v[0]));
        return FV_OK;
    case FV_SDF_HEIGHTFIELD:
        if (n->p[1] < 0.0f) REFUSE("sdf node %d (%s): p[1] amplitude %g must be >= 0", i, kn, n->p[1]);
        if ((st = check_positive(i, kn, "p[2] frequency", n->p[2], err))) return st;
        if (!is_integer(n->p[3]) || n->p[3] < 1.0f || n->p[3] > 8.0f)
            REFUSE("sdf node %d (%s): p[3] octaves %g must be an integer in 1..8", i, kn, n->p[3]);
        if (!is_integer(n->p[4]) || n->p[4] < 0.0f || n->p[4] > 16777216.0f)
            REFUSE("sdf node %d (%s): p[4] seed %g must be an integer in 0..16777216", i, kn, n->p[4]);
        return FV_OK;
    case FV_SDF_SMOOTH_UNION:
        if ((st = check_positive(i, kn, "p[0] k", n->p[0], err))) return st;
        /* fall through */
    case FV_SDF_UNION:
    case FV_SDF_SUBTRACT:
    case FV_SDF_INTERSECT:
        if ((st = check_child(i, kn, 'a', n->a, count, err))) return st;
        return check_child(i, kn, 'b', n->b, count, err);
    case FV_SDF_TRANSFORM: {
        float ql = sqrtf(qc[0] * qc[0] + qc[1] * qc[1] + qc[2] * qc[2] + qc[3] * qc[3]);
        if (fabsf(ql - 1.0f) > 1e-4f) REFUSE("sdf node %d (%s): q has length %g, not 1", i, kn, ql);
        if ((st = check_positive(i, kn, "p[0] scale", n->p[0], err))) return st;
        return check_child(i, kn, 'a', n->a, count, err);
    }
    case FV_SDF_REPEAT:
        for (int a = 0; a < 3; a++) {
            float c = v3_get(n->v[0], a), lim = v3_get(n->v[1], a);
            if (c < 0.0f) REFUSE("sdf node %d (%s): v[0].%c period %g must be >= 0", i, kn, axis_name[a], c);
            if (!is_integer(lim) || lim < 0.0f || lim > 1048576.0f)
                REFUSE("sdf node %d (%s): v[1].%c cell limit %g must be an integer in 0..1048576", i, kn, axis_name[a], lim);
            if (c == 0.0f && lim != 0.0f)
                REFUSE("sdf node %d (%s): v[1].%c cell limit %g on an axis with period 0", i, kn, axis_name[a], lim);
        }
        return check_child(i, kn, 'a', n->a, count, err);
    case FV_SDF_KIND_COUNT: break;
    }
    REFUSE("sdf node %d: unknown kind %d", i, (int)n->kind);
}

/* ---- bounds ---- */

/* A primitive's box: exact fields, so d >= dist(p, box) (c = 1) and d <= the farthest point's
 * distance (upper) whenever the box is finite. */
static box3 box_sym(float x, float y, float z)
{
    box3 b = {{-x, -y, -z}, {x, y, z}, 1.0f, isfinite(x) && isfinite(y) && isfinite(z), 0.0f};
    return b;
}

/* The largest finite coordinate of the box, at least m. */
static float box_mag(const box3 *b, float m)
{
    for (int k = 0; k < 3; k++) {
        if (isfinite(b->lo[k])) m = fmaxf(m, fabsf(b->lo[k]));
        if (isfinite(b->hi[k])) m = fmaxf(m, fabsf(b->hi[k]));
    }
    return m;
}

static box3 box_union(box3 a, box3 b)
{
    box3 r;
    for (int k = 0; k < 3; k++) {
        r.lo[k] = fminf(a.lo[k], b.lo[k]);
        r.hi[k] = fmaxf(a.hi[k], b.hi[k]);
    }
    r.c = fminf(a.c, b.c);
    /* min(a, b) <= the bounded child's value <= its farthest point's distance <= the union box's */
    r.upper = a.upper || b.upper;
    r.mag = fmaxf(a.mag, b.mag);
    return r;
}

static bool box_finite(const box3 *b)
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(b->lo[k]) || !isfinite(b->hi[k])) return false;
    return true;
}

/* ---- compilation ---- */

static fv_sdf_op *emit(compiler *cc, int code, int node)
{
    if (cc->n_ops >= cc->max_ops) {
        fv_error_set(cc->err, FV_ERR_INVALID,
                     "sdf node %d: the compiled tree exceeds %d instructions (shared nodes are expanded once per use)", node,
                     cc->max_ops);
        return NULL;
    }
    if (fv_grow((void **)&cc->ops, &cc->cap, cc->n_ops + 1, sizeof *cc->ops)) {
        fv_error_set(cc->err, FV_ERR_NOMEM, "sdf: out of memory compiling %d instructions", cc->n_ops + 1);
        return NULL;
    }
    fv_sdf_op *op = &cc->ops[cc->n_ops++];
    *op = (fv_sdf_op){0};
    op->code = code;
    return op;
}

#define EMIT(var, code)                                                                                                \
    do {                                                                                                               \
        if (!((var) = emit(cc, (code), i))) return cc->err->status;                                                     \
    } while (0)

static fv_status compile_node(compiler *cc, int i, int depth, box3 *out);

static fv_status compile_child(compiler *cc, int i, char which, int child, int depth, box3 *out)
{
    if (cc->on_path[child])
        return fv_error_set(cc->err, FV_ERR_INVALID, "sdf node %d (%s): child %c = %d forms a cycle", i,
                            kind_names[cc->nodes[i].kind], which, child);
    if (depth + 1 > FV_SDF_MAX_DEPTH)
        return fv_error_set(cc->err, FV_ERR_INVALID, "sdf node %d (%s): child %c = %d nests deeper than %d levels", i,
                            kind_names[cc->nodes[i].kind], which, child, FV_SDF_MAX_DEPTH);
    return compile_node(cc, child, depth + 1, out);
}

static fv_status compile_leaf(compiler *cc, int i, box3 *out)
{
    const fv_sdf_node *n = &cc->nodes[i];
    const float *p = n->p;
    fv_sdf_op *op;
    switch (n->kind) {
    case FV_SDF_SPHERE:
        EMIT(op, FV_OP_SPHERE);
        op->f[0] = p[0];
        *out = box_sym(p[0], p[0], p[0]);
        break;
    case FV_SDF_BOX:
        EMIT(op, FV_OP_BOX);
        op->f[0] = n->v[0].x, op->f[1] = n->v[0].y, op->f[2] = n->v[0].z;
        *out = box_sym(n->v[0].x, n->v[0].y, n->v[0].z);
        break;
    case FV_SDF_ROUND_BOX:
        EMIT(op, FV_OP_ROUND_BOX);
        op->f[0] = n->v[0].x - p[0], op->f[1] = n->v[0].y - p[0], op->f[2] = n->v[0].z - p[0];
        op->f[3] = p[0];
        *out = box_sym(n->v[0].x, n->v[0].y, n->v[0].z);
        break;
    case FV_SDF_TORUS:
        EMIT(op, FV_OP_TORUS);
        op->f[0] = p[0], op->f[1] = p[1];
        *out = box_sym(p[0] + p[1], p[1], p[0] + p[1]);
        break;
    case FV_SDF_CAPSULE: {
        EMIT(op, FV_OP_CAPSULE);
        fv_vec3 a = n->v[0], ba = fv_sub(n->v[1], n->v[0]);
        float l2 = fv_dot(ba, ba);
        op->f[0] = a.x, op->f[1] = a.y, op->f[2] = a.z;
        op->f[3] = ba.x, op->f[4] = ba.y, op->f[5] = ba.z;
        op->f[6] = l2 > 0.0f ? 1.0f / l2 : 0.0f;
        op->f[7] = p[0];
        fv_vec3 lo = fv_vmin(n->v[0], n->v[1]), hi = fv_vmax(n->v[0], n->v[1]);
        *out = (box3){{lo.x - p[0], lo.y - p[0], lo.z - p[0]}, {hi.x + p[0], hi.y + p[0], hi.z + p[0]}, 1.0f, true, 0.0f};
        break;
    }
    case FV_SDF_CYLINDER:
        EMIT(op, FV_OP_CYLINDER);
        op->f[0] = p[0], op->f[1] = p[1];
        *out = box_sym(p[0], p[1], p[0]);
        break;
    case FV_SDF_CONE: {
        EMIT(op, FV_OP_CONE);
        float er = p[1] - p[0], ey = 2.0f * p[2];
        op->f[0] = p[0], op->f[1] = p[1], op->f[2] = p[2];
        op->f[3] = er, op->f[4] = ey, op->f[5] = 1.0f / (er * er + ey * ey);
        float r = fmaxf(p[0], p[1]);
        *out = box_sym(r, p[2], r);
        break;
    }
    case FV_SDF_PLANE: {
        EMIT(op, FV_OP_PLANE);
        fv_vec3 nn = fv_normalize(n->v[0]);
        op->f[0] = nn.x, op->f[1] = nn.y, op->f[2] = nn.z, op->f[3] = p[0];
        *out = box_sym(INFINITY, INFINITY, INFINITY);
        /* An axis-aligned plane bounds one side: the solid n_k x_k <= h. */
        for (int k = 0; k < 3; k++) {
            float c = v3_get(nn, k);
            if (fabsf(c) == 1.0f && v3_get(nn, (k + 1) % 3) == 0.0f && v3_get(nn, (k + 2) % 3) == 0.0f) {
                if (c > 0.0f) out->hi[k] = p[0];
                else out->lo[k] = -p[0];
            }
        }
        break;
    }
    case FV_SDF_HEIGHTFIELD: {
        EMIT(op, FV_OP_HEIGHTFIELD);
        int oct = (int)p[3];
        float lh = (float)oct * p[1] * p[2] * 3.0f * sqrtf(2.0f);
        op->f[0] = p[0], op->f[1] = p[1], op->f[2] = p[2];
        op->f[3] = 1.0f / sqrtf(1.0f + lh * lh);
        op->ia = oct;
        op->ib = (int)p[4];
        /* The octaves' amplitudes sum to A (2 - 2^(1-o)) < 2A. */
        *out = box_sym(INFINITY, INFINITY, INFINITY);
        out->hi[1] = p[0] + p[1] * (2.0f - ldexpf(1.0f, 1 - oct));
        out->c = op->f[3];
        break;
    }
    default: return fv_error_set(cc->err, FV_ERR_INTERNAL, "sdf node %d: not a leaf", i);
    }
    op->material = n->material;
    float m = 0.0f;
    for (int k = 0; k < 13; k++) m = fmaxf(m, fabsf(op->f[k]));
    out->mag = box_mag(out, m);
    return FV_OK;
}

/* A CULL_DATA op from a child's box (sdf_impl.h); infinite sides become +-1e30, which the kernel's
 * box distance handles without inf - inf. */
static void cull_data(fv_sdf_op *op, const box3 *b)
{
    for (int k = 0; k < 3; k++) {
        op->f[k] = fmaxf(b->lo[k], -1e30f);
        op->f[3 + k] = fminf(b->hi[k], 1e30f);
    }
    op->f[6] = b->c;
    op->material = b->upper ? 1 : 0;
}

/* One child of a union, already compiled: its ops, the index its first op had when its own jump
 * and data indices (CULL, CULL_DATA) were written, and its box. */
typedef struct chain_part {
    const fv_sdf_op *ops;
    int count, origin;
    box3 box;
} chain_part;

/* Appends part p, moving its CULL jump targets and data indices to where it lands. */
static fv_status copy_part(compiler *cc, int node, const chain_part *p)
{
    int shift = cc->n_ops - p->origin;
    for (int j = 0; j < p->count; j++) {
        fv_sdf_op *op = emit(cc, p->ops[j].code, node);
        if (!op) return cc->err->status;
        *op = p->ops[j];
        if (op->code == FV_OP_CULL) op->ia += shift, op->ib += shift;
        if (op->code == FV_OP_CULL_DATA && op->ib > 0) op->ia += shift; /* a group's first member */
    }
    return FV_OK;
}

/* Whether a CULL can ever skip the child: c > 0 and a box that is not everywhere. */
static bool cullable(const box3 *b)
{
    if (!(b->c > 0.0f)) return false;
    for (int k = 0; k < 3; k++)
        if (isfinite(b->lo[k]) || isfinite(b->hi[k])) return true;
    return false;
}

/* Emits the union of n compiled children in their order. With fewer than FV_SDF_CULL_MIN children
 * a CULL could skip, the plain fold (c0 c1 UNION c2 UNION ...), which is what a recursive compile
 * gives. Otherwise a culled chain (sdf_impl.h): the same children and UNIONs in the same order,
 * the cullable ones in runs of consecutive children cut into groups of about sqrt(n), each child
 * and each group behind a CULL whose box lets the kernel jump past it (kernel.h shows why the
 * result stays the same); a child no CULL could skip (a repetition: c = 0) stands between groups
 * without one, so it costs no box test and does not widen a group's box. */
static fv_status emit_parts(compiler *cc, int node, const chain_part *parts, int n, box3 *out)
{
    fv_status st;
    box3 acc = parts[0].box;
    for (int k = 1; k < n; k++) acc = box_union(acc, parts[k].box);
    *out = acc;
    int ncull = 0;
    for (int k = 0; k < n; k++) ncull += cullable(&parts[k].box);
    if (ncull < FV_SDF_CULL_MIN) {
        for (int k = 0; k < n; k++) {
            if ((st = copy_part(cc, node, &parts[k]))) return st;
            if (k > 0 && !emit(cc, FV_OP_UNION, node)) return cc->err->status;
        }
        return FV_OK;
    }
    /* groups: runs of at most gsize consecutive cullable children */
    int gsize = (int)ceil(sqrt((double)ncull)), ng = 0;
    for (int k = 0, run = 0; k < n; k++) {
        if (!cullable(&parts[k].box)) {
            run = 0;
            continue;
        }
        if (run == 0) ng++;
        run = run + 1 == gsize ? 0 : run + 1;
    }
    fv_sdf_op *op;
    if (!(op = emit(cc, FV_OP_CULL_BEGIN, node))) return cc->err->status;
    op->ia = ng;
    op->ib = ng + ncull;
    op->f[0] = acc.mag;
    int data = cc->n_ops, g = -1, m = 0, gcull = -1;
    for (int k = 0; k < ng + ncull; k++)
        if (!emit(cc, FV_OP_CULL_DATA, node)) return cc->err->status;
    box3 gb;
    memset(&gb, 0, sizeof gb);
    for (int k = 0, run = 0; k <= n; k++) {
        bool cull = k < n && cullable(&parts[k].box);
        if (gcull >= 0 && (!cull || run == 0)) { /* close the open group */
            cc->ops[gcull].ia = cc->n_ops;       /* ops may have moved: indices, not pointers */
            fv_sdf_op *gd = &cc->ops[data + g];
            cull_data(gd, &gb);
            gd->ib = m - (gd->ia - data - ng); /* > 0: marks a group's data (copy_part moves ia) */
            gcull = -1;
        }
        if (k == n) break;
        if (!cull) {
            run = 0;
            if ((st = copy_part(cc, node, &parts[k]))) return st;
            if (!emit(cc, FV_OP_UNION, node)) return cc->err->status;
            continue;
        }
        if (run == 0) { /* open a group */
            g++;
            gcull = cc->n_ops;
            if (!(op = emit(cc, FV_OP_CULL, node))) return cc->err->status;
            op->ib = data + g;
            cc->ops[data + g].ia = data + ng + m;
            gb = parts[k].box;
        } else {
            gb = box_union(gb, parts[k].box);
        }
        run = run + 1 == gsize ? 0 : run + 1;
        int mcull = cc->n_ops;
        if (!(op = emit(cc, FV_OP_CULL, node))) return cc->err->status;
        op->ib = data + ng + m;
        if ((st = copy_part(cc, node, &parts[k]))) return st;
        if (!emit(cc, FV_OP_UNION, node)) return cc->err->status;
        cc->ops[mcull].ia = cc->n_ops;
        cull_data(&cc->ops[data + ng + m], &parts[k].box);
        m++;
    }
    if (!emit(cc, FV_OP_CULL_END, node)) return cc->err->status;
    return FV_OK;
}

/* Compiles the n children child(cc, ctx, k, box) one after another, then lays them out as a union
 * (emit_parts): which layout pays is known only once their boxes are. */
typedef fv_status (*chain_child_fn)(compiler *cc, void *ctx, int k, box3 *out);

static fv_status emit_chain(compiler *cc, int node, int n, chain_child_fn child, void *ctx, box3 *out)
{
    int base = cc->n_ops;
    chain_part *parts = fv_calloc_array((size_t)n, sizeof *parts);
    if (!parts) return fv_error_set(cc->err, FV_ERR_NOMEM, "sdf: out of memory compiling a union of %d children", n);
    fv_status st = FV_OK;
    for (int k = 0; k < n && st == FV_OK; k++) {
        parts[k].origin = cc->n_ops;
        st = child(cc, ctx, k, &parts[k].box);
        parts[k].count = cc->n_ops - parts[k].origin;
    }
    fv_sdf_op *held = NULL;
    if (st == FV_OK) {
        held = fv_alloc_array((size_t)(cc->n_ops - base > 0 ? cc->n_ops - base : 1), sizeof *held);
        if (!held) st = fv_error_set(cc->err, FV_ERR_NOMEM, "sdf: out of memory compiling a union of %d children", n);
    }
    if (st == FV_OK) {
        memcpy(held, cc->ops + base, (size_t)(cc->n_ops - base) * sizeof *held);
        for (int k = 0; k < n; k++) parts[k].ops = held + (parts[k].origin - base);
        cc->n_ops = base;
        st = emit_parts(cc, node, parts, n, out);
    }
    free(held);
    free(parts);
    return st;
}

/* The children of a chain of UNION nodes, for emit_chain. */
typedef struct union_chain {
    const int *chain;
    int len, depth;
} union_chain;

static fv_status union_child(compiler *cc, void *ctx, int k, box3 *out)
{
    const union_chain *u = ctx;
    int holder = u->chain[u->len - (k == 0 ? 1 : k)];
    const fv_sdf_node *h = &cc->nodes[holder];
    return compile_child(cc, holder, k == 0 ? 'a' : 'b', k == 0 ? h->a : h->b, u->depth, out);
}

/* A UNION node and every UNION below it through child a: the left fold u(u(c0, c1), c2) ... of a
 * flat list, which is how the scene loader builds a "union" of many children. Its children (c0, the
 * last node's a, then each node's b from the bottom up) are one level below the chain however long
 * it is: a flat list is not nesting, so only the children count towards FV_SDF_MAX_DEPTH. */
static fv_status compile_union(compiler *cc, int i, int depth, box3 *out)
{
    int *chain = NULL, len = 0, cap = 0;
    fv_status st = FV_OK;
    for (int u = i;;) {
        if (fv_grow((void **)&chain, &cap, len + 1, sizeof *chain)) {
            st = fv_error_set(cc->err, FV_ERR_NOMEM, "sdf: out of memory compiling node %d (union)", i);
            break;
        }
        chain[len++] = u;
        cc->on_path[u] = 1;
        int a = cc->nodes[u].a;
        if (cc->nodes[a].kind != FV_SDF_UNION) break;
        if (cc->on_path[a]) {
            st = fv_error_set(cc->err, FV_ERR_INVALID, "sdf node %d (union): child a = %d forms a cycle", u, a);
            break;
        }
        u = a;
    }
    if (st == FV_OK) {
        union_chain u = {chain, len, depth};
        st = emit_chain(cc, i, len + 1, union_child, &u, out);
    }
    if (st == FV_OK)
        for (int k = 0; k < len; k++) cc->on_path[chain[k]] = 0;
    free(chain);
    return st;
}

static fv_status compile_node(compiler *cc, int i, int depth, box3 *out)
{
    const fv_sdf_node *n = &cc->nodes[i];
    const char *kn = kind_names[n->kind];
    if (n->kind <= FV_SDF_HEIGHTFIELD) return compile_leaf(cc, i, out);
    if (n->kind == FV_SDF_UNION) return compile_union(cc, i, depth, out);
    fv_status st;
    fv_sdf_op *op;
    box3 ba, bb;
    cc->on_path[i] = 1;
    switch (n->kind) {
    case FV_SDF_UNION:
    case FV_SDF_SUBTRACT:
    case FV_SDF_INTERSECT:
    case FV_SDF_SMOOTH_UNION: {
        if ((st = compile_child(cc, i, 'a', n->a, depth, &ba))) return st;
        if ((st = compile_child(cc, i, 'b', n->b, depth, &bb))) return st;
        static const int code[] = {FV_OP_UNION, FV_OP_SUBTRACT, FV_OP_INTERSECT, FV_OP_SMOOTH_UNION};
        EMIT(op, code[n->kind - FV_SDF_UNION]);
        if (n->kind == FV_SDF_UNION) {
            *out = box_union(ba, bb);
        } else if (n->kind == FV_SDF_SUBTRACT) {
            *out = ba; /* max(a, -b) >= a */
            out->upper = false; /* b may remove all of a */
            out->mag = fmaxf(ba.mag, bb.mag);
        } else if (n->kind == FV_SDF_INTERSECT) {
            out->upper = false; /* the intersection may be empty */
            out->mag = fmaxf(ba.mag, bb.mag);
            for (int k = 0; k < 3; k++) {
                out->lo[k] = fmaxf(ba.lo[k], bb.lo[k]);
                out->hi[k] = fminf(ba.hi[k], bb.hi[k]);
                if (out->lo[k] > out->hi[k])
                    return fv_error_set(cc->err, FV_ERR_INVALID,
                                        "sdf node %d (%s): children %d and %d do not overlap on %c, the result is empty",
                                        i, kn, n->a, n->b, axis_name[k]);
            }
            /* dist to the intersection of boxes <= sqrt(2) x the larger distance to either. */
            out->c = fminf(ba.c, bb.c) / sqrtf(2.0f);
        } else {
            op->f[0] = n->p[0];
            op->f[1] = 1.0f / n->p[0];
            *out = box_union(ba, bb);
            /* The blend lowers min(a, b) by at most k/4; outside the box grown by k/(4c) it stays
             * positive, and d >= (c / sqrt(3)) dist to the grown box (docs/sdf.md). */
            float c = out->c, grow = c > 0.0f ? n->p[0] / (4.0f * c) : INFINITY;
            for (int k = 0; k < 3; k++) {
                out->lo[k] -= grow;
                out->hi[k] += grow;
            }
            out->c = c / sqrtf(3.0f);
            out->mag += n->p[0]; /* the result stays below min(a, b): upper is kept */
        }
        break;
    }
    case FV_SDF_TRANSFORM: {
        EMIT(op, FV_OP_XFORM_PUSH);
        int at = cc->n_ops - 1; /* ops may move when the child grows the program */
        float ql = sqrtf(n->q.x * n->q.x + n->q.y * n->q.y + n->q.z * n->q.z + n->q.w * n->q.w);
        fv_quat q = {n->q.x / ql, n->q.y / ql, n->q.z / ql, n->q.w / ql};
        fv_xform m = fv_xform_trs(fv_v3s(0.0f), q, fv_v3s(1.0f));
        float s = n->p[0];
        if ((st = compile_child(cc, i, 'a', n->a, depth, &ba))) return st;
        op = &cc->ops[at];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) op->f[3 * r + c] = m.m[c][r]; /* R^T: the inverse rotation */
        op->f[9] = n->v[0].x, op->f[10] = n->v[0].y, op->f[11] = n->v[0].z;
        op->f[12] = 1.0f / s;
        EMIT(op, FV_OP_XFORM_POP);
        op->f[0] = s;
        /* Interval arithmetic of t + s R [lo, hi]; zero entries skipped so 0 x inf never appears. */
        for (int r = 0; r < 3; r++) {
            float lo = 0.0f, hi = 0.0f;
            for (int c = 0; c < 3; c++) {
                float e = m.m[r][c] * s;
                if (e == 0.0f) continue;
                float u = e * ba.lo[c], w = e * ba.hi[c];
                lo += fminf(u, w);
                hi += fmaxf(u, w);
            }
            out->lo[r] = v3_get(n->v[0], r) + lo;
            out->hi[r] = v3_get(n->v[0], r) + hi;
        }
        out->c = ba.c;
        /* s d(R^-1 (x - t) / s) is the distance of the moved surface, which stays in the moved box */
        out->upper = ba.upper;
        out->mag = box_mag(out, fmaxf(fabsf(n->v[0].x), fmaxf(fabsf(n->v[0].y), fabsf(n->v[0].z))) + s * ba.mag);
        break;
    }
    case FV_SDF_REPEAT: {
        EMIT(op, FV_OP_REPEAT_PUSH);
        int at = cc->n_ops - 1;
        if ((st = compile_child(cc, i, 'a', n->a, depth, &ba))) return st;
        op = &cc->ops[at];
        float margin = INFINITY;
        *out = ba;
        out->c = 0.0f; /* only a lower bound between copies (kernel.h) */
        out->upper = false;
        for (int k = 0; k < 3; k++) {
            float c = v3_get(n->v[0], k), lim = v3_get(n->v[1], k);
            op->f[k] = c;
            op->f[3 + k] = c > 0.0f ? 1.0f / c : 0.0f;
            op->f[6 + k] = lim;
            if (c == 0.0f) continue;
            float ext = fmaxf(fabsf(ba.lo[k]), fabsf(ba.hi[k]));
            if (!(ext < 0.5f * c))
                return fv_error_set(cc->err, FV_ERR_INVALID,
                                    "sdf node %d (%s): child %d reaches %g from the origin on %c, not inside the cell "
                                    "half period %g of v[0].%c",
                                    i, kn, n->a, ext, axis_name[k], 0.5f * c, axis_name[k]);
            margin = fminf(margin, 0.5f * c - ext);
            out->lo[k] = lim > 0.0f ? ba.lo[k] - lim * c : -INFINITY;
            out->hi[k] = lim > 0.0f ? ba.hi[k] + lim * c : INFINITY;
        }
        out->mag = box_mag(out, ba.mag);
        EMIT(op, FV_OP_REPEAT_POP);
        op->f[0] = isfinite(margin) ? margin : 0.0f;
        for (int k = 0; k < 3; k++) {
            op->f[1 + k] = fmaxf(out->lo[k], -1e30f);
            op->f[4 + k] = fminf(out->hi[k], 1e30f);
        }
        break;
    }
    default: return fv_error_set(cc->err, FV_ERR_INTERNAL, "sdf node %d: unexpected kind", i);
    }
    cc->on_path[i] = 0;
    return FV_OK;
}

/* The end of a compile: on success the program and its bounds go into s, *out = s; on failure
 * both are freed and st returned. */
static fv_status finish(compiler *cc, fv_sdf *s, const box3 *b, fv_status st, fv_sdf **out)
{
    if (st != FV_OK) {
        free(cc->ops);
        free(s);
        return st;
    }
    s->ops = cc->ops;
    s->count = cc->n_ops;
    s->lo = fv_v3(b->lo[0], b->lo[1], b->lo[2]);
    s->hi = fv_v3(b->hi[0], b->hi[1], b->hi[2]);
    s->c = b->c;
    s->upper = b->upper ? 1 : 0;
    s->mag = b->mag;
    s->normal_h = 1e-4f * fv_length(fv_sub(s->hi, s->lo));
    if (!(s->normal_h > 0.0f)) s->normal_h = 1e-6f;
    *out = s;
    return FV_OK;
}

fv_status fv_sdf_create(const fv_sdf_node *nodes, int count, int root, fv_sdf **out, fv_error *err)
{
    fv_error_clear(err);
    if (!out) return fv_error_set(err, FV_ERR_INVALID, "fv_sdf_create: out is NULL");
    *out = NULL;
    if (!nodes || count < 1 || count > FV_SDF_MAX_NODES)
        REFUSE("sdf: %d nodes (need 1..%d and a node array)", nodes ? count : 0, FV_SDF_MAX_NODES);
    if (root < 0 || root >= count) REFUSE("sdf: root %d is not a node index (0..%d)", root, count - 1);
    fv_status st;
    for (int i = 0; i < count; i++)
        if ((st = check_node(nodes, count, i, err))) return st;
    compiler cc = {nodes, count, fv_calloc_array((size_t)count, 1), NULL, 0, 0, err, FV_SDF_MAX_OPS};
    fv_error local;
    if (!err) cc.err = &local;
    fv_sdf *s = calloc(1, sizeof *s);
    if (!cc.on_path || !s) {
        free(cc.on_path);
        free(s);
        return fv_error_set(err, FV_ERR_NOMEM, "sdf: out of memory for %d nodes", count);
    }
    box3 b;
    st = compile_node(&cc, root, 0, &b);
    free(cc.on_path);
    if (st == FV_OK && !box_finite(&b))
        st = fv_error_set(err, FV_ERR_INVALID,
                          "sdf: root %d (%s) is unbounded; intersect planes, height fields and repetitions with a box",
                          root, kind_names[nodes[root].kind]);
    return finish(&cc, s, &b, st, out);
}

void fv_sdf_destroy(fv_sdf *sdf)
{
    if (!sdf) return;
    free(sdf->ops);
    free(sdf);
}

void fv_sdf_bounds(const fv_sdf *sdf, fv_vec3 *lo, fv_vec3 *hi)
{
    if (lo) *lo = sdf->lo;
    if (hi) *hi = sdf->hi;
}

/* ---- the union of compiled fields (sdf_eval.h) ---- */

fv_status fv_sdf_union_create(const fv_sdf *const *parts, int n, fv_sdf **out, fv_error *err)
{
    fv_error_clear(err);
    if (!out) return fv_error_set(err, FV_ERR_INVALID, "fv_sdf_union_create: out is NULL");
    *out = NULL;
    if (!parts || n < 1) REFUSE("sdf union: %d fields (need at least 1)", n);
    fv_error local;
    compiler cc = {NULL, 0, NULL, NULL, 0, 0, err ? err : &local, INT_MAX / 2};
    fv_sdf *s = calloc(1, sizeof *s);
    if (!s) return fv_error_set(err, FV_ERR_NOMEM, "sdf union: out of memory");
    chain_part *cp = fv_calloc_array((size_t)n, sizeof *cp);
    if (!cp) {
        free(s);
        return fv_error_set(err, FV_ERR_NOMEM, "sdf union: out of memory");
    }
    for (int k = 0; k < n; k++) {
        const fv_sdf *p = parts[k];
        cp[k].ops = p->ops;
        cp[k].count = p->count;
        cp[k].origin = 0; /* a compiled field's indices count from its first op */
        const float lo[3] = {p->lo.x, p->lo.y, p->lo.z}, hi[3] = {p->hi.x, p->hi.y, p->hi.z};
        for (int a = 0; a < 3; a++) cp[k].box.lo[a] = lo[a], cp[k].box.hi[a] = hi[a];
        cp[k].box.c = p->c;
        cp[k].box.upper = p->upper != 0;
        cp[k].box.mag = p->mag;
    }
    box3 b;
    fv_status st = emit_parts(&cc, 0, cp, n, &b);
    free(cp);
    return finish(&cc, s, &b, st, out);
}

float fv_sdf_bound_c(const fv_sdf *sdf) { return sdf->c; }
