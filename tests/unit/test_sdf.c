/* Signed distance fields (fovea/sdf.h, src/sdf/): every primitive and operator against its exact
 * distance at hand-worked points (inside, outside, on the surface, near edges and corners);
 * transforms and repetition; the distance bound of every kind on a grid (|d(p) - d(q)| <= |p - q|,
 * and |d| never more than the distance to surface points found by bisection); the bounds hold the
 * surface; the eight-lane evaluator equals the scalar one bit for bit; each refusal names its node
 * and field in one line. Ends with a speed report (evaluations per second, scalar and 8-wide). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "sdf/sdf_eval.h"
#include "testkit.h"

#define TOL 2e-6f

/* ---- building trees ---- */

static fv_sdf_node node(fv_sdf_kind k)
{
    fv_sdf_node n;
    memset(&n, 0, sizeof n);
    n.kind = k;
    n.q.w = 1.0f;
    return n;
}
static fv_sdf_node sphere(float r)
{
    fv_sdf_node n = node(FV_SDF_SPHERE);
    n.p[0] = r;
    return n;
}
static fv_sdf_node box(float x, float y, float z)
{
    fv_sdf_node n = node(FV_SDF_BOX);
    n.v[0] = fv_v3(x, y, z);
    return n;
}
static fv_sdf_node op2(fv_sdf_kind k, int a, int b)
{
    fv_sdf_node n = node(k);
    n.a = a;
    n.b = b;
    return n;
}
static fv_sdf_node xform(int a, fv_vec3 t, fv_quat q, float s)
{
    fv_sdf_node n = node(FV_SDF_TRANSFORM);
    n.a = a;
    n.v[0] = t;
    n.q = q;
    n.p[0] = s;
    return n;
}
static fv_sdf_node translate(int a, float x, float y, float z) { return xform(a, fv_v3(x, y, z), (fv_quat){0, 0, 0, 1}, 1.0f); }

static fv_sdf *make(const fv_sdf_node *n, int count, int root)
{
    fv_sdf *s = NULL;
    fv_error err;
    fv_status st = fv_sdf_create(n, count, root, &s, &err);
    if (st != FV_OK) fail_msg("fv_sdf_create: %s", err.msg);
    return s;
}
static fv_sdf *make1(fv_sdf_node n) { return make(&n, 1, 0); }

static float D(const fv_sdf *s, float x, float y, float z) { return fv_sdf_distance(s, fv_v3(x, y, z), NULL); }
#define AT(s, x, y, z, want) assert_float_equal(D(s, x, y, z), (want), TOL)

/* ---- primitives at hand-worked points ---- */

static void test_sphere_box(void **st)
{
    (void)st;
    fv_sdf *s = make1(sphere(1.0f));
    AT(s, 2, 0, 0, 1.0f);
    AT(s, 0, 0, 0, -1.0f);
    AT(s, 0.6f, 0.8f, 0, 0.0f);                 /* on the surface */
    AT(s, 1, 1, 1, 0.7320508f);                 /* sqrt(3) - 1 */
    fv_sdf_destroy(s);

    s = make1(box(1, 2, 3));
    AT(s, 2, 0, 0, 1.0f);                       /* off the x face */
    AT(s, 0, 0, 0, -1.0f);                      /* inside: nearest face x = 1 */
    AT(s, 0.5f, 1.9f, 0, -0.1f);                /* inside near the y face */
    AT(s, 2, 3, 0, 1.4142136f);                 /* off the edge x=1,y=2: sqrt(1 + 1) */
    AT(s, 2, 3, 4, 1.7320508f);                 /* off the corner: sqrt(3) */
    AT(s, 1, 2, 3, 0.0f);                       /* the corner itself */
    fv_sdf_destroy(s);

    fv_sdf_node rb = node(FV_SDF_ROUND_BOX);
    rb.v[0] = fv_v3(1, 1, 1);
    rb.p[0] = 0.25f;                            /* inner box half 0.75 */
    s = make1(rb);
    AT(s, 2, 0, 0, 1.0f);                       /* faces stay where the box's are */
    AT(s, 0, 0, 0, -1.0f);
    AT(s, 2, 2, 2, 1.9150635f);                 /* 1.25 sqrt(3) - 0.25 */
    AT(s, 0.75f + 0.25f / 1.7320508f, 0.75f + 0.25f / 1.7320508f, 0.75f + 0.25f / 1.7320508f, 0.0f); /* rounded corner */
    fv_sdf_destroy(s);
}

static void test_torus_capsule_cylinder(void **st)
{
    (void)st;
    fv_sdf_node t = node(FV_SDF_TORUS);
    t.p[0] = 2.0f;
    t.p[1] = 0.5f;
    fv_sdf *s = make1(t);
    AT(s, 2, 0, 0, -0.5f);                      /* tube centre */
    AT(s, 0, 0, 0, 1.5f);                       /* the hole's centre: 2 - 0.5 */
    AT(s, 2, 1, 0, 0.5f);                       /* above the tube */
    AT(s, 0, 0, 3, 0.5f);                       /* outside along z (the ring lies in xz) */
    AT(s, 3, 1, 0, 0.9142136f);                 /* sqrt(2) - 0.5 */
    fv_sdf_destroy(s);

    fv_sdf_node c = node(FV_SDF_CAPSULE);
    c.v[0] = fv_v3(0, 0, 0);
    c.v[1] = fv_v3(0, 2, 0);
    c.p[0] = 0.5f;
    s = make1(c);
    AT(s, 1, 1, 0, 0.5f);                       /* beside the segment */
    AT(s, 0, 3, 0, 0.5f);                       /* beyond end b */
    AT(s, 0, -1, 0, 0.5f);                      /* beyond end a */
    AT(s, 0, 1, 0, -0.5f);                      /* on the segment */
    AT(s, 1, 3, 0, 0.9142136f);                 /* off end b diagonally: sqrt(2) - 0.5 */
    fv_sdf_destroy(s);

    fv_sdf_node y = node(FV_SDF_CYLINDER);
    y.p[0] = 1.0f;
    y.p[1] = 2.0f;
    s = make1(y);
    AT(s, 2, 0, 0, 1.0f);
    AT(s, 0, 3, 0, 1.0f);
    AT(s, 2, 3, 0, 1.4142136f);                 /* off the rim */
    AT(s, 0, 0, 0, -1.0f);
    AT(s, 0.5f, 1.8f, 0, -0.2f);                /* inside near the cap */
    AT(s, 0.6f, 0, 0.8f, 0.0f);                 /* on the side */
    fv_sdf_destroy(s);
}

