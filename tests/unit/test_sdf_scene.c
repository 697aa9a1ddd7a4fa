/* Tests of signed distance fields as scene objects (src/scene/scene_sdf.c, issue 11 "SDF scenes
 * are scenes"): Embree user geometry that sphere-traces the field. Hand-worked hits (t, normal,
 * material) on spheres and a union, 8-ray packets and occlusion against single rays, a mesh and
 * an SDF in one scene (the nearer wins), a moving SDF, SDF-only scenes, refusals of bad input,
 * `pt` on an SDF sphere against `pt` on a finely tessellated sphere, and the JSON "sdf" block: a
 * tree that loads, and bad trees refused with the JSON path of the fault. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include "core/rng.h"
#include "scene/mesh_gen.h"
#include "scene/query.h"
#include "testkit.h"

static fv_sdf_node leaf(fv_sdf_kind k, float p0, float p1, int mat)
{
    fv_sdf_node n;
    memset(&n, 0, sizeof n);
    n.kind = k;
    n.p[0] = p0;
    n.p[1] = p1;
    n.q = (fv_quat){0, 0, 0, 1};
    n.material = mat;
    return n;
}

static fv_sdf_node moved(int child, fv_vec3 t)
{
    fv_sdf_node n = leaf(FV_SDF_TRANSFORM, 1.0f, 0, 0);
    n.v[0] = t;
    n.a = child;
    return n;
}

static int add_mat(fv_scene *s, const char *name, fv_vec3 albedo, fv_vec3 emission)
{
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    snprintf(m.name, sizeof m.name, "%s", name);
    m.albedo = albedo;
    m.emission = emission;
    int id = -1;
    fv_error err;
    assert_int_equal(fv_scene_add_material(s, &m, &id, &err), FV_OK);
    return id;
}

static fv_scene *new_scene(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    return s;
}

static void add_light(fv_scene *s, fv_vec3 pos, float power)
{
    fv_light_desc l = {FV_LIGHT_POINT, pos, {0, -1, 0}, {power, power, power}, 0, 0};
    fv_error err;
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
}

/* A sphere of radius 1 translated to (1, 2, 0). A ray from (1.6, 2, 5) along -z meets it where
 * x - 1 = 0.6, so z = sqrt(1 - 0.36) = 0.8: t = 4.2, normal (0.6, 0, 0.8). Head-on from (1, 2, 5):
 * t = 4, normal (0, 0, 1). */
