/* SDF scenes of many shapes (issue 29, item 4; src/sdf/compile.c, kernel.h, technique/sdf/world.c).
 *
 * A union of many children is compiled as a culled chain: children whose box proves they cannot be
 * the nearest are skipped. These tests check that the skipping changes nothing and that a flat list
 * is not nesting:
 *  - a union of 150 mixed children (rotated, scaled, smooth unions, subtractions, an intersection
 *    with a plane, a limited repetition, nested unions of ten) gives at 12 000 points, far and near,
 *    exactly the fold of its children's own fields (value and material bit for bit), through the
 *    scalar evaluator, both eight-lane builds and the kernel's (kernel/ksdf_trace.h);
 *  - fv_sdf_union_create (how the SDF world merges its static objects) gives the same fold, also
 *    when a part holds a culled chain of its own (its jumps are relocated);
 *  - a union of 200 spheres returns the exact distance min |p - c| - r (within float rounding) and
 *    never more; the mixed union is 1-Lipschitz between nearby points;
 *  - 200 children in one flat union compile, a real nesting 49 deep is refused, and so is a cycle;
 *  - the 81-shape grid of scripts/gen-sdf-grid in three layouts (one flat union, a union of row
 *    unions, one object per shape) renders the same pixels with sdf-gt and ipr;
 *  - the SDF family's world of 44 static and 8 moving objects (turned, scaled, one non-uniformly)
 *    gives, with its static union and its skipped moving objects, the numbers of the plain loop
 *    over every object, scalar and 8-wide.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "core/rng.h"
#include "kernel/ksdf_trace.h"
#include "sdf/sdf_eval.h"
#include "technique/sdf/world.h"
#include "testkit.h"

/* ---- building trees ---- */

typedef struct tree {
    fv_sdf_node *n;
    int count, cap;
} tree;

static int add(tree *t, fv_sdf_node n)
{
    if (t->count == t->cap) {
        t->cap = t->cap ? 2 * t->cap : 64;
        t->n = realloc(t->n, (size_t)t->cap * sizeof *t->n);
        assert_non_null(t->n);
    }
    t->n[t->count] = n;
    return t->count++;
}

static fv_sdf_node node(fv_sdf_kind k, int mat)
{
    fv_sdf_node n;
    memset(&n, 0, sizeof n);
    n.kind = k;
    n.q.w = 1.0f;
    n.a = n.b = -1;
    n.material = mat;
    return n;
}

static int op2(tree *t, fv_sdf_kind k, int a, int b)
{
    fv_sdf_node n = node(k, 0);
    n.a = a;
    n.b = b;
    return add(t, n);
}

static int placed(tree *t, int child, fv_vec3 at, fv_quat q, float s)
{
    fv_sdf_node n = node(FV_SDF_TRANSFORM, 0);
    n.a = child;
    n.v[0] = at;
    n.q = q;
    n.p[0] = s;
    return add(t, n);
}

static float uni(fv_rng *r, float lo, float hi) { return lo + (hi - lo) * fv_rng_next(r); }

static fv_quat random_rotation(fv_rng *r)
{
    float x = uni(r, -1, 1), y = uni(r, -1, 1), z = uni(r, -1, 1), w = uni(r, -1, 1);
    float l = sqrtf(x * x + y * y + z * z + w * w);
    if (!(l > 0.1f)) return (fv_quat){0, 0, 0, 1};
    return (fv_quat){x / l, y / l, z / l, w / l};
}