static void test_cone_plane(void **st)
{
    (void)st;
    /* Pointed cone: base radius 1 at y = -1, apex at y = 1. The side is the line 2 rho + y = 1. */
    fv_sdf_node c = node(FV_SDF_CONE);
    c.p[0] = 1.0f;
    c.p[1] = 0.0f;
    c.p[2] = 1.0f;
    fv_sdf *s = make1(c);
    AT(s, 0, 2, 0, 1.0f);                       /* above the apex */
    AT(s, 0, -2, 0, 1.0f);                      /* below the base */
    AT(s, 0, 0, 0, -0.4472136f);                /* inside: to the side, 1/sqrt(5) */
    AT(s, 2, -1, 0, 1.0f);                      /* level with the base rim */
    AT(s, 1, 1, 0, 0.8944272f);                 /* outside the side: 2/sqrt(5) */
    AT(s, 0, 0.5f, 0.25f, 0.0f);                /* on the side: 2 * 0.25 + 0.5 = 1 */
    fv_sdf_destroy(s);
    /* Truncated: radius 1 at y = -1, 0.5 at y = 1; side direction e = (-0.5, 2). From the origin
     * w = (-1, 1): |cross(e, w)| / |e| = 1.5 / sqrt(4.25). */
    c.p[1] = 0.5f;
    s = make1(c);
    AT(s, 0, 0, 0, -0.7276069f);
    AT(s, 0, 1.5f, 0, 0.5f);                    /* above the top cap */
    AT(s, 0.5f, 1, 0, 0.0f);                    /* the top rim */
    fv_sdf_destroy(s);

    /* Planes need a box to be bounded: the solid y <= 1 clipped to |x|,|y|,|z| <= 10. */
    fv_sdf_node n[3] = {node(FV_SDF_PLANE), box(10, 10, 10), op2(FV_SDF_INTERSECT, 0, 1)};
    n[0].v[0] = fv_v3(0, 1, 0);
    n[0].p[0] = 1.0f;
    s = make(n, 3, 2);
    AT(s, 5, 3, -2, 2.0f);
    AT(s, 0, 0, 0, -1.0f);
    fv_vec3 lo, hi;
    fv_sdf_bounds(s, &lo, &hi);
    assert_float_equal(hi.y, 1.0f, 0.0f);       /* the axis-aligned plane bounds the top */
    assert_float_equal(lo.y, -10.0f, 0.0f);
    fv_sdf_destroy(s);
    n[0].v[0] = fv_v3(0.6f, 0.8f, 0);
    n[0].p[0] = 0.0f;
    s = make(n, 3, 2);
    AT(s, 3, 4, 0, 5.0f);                       /* 0.6 * 3 + 0.8 * 4 */
    fv_sdf_destroy(s);
}

static fv_sdf_node heightfield(float base, float amp, float freq, int oct, int seed)
{
    fv_sdf_node h = node(FV_SDF_HEIGHTFIELD);
    h.p[0] = base;
    h.p[1] = amp;
    h.p[2] = freq;
    h.p[3] = (float)oct;
    h.p[4] = (float)seed;
    return h;
}

static void test_heightfield(void **st)
{
    (void)st;
    /* Amplitude 0: the plane y = base exactly (the Lipschitz divisor is 1). */
    fv_sdf_node n[3] = {heightfield(0.5f, 0.0f, 1.0f, 1, 7), box(4, 4, 4), op2(FV_SDF_INTERSECT, 0, 1)};
    fv_sdf *s = make(n, 3, 2);
    AT(s, 1.3f, 2.5f, -0.7f, 2.0f);
    AT(s, 0, 0, 0, -0.5f);
    fv_sdf_destroy(s);
    /* A = 0.5, F = 1, one octave: L_h = 0.5 * 3 sqrt(2), divisor sqrt(1 + 4.5) = 2.3452079. At a
     * lattice point the noise is the lattice value v exactly, so d = (y - 0.5 v) / 2.3452079, and
     * a point far above or below keeps its sign. Deterministic: the same seed gives the same field,
     * another seed another one. */
    n[0] = heightfield(0.0f, 0.5f, 1.0f, 1, 7);
    s = make(n, 3, 2);
    float d0 = D(s, 0, 0, 0);
    float v = -d0 * 2.3452079f / 0.5f;          /* the lattice value at (0, 0) */
    assert_true(v >= -1.0f && v < 1.0f);
    AT(s, 0, 0.25f, 0, (0.25f - 0.5f * v) / 2.3452079f);
    assert_true(D(s, 0.3f, 1.2f, 0.7f) > 0.0f);
    assert_true(D(s, 0.3f, -1.2f, 0.7f) < 0.0f);
    fv_sdf *s2 = make(n, 3, 2);
    assert_true(D(s2, 0.37f, 0.1f, 1.3f) == D(s, 0.37f, 0.1f, 1.3f));
    n[0].p[4] = 8.0f;
    fv_sdf *s3 = make(n, 3, 2);
    int differ = 0;
    for (int i = 0; i < 16; i++) /* inside the clip box */
        differ += D(s3, 0.45f * (float)i - 3.4f, 0, 0.5f) != D(s, 0.45f * (float)i - 3.4f, 0, 0.5f);
    assert_true(differ > 8);
    fv_vec3 lo, hi;
    fv_sdf_bounds(s, &lo, &hi);
    assert_float_equal(hi.y, 0.5f, 0.0f);       /* base + A (2 - 2^0) */
    fv_sdf_destroy(s);
    fv_sdf_destroy(s2);
    fv_sdf_destroy(s3);
}

