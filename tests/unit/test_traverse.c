/* Tests of the portable traversal (kernel/ktraverse.h) over an exported scene (scene/flat_export.c)
 * against Embree (scene/query.h): the same rays through both must find the same surfaces.
 *
 * Agreement, per scene (random rays from inside and outside the bounds with random directions
 * and limits, every camera ray of a small view, rays leaving the camera hits, shadow rays):
 *  - hit or miss, and for hits t within 1e-4 relative, the same object and triangle, the same
 *    material, ng and ns within 1e-3, u and v within 1e-3;
 *  - a different triangle at the same t (1e-4 relative) is a tie: on a shared edge or vertex
 *    allowed for at most 0.1% of the rays; between coplanar overlapping surfaces (cornell-fpm's
 *    cube standing on the floor seen from below, the doubled floor of Embree's Cornell box), where
 *    rounding alone picks the winner in either tracer, for at most 1%;
 *  - a hit one side misses, or a different surface farther away, happens only where a ray
 *    grazes an edge: the two Moeller-Trumbore variants round differently within an ulp or so of
 *    an edge, so we allow at most 1e-4 of the rays (well above the measured rate, which is 0 on
 *    most runs, far below anything an image would show);
 *  - occlusion and visibility disagree no more often than that.
 * A hand-worked triangle checks exact t and barycentrics; a scene with moving meshes (vertex
 * normals, non-uniform scale) and moving fields checks fv_scene_export_update.
 */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "core/rng.h"
#include "kernel/ktraverse.h"
#include "scene/flat_export.h"
#include "scene/mesh_gen.h"
#include "scene/query.h"
#include "testkit.h"

#define GRAZE_MAX 1e-4  /* hit/miss or far-surface disagreements per ray (see the banner) */
#define TIE_MAX 1e-3    /* ties on a shared edge or vertex per ray */
#define OVERLAP_MAX 1e-2 /* ties between coplanar overlapping surfaces per ray */

typedef struct tally {
    long rays, hits, exact_t, ties, coplanar, graze, occl_rays, occl_diff;
    long bad; /* real mismatches: same surface with wrong fields, or different surfaces apart */
} tally;

/* A tiny xorshift for the rays (the library's streams are keyed by pixel and frame). */
static float rnd(uint64_t *st)
{
    *st ^= *st << 13;
    *st ^= *st >> 7;
    *st ^= *st << 17;
    return (float)(*st >> 40) * (1.0f / 16777216.0f);
}

static fv_vec3 rnd_dir(uint64_t *st)
{
    float z = 2.0f * rnd(st) - 1.0f, phi = 2.0f * FV_PI * rnd(st), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return fv_v3(r * cosf(phi), r * sinf(phi), z);
}

static bool near3(fv_vec3 a, fv_vec3 b, float tol) { return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol; }

static void report(const char *what, const fv_hit *a, const fv_hit *b, bool ha, bool hb, fv_vec3 o, fv_vec3 d, float tmax)
{
    print_message("  %s: o (%.9g %.9g %.9g) d (%.9g %.9g %.9g) tmax %g: embree %s t %.9g obj %d prim %d mat %d | kernel %s t %.9g obj %d prim %d mat %d\n",
                  what, o.x, o.y, o.z, d.x, d.y, d.z, tmax, ha ? "hit" : "miss", ha ? a->t : 0.0f, ha ? a->obj : -1, ha ? a->prim : -1,
                  ha ? a->mat : -1, hb ? "hit" : "miss", hb ? b->t : 0.0f, hb ? b->obj : -1, hb ? b->prim : -1, hb ? b->mat : -1);
}

/* Whether the two triangles hit share a corner: a tie on their common edge or vertex. Otherwise
 * two surfaces overlap in one plane (a cube standing on a floor seen from below, a doubled floor)
 * and rounding picks the winner in either tracer. */