/* One primitive of kind k % 7 at the origin, about unit size, material mat. */
static int primitive(tree *t, int k, int mat)
{
    fv_sdf_node n;
    switch (k % 7) {
    case 0: n = node(FV_SDF_SPHERE, mat), n.p[0] = 0.7f; break;
    case 1: n = node(FV_SDF_BOX, mat), n.v[0] = fv_v3(0.5f, 0.3f, 0.7f); break;
    case 2: n = node(FV_SDF_ROUND_BOX, mat), n.v[0] = fv_v3(0.6f, 0.4f, 0.4f), n.p[0] = 0.1f; break;
    case 3: n = node(FV_SDF_TORUS, mat), n.p[0] = 0.5f, n.p[1] = 0.2f; break;
    case 4: n = node(FV_SDF_CAPSULE, mat), n.v[0] = fv_v3(-0.5f, 0, 0), n.v[1] = fv_v3(0.4f, 0.3f, 0), n.p[0] = 0.25f; break;
    case 5: n = node(FV_SDF_CYLINDER, mat), n.p[0] = 0.4f, n.p[1] = 0.6f; break;
    default: n = node(FV_SDF_CONE, mat), n.p[0] = 0.6f, n.p[1] = 0.1f, n.p[2] = 0.6f; break;
    }
    return add(t, n);
}

/* Child k of the mixed union: mostly placed primitives, with every operator the culling must
 * respect (smooth union: its blend widens the box; subtract and intersect: no farthest-point bound;
 * repetition: c = 0; a plane: an unbounded part; a nested union: a culled chain inside a child). */
static int mixed_child(tree *t, fv_rng *r, int k)
{
    int mat = k + 1, c;
    switch (k % 9) {
    case 3: c = op2(t, FV_SDF_SMOOTH_UNION, primitive(t, k, mat), placed(t, primitive(t, k + 1, mat + 1000), fv_v3(0.6f, 0.2f, 0), (fv_quat){0, 0, 0, 1}, 1.0f));
        t->n[c].p[0] = 0.4f;
        break;
    case 5: {
        fv_sdf_node s = node(FV_SDF_SPHERE, mat + 2000);
        s.p[0] = 0.45f;
        c = op2(t, FV_SDF_SUBTRACT, primitive(t, 1, mat), placed(t, add(t, s), fv_v3(0.3f, 0.3f, 0.3f), (fv_quat){0, 0, 0, 1}, 1.0f));
        break;
    }
    case 6: {
        fv_sdf_node p = node(FV_SDF_PLANE, mat);
        p.v[0] = fv_v3(0, 0.6f, 0.8f);
        p.p[0] = 0.1f;
        c = op2(t, FV_SDF_INTERSECT, add(t, p), primitive(t, 1, mat + 3000));
        break;
    }
    case 7: {
        fv_sdf_node s = node(FV_SDF_SPHERE, mat), rp = node(FV_SDF_REPEAT, 0);
        s.p[0] = 0.15f;
        rp.a = add(t, s);
        rp.v[0] = fv_v3(0.5f, 0, 0.5f);
        rp.v[1] = fv_v3(2, 0, 1);
        c = add(t, rp);
        break;
    }
    case 8: { /* a union of ten inside: its own culled chain */
        c = placed(t, primitive(t, 0, mat), fv_v3(-1, 0, 0), (fv_quat){0, 0, 0, 1}, 0.5f);
        for (int j = 1; j < 10; j++) c = op2(t, FV_SDF_UNION, c, placed(t, primitive(t, j, mat + 100 * j), fv_v3(-1.0f + 0.25f * j, 0, 0), (fv_quat){0, 0, 0, 1}, 0.5f));
        break;
    }
    default: c = primitive(t, k, mat);
    }
    return placed(t, c, fv_v3(uni(r, -12, 12), uni(r, -3, 3), uni(r, -12, 12)), random_rotation(r), uni(r, 0.5f, 2.0f));
}

/* A flat union (the loader's left fold) of n mixed children; their node indices in kids. */
static int mixed_union(tree *t, int n, int *kids, uint64_t seed)
{
    fv_rng r = fv_rng_make(seed, 0, 0, 0);
    int acc = -1;
    for (int k = 0; k < n; k++) {
        kids[k] = mixed_child(t, &r, k);
        acc = acc < 0 ? kids[k] : op2(t, FV_SDF_UNION, acc, kids[k]);
    }
    return acc;
}

static fv_sdf *compile(const tree *t, int root)
{
    fv_sdf *s = NULL;
    fv_error err;
    if (fv_sdf_create(t->n, t->count, root, &s, &err) != FV_OK) fail_msg("%s", err.msg);
    return s;
}