/* ---- operators, transforms, repetition ---- */

static void test_operators(void **st)
{
    (void)st;
    fv_sdf_node n[4] = {sphere(1.0f), sphere(1.0f), translate(1, 3, 0, 0), op2(FV_SDF_UNION, 0, 2)};
    n[0].material = 1;
    n[1].material = 2;
    fv_sdf *s = make(n, 4, 3);
    int m = -1;
    assert_float_equal(fv_sdf_distance(s, fv_v3(1.4f, 0, 0), &m), 0.4f, TOL);
    assert_int_equal(m, 1);
    assert_float_equal(fv_sdf_distance(s, fv_v3(1.6f, 0, 0), &m), 0.4f, TOL);
    assert_int_equal(m, 2);
    AT(s, 3, 0, 0, -1.0f);
    fv_sdf_destroy(s);

    /* Shell: sphere 2 minus sphere 1. */
    fv_sdf_node sh[3] = {sphere(2.0f), sphere(1.0f), op2(FV_SDF_SUBTRACT, 0, 1)};
    sh[0].material = 4;
    sh[1].material = 5;
    s = make(sh, 3, 2);
    assert_float_equal(fv_sdf_distance(s, fv_v3(0, 0, 0), &m), 1.0f, TOL); /* in the hole: 1 to its wall */
    assert_int_equal(m, 5);                     /* the cut's surface is b's */
    AT(s, 1.5f, 0, 0, -0.5f);                   /* in the shell's middle */
    assert_float_equal(fv_sdf_distance(s, fv_v3(3, 0, 0), &m), 1.0f, TOL);
    assert_int_equal(m, 4);
    fv_sdf_destroy(s);

    /* Lens: sphere 1 and a slab |x| <= 0.5. */
    fv_sdf_node in[3] = {sphere(1.0f), box(0.5f, 2, 2), op2(FV_SDF_INTERSECT, 0, 1)};
    s = make(in, 3, 2);
    AT(s, 0, 0, 0, -0.5f);
    AT(s, 0, 1.5f, 0, 0.5f);
    AT(s, 1, 0, 0, 0.5f);
    fv_sdf_destroy(s);

    /* Smooth union k = 1 of unit spheres at x = -1.5 and 1.5: at the origin a = b = 0.5, h = 1,
     * d = 0.5 - 1/4 = 0.25; far away (|a - b| >= k) it is the plain minimum. */
    fv_sdf_node su[5] = {sphere(1.0f), translate(0, -1.5f, 0, 0), translate(0, 1.5f, 0, 0), op2(FV_SDF_SMOOTH_UNION, 1, 2)};
    su[3].p[0] = 1.0f;
    s = make(su, 4, 3);
    AT(s, 0, 0, 0, 0.25f);
    AT(s, 10, 0, 0, 7.5f);
    AT(s, 1.5f, 0, 0, -1.0f);
    fv_vec3 lo, hi;
    fv_sdf_bounds(s, &lo, &hi);
    assert_float_equal(hi.x, 2.5f + 0.25f, TOL); /* the union's box grown by k/4 */
    fv_sdf_destroy(s);
}

static void test_transform(void **st)
{
    (void)st;
    fv_quat rz = fv_quat_axis_angle(fv_v3(0, 0, 1), 0.5f * FV_PI);
    /* Box (1, 2, 0.5) turned 90 degrees about z: world half extents (2, 1, 0.5). */
    fv_sdf_node n[2] = {box(1, 2, 0.5f), xform(0, fv_v3(0, 0, 0), rz, 1.0f)};
    fv_sdf *s = make(n, 2, 1);
    AT(s, 3, 0, 0, 1.0f);
    AT(s, 0, 2, 0, 1.0f);
    fv_sdf_destroy(s);
    /* ... scaled by 2 and moved to (1, 2, 3): half extents (4, 2, 1) around (1, 2, 3). */
    n[1] = xform(0, fv_v3(1, 2, 3), rz, 2.0f);
    s = make(n, 2, 1);
    AT(s, 6, 2, 3, 1.0f);
    AT(s, 1, 5, 3, 1.0f);
    AT(s, 1, 2, 3, -1.0f);                      /* centre: nearest face z at 1 */
    fv_vec3 lo, hi;
    fv_sdf_bounds(s, &lo, &hi);
    assert_float_equal(lo.x, -3.0f, 1e-5f);
    assert_float_equal(hi.y, 4.0f, 1e-5f);
    assert_float_equal(hi.z, 4.0f, 1e-5f);
    fv_vec3 nn = fv_sdf_normal(s, fv_v3(6, 2, 3), 0.0f);
    assert_float_equal(nn.x, 1.0f, 1e-4f);
    fv_sdf_destroy(s);
    /* Normal of a sphere at 45 degrees. */
    s = make1(sphere(1.0f));
    nn = fv_sdf_normal(s, fv_v3(1.5f, 1.5f, 0), 1e-3f);
    assert_float_equal(nn.x, 0.7071068f, 1e-4f);
    assert_float_equal(nn.y, 0.7071068f, 1e-4f);
    assert_float_equal(nn.z, 0.0f, 1e-4f);
    fv_sdf_destroy(s);
}