static void test_sphere_hit(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    int red = add_mat(s, "red", fv_v3(0.8f, 0.1f, 0.1f), fv_v3s(0));
    fv_sdf_node n[2] = {leaf(FV_SDF_SPHERE, 1.0f, 0, red), moved(0, fv_v3(1, 2, 0))};
    fv_error err;
    int id = -1;
    assert_int_equal(fv_scene_add_sdf(s, "ball", n, 2, 1, NULL, &id, &err), FV_OK);
    add_light(s, fv_v3(0, 10, 0), 10);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK); /* an SDF-only scene is a scene */
    assert_int_equal(fv_scene_object_kind(s, id), FV_OBJECT_SDF);
    assert_non_null(fv_scene_object_sdf(s, id));
    assert_int_equal(fv_scene_sdf_object_count(s), 1);
    assert_int_equal(fv_scene_triangle_count(s), 0);
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    assert_true(lo.x <= 0.0f && hi.x >= 2.0f && lo.y <= 1.0f && hi.y >= 3.0f);

    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(1.6f, 2, 5), fv_v3(0, 0, -1), INFINITY, &h));
    assert_float_equal(h.t, 4.2f, 1e-4);
    assert_float_equal(h.ng.x, 0.6f, 1e-3);
    assert_float_equal(h.ng.y, 0.0f, 1e-3);
    assert_float_equal(h.ng.z, 0.8f, 1e-3);
    assert_float_equal(h.ns.x, h.ng.x, 0);
    assert_int_equal(h.mat, red);
    assert_int_equal(h.obj, id);
    assert_int_equal(h.prim, 0);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(1, 2, 5), fv_v3(0, 0, -2), INFINITY, &h));
    assert_float_equal(h.t, 2.0f, 1e-4); /* d not unit: t in units of d */
    assert_float_equal(h.ng.z, 1.0f, 1e-4);
    assert_float_equal(h.p.z, 1.0f, 1e-4);
    /* Misses beside it, and stops at tmax. */
    assert_false(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(2.1f, 2, 5), fv_v3(0, 0, -1), INFINITY, &h));
    assert_false(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(1, 2, 5), fv_v3(0, 0, -1), 3.9f, &h));
    assert_false(fv_scene_occluded(s, FV_TRACE_ALL, fv_v3(1, 2, 5), fv_v3(0, 0, -1), 3.9f));
    assert_true(fv_scene_occluded(s, FV_TRACE_ALL, fv_v3(1, 2, 5), fv_v3(0, 0, -1), 4.1f));
    /* From inside (a refracted ray): the far side, normal still outward. */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(1, 2, 0), fv_v3(0, 0, -1), INFINITY, &h));
    assert_float_equal(h.t, 1.0f, 1e-4);
    assert_float_equal(h.ng.z, -1.0f, 1e-4);
    /* A ray leaving the surface from the offset point does not hit itself. */
    fv_vec3 p = fv_offset_point(s, fv_v3(1, 3, 0), fv_v3(0, 1, 0), fv_v3(0, 1, 0));
    assert_false(fv_scene_intersect(s, FV_TRACE_ALL, p, fv_v3(0.3f, 1, 0), INFINITY, &h));
    assert_true(fv_scene_visible(s, FV_TRACE_ALL, fv_v3(1, 3, 0), fv_v3(0, 1, 0), fv_v3(0, 10, 0)));
    assert_false(fv_scene_visible(s, FV_TRACE_ALL, fv_v3(1, 1, 0), fv_v3(0, -1, 0), fv_v3(0, 10, 0)));
    fv_scene_destroy(s);
}

/* Union of a red sphere (radius 1 at x = -2) and a blue box (half 1 at x = +2): each leaf's own
 * material where it is hit. Returns the committed scene. */
static fv_scene *union_scene(int *red, int *blue)
{
    fv_scene *s = new_scene();
    *red = add_mat(s, "red", fv_v3(0.8f, 0.1f, 0.1f), fv_v3s(0));
    *blue = add_mat(s, "blue", fv_v3(0.1f, 0.1f, 0.8f), fv_v3s(0));
    fv_sdf_node box = leaf(FV_SDF_BOX, 0, 0, *blue);
    box.v[0] = fv_v3s(1.0f);
    fv_sdf_node u = leaf(FV_SDF_UNION, 0, 0, 0);
    u.a = 2;
    u.b = 3;
    fv_sdf_node n[5] = {leaf(FV_SDF_SPHERE, 1.0f, 0, *red), box, moved(0, fv_v3(-2, 0, 0)), moved(1, fv_v3(2, 0, 0)), u};
    fv_error err;
    assert_int_equal(fv_scene_add_sdf(s, "pair", n, 5, 4, NULL, NULL, &err), FV_OK);
    add_light(s, fv_v3(0, 10, 0), 10);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

static void test_union_materials(void **st)
{
    (void)st;
    int red, blue;
    fv_scene *s = union_scene(&red, &blue);
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(-2, 0, 5), fv_v3(0, 0, -1), INFINITY, &h));
    assert_float_equal(h.t, 4.0f, 1e-4);
    assert_int_equal(h.mat, red);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(2.5f, 0.5f, 5), fv_v3(0, 0, -1), INFINITY, &h));
    assert_float_equal(h.t, 4.0f, 1e-4);
    assert_float_equal(h.ng.z, 1.0f, 1e-3);
    assert_int_equal(h.mat, blue);
    /* The box's top from above. */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(2.2f, 4, 0.3f), fv_v3(0, -1, 0), INFINITY, &h));
    assert_float_equal(h.t, 3.0f, 1e-4);
    assert_float_equal(h.ng.y, 1.0f, 1e-3);
    fv_scene_destroy(s);
}

