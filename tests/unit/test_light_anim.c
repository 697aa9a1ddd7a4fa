/* Tests of moving point and spot lights (fv_scene_animate_light, src/scene/anim.c, scene.c,
 * light.c): positions and a spot's axis at hand-worked times, the delta-light enumeration
 * techniques use, the refusals, sdf-columns' lights keeping clear of its columns, and renders that follow the light: pt's image changes with time
 * only when a light moves, and pm-t and fpm, which keep photons across frames, match pm's image of
 * the frame after the light moved rather than the frame before. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "scene/light.h"
#include "testkit.h"

#define N 32 /* film side of the renders */

static void assert_vec3(fv_vec3 v, float x, float y, float z, float tol)
{
    if (fabsf(v.x - x) > tol || fabsf(v.y - y) > tol || fabsf(v.z - z) > tol)
        fail_msg("(%g, %g, %g) != (%g, %g, %g)", v.x, v.y, v.z, x, y, z);
}

static fv_anim_key key(double t, float x, float y, float z)
{
    return (fv_anim_key){t, fv_v3(x, y, z), (fv_quat){0, 0, 0, 1}, fv_v3s(1.0f)};
}

/* A 4 x 4 floor at y = 0 facing up, centred on the origin, and nothing else. */
static fv_scene *floor_scene(void)
{
    static const fv_vec3 pos[4] = {{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.5f);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    fv_mesh_desc mesh = {"floor", pos, 4, NULL, idx, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &mesh, NULL, NULL, &err), FV_OK);
    return s;
}

static void set_time(fv_scene *s, double t)
{
    fv_error err;
    assert_int_equal(fv_scene_set_time(s, t, &err), FV_OK);
}

/* Three keys, with a dark light before the moving one (it does not emit, so it is not enumerated
 * but still counts for light_index): the position lerps between keys and holds outside them. */
