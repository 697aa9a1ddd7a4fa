/* Tests of the view (src/scene/view.c): the camera framing a committed scene's bounds (numbers
 * worked by hand below), with and without a view, before and after commit; the view's own camera
 * resized; camera paths evaluated before, between and after their keys and refused when bad;
 * the display present and absent; the view owning its gaze path (run under ASan: no leak, no
 * double free); and the loaders returning the view, or dropping it when asked to. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"

#define DATA(f) FOVEA_TEST_DATA "/" f

static void assert_vec3(fv_vec3 v, float x, float y, float z, float tol)
{
    if (fabsf(v.x - x) > tol || fabsf(v.y - y) > tol || fabsf(v.z - z) > tol)
        fail_msg("(%g, %g, %g) != (%g, %g, %g)", v.x, v.y, v.z, x, y, z);
}

/* A 6 x 8 quad in the plane z = 5, x in [1, 7], y in [2, 10], lit by a point light (so the commit
 * adds none). Its bounds: centre (4, 6, 5), diagonal sqrt(6^2 + 8^2) = 10. Left uncommitted. */
static fv_scene *quad_scene(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    const fv_vec3 p[4] = {{1, 2, 5}, {7, 2, 5}, {7, 10, 5}, {1, 10, 5}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc d = {"quad", p, 4, NULL, idx, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
    fv_light_desc l = {FV_LIGHT_POINT, {4, 6, 20}, {0, 0, -1}, {100, 100, 100}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    return s;
}

/* The framing camera of the quad: the bounding sphere (r = 10 / 2 = 5) seen from +z with a 45
 * degree view at 1.05 r / sin(22.5 deg) = 5.25 / 0.382683 = 13.718911 from the centre, so at
 * (4, 6, 18.718911), looking at (4, 6, 5), up +y. Without a committed scene there is nothing to
 * frame: the base is zero but for the size. */
static void test_framing(void **st)
{
    (void)st;
    fv_scene *s = quad_scene();
    fv_view *v;
    fv_error err;
    fv_camera c;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    assert_false(fv_view_has_camera(v));
    assert_false(fv_view_has_camera_path(v));

    fv_view_camera(v, s, 0.0, 64, 48, &c); /* not committed yet */
    assert_vec3(c.pos, 0, 0, 0, 0);
    assert_vec3(c.look, 0, 0, 0, 0);
    assert_float_equal(c.fov_y, 0.0f, 0.0f);
    assert_int_equal(c.width, 64);
    assert_int_equal(c.height, 48);
    fv_view_camera(NULL, NULL, 0.0, 32, 16, &c);
    assert_vec3(c.pos, 0, 0, 0, 0);
    assert_int_equal(c.width, 32);
    assert_int_equal(c.height, 16);

    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    fv_view_camera(v, s, 0.0, 64, 48, &c);
    assert_vec3(c.look, 4, 6, 5, 1e-6f);
    assert_vec3(c.up, 0, 1, 0, 0);
    assert_float_equal(c.fov_y, 45.0f, 0.0f);
    assert_int_equal(c.width, 64);
    assert_int_equal(c.height, 48);
    /* No view at all: the same camera, bit for bit; time does not move it. */
    fv_camera n;
    fv_view_camera(NULL, s, 3.0, 64, 48, &n);
    assert_memory_equal(&c, &n, sizeof c);
    /* Three-quarter: from the front (+z) 35 degrees to the right (+x) and 25 above, so the centre
     * ray runs along minus that direction onto the quad's centre; as close as keeps the four
     * corners inside the frame with a 5% margin, one of them on it. */
    fv_camera_basis b;
    assert_int_equal(fv_camera_basis_make(&c, &b, &err), FV_OK);
    const float az = 35.0f * FV_PI / 180.0f, el = 25.0f * FV_PI / 180.0f;
    assert_vec3(fv_camera_dir(&b, 32, 24), -cosf(el) * sinf(az), -sinf(el), -cosf(el) * cosf(az), 1e-5f);
    float margin = 1e9f;
    const fv_vec3 corner[4] = {{1, 2, 5}, {7, 2, 5}, {7, 10, 5}, {1, 10, 5}};
    for (int k = 0; k < 4; k++) {
        float px, py;
        assert_true(fv_camera_project(&b, corner[k], &px, &py));
        float m = fminf(fminf(px - 0.025f * 64, 0.975f * 64 - px), fminf(py - 0.025f * 48, 0.975f * 48 - py));
        assert_true(m > -1e-3f);
        margin = fminf(margin, m);
    }
    assert_float_equal(margin, 0.0f, 1e-3f);
    /* The named views, worked by hand for this 6 x 8 quad (zero depth) and a 64 x 48 film:
     * tan(22.5 deg) = 0.414214 vertically, 4/3 of it across. Front: the height binds,
     * D = 4 / (0.95 x 0.414214) = 10.16524 from the centre along +z. */
    fv_view_set_frame(v, FV_FRAME_FRONT);
    fv_view_camera(v, s, 0.0, 64, 48, &c);
    assert_vec3(c.pos, 4, 6, 5 + 10.16524f, 1e-3f);
    assert_vec3(c.up, 0, 1, 0, 0);
    fv_view_set_frame(v, FV_FRAME_BACK);
    fv_view_camera(v, s, 0.0, 64, 48, &c);
    assert_vec3(c.pos, 4, 6, 5 - 10.16524f, 1e-3f);
    /* Top: looking down -y with the front (+z) at the bottom, so the image's up is -z and its
     * right +x; the width (6) binds at the near edge y = 10, 4 closer: D = 3 / (0.95 x 0.552285) + 4. */
    fv_view_set_frame(v, FV_FRAME_TOP);
    fv_view_camera(v, s, 0.0, 64, 48, &c);
    assert_vec3(c.pos, 4, 6 + 9.71779f, 5, 1e-3f);
    assert_vec3(c.up, 0, 0, -1, 0);
    /* Left and right: the quad seen edge-on from -x and +x. */
    fv_view_set_frame(v, FV_FRAME_RIGHT);
    fv_view_camera(v, s, 0.0, 64, 48, &c);
    assert_true(c.pos.x > 7.0f && fabsf(c.pos.y - 6) < 1e-4f && fabsf(c.pos.z - 5) < 1e-4f);
    fv_view_set_frame(v, FV_FRAME_LEFT);
    fv_view_camera(v, s, 0.0, 64, 48, &c);
    assert_true(c.pos.x < 1.0f && fabsf(c.pos.y - 6) < 1e-4f && fabsf(c.pos.z - 5) < 1e-4f);
    /* A z-up model: its front is -y, the three-quarter view comes from -y, +x and above (+z). */
    fv_view_set_frame(v, FV_FRAME_THREE_QUARTER);
    fv_view_set_up_axis(v, fv_v3(0, 0, 2));
    assert_vec3(fv_view_up_axis(v), 0, 0, 1, 0);
    fv_view_camera(v, s, 0.0, 64, 48, &c);
    assert_vec3(c.up, 0, 0, 1, 0);
    assert_true(c.pos.y < 6.0f && c.pos.x > 4.0f && c.pos.z > 5.0f);
    fv_view_set_up_axis(v, fv_v3(0, 1, 0));

    /* The view's own camera wins over the framing one, resized to each call. */
    fv_camera mine = {{1, 2, 3}, {1, 2, 0}, {0, 1, 0}, 30.0f, 512, 512};
    fv_view_set_camera(v, &mine);
    assert_true(fv_view_has_camera(v));
    fv_view_camera(v, s, 0.0, 20, 10, &c);
    assert_vec3(c.pos, 1, 2, 3, 0);
    assert_vec3(c.look, 1, 2, 0, 0);
    assert_float_equal(c.fov_y, 30.0f, 0.0f);
    assert_int_equal(c.width, 20);
    assert_int_equal(c.height, 10);
    fv_view_camera(v, NULL, 0.0, 20, 10, &n); /* the scene is not needed then */
    assert_memory_equal(&c, &n, sizeof c);

    fv_view_destroy(v);
    fv_view_destroy(NULL);
    fv_scene_destroy(s);
}

/* Keys at 0 s and 2 s: before the first key the first holds, after the last the last, at 1 s
 * everything is halfway (pos (5, 0, 10), look (0, 1, 0), fov 40, up normalised from (0.5, 0.5, 0)).
 * A path moves the framing camera too; bad paths are refused and the earlier one stays. */
static void test_camera_path(void **st)
{
    (void)st;
    fv_view *v;
    fv_error err;
    fv_camera c;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    const fv_camera_key k[2] = {
        {0.0, {0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 30.0f},
        {2.0, {10, 0, 10}, {0, 2, 0}, {1, 0, 0}, 50.0f},
    };
    assert_int_equal(fv_view_set_camera_path(v, k, 2, &err), FV_OK);
    assert_true(fv_view_has_camera_path(v));
    assert_false(fv_view_has_camera(v));

    fv_view_camera(v, NULL, -1.0, 40, 30, &c);
    assert_vec3(c.pos, 0, 0, 10, 0);
    assert_float_equal(c.fov_y, 30.0f, 0.0f);
    assert_int_equal(c.width, 40);
    assert_int_equal(c.height, 30);
    fv_view_camera(v, NULL, 1.0, 40, 30, &c);
    assert_vec3(c.pos, 5, 0, 10, 1e-6f);
    assert_vec3(c.look, 0, 1, 0, 1e-6f);
    assert_vec3(c.up, 0.707107f, 0.707107f, 0, 1e-6f);
    assert_float_equal(c.fov_y, 40.0f, 1e-5f);
    fv_view_camera(v, NULL, 9.0, 40, 30, &c);
    assert_vec3(c.pos, 10, 0, 10, 0);
    assert_vec3(c.up, 1, 0, 0, 0);
    assert_float_equal(c.fov_y, 50.0f, 0.0f);

    /* Over a committed scene without a view camera: still the path. */
    fv_scene *s = quad_scene();
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    fv_view_camera(v, s, 1.0, 40, 30, &c);
    assert_vec3(c.pos, 5, 0, 10, 1e-6f);
    fv_scene_destroy(s);

    /* The keys were copied: changing the caller's array changes nothing. */
    fv_camera_key k2[2];
    memcpy(k2, k, sizeof k2);
    assert_int_equal(fv_view_set_camera_path(v, k2, 2, &err), FV_OK);
    k2[1].pos.x = 1000.0f;
    fv_view_camera(v, NULL, 9.0, 40, 30, &c);
    assert_float_equal(c.pos.x, 10.0f, 0.0f);

    /* Refused: no keys, times not increasing, a fov out of range; the path stays as it was. */
    assert_int_equal(fv_view_set_camera_path(v, k, 0, &err), FV_ERR_INVALID);
    k2[1].pos.x = 10.0f;
    k2[1].time = 0.0;
    assert_int_equal(fv_view_set_camera_path(v, k2, 2, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "increase"));
    k2[1].time = 2.0;
    k2[1].fov_y = 180.0f;
    assert_int_equal(fv_view_set_camera_path(v, k2, 2, &err), FV_ERR_INVALID);
    fv_view_camera(v, NULL, 1.0, 40, 30, &c);
    assert_vec3(c.pos, 5, 0, 10, 1e-6f);
    assert_float_equal(c.fov_y, 40.0f, 1e-5f);
    fv_view_destroy(v);
}

/* Absent, the display leaves *out alone; present, it comes back as set. */
static void test_display(void **st)
{
    (void)st;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    fv_eye_model out, before;
    memset(&out, 0xab, sizeof out);
    before = out;
    assert_false(fv_view_display(v, &out));
    assert_memory_equal(&out, &before, sizeof out);
    fv_eye_model eye;
    fv_eye_model_default(1920, 1080, &eye);
    eye.fovea_deg = 7.0f;
    fv_view_set_display(v, &eye);
    assert_true(fv_view_display(v, &out));
    assert_memory_equal(&out, &eye, sizeof out);
    fv_view_destroy(v);
}

/* The view owns its gaze path: a new one replaces and frees the old, setting the same one again
 * keeps it, NULL frees it, and destroying the view frees the last (ASan reports any leak or
 * double free). */
static void test_gaze_ownership(void **st)
{
    (void)st;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    assert_null(fv_view_gaze_path(v));
    fv_gaze_path *a, *b, *c;
    assert_int_equal(fv_gaze_path_create_fixed((fv_gaze){0.25f, 0.5f}, &a, &err), FV_OK);
    assert_int_equal(fv_gaze_path_create_fixed((fv_gaze){0.75f, 0.5f}, &b, &err), FV_OK);
    assert_int_equal(fv_gaze_path_create_fixed((fv_gaze){0.5f, 0.125f}, &c, &err), FV_OK);
    fv_view_set_gaze_path(v, a);
    assert_ptr_equal(fv_view_gaze_path(v), a);
    fv_view_set_gaze_path(v, a);
    fv_view_set_gaze_path(v, b); /* frees a */
    assert_ptr_equal(fv_view_gaze_path(v), b);
    fv_gaze g;
    fv_gaze_path_eval(fv_view_gaze_path(v), 0.0, &g, NULL);
    assert_float_equal(g.x, 0.75f, 0.0f);
    fv_view_set_gaze_path(v, NULL); /* frees b */
    assert_null(fv_view_gaze_path(v));
    fv_view_set_gaze_path(v, c); /* freed with the view */
    fv_view_destroy(v);
}

/* The loaders: a scene file's view blocks come back in the view (scene.json: camera path,
 * display, gaze); a mesh file without a camera gives an empty view that frames the scene; with
 * view NULL the blocks are still checked (a bad gaze block fails) and nothing is returned. */
/* The up axis of a model whose file does not say: the smallest extent's axis when that extent is
 * under half the middle one, else +y. */
static void test_up_guess(void **st)
{
    (void)st;
    fv_vec3 o = fv_v3(0, 0, 0);
    assert_vec3(fv_up_axis_guess(o, fv_v3(10, 1, 8)), 0, 1, 0, 0);    /* a terrain */
    assert_vec3(fv_up_axis_guess(o, fv_v3(10, 10, 2)), 0, 0, 1, 0);   /* a plan lying in xy */
    assert_vec3(fv_up_axis_guess(o, fv_v3(0.4f, 3, 2)), 1, 0, 0, 0);  /* a relief facing x */
    assert_vec3(fv_up_axis_guess(o, fv_v3(1, 1, 1)), 0, 1, 0, 0);     /* a box */
    assert_vec3(fv_up_axis_guess(o, fv_v3(0.5f, 1.8f, 0.3f)), 0, 1, 0, 0); /* a standing figure: not flat */
    fv_frame_view f;
    assert_true(fv_frame_view_from_name("three-quarter", &f) && f == FV_FRAME_THREE_QUARTER);
    assert_true(fv_frame_view_from_name("top", &f) && f == FV_FRAME_TOP);
    assert_false(fv_frame_view_from_name("bottom", &f));
    assert_string_equal(fv_frame_view_name(FV_FRAME_LEFT), "left");
}

static void test_loaders(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    fv_error err;
    assert_int_equal(fv_scene_load(DATA("scene.json"), NULL, &s, &v, &err), FV_OK);
    fv_eye_model eye;
    assert_true(fv_view_has_camera_path(v));
    assert_true(fv_view_display(v, &eye));
    assert_non_null(fv_view_gaze_path(v));
    fv_view_destroy(v);
    fv_scene_destroy(s);

    v = NULL;
    assert_int_equal(fv_scene_load(DATA("quad.ply"), NULL, &s, &v, &err), FV_OK);
    assert_false(fv_view_has_camera(v));
    assert_false(fv_view_has_camera_path(v));
    assert_false(fv_view_display(v, &eye));
    assert_null(fv_view_gaze_path(v));
    /* quad.ply is a flat quad: its up axis is guessed as its normal's axis, and the default
     * camera frames it with that up. */
    fv_camera a, b;
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    fv_vec3 up = fv_view_up_axis(v);
    fv_vec3 guess = fv_up_axis_guess(lo, hi);
    assert_vec3(up, guess.x, guess.y, guess.z, 0);
    fv_view_camera(v, s, 0.0, 16, 16, &a);
    fv_camera_frame(lo, hi, up, FV_FRAME_THREE_QUARTER, 16, 16, &b);
    assert_memory_equal(&a, &b, sizeof a);
    assert_float_equal(a.fov_y, 45.0f, 0.0f);
    fv_view_destroy(v);
    fv_scene_destroy(s);

    s = NULL;
    assert_int_equal(fv_scene_load(DATA("scene.json"), NULL, &s, NULL, &err), FV_OK);
    fv_scene_destroy(s);
    s = NULL;
    v = NULL;
    assert_int_equal(fv_scene_load(DATA("bad_gaze.json"), NULL, &s, NULL, &err), FV_ERR_INVALID);
    assert_int_equal(fv_scene_open(DATA("bad_gaze.json"), NULL, &s, &v, &err), FV_ERR_INVALID);
    assert_null(s);
    assert_null(v);

    /* A built-in into a caller's view, and into none. */
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    assert_int_equal(fv_builtin_build("cornell-fpm", s, v, NULL, &err), FV_OK);
    assert_true(fv_view_has_camera(v));
    assert_true(fv_view_has_camera_path(v));
    fv_view_destroy(v);
    fv_scene_destroy(s);
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    assert_int_equal(fv_builtin_build("cornell-fpm", s, NULL, NULL, &err), FV_OK);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_framing),        cmocka_unit_test(test_camera_path), cmocka_unit_test(test_display),
        cmocka_unit_test(test_gaze_ownership), cmocka_unit_test(test_loaders), cmocka_unit_test(test_up_guess),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