/* Random rays from one origin: packets (fv_scene_intersect8, Embree's N-wide callback) give the
 * single rays' hits, and occlusion agrees with the closest hit. */
static void test_packets_and_occlusion(void **st)
{
    (void)st;
    int red, blue;
    fv_scene *s = union_scene(&red, &blue);
    fv_rng r = fv_rng_stream(7, FV_STREAM_CAMERA, 0, 0, 0);
    fv_vec3 o = fv_v3(0.3f, 1.5f, 6);
    int hits = 0, agree = 0;
    for (int k = 0; k < 64; k++) {
        fv_vec3 d[8];
        for (int i = 0; i < 8; i++)
            d[i] = fv_normalize(fv_v3(fv_rng_next(&r) * 7 - 3.5f, fv_rng_next(&r) * 3 - 2.0f, -6.0f));
        fv_hit h8[8];
        bool ok[8];
        fv_scene_intersect8(s, o, d, 8, h8, ok);
        for (int i = 0; i < 8; i++) {
            fv_hit h1;
            bool one = fv_scene_intersect(s, FV_TRACE_ALL, o, d[i], INFINITY, &h1);
            assert_int_equal(one, ok[i]);
            if (!one) {
                assert_false(fv_scene_occluded(s, FV_TRACE_ALL, o, d[i], 100.0f));
                continue;
            }
            hits++;
            assert_float_equal(h8[i].t, h1.t, 1e-5);
            assert_int_equal(h8[i].mat, h1.mat);
            assert_float_equal(h8[i].ng.x, h1.ng.x, 1e-5);
            assert_true(fv_scene_occluded(s, FV_TRACE_ALL, o, d[i], h1.t + 1e-3f));
            assert_false(fv_scene_occluded(s, FV_TRACE_ALL, o, d[i], h1.t - 1e-3f));
            agree++;
        }
    }
    assert_true(hits > 100 && hits < 500); /* both hits and misses were exercised */
    assert_int_equal(agree, hits);
    fv_scene_destroy(s);
}

/* A mesh floor (y = 0, [-5, 5]^2) under an SDF sphere resting on it (radius 1 at y = 1): from
 * above the sphere wins at x = 0 and the floor beside it; from below the floor wins. */
static void test_mesh_and_sdf(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    int grey = add_mat(s, "grey", fv_v3s(0.5f), fv_v3s(0));
    int red = add_mat(s, "red", fv_v3(0.8f, 0.1f, 0.1f), fv_v3s(0));
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_axis_quad(&mb, 1, 0.0f, -5, -5, 5, 5, 1, grey);
    fv_error err;
    int floor = -1, ball = -1;
    assert_int_equal(fv_meshbuf_add(&mb, s, "floor", NULL, &floor, &err), FV_OK);
    fv_meshbuf_free(&mb);
    fv_sdf_node n[2] = {leaf(FV_SDF_SPHERE, 1.0f, 0, red), moved(0, fv_v3(0, 1, 0))};
    assert_int_equal(fv_scene_add_sdf(s, "ball", n, 2, 1, NULL, &ball, &err), FV_OK);
    add_light(s, fv_v3(0, 10, 0), 10);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_object_kind(s, floor), FV_OBJECT_MESH);
    assert_null(fv_scene_object_sdf(s, floor));
    assert_int_equal(fv_scene_triangle_count(s), 2);
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(0, 5, 0), fv_v3(0, -1, 0), INFINITY, &h));
    assert_int_equal(h.obj, ball);
    assert_float_equal(h.t, 3.0f, 1e-4);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(3, 5, 0), fv_v3(0, -1, 0), INFINITY, &h));
    assert_int_equal(h.obj, floor);
    assert_int_equal(h.mat, grey);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(0.5f, -1, 0), fv_v3(0, 1, 0), INFINITY, &h));
    assert_int_equal(h.obj, floor);
    assert_float_equal(h.t, 1.0f, 1e-5);
    /* The floor under the ball is in its shadow. */
    assert_false(fv_scene_visible(s, FV_TRACE_ALL, fv_v3(0.2f, 0, 0.1f), fv_v3(0, 1, 0), fv_v3(0, 10, 0)));
    assert_true(fv_scene_visible(s, FV_TRACE_ALL, fv_v3(3, 0, 0), fv_v3(0, 1, 0), fv_v3(0, 10, 0)));
    fv_scene_destroy(s);
}