/* The unculled union: the fold of the children's own fields, the earliest nearest winning. */
static float fold(fv_sdf *const *parts, int n, fv_vec3 p, int *mat)
{
    int m = 0;
    float best = fv_sdf_distance1(parts[0], p.x, p.y, p.z, &m);
    for (int k = 1; k < n; k++) {
        int mk;
        float d = fv_sdf_distance1(parts[k], p.x, p.y, p.z, &mk);
        if (d < best) best = d, m = mk;
    }
    *mat = m;
    return best;
}

/* Points far and near: uniform over the union's box grown by 3, and close to random children. */
static fv_vec3 sample_point(fv_rng *r, const fv_sdf *u, fv_sdf *const *parts, int n, int i)
{
    fv_vec3 lo, hi;
    if (i % 2 == 0) {
        fv_sdf_bounds(u, &lo, &hi);
        lo = fv_sub(lo, fv_v3s(3.0f));
        hi = fv_add(hi, fv_v3s(3.0f));
    } else {
        fv_sdf_bounds(parts[(int)(fv_rng_next(r) * (float)n) % n], &lo, &hi);
        lo = fv_sub(lo, fv_v3s(0.3f));
        hi = fv_add(hi, fv_v3s(0.3f));
    }
    return fv_v3(uni(r, lo.x, hi.x), uni(r, lo.y, hi.y), uni(r, lo.z, hi.z));
}

