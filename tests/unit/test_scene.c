/* Tests of the scene model and its Embree queries (src/scene/scene.c, light.c): hits at known
 * distances, dynamic objects moving with time, the static/dynamic ray sets, the NaN and
 * degenerate-triangle guard, and refusals of bad input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>
#include "core/rng.h"
#include "scene/light.h"
#include "scene/scene_impl.h"
#include "testkit.h"

/* Unit square in the y=0 plane, [0,1]x[0,1] in x,z, normal +y (wound counter-clockwise from above). */
static const fv_vec3 k_quad[4] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}};
static const uint32_t k_quad_idx[6] = {0, 1, 2, 0, 2, 3};

static int add_quad(fv_scene *s, int mat, const char *name)
{
    fv_mesh_desc m = {name, k_quad, 4, NULL, k_quad_idx, 2, NULL, mat, NULL};
    int id = -1;
    fv_error err;
    assert_int_equal(fv_scene_add_mesh(s, &m, NULL, &id, &err), FV_OK);
    return id;
}

static fv_scene *quad_scene(int *mat_out)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    add_quad(s, mat, "floor");
    if (mat_out) *mat_out = mat;
    return s;
}

static void test_intersect_quad(void **st)
{
    (void)st;
    fv_scene *s = quad_scene(NULL);
    fv_error err;
    fv_test_warnings cap = {0};
    fv_log log = {fv_test_warn, &cap};
    assert_int_equal(fv_scene_commit(s, &log, &err), FV_OK);
    assert_int_equal(cap.count, 1); /* no light -> a default light, and a warning saying so */
    assert_non_null(strstr(cap.last, "no lights"));
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(0.25f, 2.0f, 0.5f), fv_v3(0, -1, 0), INFINITY, &h));
    assert_float_equal(h.t, 2.0f, 1e-5);
    assert_float_equal(h.ng.y, 1.0f, 1e-6);
    assert_float_equal(h.p.x, 0.25f, 1e-6);
    assert_int_equal(h.obj, 0);
    /* Misses beside the quad, and stops at tmax. */
    assert_false(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(1.5f, 2.0f, 0.5f), fv_v3(0, -1, 0), INFINITY, &h));
    assert_false(fv_scene_occluded(s, FV_TRACE_ALL, fv_v3(0.5f, 2.0f, 0.5f), fv_v3(0, -1, 0), 1.9f));
    assert_true(fv_scene_occluded(s, FV_TRACE_ALL, fv_v3(0.5f, 2.0f, 0.5f), fv_v3(0, -1, 0), 2.1f));
    assert_int_equal(fv_scene_triangle_count(s), 2);
    fv_scene_destroy(s);
}

/* A dynamic quad moved up by 1 along y between t=0 and t=1 (linear): at t=0.5 it is at y=0.5+1. */
static void test_dynamic_object(void **st)
{
    (void)st;
    int mat;
    fv_scene *s = quad_scene(&mat);
    fv_error err;
    int dyn = add_quad(s, mat, "mover");
    fv_anim_key keys[2] = {{0.0, {0, 1, 0}, {0, 0, 0, 1}, {1, 1, 1}}, {1.0, {0, 2, 0}, {0, 0, 0, 1}, {1, 1, 1}}};
    assert_int_equal(fv_scene_animate_object(s, dyn, keys, 2, &err), FV_OK);
    fv_light_desc l = {FV_LIGHT_POINT, {0.5f, 5, 0.5f}, {0, -1, 0}, {1, 1, 1}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_dynamic_object_count(s), 1);
    fv_hit h;
    fv_vec3 o = fv_v3(0.5f, 5.0f, 0.5f), d = fv_v3(0, -1, 0);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h));
    assert_float_equal(h.t, 4.0f, 1e-5); /* mover at y=1 */
    assert_int_equal(h.obj, dyn);
    assert_int_equal(fv_scene_set_time(s, 0.5, &err), FV_OK);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h));
    assert_float_equal(h.t, 3.5f, 1e-5);
    assert_float_equal(h.ng.y, 1.0f, 1e-5);
    /* Static set sees only the floor; dynamic set only the mover. */
    assert_true(fv_scene_intersect(s, FV_TRACE_STATIC, o, d, INFINITY, &h));
    assert_float_equal(h.t, 5.0f, 1e-5);
    assert_int_equal(h.obj, 0);
    assert_true(fv_scene_intersect(s, FV_TRACE_DYNAMIC, o, d, INFINITY, &h));
    assert_float_equal(h.t, 3.5f, 1e-5);
    assert_int_equal(h.obj, dyn);
    assert_false(fv_scene_intersect(s, FV_TRACE_DYNAMIC, fv_v3(0.5f, 1.0f, 0.5f), d, INFINITY, &h));
    /* After the last key the object holds still. */
    assert_int_equal(fv_scene_set_time(s, 7.0, &err), FV_OK);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h));
    assert_float_equal(h.t, 3.0f, 1e-5);
    fv_scene_destroy(s);
}