/* An SDF made dynamic is instanced like a mesh: it moves with the time, in the dynamic set. */
static void test_dynamic_sdf(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    int red = add_mat(s, "red", fv_v3(0.8f, 0.1f, 0.1f), fv_v3s(0));
    fv_sdf_node n = leaf(FV_SDF_SPHERE, 1.0f, 0, red);
    fv_error err;
    int id = -1;
    assert_int_equal(fv_scene_add_sdf(s, "ball", &n, 1, 0, NULL, &id, &err), FV_OK);
    fv_anim_key keys[2] = {{0.0, {0, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}, {1.0, {4, 0, 0}, {0, 0, 0, 1}, {2, 2, 2}}};
    assert_int_equal(fv_scene_animate_object(s, id, keys, 2, &err), FV_OK);
    add_light(s, fv_v3(0, 10, 0), 10);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_true(fv_scene_object_dynamic(s, id));
    assert_int_equal(fv_scene_set_time(s, 0.5, &err), FV_OK); /* centre (2, 0, 0), radius 1.5 */
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(2, 0, 5), fv_v3(0, 0, -1), INFINITY, &h));
    assert_float_equal(h.t, 3.5f, 1e-3);
    assert_float_equal(h.ng.z, 1.0f, 1e-3);
    assert_int_equal(h.mat, red);
    assert_true(fv_scene_intersect(s, FV_TRACE_DYNAMIC, fv_v3(2, 0, 5), fv_v3(0, 0, -1), INFINITY, &h));
    assert_false(fv_scene_intersect(s, FV_TRACE_STATIC, fv_v3(2, 0, 5), fv_v3(0, 0, -1), INFINITY, &h));
    fv_vec3 d[8];
    for (int i = 0; i < 8; i++) d[i] = fv_v3(0, 0, -1);
    fv_hit h8[8];
    bool ok[8];
    assert_int_equal(fv_scene_intersect8(s, fv_v3(2, 0, 5), d, 8, h8, ok), 8);
    assert_float_equal(h8[3].t, 3.5f, 1e-3);
    fv_scene_destroy(s);
}

static void test_refusals(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    int red = add_mat(s, "red", fv_v3(0.8f, 0.1f, 0.1f), fv_v3s(0));
    int lamp = add_mat(s, "lamp", fv_v3s(0), fv_v3s(5));
    fv_error err;
    fv_sdf_node n[2] = {leaf(FV_SDF_SPHERE, 1.0f, 0, 7), moved(0, fv_v3(0, 0, 0))};
    fv_test_expect_fail(fv_scene_add_sdf(s, "bad", n, 2, 1, NULL, NULL, &err), &err, FV_ERR_INVALID, "node 0", "material 7");
    fv_test_expect_msg(&err, "material id 7", "material 7");
    n[0].material = lamp;
    fv_test_expect_fail(fv_scene_add_sdf(s, "glow", n, 2, 1, NULL, NULL, &err), &err, FV_ERR_INVALID, "emissive", "emissive leaf");
    fv_test_expect_msg(&err, "sdf 'glow'", "emissive leaf");
    n[0].material = red;
    n[0].p[0] = -1.0f;
    fv_test_expect_fail(fv_scene_add_sdf(s, "neg", n, 2, 1, NULL, NULL, &err), &err, FV_ERR_INVALID, "sdf 'neg'", "negative radius");
    n[0].p[0] = NAN;
    fv_test_expect_fail(fv_scene_add_sdf(s, "nan", n, 2, 1, NULL, NULL, &err), &err, FV_ERR_INVALID, "node 0", "NaN radius");
    assert_int_equal(fv_scene_object_count(s), 0);
    /* Still nothing to commit. */
    fv_test_expect_fail(fv_scene_commit(s, NULL, &err), &err, FV_ERR_INVALID, "no objects", "empty scene");
    fv_scene_destroy(s);
}