static void test_point_position(void **st)
{
    (void)st;
    fv_scene *s = floor_scene();
    fv_error err;
    fv_light_desc dark = {FV_LIGHT_POINT, {0, 3, 0}, {0, -1, 0}, {0, 0, 0}, 0, 0};
    fv_light_desc l = {FV_LIGHT_POINT, {1, 2, 3}, {0, -1, 0}, {5, 5, 5}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &dark, &err), FV_OK);
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    const fv_anim_key keys[3] = {key(0, 0, 0, 0), key(2, 4, 0, 0), key(3, 4, 2, 0)};
    assert_int_equal(fv_scene_animate_light(s, 1, keys, 3, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_true(fv_scene_lights_move(s));
    assert_int_equal(fv_light_delta_count(s), 1);
    assert_null(fv_light_delta_at(s, 1));
    const fv_light *m = fv_light_delta_at(s, 0);
    assert_non_null(m);
    assert_vec3(fv_light_delta_pos(m), 1, 2, 3, 1e-6f); /* commit sets t = 0 */
    const struct {
        double t;
        fv_vec3 p;
    } want[] = {{1.0, {3, 2, 3}}, {0.5, {2, 2, 3}}, {2.5, {5, 3, 3}}, {3.0, {5, 4, 3}}, {10.0, {5, 4, 3}}, {-1.0, {1, 2, 3}}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        set_time(s, want[i].t);
        assert_vec3(fv_light_delta_pos(m), want[i].p.x, want[i].p.y, want[i].p.z, 1e-5f);
    }
    /* The samplers read the same position: from (5, 0, 3) at t = 1 the light is 2 up and 2 back. */
    set_time(s, 1.0);
    fv_light_sample ls;
    assert_true(fv_light_sample_li(s, fv_v3(5, 0, 3), 0.5f, 0.5f, 0.5f, &ls));
    assert_float_equal(ls.dist, sqrtf(8.0f), 1e-5);
    assert_vec3(ls.wi, -sqrtf(0.5f), sqrtf(0.5f), 0, 1e-5f);
    assert_float_equal(ls.li.x, 5.0f / 8.0f, 1e-5);
    fv_vec3 o, d, power, n;
    const float u[5] = {0.5f, 0.3f, 0.7f, 0.5f, 0.5f};
    assert_true(fv_light_sample_emission(s, u, &o, &d, &power, &n));
    assert_vec3(o, 3, 2, 3, 1e-5f);
    fv_scene_destroy(s);
}

/* A spot turned a quarter about z in one second: its axis follows the rotation, and so does its
 * position, which the key transform moves about the origin like any point. */
static void test_spot_turns(void **st)
{
    (void)st;
    fv_scene *s = floor_scene();
    fv_error err;
    fv_light_desc l = {FV_LIGHT_SPOT, {0, 2, 0}, {0, -1, 0}, {1, 1, 1}, 10, 20};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    fv_anim_key keys[2] = {key(0, 0, 0, 0), key(1, 0, 0, 0)};
    keys[1].rotate = fv_quat_axis_angle(fv_v3(0, 0, 1), 0.5f * FV_PI);
    keys[1].scale = fv_v3s(3.0f); /* scales the position, never the axis */
    assert_int_equal(fv_scene_animate_light(s, 0, keys, 2, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    const fv_light *m = fv_light_delta_at(s, 0);
    set_time(s, 1.0);
    assert_vec3(fv_light_delta_pos(m), -6, 0, 0, 1e-5f);
    assert_float_equal(fv_light_delta_intensity(m, fv_v3(1, 0, 0)).x, 1.0f, 1e-5);
    assert_float_equal(fv_light_delta_intensity(m, fv_v3(0, -1, 0)).x, 0.0f, 0.0);
    /* Half way: an eighth of a turn (slerp), scale 2. */
    set_time(s, 0.5);
    float h = sqrtf(0.5f);
    assert_vec3(fv_light_delta_pos(m), -4 * h, 4 * h, 0, 1e-5f);
    assert_float_equal(fv_light_delta_intensity(m, fv_v3(h, -h, 0)).x, 1.0f, 1e-5);
    assert_float_equal(fv_light_delta_intensity(m, fv_v3(0, -1, 0)).x, 0.0f, 0.0);
    fv_scene_destroy(s);
}

static void test_static_lights(void **st)
{
    (void)st;
    fv_scene *s = floor_scene();
    fv_error err;
    fv_light_desc l = {FV_LIGHT_POINT, {1, 2, 3}, {0, -1, 0}, {5, 5, 5}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_false(fv_scene_lights_move(s));
    set_time(s, 3.0);
    assert_vec3(fv_light_delta_pos(fv_light_delta_at(s, 0)), 1, 2, 3, 0.0f);
    fv_scene_destroy(s);
}

static void test_refusals(void **st)
{
    (void)st;
    fv_scene *s = floor_scene();
    fv_error err;
    const fv_anim_key good[2] = {key(0, 0, 0, 0), key(1, 1, 0, 0)};
    fv_test_expect_fail(fv_scene_animate_light(s, 0, good, 2, &err), &err, FV_ERR_INVALID, "light 0 does not exist", "no light yet");
    fv_light_desc l = {FV_LIGHT_POINT, {0, 2, 0}, {0, -1, 0}, {1, 1, 1}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    fv_test_expect_fail(fv_scene_animate_light(s, 1, good, 2, &err), &err, FV_ERR_INVALID, "light 1 does not exist", "index 1");
    fv_test_expect_fail(fv_scene_animate_light(s, -1, good, 2, &err), &err, FV_ERR_INVALID, "light -1 does not exist", "index -1");
    const fv_anim_key back[3] = {key(0, 0, 0, 0), key(2, 1, 0, 0), key(1, 2, 0, 0)};
    fv_test_expect_fail(fv_scene_animate_light(s, 0, back, 3, &err), &err, FV_ERR_INVALID,
                        "animation of light 0: key times must increase (key 2)", "decreasing times");
    fv_anim_key flat[1] = {key(0, 0, 0, 0)};
    flat[0].scale.y = 0.0f;
    fv_test_expect_fail(fv_scene_animate_light(s, 0, flat, 1, &err), &err, FV_ERR_INVALID, "key 0 has a scale <= 0", "zero scale");
    fv_anim_key nan[1] = {key(NAN, 0, 0, 0)};
    fv_test_expect_fail(fv_scene_animate_light(s, 0, nan, 1, &err), &err, FV_ERR_INVALID, "non-finite", "NaN time");
    fv_test_expect_fail(fv_scene_animate_light(s, 0, good, 0, &err), &err, FV_ERR_INVALID, "no keys", "no keys");
    /* The refusals left the light standing still. */
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_false(fv_scene_lights_move(s));
    fv_test_expect_fail(fv_scene_animate_light(s, 0, good, 2, &err), &err, FV_ERR_INTERNAL, "already committed", "after commit");
    fv_scene_destroy(s);
}

/* sdf-columns: five lights loop through the aisles over the camera path's 4 s, never nearer than
 * 0.8 m to a column, wall, floor or ceiling (the field's own distance), and back where they
 * started at 4 s. */
static void test_columns_lights(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    assert_int_equal(fv_test_load("sdf-columns", &s, &v), 0);
    assert_true(fv_scene_lights_move(s));
    assert_int_equal(fv_light_delta_count(s), 5);
    const fv_sdf *field = fv_scene_object_sdf(s, 0);
    assert_non_null(field);
    fv_vec3 start[5];
    for (int i = 0; i < 5; i++) start[i] = fv_light_delta_pos(fv_light_delta_at(s, i));
    float nearest = INFINITY, travel = 0.0f;
    for (int k = 1; k <= 200; k++) {
        set_time(s, 0.02 * k);
        for (int i = 0; i < 5; i++) {
            fv_vec3 p = fv_light_delta_pos(fv_light_delta_at(s, i));
            int mat;
            nearest = fminf(nearest, fv_sdf_distance(field, p, &mat));
            if (k == 100) travel += fv_length(fv_sub(p, start[i]));
            if (k == 200) assert_vec3(p, start[i].x, start[i].y, start[i].z, 1e-5f);
        }
    }
    print_message("sdf-columns: lights at least %.2f m from any surface; %.1f m from their start at 2 s\n", nearest, travel / 5);
    assert_true(nearest >= 0.8f);
    assert_true(travel / 5 > 3.0f);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* ---- renders ---- */

/* The floor seen from 5 above (x to the right, z down the image), lit by one point light 1 above
 * it that, when `moving`, crosses from x = -1.5 (t = 0) to x = +1.5 (t = 1). */
static fv_scene *lit_floor(bool moving)
{
    fv_scene *s = floor_scene();
    fv_error err;
    fv_light_desc l = {FV_LIGHT_POINT, {-1.5f, 1, 0}, {0, -1, 0}, {4, 4, 4}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    const fv_anim_key keys[2] = {key(0, 0, 0, 0), key(1, 3, 0, 0)};
    if (moving) assert_int_equal(fv_scene_animate_light(s, 0, keys, 2, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

static const fv_camera k_cam = {{0, 5, 0}, {0, 0, 0}, {0, 0, -1}, 40.0f, N, N};

static fv_technique *make(const fv_scene *s, const char *method, const char *params, fv_test_warnings *warn)
{
    fv_error err;
    fv_params *p = fv_test_params_str(params);
    fv_log log = {fv_test_warn, warn};
    fv_technique *t = NULL;
    if (fv_technique_create(method, s, p, warn ? &log : NULL, &t, &err) != FV_OK) fail_msg("%s: %s", method, err.msg);
    fv_params_destroy(p);
    return t;
}

/* Frame `index` at time t (the scene is set to it first) into film, gaze on the right half where
 * the light ends up; stats may be NULL. */
static void render_at(fv_technique *t, fv_scene *s, double time, int index, fv_film *film, fv_stats *stats)
{
    set_time(s, time);
    fv_frame fr;
    fv_frame_init(&fr, &k_cam);
    fr.time = time;
    fr.index = index;
    fr.seed = 11;
    fr.threads = 2;
    fr.prev_camera = index > 0 ? &k_cam : NULL;
    fr.gaze = (fv_gaze){0.75f, 0.5f};
    fv_stats own;
    if (!stats) stats = &own;
    fv_stats_clear(stats);
    fv_error err;
    if (fv_technique_render(t, &fr, film, stats, &err) != FV_OK) fail_msg("%s", err.msg);
}

static fv_film *new_film(void)
{
    fv_film *f;
    fv_error err;
    assert_int_equal(fv_film_create(N, N, 0, &f, &err), FV_OK);
    return f;
}

/* Mean luminance of the left and right halves. */
static void halves(const fv_film *f, double *left, double *right)
{
    const float *c = fv_film_color_const(f);
    *left = *right = 0.0;
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            const float *p = &c[3 * (y * N + x)];
            *(x < N / 2 ? left : right) += fv_luminance(fv_v3(p[0], p[1], p[2]));
        }
}

/* Relative L1 distance between the 4 x 4 block means of two films (blocks average the photon
 * noise away, not the light's position). */
static double block_distance(const fv_film *a, const fv_film *b)
{
    const float *ca = fv_film_color_const(a), *cb = fv_film_color_const(b);
    double diff = 0.0, sum = 0.0;
    for (int by = 0; by < 4; by++)
        for (int bx = 0; bx < 4; bx++) {
            double ma = 0.0, mb = 0.0;
            for (int y = by * N / 4; y < (by + 1) * N / 4; y++)
                for (int x = bx * N / 4; x < (bx + 1) * N / 4; x++) {
                    size_t i = 3 * ((size_t)y * N + x);
                    ma += fv_luminance(fv_v3(ca[i], ca[i + 1], ca[i + 2]));
                    mb += fv_luminance(fv_v3(cb[i], cb[i + 1], cb[i + 2]));
                }
            diff += fabs(ma - mb);
            sum += mb;
        }
    return diff / sum;
}

/* pt, same frame and seed at t = 0 and t = 1: identical images when the light stands still, the
 * bright side swapping when it moves. */
static void test_pt_follows_light(void **st)
{
    (void)st;
    for (int moving = 0; moving < 2; moving++) {
        fv_scene *s = lit_floor(moving);
        fv_technique *t = make(s, "pt", "spp=4", NULL);
        fv_film *a = new_film(), *b = new_film();
        render_at(t, s, 0.0, 0, a, NULL);
        render_at(t, s, 1.0, 0, b, NULL);
        size_t bytes = (size_t)3 * N * N * sizeof(float);
        double la, ra, lb, rb;
        halves(a, &la, &ra);
        halves(b, &lb, &rb);
        if (!moving) {
            assert_memory_equal(fv_film_color_const(a), fv_film_color_const(b), bytes);
        } else {
            assert_memory_not_equal(fv_film_color_const(a), fv_film_color_const(b), bytes);
            assert_true(la > 2.0 * ra && rb > 2.0 * lb);
        }
        fv_film_destroy(a);
        fv_film_destroy(b);
        fv_technique_destroy(t);
        fv_scene_destroy(s);
    }
}

/* pm-t and fpm keep photons across frames. Frame 0 at t = 0, frame 1 at t = 1 after the light
 * crossed the floor: frame 1 must be pm's image of t = 1 (up to photon noise), not a mix with the
 * photons of t = 0. Each says once, when created, that it retraces everything. */
static void test_photons_follow_light(void **st)
{
    (void)st;
    fv_scene *s = lit_floor(true);
    fv_film *ref = new_film(), *ref0 = new_film(), *f = new_film();
    fv_technique *pm = make(s, "pm", "photons=60000 filter=false", NULL);
    render_at(pm, s, 0.0, 0, ref0, NULL);
    render_at(pm, s, 1.0, 1, ref, NULL);
    double far = block_distance(ref0, ref); /* how different the two times are */
    print_message("pm: t = 0 vs t = 1: %.3f\n", far);
    assert_true(far > 0.5);
    const char *methods[2] = {"pm-t", "fpm"};
    for (int i = 0; i < 2; i++) {
        fv_test_warnings warn = {0};
        fv_technique *t = make(s, methods[i], "photons=60000 filter=false", &warn);
        assert_int_equal(warn.count, 1);
        assert_non_null(strstr(warn.last, "retraced every frame"));
        fv_stats stats;
        render_at(t, s, 0.0, 0, f, NULL);
        render_at(t, s, 1.0, 1, f, &stats);
        /* fpm: no foveated path of t = 0 survives into t = 1 (their flux came from the old light). */
        if (i == 1) {
            assert_true(fv_stats_get_count(&stats, "paths_traced") > 0);
            assert_float_equal(fv_stats_get_count(&stats, "paths_reused"), 0.0, 0.0);
        }
        double d = block_distance(f, ref);
        double l, r;
        halves(f, &l, &r);
        print_message("%s: frame 1 vs pm at t = 1: %.3f; left %.3f right %.3f\n", methods[i], d, l, r);
        assert_true(d < 0.1);
        assert_true(r > 2.0 * l);
        fv_technique_destroy(t);
    }
    /* A scene whose lights stand still gets no such warning. */
    fv_scene *still = lit_floor(false);
    fv_test_warnings warn = {0};
    fv_technique *t = make(still, "fpm", "photons=60000", &warn);
    assert_int_equal(warn.count, 0);
    fv_technique_destroy(t);
    fv_scene_destroy(still);
    fv_technique_destroy(pm);
    fv_film_destroy(ref);
    fv_film_destroy(ref0);
    fv_film_destroy(f);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_position),   cmocka_unit_test(test_spot_turns),
        cmocka_unit_test(test_static_lights),    cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_columns_lights),
        cmocka_unit_test(test_pt_follows_light), cmocka_unit_test(test_photons_follow_light),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