/* A rotated dynamic object: quarter turn about z maps the +y normal to -x. */
static void test_dynamic_rotation_normal(void **st)
{
    (void)st;
    int mat;
    fv_scene *s = quad_scene(&mat);
    fv_error err;
    int dyn = add_quad(s, mat, "door");
    fv_quat q = fv_quat_axis_angle(fv_v3(0, 0, 1), FV_PI * 0.5f);
    fv_anim_key k = {0.0, {3, 0, 0}, q, {2, 2, 2}};
    assert_int_equal(fv_scene_animate_object(s, dyn, &k, 1, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    /* The quad now spans x=3, y in [0,2], z in [0,2]; its normal is -x. */
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(0.0f, 1.0f, 1.0f), fv_v3(1, 0, 0), INFINITY, &h));
    assert_float_equal(h.t, 3.0f, 1e-5);
    assert_float_equal(h.ng.x, -1.0f, 1e-5);
    fv_scene_destroy(s);
}

static void test_bad_geometry_dropped(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    fv_test_warnings cap = {0};
    fv_log log = {fv_test_warn, &cap};
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    int mat;
    fv_scene_add_material(s, &m, &mat, &err);
    const fv_vec3 v[7] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {NAN, 0, 0}, {2, 0, 0}, {3, 0, 0}, {INFINITY, 1, 1}};
    /* good, NaN vertex, collinear (zero area), repeated vertex, out-of-range index, infinite vertex */
    const uint32_t idx[18] = {0, 1, 2, 0, 3, 2, 0, 1, 4, 1, 1, 2, 0, 1, 99, 6, 1, 2};
    fv_mesh_desc d = {"bad", v, 7, NULL, idx, 6, NULL, mat, NULL};
    int id;
    assert_int_equal(fv_scene_add_mesh(s, &d, &log, &id, &err), FV_OK);
    assert_int_equal(fv_scene_triangle_count(s), 1);
    assert_int_equal(cap.count, 1);
    assert_non_null(strstr(cap.last, "dropped 5 of 6"));
    /* A mesh with nothing valid is refused. */
    fv_mesh_desc d2 = {"allbad", v, 7, NULL, idx + 3, 1, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d2, &log, &id, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "allbad"));
    fv_scene_destroy(s);
}

