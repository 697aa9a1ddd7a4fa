/* Tests of the reference path tracer `pt` on scenes with known answers:
 *  - the furnace: inside of a sphere with albedo 0.5 and emission 0.5 has radiance 1 everywhere;
 *  - a point light over a diffuse plane: L = albedo/pi * I cos / d^2 (direct light only);
 *  - an area light over a diffuse plane: L = albedo * Le * F (form factor), which exercises both
 *    halves of MIS (light sampling and BSDF sampling);
 *  - determinism: same seed gives bit-identical images with 1 and 2 threads. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"

static fv_film *render(fv_scene *s, const fv_camera *cam, const char *const *kv, int threads, uint64_t seed)
{
    fv_error err;
    fv_params *p = fv_test_params(kv);
    fv_technique *t;
    fv_status st = fv_technique_create("pt", s, p, NULL, &t, &err);
    if (st != FV_OK) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(st, FV_OK);
    fv_film *film;
    assert_int_equal(fv_film_create(cam->width, cam->height, FV_AUX_DEPTH | FV_AUX_ID, &film, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, NULL);
    fr.seed = seed;
    fr.threads = threads;
    fr.camera = cam;
    fr.gaze.x = fr.gaze.y = 0.5f;
    fv_stats stats;
    fv_stats_clear(&stats);
    assert_int_equal(fv_technique_render(t, &fr, film, &stats, &err), FV_OK);
    assert_true(fv_stats_get_count(&stats, "rays") > 0);
    assert_true(fv_stats_get_count(&stats, "nan_samples") == 0);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return film;
}

static double mean_channel(fv_film *f, int c, int x0, int y0, int x1, int y1)
{
    const float *col = fv_film_color(f);
    double sum = 0;
    int w = fv_film_width(f);
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) sum += col[3 * ((size_t)y * w + x) + c];
    return sum / ((double)(x1 - x0) * (y1 - y0));
}

static void test_furnace(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("furnace", NULL, &s, &v, &err), FV_OK);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 32, 32, &cam);
    fv_view_destroy(v);
    const char *kv[] = {"spp=64", "max_depth=64", NULL};
    fv_film *f = render(s, &cam, kv, 0, 1);
    /* L = Le + a L  =>  L = 0.5 / (1 - 0.5) = 1 in every pixel and channel. */
    for (int c = 0; c < 3; c++) assert_float_equal(mean_channel(f, c, 0, 0, 32, 32), 1.0, 0.025);
    fv_film_destroy(f);
    fv_scene_destroy(s);
}