static void test_repeat(void **st)
{
    (void)st;
    /* Spheres of radius 0.5 every 2 along x: margin m = 1 - 0.5 = 0.5. */
    fv_sdf_node n[4] = {sphere(0.5f), node(FV_SDF_REPEAT), box(100, 4, 4), op2(FV_SDF_INTERSECT, 1, 2)};
    n[1].a = 0;
    n[1].v[0] = fv_v3(2, 0, 0);
    fv_sdf *s = make(n, 4, 3);
    AT(s, 4, 0, 0, -0.5f);                      /* a copy's centre */
    AT(s, 4.6f, 0, 0, 0.1f);                    /* q = 0.6, wall 0.4: min(max(0.1, 0.1), 0.9) */
    AT(s, 5, 0, 0, 0.5f);                       /* on the wall: exact, 1 - 0.5 */
    /* Above the row, wall + m = 1.5 would cap the distance; the box holding every copy (|y|, |z|
     * <= 0.5) lifts it to 2.5: exact over a centre, under the true sqrt(10) - 0.5 over a wall. */
    AT(s, 4, 3, 0, 2.5f);
    AT(s, 5, 3, 0, 2.5f);
    AT(s, 4, 0.4f, 0.4f, 0.0656854f);           /* inside that box: exact, sqrt(0.32) - 0.5 */
    AT(s, -6.2f, 0, 0, -0.3f);
    fv_sdf_destroy(s);
    /* Limited to cells -1..1 (copies at -2, 0, 2): beyond the last cell the distance is exact. */
    n[1].v[1] = fv_v3(1, 0, 0);
    s = make(n, 2, 1);
    AT(s, 7, 0, 0, 4.5f);
    AT(s, -7, 0, 0, 4.5f);
    AT(s, 2.2f, 0, 0, -0.3f);
    fv_vec3 lo, hi;
    fv_sdf_bounds(s, &lo, &hi);
    assert_float_equal(lo.x, -2.5f, 0.0f);
    assert_float_equal(hi.x, 2.5f, 0.0f);
    assert_float_equal(hi.y, 0.5f, 0.0f);
    fv_sdf_destroy(s);
}

/* ---- the bound on a grid, for every kind ---- */

typedef struct tree {
    const char *name;
    fv_sdf_node n[8];
    int count, root;
} tree;

static int build_trees(tree *t)
{
    int k = 0;
    fv_quat q = fv_quat_euler_deg(fv_v3(30, 40, 50));
    t[k++] = (tree){"sphere", {sphere(1.0f)}, 1, 0};
    t[k++] = (tree){"box", {box(1.0f, 0.5f, 0.75f)}, 1, 0};
    tree rb = {"round_box", {node(FV_SDF_ROUND_BOX)}, 1, 0};
    rb.n[0].v[0] = fv_v3(1, 0.6f, 0.8f);
    rb.n[0].p[0] = 0.3f;
    t[k++] = rb;
    tree to = {"torus", {node(FV_SDF_TORUS)}, 1, 0};
    to.n[0].p[0] = 1.0f;
    to.n[0].p[1] = 0.3f;
    t[k++] = to;
    tree ca = {"capsule", {node(FV_SDF_CAPSULE)}, 1, 0};
    ca.n[0].v[0] = fv_v3(-0.5f, -0.3f, 0.2f);
    ca.n[0].v[1] = fv_v3(0.6f, 0.4f, -0.1f);
    ca.n[0].p[0] = 0.4f;
    t[k++] = ca;
    tree cy = {"cylinder", {node(FV_SDF_CYLINDER)}, 1, 0};
    cy.n[0].p[0] = 0.7f;
    cy.n[0].p[1] = 0.9f;
    t[k++] = cy;
    tree co = {"cone", {node(FV_SDF_CONE)}, 1, 0};
    co.n[0].p[0] = 0.9f;
    co.n[0].p[1] = 0.2f;
    co.n[0].p[2] = 0.8f;
    t[k++] = co;
    tree pl = {"plane", {node(FV_SDF_PLANE), box(1, 1, 1), op2(FV_SDF_INTERSECT, 0, 1)}, 3, 2};
    pl.n[0].v[0] = fv_normalize(fv_v3(0.3f, 1, 0.2f));
    pl.n[0].p[0] = 0.1f;
    t[k++] = pl;
    t[k++] = (tree){"heightfield", {heightfield(0.0f, 0.3f, 1.5f, 3, 11), box(1.5f, 1, 1.5f), op2(FV_SDF_INTERSECT, 0, 1)}, 3, 2};
    t[k++] = (tree){"union", {sphere(0.6f), box(0.5f, 0.5f, 0.5f), translate(1, 0.7f, 0.2f, 0), op2(FV_SDF_UNION, 0, 2)}, 4, 3};
    t[k++] = (tree){"subtract", {box(0.8f, 0.8f, 0.8f), sphere(1.0f), op2(FV_SDF_SUBTRACT, 0, 1)}, 3, 2};
    t[k++] = (tree){"intersect", {box(0.8f, 0.8f, 0.8f), sphere(1.0f), op2(FV_SDF_INTERSECT, 0, 1)}, 3, 2};
    tree sm = {"smooth_union", {sphere(0.6f), box(0.4f, 0.4f, 0.4f), translate(1, 0.8f, 0, 0), op2(FV_SDF_SMOOTH_UNION, 0, 2)}, 4, 3};
    sm.n[3].p[0] = 0.5f;
    t[k++] = sm;
    t[k++] = (tree){"transform", {box(0.5f, 0.3f, 0.8f), xform(0, fv_v3(0.2f, -0.1f, 0.3f), q, 1.3f)}, 2, 1};
    tree re = {"repeat", {node(FV_SDF_TORUS), node(FV_SDF_REPEAT), box(1.6f, 1.2f, 1.4f), op2(FV_SDF_INTERSECT, 1, 2)}, 4, 3};
    re.n[0].p[0] = 0.25f;
    re.n[0].p[1] = 0.1f;
    re.n[1].v[0] = fv_v3(0.8f, 0, 0.9f);
    t[k++] = re;
    tree rl = {"repeat_limited", {sphere(0.2f), translate(0, 0.05f, 0, 0), node(FV_SDF_REPEAT)}, 3, 2};
    rl.n[2].a = 1;
    rl.n[2].v[0] = fv_v3(0.6f, 0.7f, 0);
    rl.n[2].v[1] = fv_v3(2, 1, 0);
    t[k++] = rl;
    /* Smooth union over a scaled, rotated child and a subtraction: operators nest. */
    tree mix = {"nested",
                {box(0.5f, 0.5f, 0.5f), sphere(0.6f), op2(FV_SDF_SUBTRACT, 0, 1), xform(2, fv_v3(0, 0.3f, 0), q, 0.8f),
                 node(FV_SDF_CAPSULE), op2(FV_SDF_SMOOTH_UNION, 3, 4)},
                6,
                5};
    mix.n[4].v[1] = fv_v3(0, 1, 0);
    mix.n[4].p[0] = 0.2f;
    mix.n[5].p[0] = 0.3f;
    t[k++] = mix;
    return k;
}