static bool same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* How many culled chains the program holds, after checking their structure (sdf_impl.h): each
 * CULL names a CULL_DATA op and jumps forward to just after a UNION; each group's data names a run
 * of member data ops; each CULL_BEGIN is followed by its data. A jump or index left unmoved when a
 * program is copied into another (fv_sdf_union_create, the compiler's layout) fails here. */
static int culled_chains(const fv_sdf *u)
{
    int n = 0;
    const fv_sdf_op *o = u->ops;
    for (int i = 0; i < u->count; i++) {
        if (o[i].code == FV_OP_CULL_BEGIN) {
            n++;
            assert_true(o[i].ia >= 1 && o[i].ib > o[i].ia && i + o[i].ib < u->count);
            for (int k = 1; k <= o[i].ib; k++) assert_int_equal(o[i + k].code, FV_OP_CULL_DATA);
            for (int g = 0; g < o[i].ia; g++) {
                const fv_sdf_op *gd = &o[i + 1 + g];
                assert_true(gd->ib > 0 && gd->ia > i + o[i].ia && gd->ia + gd->ib <= i + 1 + o[i].ib);
                for (int k = 0; k < gd->ib; k++) assert_int_equal(o[gd->ia + k].ib, 0); /* members, not groups */
            }
        }
        if (o[i].code == FV_OP_CULL) {
            assert_true(o[i].ib >= 0 && o[i].ib < i && o[o[i].ib].code == FV_OP_CULL_DATA);
            assert_true(o[i].ia > i + 1 && o[i].ia < u->count && o[o[i].ia - 1].code == FV_OP_UNION);
        }
    }
    return n;
}

/* Checks field u against the fold of parts at 12 000 points through every evaluator. */
static void check_against_fold(const fv_sdf *u, fv_sdf *const *parts, int n, uint64_t seed)
{
    fv_rng r = fv_rng_make(seed, 1, 0, 0);
    const bool avx2 = __builtin_cpu_supports("avx2");
    int near = 0;
    for (int b = 0; b < 1500; b++) {
        float x[8], y[8], z[8], d8[8], da[8], ref[8];
        int m8[8], ma[8], mref[8];
        for (int k = 0; k < 8; k++) {
            fv_vec3 p = sample_point(&r, u, parts, n, 8 * b + k);
            x[k] = p.x, y[k] = p.y, z[k] = p.z;
            ref[k] = fold(parts, n, p, &mref[k]);
            near += fabsf(ref[k]) < 0.3f;
            int m1 = -1;
            float d1 = fv_sdf_distance1(u, p.x, p.y, p.z, &m1);
            if (!same_bits(d1, ref[k]) || m1 != mref[k])
                fail_msg("point (%g %g %g): culled %.9g (material %d), fold %.9g (material %d)", p.x, p.y, p.z, d1, m1, ref[k], mref[k]);
            int mk = -1;
            float dk = fv_ksdf_distance(u, p, &mk);
            if (!same_bits(dk, ref[k]) || mk != mref[k]) fail_msg("kernel build: %.9g, fold %.9g", dk, ref[k]);
        }
        fv_sdf_distance8_base(u, x, y, z, d8, m8);
        if (avx2) fv_sdf_distance8_avx2(u, x, y, z, da, ma);
        for (int k = 0; k < 8; k++) {
            if (!same_bits(d8[k], ref[k]) || m8[k] != mref[k]) fail_msg("8-wide lane %d: %.9g, fold %.9g", k, d8[k], ref[k]);
            if (avx2 && (!same_bits(da[k], ref[k]) || ma[k] != mref[k])) fail_msg("AVX2 lane %d: %.9g, fold %.9g", k, da[k], ref[k]);
        }
    }
    /* the near points are what the culling could get wrong: there must be many */
    printf("%d of 12000 points within 0.3 of a surface\n", near);
    assert_true(near > 1500);
}

/* ---- the culled union equals the fold ---- */

#define N_MIXED 150

static void test_union_equals_fold(void **st)
{
    (void)st;
    tree t = {0};
    int kids[N_MIXED];
    int root = mixed_union(&t, N_MIXED, kids, 29);
    fv_sdf *u = compile(&t, root), *parts[N_MIXED];
    for (int k = 0; k < N_MIXED; k++) parts[k] = compile(&t, kids[k]);
    /* the outer union and each nested union of ten (every ninth child) are culled chains */
    assert_int_equal(culled_chains(u), 1 + N_MIXED / 9);
    check_against_fold(u, parts, N_MIXED, 1);
    /* three children: the plain fold, the same numbers */
    fv_sdf *small = compile(&t, op2(&t, FV_SDF_UNION, op2(&t, FV_SDF_UNION, kids[0], kids[1]), kids[2]));
    assert_int_equal(culled_chains(small), 0);
    check_against_fold(small, parts, 3, 2);
    fv_sdf_destroy(small);
    fv_sdf_destroy(u);
    for (int k = 0; k < N_MIXED; k++) fv_sdf_destroy(parts[k]);
    free(t.n);
}

/* fv_sdf_union_create over compiled parts, some of which (the nested unions) hold their own culled
 * chain, and over 3 parts (the plain fold). */
static void test_merged_parts(void **st)
{
    (void)st;
    tree t = {0};
    int kids[N_MIXED];
    mixed_union(&t, N_MIXED, kids, 31);
    fv_sdf *parts[N_MIXED];
    for (int k = 0; k < N_MIXED; k++) parts[k] = compile(&t, kids[k]);
    fv_error err;
    for (int n = 3; n <= N_MIXED; n += N_MIXED - 3) {
        fv_sdf *m = NULL;
        if (fv_sdf_union_create((const fv_sdf *const *)parts, n, &m, &err) != FV_OK) fail_msg("%s", err.msg);
        assert_int_equal(culled_chains(m), (n > 3) + (n - 1) / 9); /* the parts' own chains moved in */
        check_against_fold(m, parts, n, 3 + (uint64_t)n);
        fv_sdf_destroy(m);
    }
    fv_sdf *m = NULL;
    assert_int_equal(fv_sdf_union_create((const fv_sdf *const *)parts, 0, &m, &err), FV_ERR_INVALID);
    assert_null(m);
    for (int k = 0; k < N_MIXED; k++) fv_sdf_destroy(parts[k]);
    free(t.n);
}

/* ---- distances: never more than the true distance ---- */

/* 200 spheres: the field is min |p - c| - r, exact, so the culled union must return it (within
 * float rounding, 1e-5 of the scene's size) everywhere, and never more. */
static void test_spheres_exact(void **st)
{
    (void)st;
    enum { N = 200 };
    tree t = {0};
    fv_rng r = fv_rng_make(5, 0, 0, 0);
    fv_vec3 c[N];
    float rad[N];
    int acc = -1;
    for (int k = 0; k < N; k++) {
        fv_sdf_node s = node(FV_SDF_SPHERE, k);
        rad[k] = s.p[0] = uni(&r, 0.1f, 1.0f);
        c[k] = fv_v3(uni(&r, -15, 15), uni(&r, -15, 15), uni(&r, -15, 15));
        int ch = placed(&t, add(&t, s), c[k], (fv_quat){0, 0, 0, 1}, 1.0f);
        acc = acc < 0 ? ch : op2(&t, FV_SDF_UNION, acc, ch);
    }
    fv_sdf *u = compile(&t, acc);
    double worst = 0.0;
    for (int i = 0; i < 10000; i++) {
        fv_vec3 p = i % 2 ? fv_v3(uni(&r, -18, 18), uni(&r, -18, 18), uni(&r, -18, 18))
                          : fv_add(c[i % N], fv_v3(uni(&r, -1.5f, 1.5f), uni(&r, -1.5f, 1.5f), uni(&r, -1.5f, 1.5f)));
        double truth = INFINITY;
        for (int k = 0; k < N; k++) {
            double dx = (double)p.x - c[k].x, dy = (double)p.y - c[k].y, dz = (double)p.z - c[k].z;
            truth = fmin(truth, sqrt(dx * dx + dy * dy + dz * dz) - rad[k]);
        }
        float d = fv_sdf_distance(u, p, NULL);
        worst = fmax(worst, fabs(d - truth));
        if (!(d <= truth + 1e-5 * 30.0)) fail_msg("(%g %g %g): %.9g exceeds the distance %.9g", p.x, p.y, p.z, d, truth);
    }
    printf("200 spheres: largest |field - distance| %.3g over 10000 points\n", worst);
    assert_true(worst <= 1e-5 * 30.0);
    fv_sdf_destroy(u);
    free(t.n);
}

/* The mixed union is 1-Lipschitz: |d(p) - d(q)| <= |p - q| for nearby pairs, far and near (a
 * culled child that should have counted would show as a jump). */
static void test_mixed_lipschitz(void **st)
{
    (void)st;
    tree t = {0};
    int kids[N_MIXED];
    fv_sdf *u = compile(&t, mixed_union(&t, N_MIXED, kids, 37));
    fv_sdf *parts[1] = {u};
    fv_rng r = fv_rng_make(6, 0, 0, 0);
    for (int i = 0; i < 10000; i++) {
        fv_vec3 p = sample_point(&r, u, parts, 1, i);
        fv_vec3 q = fv_add(p, fv_scale(fv_v3(uni(&r, -1, 1), uni(&r, -1, 1), uni(&r, -1, 1)), 0.05f));
        float dp = fv_sdf_distance(u, p, NULL), dq = fv_sdf_distance(u, q, NULL);
        float lim = fv_length(fv_sub(p, q)) * (1.0f + 1e-4f) + 1e-5f;
        if (!(fabsf(dp - dq) <= lim)) fail_msg("(%g %g %g) %.9g, (%g %g %g) %.9g: more than %g apart", p.x, p.y, p.z, dp, q.x, q.y, q.z, dq, lim);
    }
    fv_sdf_destroy(u);
    free(t.n);
}

/* ---- nesting ---- */

static void test_flat_is_not_nesting(void **st)
{
    (void)st;
    fv_error err;
    fv_sdf *s = NULL;
    /* 200 children in one flat union (a left fold 199 unions deep) compile */
    tree t = {0};
    int acc = -1;
    for (int k = 0; k < 200; k++) {
        fv_sdf_node b = node(FV_SDF_BOX, k);
        b.v[0] = fv_v3s(0.4f);
        int ch = placed(&t, add(&t, b), fv_v3((float)(k % 20), 0, (float)(k / 20)), (fv_quat){0, 0, 0, 1}, 1.0f);
        acc = acc < 0 ? ch : op2(&t, FV_SDF_UNION, acc, ch);
    }
    s = compile(&t, acc);
    int m = -1;
    assert_true(fabsf(fv_sdf_distance(s, fv_v3(19, 0, 9), &m) + 0.4f) < 1e-6f);
    assert_int_equal(m, 199);
    fv_sdf_destroy(s);
    free(t.n);

    /* real nesting is still limited: unions through child b, 49 deep */
    tree n = {0};
    fv_sdf_node sp = node(FV_SDF_SPHERE, 0);
    sp.p[0] = 1.0f;
    int leafi = add(&n, sp), r = leafi;
    for (int k = 0; k < FV_SDF_MAX_DEPTH + 1; k++) r = op2(&n, FV_SDF_UNION, leafi, r);
    assert_int_equal(fv_sdf_create(n.n, n.count, r, &s, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "nests deeper than 48 levels"));
    assert_null(strchr(err.msg, '\n'));
    /* 48 deep is fine */
    assert_int_equal(fv_sdf_create(n.n, n.count, r - 1, &s, &err), FV_OK);
    fv_sdf_destroy(s);
    /* a cycle through child a of a chain */
    n.n[leafi + 2].a = leafi + 3;
    assert_int_equal(fv_sdf_create(n.n, n.count, leafi + 3, &s, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "forms a cycle"));
    free(n.n);
}

/* ---- the grid scene in three layouts ---- */

static fv_scene *load_grid(const char *suffix, int w, int h, fv_camera *cam)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/sdf-grid81%s.json", FOVEA_SOURCE_DIR, suffix);
    fv_scene *s;
    fv_view *v;
    if (fv_test_load(path, &s, &v) != 0) fail_msg("cannot load %s", path);
    fv_view_camera(v, s, 0.0, w, h, cam);
    fv_view_destroy(v);
    return s;
}