static bool shares_vertex(const fv_scene *s, const fv_hit *a, const fv_hit *b)
{
    if (fv_scene_object_kind(s, a->obj) != FV_OBJECT_MESH || fv_scene_object_kind(s, b->obj) != FV_OBJECT_MESH) return false;
    fv_vec3 p[3], q[3];
    fv_scene_triangle(s, a->obj, a->prim, &p[0], &p[1], &p[2]);
    fv_scene_triangle(s, b->obj, b->prim, &q[0], &q[1], &q[2]);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (near3(p[i], q[j], 0.0f)) return true;
    return false;
}

/* One ray through both; returns whether Embree hit (its hit in *out). */
static bool compare_ray(const fv_scene *s, const fv_kscene *k, fv_vec3 o, fv_vec3 d, float tmax, tally *c, fv_hit *out)
{
    fv_hit a, b;
    bool ha = fv_scene_intersect(s, FV_TRACE_ALL, o, d, tmax, &a);
    bool hb = fv_kscene_intersect(k, o, d, tmax, &b);
    c->rays++;
    if (out) *out = a;
    if (ha != hb) {
        if (c->graze < 5) report("hit/miss", &a, &b, ha, hb, o, d, tmax);
        c->graze++;
        return ha;
    }
    if (!ha) return false;
    c->hits++;
    c->exact_t += a.t == b.t;
    /* 1e-4 relative, plus a few ulps of the coordinates: a ray starting next to a surface has a
     * tiny t known only to the coordinates' absolute precision. */
    float scale = fmaxf(fv_max3(fv_vmax(fv_vmax(o, fv_neg(o)), fv_vmax(a.p, fv_neg(a.p)))), 1.0f) / fv_length(d);
    bool same_t = fabsf(a.t - b.t) <= 1e-4f * a.t + 8.0f * FLT_EPSILON * scale;
    if (a.obj != b.obj || a.prim != b.prim) {
        if (same_t) {
            if (shares_vertex(s, &a, &b)) c->ties++;
            else c->coplanar++;
            if (c->ties + c->coplanar <= 3) report("tie", &a, &b, ha, hb, o, d, tmax);
        } else {
            if (c->graze < 5) report("different surface", &a, &b, ha, hb, o, d, tmax);
            c->graze++;
        }
        return true;
    }
    bool ok = same_t && a.mat == b.mat && near3(a.ng, b.ng, 1e-3f) && near3(a.ns, b.ns, 1e-3f) && fabsf(a.u - b.u) <= 1e-3f &&
              fabsf(a.v - b.v) <= 1e-3f && near3(a.p, b.p, 1e-4f * fmaxf(1.0f, fv_length(a.p)));
    if (!ok) {
        if (c->bad < 5) {
            report("fields", &a, &b, ha, hb, o, d, tmax);
            print_message("    ng (%g %g %g) vs (%g %g %g), ns (%g %g %g) vs (%g %g %g), uv (%g %g) vs (%g %g)\n", a.ng.x, a.ng.y, a.ng.z,
                          b.ng.x, b.ng.y, b.ng.z, a.ns.x, a.ns.y, a.ns.z, b.ns.x, b.ns.y, b.ns.z, a.u, a.v, b.u, b.v);
        }
        c->bad++;
    }
    return true;
}

static void compare_occluded(const fv_scene *s, const fv_kscene *k, fv_vec3 o, fv_vec3 d, float tmax, tally *c)
{
    c->occl_rays++;
    if (fv_scene_occluded(s, FV_TRACE_ALL, o, d, tmax) != fv_kscene_occluded(k, o, d, tmax)) c->occl_diff++;
}