static void test_refusals(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_ERR_INVALID); /* empty */
    assert_non_null(strstr(err.msg, "empty"));
    fv_scene_destroy(s);

    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    snprintf(m.name, sizeof m.name, "wall");
    m.albedo = fv_v3(1.5f, 0, 0);
    assert_int_equal(fv_scene_add_material(s, &m, NULL, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "wall"));
    assert_non_null(strstr(err.msg, "albedo"));
    m = fv_material_default(FV_MAT_DIELECTRIC);
    m.ior = 0.5f;
    assert_int_equal(fv_scene_add_material(s, &m, NULL, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "ior"));
    fv_mesh_desc d = {"q", k_quad, 4, NULL, k_quad_idx, 2, NULL, 3, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_ERR_INVALID); /* material 3 does not exist */
    fv_light_desc l = {FV_LIGHT_SPOT, {0, 1, 0}, {0, -1, 0}, {1, 1, 1}, 40, 30};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_ERR_INVALID); /* inner > outer */
    fv_light_desc l2 = {FV_LIGHT_POINT, {NAN, 1, 0}, {0, -1, 0}, {1, 1, 1}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l2, &err), FV_ERR_INVALID);
    fv_scene_destroy(s);

    /* An emission beyond the intensity limit (fovea/limits.h) is refused when the material is
     * added, naming it: at 3e38 its power (pi L A) would overflow a float and turn the light
     * table into NaN, switching every light off. */
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    m = fv_material_default(FV_MAT_DIFFUSE);
    snprintf(m.name, sizeof m.name, "sun");
    m.emission = fv_v3s(3e38f);
    int id;
    assert_int_equal(fv_scene_add_material(s, &m, &id, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "'sun'"));
    assert_non_null(strstr(err.msg, "emission"));
    assert_null(strchr(err.msg, '\n'));
    /* At the limit it is taken; a point light the same. */
    m.emission = fv_v3s((float)FV_INTENSITY_MAX);
    assert_int_equal(fv_scene_add_material(s, &m, &id, &err), FV_OK);
    fv_light_desc hot = {FV_LIGHT_POINT, {0, 1, 0}, {0, -1, 0}, {3e38f, 1, 1}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &hot, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "intensity 3e+38"));
    fv_light_desc far = {FV_LIGHT_POINT, {1e19f, 1, 0}, {0, -1, 0}, {1, 1, 1}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &far, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "light: position: coordinate 1e+19 is beyond"));
    fv_scene_destroy(s);

    /* Geometry beyond the coordinate range: the triangles are dropped like non-finite ones, and
     * an object animated out of the range is refused at commit, naming it. */
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    m = fv_material_default(FV_MAT_DIFFUSE);
    assert_int_equal(fv_scene_add_material(s, &m, &id, &err), FV_OK);
    const fv_vec3 far_quad[4] = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {2e9f, 0, 1}};
    fv_mesh_desc fq = {"far", far_quad, 4, NULL, k_quad_idx, 2, NULL, id, NULL};
    int fid;
    assert_int_equal(fv_scene_add_mesh(s, &fq, NULL, &fid, &err), FV_OK); /* one of two triangles kept */
    fv_anim_key keys[2] = {{0, {0, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}, {1, {1e10f, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}};
    assert_int_equal(fv_scene_animate_object(s, fid, keys, 2, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "object 'far' (as animated): bounds: coordinate 1e+10 is beyond"));
    fv_scene_destroy(s);
}

/* Light sampling of a unit-area emissive quad at height 1 above the origin, facing down, with
 * radiance 2: directly below its centre, the solid-angle pdf of a sampled point at distance d is
 * d^2 / (cos * area), and its radiance is 2. */
static void test_area_light_sampling(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.emission = fv_v3s(2.0f);
    int mat;
    fv_scene_add_material(s, &m, &mat, &err);
    /* Quad x,z in [-0.5,0.5] at y=1, wound so the normal points down (-y). */
    const fv_vec3 v[4] = {{-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc d = {"light", v, 4, NULL, idx, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
    fv_test_warnings cap = {0};
    fv_log log = {fv_test_warn, &cap};
    assert_int_equal(fv_scene_commit(s, &log, &err), FV_OK);
    assert_int_equal(cap.count, 0); /* emissive triangles are lights: no default light */
    assert_int_equal(fv_scene_light_count(s), 2);
    fv_vec3 total = fv_light_total_power(s);
    assert_float_equal(total.x, 2.0f * FV_PI * 1.0f, 1e-4); /* L * pi * A */
    /* Monte Carlo estimate of irradiance at the origin: E = sum Li cos / pdf. Exact value for a
     * square of side a at height h, centre above the point: E = L * 4 * F_corner * pi with the
     * corner form factor F(X=Y=0.5) = (1/2pi) * 2 * (0.5/sqrt(1.25)) * atan(0.5/sqrt(1.25)) = 0.0613...
     * so E = 2 * pi * 4 * 0.061343 ... computed below in double precision. */
    double X = 0.5, c = X / sqrt(1.0 + X * X);
    double Fcorner = (1.0 / (2.0 * M_PI)) * 2.0 * c * atan(c);
    double E_exact = 2.0 * M_PI * 4.0 * Fcorner;
    double E = 0.0;
    const int n = 200000;
    for (int i = 0; i < n; i++) {
        fv_rng r = fv_rng_make(3, (uint64_t)i, 0, 0);
        float u0 = fv_rng_next(&r), u1 = fv_rng_next(&r), u2 = fv_rng_next(&r);
        fv_light_sample ls;
        if (!fv_light_sample_li(s, fv_v3(0, 0, 0), u0, u1, u2, &ls)) continue;
        E += ls.li.x * ls.wi.y / ls.pdf;
        /* the MIS density agrees with the sampling density */
        fv_hit h;
        assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(0, 0, 0), ls.wi, INFINITY, &h));
        float pdf2 = fv_light_pdf_li(s, h.obj, h.prim, fv_v3(0, 0, 0), h.p, h.ng, ls.wi);
        assert_float_equal(pdf2, ls.pdf, 1e-3f * ls.pdf);
    }
    E /= n;
    assert_float_equal(E, E_exact, 0.01 * E_exact);
    /* Above the light (behind its emitting side) nothing is sampled. */
    fv_light_sample ls;
    assert_false(fv_light_sample_li(s, fv_v3(0, 2, 0), 0.3f, 0.3f, 0.3f, &ls));
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_intersect_quad),       cmocka_unit_test(test_dynamic_object),
        cmocka_unit_test(test_dynamic_rotation_normal), cmocka_unit_test(test_bad_geometry_dropped),
        cmocka_unit_test(test_refusals),             cmocka_unit_test(test_area_light_sampling),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