/* Diffuse plane y=0 (albedo 0.5, 20x20) under a point light of intensity 10 at height 2. */
static fv_scene *plane_scene(bool area_light)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.5f);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    const fv_vec3 v[4] = {{-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc d = {"plane", v, 4, NULL, idx, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
    if (area_light) {
        /* 1x1 quad at height 1 facing down, radiance 4. */
        fv_material e = fv_material_default(FV_MAT_DIFFUSE);
        e.albedo = fv_v3s(0.0f);
        e.emission = fv_v3s(4.0f);
        int emat;
        assert_int_equal(fv_scene_add_material(s, &e, &emat, &err), FV_OK);
        const fv_vec3 lv[4] = {{-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}};
        fv_mesh_desc ld = {"light", lv, 4, NULL, idx, 2, NULL, emat, NULL};
        assert_int_equal(fv_scene_add_mesh(s, &ld, NULL, NULL, &err), FV_OK);
    } else {
        fv_light_desc l = {FV_LIGHT_POINT, {0, 2, 0}, {0, -1, 0}, {10, 10, 10}, 0, 0};
        assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    }
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

static void test_point_light_plane(void **st)
{
    (void)st;
    fv_scene *s = plane_scene(false);
    /* Camera straight down from height 4 with a narrow view: pixels see points near the origin. */
    fv_camera cam = {{0, 4, 0}, {0, 0, 0}, {0, 0, -1}, 10.0f, 16, 16};
    const char *kv[] = {"spp=16", "max_depth=1", NULL};
    fv_film *f = render(s, &cam, kv, 0, 5);
    fv_camera_basis b;
    fv_error err;
    assert_int_equal(fv_camera_basis_make(&cam, &b, &err), FV_OK);
    const float *col = fv_film_color(f);
    for (int y = 0; y < 16; y += 5) {
        for (int x = 0; x < 16; x += 5) {
            /* exact radiance at the point hit through the pixel centre; jitter moves the point by
             * at most half a pixel (~0.02 units), which changes L by well under 1% */
            fv_vec3 dir = fv_camera_dir(&b, x + 0.5f, y + 0.5f);
            float t = -4.0f / dir.y;
            fv_vec3 p = fv_madd(cam.pos, dir, t);
            fv_vec3 tol = fv_sub(fv_v3(0, 2, 0), p);
            float d2 = fv_dot(tol, tol), cosv = tol.y / sqrtf(d2);
            float L = 0.5f / FV_PI * 10.0f * cosv / d2;
            assert_float_equal(col[3 * (y * 16 + x)], L, 0.01f * L);
        }
    }
    fv_film_destroy(f);
    fv_scene_destroy(s);
}

static void test_area_light_plane_mis(void **st)
{
    (void)st;
    fv_scene *s = plane_scene(true);
    /* Look straight down at the point under the light's centre from just below the light (the
     * camera is not an occluder); the 2-degree view covers a disc of radius 0.01 where the form
     * factor varies by less than 0.1%. */
    fv_camera cam = {{0.0f, 0.5f, 0.0f}, {0, 0, 0}, {0, 0, -1}, 2.0f, 8, 8};
    const char *kv[] = {"spp=2048", "max_depth=2", NULL};
    fv_film *f = render(s, &cam, kv, 0, 9);
    /* Form factor from a point to a parallel square (side 1, height 1) centred above it: four
     * corner rectangles of 0.5 x 0.5, each F = (1/2pi) * 2 * X/sqrt(1+X^2) * atan(X/sqrt(1+X^2))
     * with X = 0.5: c = 0.447214, atan(c) = 0.420534, F = 4 * 0.059865 = 0.239456.
     * Reflected radiance = albedo * Le * F = 0.5 * 4 * 0.239456 = 0.478913. */
    double X = 0.5, c = X / sqrt(1 + X * X);
    double F = 4.0 * (1.0 / (2.0 * M_PI)) * 2.0 * c * atan(c);
    double expect = 0.5 * 4.0 * F;
    double got = mean_channel(f, 1, 0, 0, 8, 8);
    assert_float_equal(got, expect, 0.015 * expect);
    fv_film_destroy(f);
    fv_scene_destroy(s);
}

static void test_deterministic_threads(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell", NULL, &s, &v, &err), FV_OK);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 48, 40, &cam);
    fv_view_destroy(v);
    const char *kv[] = {"spp=4", NULL};
    fv_film *a = render(s, &cam, kv, 1, 42);
    fv_film *b = render(s, &cam, kv, 2, 42);
    fv_film *c = render(s, &cam, kv, 2, 43);
    size_t n = (size_t)48 * 40 * 3;
    assert_memory_equal(fv_film_color(a), fv_film_color(b), n * sizeof(float));
    assert_memory_not_equal(fv_film_color(a), fv_film_color(c), n * sizeof(float));
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_film_destroy(c);
    fv_scene_destroy(s);
}

static void test_bad_parameters(void **st)
{
    (void)st;
    fv_scene *s = plane_scene(false);
    fv_error err;
    const char *bad[][2] = {{"spp=0", "spp"}, {"spp=abc", "spp"}, {"max_depth=-1", "max_depth"}, {"sppp=4", "sppp"}};
    for (int i = 0; i < 4; i++) {
        const char *kv[] = {bad[i][0], NULL};
        fv_params *p = fv_test_params(kv);
        fv_technique *t = NULL;
        fv_test_expect_fail(fv_technique_create("pt", s, p, NULL, &t, &err), &err, FV_ERR_INVALID, bad[i][1], bad[i][0]);
        assert_null(t);
        fv_params_destroy(p);
    }
    fv_technique *t = NULL;
    assert_int_equal(fv_technique_create("nosuch", s, NULL, NULL, &t, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "nosuch"));
    assert_non_null(strstr(err.msg, "pt"));
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_furnace),           cmocka_unit_test(test_point_light_plane),
        cmocka_unit_test(test_area_light_plane_mis), cmocka_unit_test(test_deterministic_threads),
        cmocka_unit_test(test_bad_parameters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