/* Random rays, the camera rays of a small view, rays leaving the camera hits, shadow rays. */
static void compare_scene(const char *name, const fv_scene *s, const fv_view *v, const fv_kscene *k, int nrandom, int w, int h, tally *c)
{
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    fv_vec3 ext = fv_sub(hi, lo);
    float diag = fv_length(ext);
    uint64_t st = 0x9e3779b97f4a7c15ull ^ (uint64_t)strlen(name) * 0x1234567ull;
    for (int i = 0; i < nrandom; i++) {
        /* Origins in the bounds grown by 20% each way: inside and outside. */
        fv_vec3 o = fv_v3(lo.x + ext.x * (1.4f * rnd(&st) - 0.2f), lo.y + ext.y * (1.4f * rnd(&st) - 0.2f),
                          lo.z + ext.z * (1.4f * rnd(&st) - 0.2f));
        fv_vec3 d = rnd_dir(&st);
        if (i % 4 == 3) d = fv_scale(d, 0.5f + 2.0f * rnd(&st)); /* non-unit directions too */
        float tmax = i % 2 ? INFINITY : diag * rnd(&st);
        compare_ray(s, k, o, d, tmax, c, NULL);
        compare_occluded(s, k, o, d, tmax, c);
    }
    if (!v) return;
    fv_camera cam;
    fv_camera_basis b;
    fv_error err;
    fv_view_camera(v, s, fv_scene_time(s), w, h, &cam);
    assert_int_equal(fv_camera_basis_make(&cam, &b, &err), FV_OK);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            fv_vec3 d = fv_camera_dir(&b, (float)x + 0.5f, (float)y + 0.5f);
            fv_hit hit;
            if (!compare_ray(s, k, cam.pos, d, INFINITY, c, &hit)) continue;
            /* A bounce and a shadow ray from the surface, as a path tracer makes them. */
            fv_vec3 nd = rnd_dir(&st);
            fv_vec3 no = fv_offset_point(s, hit.p, hit.ng, nd);
            assert_true(near3(no, fv_kscene_offset_point(k, hit.p, hit.ng, nd), 0.0f));
            compare_ray(s, k, no, nd, INFINITY, c, NULL);
            fv_vec3 q = fv_v3(lo.x + ext.x * rnd(&st), lo.y + ext.y * rnd(&st), lo.z + ext.z * rnd(&st));
            c->occl_rays++;
            if (fv_scene_visible(s, FV_TRACE_ALL, hit.p, hit.ng, q) != fv_kscene_visible(k, hit.p, hit.ng, q)) c->occl_diff++;
        }
}

static void check_tally(const char *name, const tally *c)
{
    print_message("%s: %ld rays, %ld hits (%ld with t bit-identical), ties %ld (%.2g), coplanar %ld (%.2g), graze %ld (%.2g), bad %ld; occlusion %ld rays, %ld differ (%.2g)\n",
                  name, c->rays, c->hits, c->exact_t, c->ties, (double)c->ties / (double)c->rays, c->coplanar, (double)c->coplanar / (double)c->rays,
                  c->graze, (double)c->graze / (double)c->rays, c->bad,
                  c->occl_rays, c->occl_diff, c->occl_rays ? (double)c->occl_diff / (double)c->occl_rays : 0.0);
    assert_true(c->rays > 0);
    assert_int_equal(c->bad, 0);
    assert_true((double)c->ties <= TIE_MAX * (double)c->rays);
    assert_true((double)c->coplanar <= OVERLAP_MAX * (double)c->rays);
    assert_true((double)c->graze <= GRAZE_MAX * (double)c->rays);
    assert_true((double)c->occl_diff <= GRAZE_MAX * (double)c->occl_rays);
}

static fv_scene_export *export_of(const fv_scene *s, const char *name)
{
    fv_scene_export *x = NULL;
    fv_error err;
    if (fv_scene_export_create(s, &x, &err) != FV_OK) fail_msg("%s: %s", name, err.msg);
    fv_scene_export_stats st;
    fv_scene_export_stats_get(x, &st);
    print_message("%s: %d triangles, %d nodes (%zu B each), %d leaves, depth %d, %d instances, %d top nodes, %.1f MB, built in %.1f ms\n",
                  name, st.triangles, st.nodes, sizeof(fv_knode), st.leaves, st.max_depth, st.instances, st.tnodes,
                  (double)st.bytes / 1048576.0, st.build_ms);
    return x;
}

/* exact_t: every hit's t must be bit-identical (static fields: both tracers run the same scalar
 * SDF kernel on the same world-space ray). */