/* Surface points of the field's own zero set: sign changes along lines parallel to each axis,
 * refined by bisection. Every one of them bounds the true distance from above. */
static int surface_points(const fv_sdf *s, fv_vec3 lo, fv_vec3 hi, fv_vec3 *pts, int cap)
{
    enum { L = 36, STEPS = 96 };
    int n = 0;
    for (int ax = 0; ax < 3 && n < cap; ax++)
        for (int i = 0; i < L; i++)
            for (int j = 0; j < L; j++) {
                float base[3] = {lo.x, lo.y, lo.z}, ext[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
                float p[3];
                int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
                p[a1] = base[a1] + ext[a1] * ((float)i + 0.5f) / L;
                p[a2] = base[a2] + ext[a2] * ((float)j + 0.5f) / L;
                float t0 = base[ax], prev = 0.0f;
                for (int k = 0; k <= STEPS && n < cap; k++) {
                    p[ax] = base[ax] + ext[ax] * (float)k / STEPS;
                    float d = D(s, p[0], p[1], p[2]);
                    if (k > 0 && (d < 0.0f) != (prev < 0.0f)) {
                        float a = t0, b = p[ax], da = prev;
                        for (int it = 0; it < 40; it++) {
                            float m = 0.5f * (a + b);
                            p[ax] = m;
                            float dm = D(s, p[0], p[1], p[2]);
                            if ((dm < 0.0f) == (da < 0.0f)) a = m, da = dm;
                            else b = m;
                        }
                        p[ax] = 0.5f * (a + b);
                        pts[n++] = fv_v3(p[0], p[1], p[2]);
                        p[ax] = base[ax] + ext[ax] * (float)k / STEPS;
                    }
                    t0 = p[ax];
                    prev = d;
                }
            }
    return n;
}

static void test_lipschitz_and_bound(void **st)
{
    (void)st;
    tree t[24];
    int nt = build_trees(t);
    enum { G = 20, CAP = 40000 };
    fv_vec3 *pts = malloc(sizeof *pts * CAP);
    float *grid = malloc(sizeof *grid * G * G * G);
    assert_non_null(pts);
    assert_non_null(grid);
    for (int ti = 0; ti < nt; ti++) {
        fv_sdf *s = make(t[ti].n, t[ti].count, t[ti].root);
        fv_vec3 blo, bhi;
        fv_sdf_bounds(s, &blo, &bhi);
        fv_vec3 c = fv_scale(fv_add(blo, bhi), 0.5f), h = fv_scale(fv_sub(bhi, blo), 0.6f); /* 20% beyond */
        fv_vec3 lo = fv_sub(c, h), hi = fv_add(c, h);
        int np = surface_points(s, lo, hi, pts, CAP);
        if (np < 50) fail_msg("%s: only %d surface points found", t[ti].name, np);
        /* The bounds hold every surface point. */
        for (int i = 0; i < np; i++) {
            fv_vec3 p = pts[i];
            if (p.x < blo.x - 1e-4f || p.y < blo.y - 1e-4f || p.z < blo.z - 1e-4f || p.x > bhi.x + 1e-4f ||
                p.y > bhi.y + 1e-4f || p.z > bhi.z + 1e-4f)
                fail_msg("%s: surface point (%g %g %g) outside the bounds", t[ti].name, p.x, p.y, p.z);
        }
        fv_vec3 step = fv_scale(fv_sub(hi, lo), 1.0f / (G - 1));
        for (int z = 0; z < G; z++)
            for (int y = 0; y < G; y++)
                for (int x = 0; x < G; x++) {
                    fv_vec3 p = fv_add(lo, fv_mul(step, fv_v3((float)x, (float)y, (float)z)));
                    float d = D(s, p.x, p.y, p.z);
                    grid[(z * G + y) * G + x] = d;
                    /* Outside the bounds the field is positive. */
                    if ((p.x < blo.x || p.y < blo.y || p.z < blo.z || p.x > bhi.x || p.y > bhi.y || p.z > bhi.z) && !(d > 0.0f))
                        fail_msg("%s: d(%g %g %g) = %g outside the bounds", t[ti].name, p.x, p.y, p.z, d);
                    /* Never more than the distance to any surface point. */
                    float best = INFINITY;
                    for (int i = 0; i < np; i++) best = fminf(best, fv_length(fv_sub(p, pts[i])));
                    if (fabsf(d) > best + 1e-4f)
                        fail_msg("%s: |d(%g %g %g)| = %g exceeds the distance %g to the surface", t[ti].name, p.x, p.y, p.z,
                                 fabsf(d), best);
                }
        /* 1-Lipschitz between grid neighbours along each axis and the main diagonal. */
        const int off[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
        for (int z = 0; z + 1 < G; z++)
            for (int y = 0; y + 1 < G; y++)
                for (int x = 0; x + 1 < G; x++)
                    for (int o = 0; o < 4; o++) {
                        float d0 = grid[(z * G + y) * G + x];
                        float d1 = grid[((z + off[o][2]) * G + y + off[o][1]) * G + x + off[o][0]];
                        float len = fv_length(fv_mul(step, fv_v3((float)off[o][0], (float)off[o][1], (float)off[o][2])));
                        if (fabsf(d1 - d0) > len * (1.0f + 1e-4f) + 1e-5f)
                            fail_msg("%s: |d(p) - d(q)| = %g > |p - q| = %g at grid (%d %d %d) dir %d", t[ti].name,
                                     fabsf(d1 - d0), len, x, y, z, o);
                    }
        /* And between random pairs (short and long). */
        uint32_t r = 12345u + (uint32_t)ti;
        for (int i = 0; i < 4000; i++) {
            float u[6];
            for (int k = 0; k < 6; k++) {
                r = r * 1664525u + 1013904223u;
                u[k] = (float)(r >> 8) / 16777216.0f;
            }
            fv_vec3 p = fv_add(lo, fv_mul(fv_sub(hi, lo), fv_v3(u[0], u[1], u[2])));
            fv_vec3 q = i & 1 ? fv_add(p, fv_scale(fv_v3(u[3] - 0.5f, u[4] - 0.5f, u[5] - 0.5f), 0.05f))
                              : fv_add(lo, fv_mul(fv_sub(hi, lo), fv_v3(u[3], u[4], u[5])));
            float dd = fabsf(D(s, p.x, p.y, p.z) - D(s, q.x, q.y, q.z)), len = fv_length(fv_sub(p, q));
            if (dd > len * (1.0f + 1e-4f) + 1e-5f) fail_msg("%s: random pair |dd| = %g > %g", t[ti].name, dd, len);
        }
        fv_sdf_destroy(s);
    }
    free(pts);
    free(grid);
}

/* ---- eight lanes == scalar ---- */

static int have_avx2(void)
{
#if defined(__x86_64__) && defined(__GNUC__)
    return __builtin_cpu_supports("avx2");
#else
    return 0;
#endif
}

static void test_wide_equals_scalar(void **st)
{
    (void)st;
    tree t[24];
    int nt = build_trees(t);
    uint32_t r = 99u;
    for (int ti = 0; ti < nt; ti++) {
        fv_sdf *s = make(t[ti].n, t[ti].count, t[ti].root);
        fv_vec3 lo, hi;
        fv_sdf_bounds(s, &lo, &hi);
        for (int it = 0; it < 500; it++) {
            float x[8], y[8], z[8], d[8];
            int m[8];
            for (int l = 0; l < 8; l++) {
                float u[3];
                for (int k = 0; k < 3; k++) {
                    r = r * 1664525u + 1013904223u;
                    u[k] = (float)(r >> 8) / 16777216.0f * 1.6f - 0.3f; /* beyond the bounds too */
                }
                x[l] = lo.x + (hi.x - lo.x) * u[0];
                y[l] = lo.y + (hi.y - lo.y) * u[1];
                z[l] = lo.z + (hi.z - lo.z) * u[2];
            }
            /* The dispatching entry, then each build directly (AVX2 only where the CPU has it). */
            for (int path = 0; path < 3; path++) {
                if (path == 0) fv_sdf_distance8(s, x, y, z, d, m);
                else if (path == 1) fv_sdf_distance8_base(s, x, y, z, d, m);
                else if (have_avx2()) fv_sdf_distance8_avx2(s, x, y, z, d, m);
                else continue;
                for (int l = 0; l < 8; l++) {
                    int ms = -1;
                    float ds = fv_sdf_distance1(s, x[l], y[l], z[l], &ms);
                    if (memcmp(&ds, &d[l], sizeof ds) != 0 || ms != m[l])
                        fail_msg("%s: path %d lane %d at (%g %g %g): 8-wide %.9g/%d, scalar %.9g/%d", t[ti].name, path, l, x[l],
                                 y[l], z[l], d[l], m[l], ds, ms);
                }
            }
        }
        fv_sdf_destroy(s);
    }
}

/* ---- refusals ---- */

static void refuse(const fv_sdf_node *n, int count, int root, const char *needle)
{
    fv_sdf *s = (fv_sdf *)&s; /* must come back NULL */
    fv_error err;
    fv_status st = fv_sdf_create(n, count, root, &s, &err);
    fv_test_expect_fail(st, &err, FV_ERR_INVALID, needle, needle);
    assert_null(s);
}

static void test_refusals(void **st)
{
    (void)st;
    fv_sdf_node n[4];
    n[0] = sphere(1.0f);
    n[0].kind = (fv_sdf_kind)99;
    refuse(n, 1, 0, "sdf node 0: unknown kind 99");
    n[0] = sphere(-1.0f);
    refuse(n, 1, 0, "sdf node 0 (sphere): p[0] radius -1 must be > 0");
    n[0] = sphere(0.0f);
    refuse(n, 1, 0, "p[0] radius 0");
    n[0] = box(1, 0, 1);
    refuse(n, 1, 0, "sdf node 0 (box): v[0].y half extent 0");
    n[0] = sphere(1.0f);
    n[0].p[3] = NAN;
    refuse(n, 1, 0, "sdf node 0 (sphere): p[3] is not finite");
    n[0] = sphere(1.0f);
    n[0].v[1].z = INFINITY;
    refuse(n, 1, 0, "v[1].z is not finite");
    n[0] = sphere(1.0f);
    n[0].q.w = NAN;
    refuse(n, 1, 0, "q.w is not finite");
    n[0] = sphere(1.0f);
    n[0].material = -1;
    refuse(n, 1, 0, "material -1");
    n[0] = node(FV_SDF_ROUND_BOX);
    n[0].v[0] = fv_v3(1, 0.5f, 1);
    n[0].p[0] = 0.6f;
    refuse(n, 1, 0, "p[0] rounding radius 0.6 exceeds");
    n[0] = node(FV_SDF_TORUS);
    n[0].p[0] = 1.0f;
    refuse(n, 1, 0, "p[1] tube radius");
    n[0] = node(FV_SDF_CONE);
    n[0].p[0] = 1.0f;
    n[0].p[1] = -0.1f;
    n[0].p[2] = 1.0f;
    refuse(n, 1, 0, "(cone): p[1] top radius");
    n[0] = node(FV_SDF_PLANE);
    n[0].v[0] = fv_v3(0, 2, 0);
    refuse(n, 1, 0, "(plane): v[0] normal has length 2");
    n[0] = node(FV_SDF_PLANE);
    n[0].v[0] = fv_v3(0, 1, 0);
    refuse(n, 1, 0, "root 0 (plane) is unbounded");
    n[0] = heightfield(0, 1, 1, 0, 0);
    refuse(n, 1, 0, "(heightfield): p[3] octaves 0");
    n[0] = heightfield(0, 1, 0, 1, 0);
    refuse(n, 1, 0, "p[2] frequency 0");
    n[0] = heightfield(0, 1, 1, 1, 0);
    refuse(n, 1, 0, "root 0 (heightfield) is unbounded");

    n[0] = sphere(1.0f);
    n[1] = op2(FV_SDF_UNION, 0, 5);
    refuse(n, 2, 1, "sdf node 1 (union): child b = 5 is not a node index (0..1)");
    n[1] = op2(FV_SDF_SMOOTH_UNION, 0, 0);
    refuse(n, 2, 1, "sdf node 1 (smooth_union): p[0] k 0 must be > 0");
    n[1] = xform(0, fv_v3(0, 0, 0), (fv_quat){0, 0, 0, 2}, 1.0f);
    refuse(n, 2, 1, "sdf node 1 (transform): q has length 2");
    n[1] = xform(0, fv_v3(0, 0, 0), (fv_quat){0, 0, 0, 1}, 0.0f);
    refuse(n, 2, 1, "sdf node 1 (transform): p[0] scale 0");
    n[1] = translate(1, 0, 0, 0);
    refuse(n, 2, 1, "sdf node 1 (transform): child a = 1 forms a cycle");
    n[1] = op2(FV_SDF_UNION, 0, 2);
    n[2] = translate(1, 1, 0, 0);
    refuse(n, 3, 1, "sdf node 2 (transform): child a = 1 forms a cycle");
    n[1] = node(FV_SDF_REPEAT);
    n[1].v[0] = fv_v3(2, 0, 0);
    refuse(n, 2, 1, "sdf node 1 (repeat): child 0 reaches 1 from the origin on x");
    n[1].v[0] = fv_v3(-2, 0, 0);
    refuse(n, 2, 1, "(repeat): v[0].x period -2");
    n[1].v[0] = fv_v3(3, 0, 0);
    n[1].v[1] = fv_v3(0, 1, 0);
    refuse(n, 2, 1, "(repeat): v[1].y cell limit 1 on an axis with period 0");
    n[1].v[1] = fv_v3(1.5f, 0, 0);
    refuse(n, 2, 1, "v[1].x cell limit 1.5");
    n[1] = translate(0, 5, 0, 0);
    n[2] = op2(FV_SDF_INTERSECT, 0, 1);
    refuse(n, 3, 2, "sdf node 2 (intersect): children 0 and 1 do not overlap on x");
    refuse(n, 3, 3, "sdf: root 3 is not a node index (0..2)");
    refuse(n, 0, 0, "sdf: 0 nodes");

    /* Nesting deeper than FV_SDF_MAX_DEPTH. */
    fv_sdf_node deep[FV_SDF_MAX_DEPTH + 2];
    deep[0] = sphere(1.0f);
    for (int i = 1; i < FV_SDF_MAX_DEPTH + 2; i++) deep[i] = translate(i - 1, 0, 0, 0);
    refuse(deep, FV_SDF_MAX_DEPTH + 2, FV_SDF_MAX_DEPTH + 1, "nests deeper than 48 levels");
    /* A node the root does not reach is validated too. */
    n[0] = sphere(1.0f);
    n[1] = sphere(-2.0f);
    refuse(n, 2, 0, "sdf node 1 (sphere): p[0] radius -2");
    assert_string_equal(fv_sdf_kind_name(FV_SDF_SMOOTH_UNION), "smooth_union");
    assert_string_equal(fv_sdf_kind_name((fv_sdf_kind)-1), "unknown");
}

/* ---- speed report (not an assertion) ---- */

/* A scene-like tree: 20 primitives (4 of each of five kinds, placed on a ring) under unions, on a
 * clipped ground plane. */
static int scene_tree(fv_sdf_node *n)
{
    int c = 0, acc = -1;
    for (int i = 0; i < 20; i++) {
        float a = 2.0f * FV_PI * (float)i / 20.0f;
        fv_sdf_node leaf;
        switch (i % 5) {
        case 0: leaf = sphere(0.4f); break;
        case 1: leaf = box(0.3f, 0.5f, 0.3f); break;
        case 2: leaf = node(FV_SDF_TORUS), leaf.p[0] = 0.35f, leaf.p[1] = 0.1f; break;
        case 3: leaf = node(FV_SDF_CYLINDER), leaf.p[0] = 0.25f, leaf.p[1] = 0.6f; break;
        default: leaf = node(FV_SDF_CONE), leaf.p[0] = 0.35f, leaf.p[1] = 0.0f, leaf.p[2] = 0.5f; break;
        }
        leaf.material = i;
        n[c++] = leaf;
        n[c] = xform(c - 1, fv_v3(4.0f * cosf(a), 0.6f, 4.0f * sinf(a)), fv_quat_axis_angle(fv_v3(0, 1, 0), a), 1.0f);
        c++;
        if (acc >= 0) {
            n[c] = op2(FV_SDF_UNION, acc, c - 1);
            acc = c++;
        } else {
            acc = c - 1;
        }
    }
    n[c] = node(FV_SDF_PLANE);
    n[c].v[0] = fv_v3(0, 1, 0);
    n[c + 1] = box(6, 1, 6);
    n[c + 2] = op2(FV_SDF_INTERSECT, c, c + 1);
    n[c + 3] = op2(FV_SDF_UNION, acc, c + 2);
    return c + 4;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void test_speed_report(void **st)
{
    (void)st;
    fv_sdf_node n[80];
    int count = scene_tree(n);
    fv_sdf *s = make(n, count, count - 1);
    enum { N = 4096 };
    static float x[N], y[N], z[N], d[N];
    uint32_t r = 7u;
    for (int i = 0; i < N; i++) {
        float u[3];
        for (int k = 0; k < 3; k++) {
            r = r * 1664525u + 1013904223u;
            u[k] = (float)(r >> 8) / 16777216.0f;
        }
        x[i] = -6.0f + 12.0f * u[0];
        y[i] = -1.0f + 3.0f * u[1];
        z[i] = -6.0f + 12.0f * u[2];
    }
    int reps = getenv("FOVEA_SANITIZED") ? 1 : 40;
    double sink = 0.0;
    double t0 = now_s();
    for (int rep = 0; rep < reps; rep++)
        for (int i = 0; i < N; i++) d[i] = fv_sdf_distance1(s, x[i], y[i], z[i], NULL);
    double t1 = now_s();
    for (int i = 0; i < N; i++) sink += d[i];
    for (int rep = 0; rep < reps; rep++)
        for (int i = 0; i < N; i += 8) fv_sdf_distance8(s, x + i, y + i, z + i, d + i, NULL);
    double t2 = now_s();
    for (int i = 0; i < N; i++) sink += d[i];
    for (int rep = 0; rep < reps; rep++)
        for (int i = 0; i < N; i += 8) fv_sdf_distance8_base(s, x + i, y + i, z + i, d + i, NULL);
    double t3 = now_s();
    for (int i = 0; i < N; i++) sink += d[i];
    double ev = (double)N * reps;
    printf("sdf speed: %d nodes (20 primitives + clipped plane under unions), 1 thread: scalar %.2f M eval/s, 8-wide %.2f "
           "M eval/s (x%.2f; %s), 8-wide baseline build %.2f M eval/s (x%.2f) [checksum %.3f]\n",
           count, ev / (t1 - t0) * 1e-6, ev / (t2 - t1) * 1e-6, (t1 - t0) / (t2 - t1), have_avx2() ? "AVX2" : "baseline",
           ev / (t3 - t2) * 1e-6, (t1 - t0) / (t3 - t2), sink);
    fv_sdf_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_box),
        cmocka_unit_test(test_torus_capsule_cylinder),
        cmocka_unit_test(test_cone_plane),
        cmocka_unit_test(test_heightfield),
        cmocka_unit_test(test_operators),
        cmocka_unit_test(test_transform),
        cmocka_unit_test(test_repeat),
        cmocka_unit_test(test_lipschitz_and_bound),
        cmocka_unit_test(test_wide_equals_scalar),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_speed_report),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