static void test_layouts_same_pixels(void **st)
{
    (void)st;
    const int w = 96, h = 54;
    static const char *const layouts[3] = {"", "-rows", "-objects"};
    static const char *const methods[2] = {"sdf-gt", "ipr"};
    fv_scene *s[3];
    fv_camera cam[3];
    for (int l = 0; l < 3; l++) s[l] = load_grid(layouts[l], w, h, &cam[l]);
    assert_int_equal(fv_scene_object_count(s[0]), 2);
    assert_int_equal(fv_scene_object_count(s[2]), 82);
    for (int m = 0; m < 2; m++) {
        fv_film *f[3];
        for (int l = 0; l < 3; l++) f[l] = fv_test_render_once(methods[m], "", s[l], &cam[l], 7);
        const float *c0 = fv_film_color_const(f[0]);
        double mean = 0.0;
        for (size_t i = 0; i < (size_t)3 * w * h; i++) mean += c0[i];
        assert_true(mean / (3.0 * w * h) > 0.02); /* not black */
        for (int l = 1; l < 3; l++)
            if (memcmp(c0, fv_film_color_const(f[l]), (size_t)3 * w * h * sizeof(float)) != 0)
                fail_msg("%s: layout '%s' differs from the flat union", methods[m], layouts[l]);
        for (int l = 0; l < 3; l++) fv_film_destroy(f[l]);
    }
    for (int l = 0; l < 3; l++) fv_scene_destroy(s[l]);
}