static void run_builtin(const char *name, int nrandom, int w, int h, bool exact_t)
{
    fv_scene *s;
    fv_view *v;
    fv_error err;
    if (fv_scene_load(name, NULL, &s, &v, &err) != FV_OK) fail_msg("%s: %s", name, err.msg);
    fv_scene_export *x = export_of(s, name);
    tally c = {0};
    compare_scene(name, s, v, fv_scene_export_view(x), nrandom, w, h, &c);
    check_tally(name, &c);
    if (exact_t) assert_int_equal(c.exact_t, c.hits);
    fv_scene_export_destroy(x);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_cornell(void **state)
{
    (void)state;
    run_builtin("cornell", 40000, 64, 48, false);
}

/* Single-thread speed of both on the same rays, printed for the docs (not asserted: machines
 * differ and the portable loop is written for GPUs, not for one CPU core). */
static void time_rays(const char *name, const fv_scene *s, const fv_kscene *k)
{
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    fv_vec3 ext = fv_sub(hi, lo), c = fv_scale(fv_add(lo, hi), 0.5f);
    enum { N = 100000 };
    uint64_t st = 77;
    double t0 = fv_time_ms();
    int ha = 0, hb = 0;
    for (int i = 0; i < N; i++) {
        fv_vec3 o = fv_v3(c.x + 0.3f * ext.x * (rnd(&st) - 0.5f), c.y + 0.3f * ext.y * (rnd(&st) - 0.5f), c.z + 0.3f * ext.z * (rnd(&st) - 0.5f));
        fv_hit h;
        ha += fv_scene_intersect(s, FV_TRACE_ALL, o, rnd_dir(&st), INFINITY, &h);
    }
    double t1 = fv_time_ms();
    st = 77;
    for (int i = 0; i < N; i++) {
        fv_vec3 o = fv_v3(c.x + 0.3f * ext.x * (rnd(&st) - 0.5f), c.y + 0.3f * ext.y * (rnd(&st) - 0.5f), c.z + 0.3f * ext.z * (rnd(&st) - 0.5f));
        fv_hit h;
        hb += fv_kscene_intersect(k, o, rnd_dir(&st), INFINITY, &h);
    }
    double t2 = fv_time_ms();
    print_message("%s: %d random rays from the middle, one thread: Embree %.2f Mrays/s, kernel %.2f Mrays/s (%d / %d hits)\n", name, N,
                  N / (t1 - t0) * 1e-3, N / (t2 - t1) * 1e-3, ha, hb);
}

static void test_city(void **state)
{
    (void)state;
    run_builtin("city", 60000, 96, 72, false);
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_load("city", NULL, &s, NULL, &err), FV_OK);
    fv_scene_export *x = export_of(s, "city");
    time_rays("city", s, fv_scene_export_view(x));
    fv_scene_export_destroy(x);
    fv_scene_destroy(s);
}

static void test_sdf_primitives(void **state)
{
    (void)state;
    run_builtin("sdf-primitives", 20000, 64, 48, true);
}