/* ---- pt on an SDF sphere against pt on a tessellated sphere ---- */

static fv_film *render_pt(fv_scene *s, const fv_camera *cam, uint64_t seed)
{
    fv_error err;
    const char *kv[] = {"spp=32", NULL};
    fv_params *p = fv_test_params(kv);
    fv_technique *t;
    assert_int_equal(fv_technique_create("pt", s, p, NULL, &t, &err), FV_OK);
    fv_film *film;
    assert_int_equal(fv_film_create(cam->width, cam->height, 0, &film, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, NULL);
    fr.seed = seed;
    fr.camera = cam;
    fr.gaze.x = fr.gaze.y = 0.5f;
    fv_stats stats;
    fv_stats_clear(&stats);
    assert_int_equal(fv_technique_render(t, &fr, film, &stats, &err), FV_OK);
    assert_true(fv_stats_get_count(&stats, "nan_samples") == 0);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return film;
}

/* A glossy-free diffuse sphere (radius 1 at y = 1) on a mesh floor, one point light: as an SDF or
 * as a UV sphere of 256 x 128 segments with smooth normals (its facets lie at most
 * 1 - cos(pi/256) = 7.5e-5 inside the sphere, far below what a 64 x 64 image resolves). */
static fv_scene *sphere_scene(bool sdf)
{
    fv_scene *s = new_scene();
    int grey = add_mat(s, "grey", fv_v3s(0.6f), fv_v3s(0));
    int red = add_mat(s, "red", fv_v3(0.8f, 0.3f, 0.2f), fv_v3s(0));
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_axis_quad(&mb, 1, 0.0f, -6, -6, 6, 6, 1, grey);
    fv_error err;
    assert_int_equal(fv_meshbuf_add(&mb, s, "floor", NULL, NULL, &err), FV_OK);
    fv_meshbuf_clear(&mb);
    if (sdf) {
        fv_sdf_node n[2] = {leaf(FV_SDF_SPHERE, 1.0f, 0, red), moved(0, fv_v3(0, 1, 0))};
        assert_int_equal(fv_scene_add_sdf(s, "ball", n, 2, 1, NULL, NULL, &err), FV_OK);
    } else {
        fv_mesh_sphere(&mb, fv_v3(0, 1, 0), 1.0f, 256, 128, false, red);
        assert_int_equal(fv_meshbuf_add(&mb, s, "ball", NULL, NULL, &err), FV_OK);
    }
    fv_meshbuf_free(&mb);
    add_light(s, fv_v3(2, 5, 3), 30);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

static void diff(fv_film *a, fv_film *b, double *mean_a, double *mean_b, double *rms)
{
    const float *ca = fv_film_color(a), *cb = fv_film_color(b);
    size_t n = 3 * (size_t)fv_film_width(a) * fv_film_height(a);
    double sa = 0, sb = 0, sd = 0;
    for (size_t i = 0; i < n; i++) {
        sa += ca[i];
        sb += cb[i];
        sd += (double)(ca[i] - cb[i]) * (ca[i] - cb[i]);
    }
    *mean_a = sa / n;
    *mean_b = sb / n;
    *rms = sqrt(sd / n);
}

/* The tolerance is the noise itself: two renders of the mesh sphere with different seeds differ
 * per pixel by the path tracer's noise (indirect light off the floor, edge sampling); the SDF
 * render against the mesh render with a third seed must differ by no more than that plus 10%
 * (what a 1e-4 hit band and the facets could add is far below it), and the image means, which
 * average the noise out, must agree within 1%. */
static void test_pt_sdf_matches_mesh(void **st)
{
    (void)st;
    fv_scene *ms = sphere_scene(false), *ss = sphere_scene(true);
    fv_camera cam = {fv_v3(0, 2.5f, 6), fv_v3(0, 0.8f, 0), fv_v3(0, 1, 0), 35.0f, 64, 64};
    fv_film *m1 = render_pt(ms, &cam, 1), *m2 = render_pt(ms, &cam, 2), *s3 = render_pt(ss, &cam, 3);
    double mm1, mm2, ms3, rms_noise, rms_sdf, d0, d1;
    diff(m1, m2, &mm1, &mm2, &rms_noise);
    diff(s3, m1, &ms3, &d0, &rms_sdf);
    double rms2;
    diff(s3, m2, &d0, &d1, &rms2);
    double mesh_mean = 0.5 * (mm1 + mm2);
    print_message("pt sphere 64x64 spp 32: mean mesh %.5f / %.5f, sdf %.5f (%.3f%%); rms mesh-mesh %.5f, sdf-mesh %.5f / %.5f\n",
                  mm1, mm2, ms3, 100.0 * fabs(ms3 - mesh_mean) / mesh_mean, rms_noise, rms_sdf, rms2);
    assert_true(mesh_mean > 0.02);
    assert_true(fabs(ms3 - mesh_mean) < 0.01 * mesh_mean);
    assert_true(rms_sdf < 1.1 * rms_noise);
    assert_true(rms2 < 1.1 * rms_noise);
    fv_film_destroy(m1);
    fv_film_destroy(m2);
    fv_film_destroy(s3);
    fv_scene_destroy(ms);
    fv_scene_destroy(ss);
}

/* ---- the JSON "sdf" block ---- */

static const char *const k_json_head =
    "{\"materials\": {\"red\": {\"albedo\": [0.8, 0.2, 0.2]}, \"lamp\": {\"emission\": [4, 4, 4]}},\n"
    " \"objects\": [{\"name\": \"floor\", \"quad\": [[-5,0,-5],[-5,0,5],[5,0,5],[5,0,-5]], \"material\": \"red\"},\n"
    "  {\"material\": \"red\", \"sdf\": ";

/* Loads a scene whose second object's sdf block is `sdf`; returns the status, the error in err. */
static fv_status load_sdf_text(const char *sdf, fv_scene **out, fv_error *err)
{
    char path[] = "/tmp/fovea_test_sdf_XXXXXX.json";
    int fd = mkstemps(path, 5);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    fprintf(f, "%s%s}]}\n", k_json_head, sdf);
    fclose(f);
    fv_scene *s = NULL;
    fv_status st = fv_scene_load(path, NULL, &s, NULL, err);
    unlink(path);
    if (out) *out = s;
    else fv_scene_destroy(s);
    return st;
}

static void test_json_sdf(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    const char *good = "{\"union\": [{\"transform\": {\"translate\": [0, 1, 0], \"child\": {\"sphere\": {\"radius\": 1}}}},"
                       " {\"transform\": {\"translate\": [3, 1, 0], \"rotate_deg\": [0, 45, 0], \"scale\": 2, \"child\":"
                       " {\"box\": {\"half\": [0.5, 0.5, 0.5]}}}}]}";
    fv_status r = load_sdf_text(good, &s, &err);
    if (r != FV_OK) fail_msg("%s", err.msg);
    assert_int_equal(fv_scene_sdf_object_count(s), 1);
    assert_int_equal(fv_scene_object_kind(s, 1), FV_OBJECT_SDF);
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(0, 5, 0), fv_v3(0, -1, 0), INFINITY, &h));
    assert_float_equal(h.t, 3.0f, 1e-4);
    assert_int_equal(h.obj, 1);
    /* The box scaled by 2: half 1 around (3, 1, 0); its top at y = 2. */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(3, 5, 0), fv_v3(0, -1, 0), INFINITY, &h));
    assert_float_equal(h.t, 3.0f, 1e-3);
    fv_scene_destroy(s);

    static const char *const bad[][2] = {
        {"{\"union\": [{\"sphere\": {\"radius\": 1}}, {\"sphear\": {\"radius\": 1}}]}", "objects[1].sdf.union[1]: unknown field 'sphear'"},
        {"{\"union\": [{\"sphere\": {\"radius\": 1}}, {\"sphere\": {\"radius\": -1}}]}", "objects[1].sdf.union[1].sphere.radius: must be > 0"},
        {"{\"sphere\": {\"radius\": 1e999}}", "objects[1].sdf.sphere.radius: expected a finite number"},
        {"{\"sphere\": {\"radius\": \"NaN\"}}", "objects[1].sdf.sphere.radius: expected a finite number"},
        {"{\"transform\": {\"scale\": [1, 2, 1], \"child\": {\"sphere\": {\"radius\": 1}}}}", "objects[1].sdf.transform.scale: must be one number"},
        {"{\"smooth_union\": {\"k\": 0, \"children\": [{\"sphere\": {\"radius\": 1}}, {\"sphere\": {\"radius\": 1}}]}}", "objects[1].sdf.smooth_union.k: must be > 0"},
        {"{\"union\": [{\"sphere\": {\"radius\": 1}}]}", "objects[1].sdf.union: expected an array of at least 2 nodes"},
        {"{\"sphere\": {\"radius\": 1}, \"material\": \"lamp\"}", "emissive"},
        {"{\"sphere\": {\"radius\": 1}, \"material\": \"nope\"}", "objects[1].sdf.material: unknown material 'nope'"},
        {"{\"plane\": {\"normal\": [0, 1, 0]}}", "unbounded"},
        {"{\"repeat\": {\"period\": [1, 0, 0], \"count\": [2, 0, 0], \"child\": {\"sphere\": {\"radius\": 0.8}}}}", "objects[1].sdf.repeat"},
        {"{\"box\": {\"half\": [1, 1, 1]}, \"sphere\": {\"radius\": 1}}", "objects[1].sdf: give exactly one of"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        fv_test_expect_fail(load_sdf_text(bad[i][0], NULL, &err), &err, FV_ERR_INVALID, bad[i][1], bad[i][0]);
}

/* The built-in SDF scenes load (SDF objects only, lights, a camera path) and `pt` renders them
 * to a lit image (8 spp at 48 x 48 from their own camera). */
static void test_builtin_sdf_scenes(void **st)
{
    (void)st;
    const char *names[] = {"sdf-primitives", "sdf-columns", "sdf-temple"};
    for (int i = 0; i < 3; i++) {
        fv_scene *s;
        fv_view *v;
        fv_error err;
        fv_status r = fv_scene_load(names[i], NULL, &s, &v, &err);
        if (r != FV_OK) fail_msg("%s: %s", names[i], err.msg);
        assert_true(fv_scene_sdf_object_count(s) >= 1);
        assert_int_equal(fv_scene_triangle_count(s), 0);
        assert_true(fv_scene_light_count(s) >= 2);
        fv_camera cam;
        fv_view_camera(v, s, 1.0, 48, 48, &cam);
        fv_film *f = render_pt(s, &cam, 5);
        const float *c = fv_film_color(f);
        double sum = 0;
        int lit = 0;
        for (int p = 0; p < 48 * 48; p++) {
            double y = c[3 * p] + c[3 * p + 1] + c[3 * p + 2];
            sum += y;
            lit += y > 0.01;
        }
        print_message("%s: mean %.4f, %d of %d pixels lit\n", names[i], sum / (3.0 * 48 * 48), lit, 48 * 48);
        assert_true(lit > 48 * 48 / 3);
        fv_film_destroy(f);
        fv_view_destroy(v);
        fv_scene_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_hit),         cmocka_unit_test(test_union_materials), cmocka_unit_test(test_packets_and_occlusion),
        cmocka_unit_test(test_mesh_and_sdf),       cmocka_unit_test(test_dynamic_sdf),     cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_pt_sdf_matches_mesh), cmocka_unit_test(test_json_sdf),
        cmocka_unit_test(test_builtin_sdf_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