/* ---- the world: static objects merged, moving ones skipped by their boxes ---- */

static void test_world_moving(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    int mats[3];
    for (int i = 0; i < 3; i++) {
        fv_material m = fv_material_default(FV_MAT_DIFFUSE);
        snprintf(m.name, sizeof m.name, "m%d", i);
        assert_int_equal(fv_scene_add_material(s, &m, &mats[i], &err), FV_OK);
    }
    fv_rng r = fv_rng_make(11, 0, 0, 0);
    int ids[52];
    for (int k = 0; k < 52; k++) {
        tree t = {0};
        int root = placed(&t, primitive(&t, k, mats[k % 3]), fv_v3(uni(&r, -8, 8), uni(&r, -2, 2), uni(&r, -8, 8)), random_rotation(&r),
                          uni(&r, 0.5f, 1.5f));
        char name[16];
        snprintf(name, sizeof name, "o%d", k);
        if (fv_scene_add_sdf(s, name, t.n, t.count, root, NULL, &ids[k], &err) != FV_OK) fail_msg("%s", err.msg);
        free(t.n);
        if (k % 13 == 4 || k % 13 == 9) { /* 8 moving objects, one stretched */
            fv_anim_key keys[2] = {{0.0, {0, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}},
                                   {1.0, {uni(&r, -3, 3), 1, uni(&r, -3, 3)}, {0, 0.3826834f, 0, 0.9238795f}, {1.5f, 1.5f, 1.5f}}};
            if (k == 4) keys[1].scale = fv_v3(1.0f, 2.0f, 0.7f);
            if (fv_scene_animate_object(s, ids[k], keys, 2, &err) != FV_OK) fail_msg("%s", err.msg);
        }
    }
    fv_light_desc l = {FV_LIGHT_POINT, {0, 10, 0}, {0, -1, 0}, {10, 10, 10}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_set_time(s, 0.6, &err), FV_OK);
    fv_sdf_world w;
    assert_int_equal(fv_sdf_world_build(&w, s, &err), FV_OK);
    assert_int_equal(w.k.count, 8);
    assert_non_null(w.merged);
    assert_int_equal(culled_chains(w.merged), 1);
    /* the skip test is live for every moving object, the stretched one too */
    for (int i = 0; i < w.k.count; i++) assert_true(w.objs[i].cull_c > 0.1f && w.objs[i].cull_c <= 1.0f);
    for (int b = 0; b < 2000; b++) {
        float x[8], y[8], z[8], d8[8];
        int m8[8];
        for (int k = 0; k < 8; k++) {
            x[k] = uni(&r, -12, 12), y[k] = uni(&r, -4, 5), z[k] = uni(&r, -12, 12);
            if (b % 2) x[k] = x[0] + 0.05f * k, y[k] = y[0], z[k] = z[0]; /* a coherent packet */
        }
        fv_sdf_world_eval8(&w, x, y, z, d8, m8);
        for (int k = 0; k < 8; k++) {
            /* the plain loop: every object, static ones first in scene order, then the moving */
            float best = INFINITY;
            int bm = 0;
            for (int o = 0; o < fv_scene_object_count(s); o++) {
                if (fv_scene_object_dynamic(s, o)) continue;
                int m;
                float v = fv_sdf_distance1(fv_scene_object_sdf(s, o), x[k], y[k], z[k], &m);
                if (v < best) best = v, bm = m;
            }
            for (int i = 0; i < w.k.count; i++) {
                const fv_ksdf_object *o = &w.objs[i];
                const fv_xform *mm = &o->inv;
                float lx = mm->m[0][0] * x[k] + mm->m[0][1] * y[k] + mm->m[0][2] * z[k] + mm->m[0][3];
                float ly = mm->m[1][0] * x[k] + mm->m[1][1] * y[k] + mm->m[1][2] * z[k] + mm->m[1][3];
                float lz = mm->m[2][0] * x[k] + mm->m[2][1] * y[k] + mm->m[2][2] * z[k] + mm->m[2][3];
                int m;
                float v = fv_sdf_distance1(w.sdfs[i], lx, ly, lz, &m) * o->lip;
                if (v < best) best = v, bm = m;
            }
            int m1;
            float d1 = fv_sdf_world_eval1(&w, x[k], y[k], z[k], &m1);
            if (!same_bits(d1, best) || m1 != bm) fail_msg("(%g %g %g): world %.9g (%d), plain loop %.9g (%d)", x[k], y[k], z[k], d1, m1, best, bm);
            if (!same_bits(d8[k], best) || m8[k] != bm) fail_msg("8-wide lane %d: world %.9g, plain loop %.9g", k, d8[k], best);
        }
    }
    fv_sdf_world_free(&w);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_union_equals_fold),   cmocka_unit_test(test_merged_parts),
        cmocka_unit_test(test_spheres_exact),       cmocka_unit_test(test_mixed_lipschitz),
        cmocka_unit_test(test_flat_is_not_nesting), cmocka_unit_test(test_layouts_same_pixels),
        cmocka_unit_test(test_world_moving),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