/* The moving mirror cube of cornell-fpm at two times: the export follows fv_scene_set_time. */
static void test_dynamic_builtin(void **state)
{
    (void)state;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell-fpm", NULL, &s, &v, &err), FV_OK);
    fv_scene_export *x = export_of(s, "cornell-fpm");
    const double times[3] = {0.0, 2.0, 3.5};
    int moving = -1;
    for (int i = 0; i < fv_scene_object_count(s); i++)
        if (fv_scene_object_dynamic(s, i)) moving = i;
    assert_true(moving >= 0);
    for (int ti = 0; ti < 3; ti++) {
        assert_int_equal(fv_scene_set_time(s, times[ti], &err), FV_OK);
        assert_int_equal(fv_scene_export_update(x, s, &err), FV_OK);
        const fv_kscene *k = fv_scene_export_view(x);
        tally c = {0};
        compare_scene("cornell-fpm", s, v, k, 20000, 48, 36, &c);
        check_tally("cornell-fpm", &c);
        /* Rays at the moving cube's centre now, from the camera: both find the cube. */
        fv_vec3 lo, hi;
        fv_scene_object_bounds(s, moving, &lo, &hi);
        fv_camera cam;
        fv_view_camera(v, s, times[ti], 16, 16, &cam);
        fv_vec3 d = fv_normalize(fv_sub(fv_scale(fv_add(lo, hi), 0.5f), cam.pos));
        fv_hit a, b;
        assert_true(fv_scene_intersect(s, FV_TRACE_ALL, cam.pos, d, INFINITY, &a));
        assert_true(fv_kscene_intersect(k, cam.pos, d, INFINITY, &b));
        assert_int_equal(a.obj, moving);
        assert_int_equal(b.obj, moving);
        assert_true(fabsf(a.t - b.t) <= 1e-4f * a.t);
    }
    fv_scene_export_stats st;
    fv_scene_export_stats_get(x, &st);
    print_message("cornell-fpm: update (top level of %d instances) %.3f ms\n", st.instances, st.update_ms);
    fv_scene_export_destroy(x);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* Moving meshes with vertex normals under rotation and non-uniform scale, moving and static
 * fields, over a static floor. */
static fv_scene *moving_scene(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    int m0, m1;
    snprintf(m.name, sizeof m.name, "a");
    assert_int_equal(fv_scene_add_material(s, &m, &m0, &err), FV_OK);
    snprintf(m.name, sizeof m.name, "b");
    assert_int_equal(fv_scene_add_material(s, &m, &m1, &err), FV_OK);
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_grid(&mb, fv_v3(-4, 0, -4), fv_v3(8, 0, 0), fv_v3(0, 0, 8), 6, 6, m0);
    assert_int_equal(fv_meshbuf_add(&mb, s, "floor", NULL, NULL, &err), FV_OK);
    fv_meshbuf_clear(&mb);
    fv_mesh_sphere(&mb, fv_v3(0, 0, 0), 0.7f, 24, 12, false, m1);
    int ball;
    assert_int_equal(fv_meshbuf_add(&mb, s, "ball", NULL, &ball, &err), FV_OK);
    fv_meshbuf_clear(&mb);
    fv_mesh_box(&mb, fv_v3(0, 0, 0), fv_v3(0.5f, 0.3f, 0.4f), 20.0f, m0);
    int box;
    assert_int_equal(fv_meshbuf_add(&mb, s, "box", NULL, &box, &err), FV_OK);
    fv_meshbuf_free(&mb);

    fv_sdf_node n[3];
    memset(n, 0, sizeof n);
    n[0].kind = FV_SDF_SPHERE;
    n[0].p[0] = 0.5f;
    n[0].material = m1;
    n[0].q = (fv_quat){0, 0, 0, 1};
    n[1].kind = FV_SDF_BOX;
    n[1].v[0] = fv_v3(0.4f, 0.4f, 0.4f);
    n[1].material = m0;
    n[1].q = (fv_quat){0, 0, 0, 1};
    n[2].kind = FV_SDF_SMOOTH_UNION;
    n[2].a = 0;
    n[2].b = 1;
    n[2].p[0] = 0.2f;
    n[2].q = (fv_quat){0, 0, 0, 1};
    int field, still;
    if (fv_scene_add_sdf(s, "blob", n, 3, 2, NULL, &field, &err) != FV_OK) fail_msg("%s", err.msg);
    if (fv_scene_add_sdf(s, "still", n, 1, 0, NULL, &still, &err) != FV_OK) fail_msg("%s", err.msg);

    fv_anim_key k[3];
    for (int i = 0; i < 3; i++) {
        k[i].time = i;
        k[i].translate = fv_v3(-2.0f + 2.0f * (float)i, 1.0f + 0.3f * (float)i, 0.5f * (float)i);
        k[i].rotate = fv_quat_axis_angle(fv_v3(0.3f, 1, 0.2f), 0.8f * (float)i);
        k[i].scale = fv_v3(1.0f + 0.5f * (float)i, 1.0f, 0.7f + 0.2f * (float)i);
    }
    assert_int_equal(fv_scene_animate_object(s, ball, k, 3, &err), FV_OK);
    for (int i = 0; i < 3; i++) k[i].translate = fv_v3(2.0f - 1.5f * (float)i, 0.6f, -1.5f + (float)i);
    assert_int_equal(fv_scene_animate_object(s, box, k, 3, &err), FV_OK);
    for (int i = 0; i < 3; i++) {
        k[i].translate = fv_v3(0.5f * (float)i, 1.2f, 2.0f - (float)i);
        k[i].scale = fv_v3s(1.0f + 0.25f * (float)i); /* fields keep their distance under uniform scale only */
    }
    assert_int_equal(fv_scene_animate_object(s, field, k, 3, &err), FV_OK);
    fv_light_desc l = {FV_LIGHT_POINT, fv_v3(0, 5, 0), fv_v3(0, -1, 0), fv_v3s(10.0f), 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    (void)still;
    return s;
}

static void test_dynamic_update(void **state)
{
    (void)state;
    fv_scene *s = moving_scene();
    fv_error err;
    fv_scene_export *x = export_of(s, "moving");
    fv_view *v = NULL;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    const double times[4] = {0.0, 0.7, 1.5, 2.0};
    const fv_vec3 aims[6] = {{0, 10, 0}, {0, -10, 0}, {10, 0, 0}, {-10, 0, 0}, {0, 0, 10}, {0, 0, -10}};
    for (int ti = 0; ti < 4; ti++) {
        assert_int_equal(fv_scene_set_time(s, times[ti], &err), FV_OK);
        assert_int_equal(fv_scene_export_update(x, s, &err), FV_OK);
        const fv_kscene *k = fv_scene_export_view(x);
        tally c = {0};
        compare_scene("moving", s, v, k, 6000, 48, 36, &c);
        check_tally("moving", &c);
        /* Each moving object, aimed at from outside the scene along an axis where Embree finds
         * it first: the kernel finds it there too, where it now stands. */
        for (int o = 0; o < fv_scene_object_count(s); o++) {
            if (!fv_scene_object_dynamic(s, o)) continue;
            fv_vec3 lo, hi;
            fv_scene_object_bounds(s, o, &lo, &hi);
            fv_vec3 ctr = fv_scale(fv_add(lo, hi), 0.5f);
            int found = 0;
            for (int a6 = 0; a6 < 6; a6++) {
                fv_vec3 org = fv_add(ctr, fv_add(aims[a6], fv_v3(0.011f, 0.007f, 0.013f)));
                fv_vec3 d = fv_normalize(fv_sub(ctr, org));
                fv_hit a, b;
                if (!fv_scene_intersect(s, FV_TRACE_ALL, org, d, INFINITY, &a) || a.obj != o) continue;
                assert_true(fv_kscene_intersect(k, org, d, INFINITY, &b));
                assert_int_equal(b.obj, o);
                assert_true(fabsf(a.t - b.t) <= 1e-4f * a.t);
                found++;
            }
            assert_true(found > 0);
        }
    }
    /* The time again: nothing to do. */
    assert_int_equal(fv_scene_export_update(x, s, &err), FV_OK);
    fv_view_destroy(v);
    fv_scene_export_destroy(x);
    fv_scene_destroy(s);
}

/* A third-party mesh: Embree's own Cornell box when installed (Debian's embree-tools; absent where
 * scripts/gpu-check carries this test), else one of ours from the test data. */
static void test_third_party_mesh(void **state)
{
    (void)state;
    char ours[512];
    const char *paths[] = {"/usr/share/doc/embree3/models/cornell_box.obj", fv_test_data("materials.obj", ours, sizeof ours)};
    for (int i = 0; i < 2; i++) {
        FILE *f = fopen(paths[i], "rb");
        if (!f) {
            print_message("%s: absent, skipped\n", paths[i]);
            continue;
        }
        fclose(f);
        fv_scene *s;
        fv_view *v;
        fv_error err;
        if (fv_scene_load(paths[i], NULL, &s, &v, &err) != FV_OK) fail_msg("%s: %s", paths[i], err.msg);
        fv_scene_export *x = export_of(s, paths[i]);
        tally c = {0};
        compare_scene(paths[i], s, v, fv_scene_export_view(x), 20000, 48, 36, &c);
        check_tally(paths[i], &c);
        fv_scene_export_destroy(x);
        fv_view_destroy(v);
        fv_scene_destroy(s);
        return;
    }
    print_message("no third-party mesh found: skipped\n");
    skip();
}

/* One triangle, one ray, worked by hand: all values exact in binary. */
static void test_hand_worked(void **state)
{
    (void)state;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    const fv_vec3 p[3] = {{1, 1, 1}, {3, 1, 1}, {1, 5, 1}};
    const uint32_t idx[3] = {0, 1, 2};
    fv_mesh_desc d = {"tri", p, 3, NULL, idx, 1, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
    fv_light_desc l = {FV_LIGHT_POINT, fv_v3(0, 0, 5), fv_v3(0, -1, 0), fv_v3s(1.0f), 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    fv_scene_export *x = NULL;
    assert_int_equal(fv_scene_export_create(s, &x, &err), FV_OK);
    const fv_kscene *k = fv_scene_export_view(x);
    /* From (1.5, 2, 4) along (0, 0, -2): the plane z = 1 at t = 1.5; the point (1.5, 2, 1) is
     * v0 + 0.25 (v1 - v0) + 0.25 (v2 - v0). */
    fv_hit h;
    assert_true(fv_kscene_intersect(k, fv_v3(1.5f, 2.0f, 4.0f), fv_v3(0, 0, -2), INFINITY, &h));
    assert_true(h.t == 1.5f);
    assert_true(h.u == 0.25f && h.v == 0.25f);
    assert_true(h.ng.x == 0.0f && h.ng.y == 0.0f && h.ng.z == 1.0f);
    assert_true(h.ns.z == 1.0f);
    assert_true(h.p.x == 1.5f && h.p.y == 2.0f && h.p.z == 1.0f);
    assert_int_equal(h.obj, 0);
    assert_int_equal(h.prim, 0);
    assert_int_equal(h.mat, mat);
    /* The limit is inclusive as Embree's, and a shorter one misses; so does the back half-line. */
    assert_true(fv_kscene_intersect(k, fv_v3(1.5f, 2.0f, 4.0f), fv_v3(0, 0, -2), 1.5f, &h));
    assert_false(fv_kscene_intersect(k, fv_v3(1.5f, 2.0f, 4.0f), fv_v3(0, 0, -2), 1.49f, &h));
    assert_false(fv_kscene_intersect(k, fv_v3(1.5f, 2.0f, 4.0f), fv_v3(0, 0, 2), INFINITY, &h));
    assert_true(fv_kscene_occluded(k, fv_v3(1.5f, 2.0f, 4.0f), fv_v3(0, 0, -1), 10.0f));
    assert_false(fv_kscene_occluded(k, fv_v3(1.5f, 2.0f, 4.0f), fv_v3(0, 0, -1), 2.0f));
    /* Just outside the hypotenuse (u + v > 1) misses. */
    assert_false(fv_kscene_intersect(k, fv_v3(2.5f, 2.5f, 4.0f), fv_v3(0, 0, -1), INFINITY, &h));
    fv_hit e;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(1.5f, 2.0f, 4.0f), fv_v3(0, 0, -2), INFINITY, &e));
    assert_float_equal(e.t, 1.5f, 1e-6f);
    assert_float_equal(e.u, 0.25f, 1e-6f);
    assert_float_equal(e.v, 0.25f, 1e-6f);
    fv_scene_export_destroy(x);
    fv_scene_destroy(s);
}

static void test_refusals(void **state)
{
    (void)state;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_scene_export *x = (fv_scene_export *)&err; /* must come back NULL */
    fv_test_expect_fail(fv_scene_export_create(s, &x, &err), &err, FV_ERR_INVALID, "not committed", "uncommitted scene");
    assert_null(x);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_worked),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_cornell),
        cmocka_unit_test(test_city),
        cmocka_unit_test(test_sdf_primitives),
        cmocka_unit_test(test_dynamic_builtin),
        cmocka_unit_test(test_dynamic_update),
        cmocka_unit_test(test_third_party_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
