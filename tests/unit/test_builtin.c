/* Tests of the built-in scenes (src/scene/builtin*.c) and the mesh generators (mesh_gen.c):
 * every built-in builds and commits without warnings with the hand-counted number of triangles
 * and at least one light; the Cornell box has the measured bounds, a camera whose centre ray hits
 * the tall block at z = 292, rays above it the back wall at z = 559.2, and the red wall on the
 * left; cornell-fpm's mirror cube moves with time; cornell-fir is all diffuse, lit by one point
 * light that circles under the ceiling, with a yellow cube that slides and returns; the furnace is a closed unit sphere; the
 * city is large and deterministic; unknown names are refused with a message naming them;
 * generated spheres and boxes have the right areas, counts and outward normals. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>
#include "scene/mesh_gen.h"
#include "fovea/view.h"
#include "scene/edit.h"
#include "scene/light.h"
#include "scene/scene_impl.h"
#include "testkit.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Builds and commits built-in `name`, its view into a new *view when view is not NULL (else
 * dropped); fails the test on any error or warning. */
static fv_scene *build(const char *name, fv_view **view, double *build_seconds)
{
    fv_scene *s;
    fv_error err;
    fv_test_warnings cap = {0};
    fv_log log = {fv_test_warn, &cap};
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    if (view) assert_int_equal(fv_view_create(view, &err), FV_OK);
    double t0 = now_s();
    fv_status st = fv_builtin_build(name, s, view ? *view : NULL, &log, &err);
    if (build_seconds) *build_seconds = now_s() - t0;
    if (st != FV_OK) fail_msg("%s: %s", name, err.msg);
    if (fv_scene_commit(s, &log, &err) != FV_OK) fail_msg("%s: commit: %s", name, err.msg);
    if (cap.count != 0) fail_msg("%s: %d warning(s), last: %s", name, cap.count, cap.last);
    return s;
}

static fv_vec3 tri_normal(const fv_meshbuf *mb, int t)
{
    fv_vec3 a = mb->pos[mb->idx[3 * t]], b = mb->pos[mb->idx[3 * t + 1]], c = mb->pos[mb->idx[3 * t + 2]];
    return fv_cross(fv_sub(b, a), fv_sub(c, a)); /* length = twice the area */
}

static fv_vec3 tri_centroid(const fv_meshbuf *mb, int t)
{
    fv_vec3 a = mb->pos[mb->idx[3 * t]], b = mb->pos[mb->idx[3 * t + 1]], c = mb->pos[mb->idx[3 * t + 2]];
    return fv_scale(fv_add(a, fv_add(b, c)), 1.0f / 3.0f);
}

static double total_area(const fv_meshbuf *mb)
{
    double a = 0;
    for (int t = 0; t < mb->nt; t++) a += 0.5 * fv_length(tri_normal(mb, t));
    return a;
}

/* ---- the table ---- */

static void test_table(void **st)
{
    (void)st;
    int n = fv_builtin_count();
    assert_int_equal(n, 10);
    const char *want[] = {"cornell", "cornell-glossy", "cornell-fpm", "cornell-fir", "city", "sdf-primitives", "sdf-columns", "sdf-temple", "sdf-furnace", "furnace"};
    for (int i = 0; i < n; i++) {
        assert_string_equal(fv_builtin_name(i), want[i]);
        const char *sum = fv_builtin_summary(i);
        assert_non_null(sum);
        assert_true(strlen(sum) > 10 && strlen(sum) < 110);
        assert_null(strchr(sum, '\n'));
    }
    assert_null(fv_builtin_name(-1));
    assert_null(fv_builtin_name(n));
    assert_null(fv_builtin_summary(n));
}

static void test_unknown_name(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    assert_int_equal(fv_builtin_build("cornel", s, NULL, NULL, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "'cornel'"));
    assert_non_null(strstr(err.msg, "cornell-fpm"));
    assert_null(strchr(err.msg, '\n'));
    /* The refused call added nothing. */
    assert_int_equal(fv_scene_material_count(s), 0);
    fv_scene_destroy(s);
}

/* ---- every scene: counts and lights ---- */

static void test_counts(void **st)
{
    (void)st;
    /* room 5 quads + light 1 quad + 2 blocks of 5 quads = 16 quads. */
    const struct {
        const char *name;
        int tris, lights;
    } k[] = {
        {"cornell", 32, 2},
        {"cornell-glossy", 32, 2},
        /* room 10 + light 2 + sphere 2*64*31 + cube 12 */
        {"cornell-fpm", 10 + 2 + 2 * 64 * 31 + 12, 2},
        /* room 10 + tall block 10 + cube 12; one point light */
        {"cornell-fir", 10 + 10 + 12, 1},
        /* 2*48*23 triangles, every one emissive */
        {"furnace", 2 * 48 * 23, 2 * 48 * 23},
    };
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++) {
        fv_scene *s = build(k[i].name, NULL, NULL);
        assert_int_equal(fv_scene_triangle_count(s), k[i].tris);
        assert_int_equal(fv_scene_light_count(s), k[i].lights);
        fv_scene_destroy(s);
    }
}

/* ---- cornell ---- */

static void test_cornell_geometry(void **st)
{
    (void)st;
    fv_view *v;
    fv_scene *s = build("cornell", &v, NULL);
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    assert_float_equal(lo.x, 0.0, 0.5);
    assert_float_equal(lo.y, 0.0, 0.5);
    assert_float_equal(lo.z, 0.0, 0.5);
    assert_float_equal(hi.x, 556.0, 0.5);
    assert_float_equal(hi.y, 548.8, 0.5);
    assert_float_equal(hi.z, 559.2, 0.5);
    assert_int_equal(fv_scene_dynamic_object_count(s), 0);
    assert_int_equal(fv_scene_material_count(s), 4);

    fv_camera cam;
    fv_view_camera(v, s, 0.0, 512, 512, &cam);
    assert_float_equal(cam.pos.x, 278.0, 1e-3);
    assert_float_equal(cam.pos.y, 273.0, 1e-3);
    assert_float_equal(cam.pos.z, -800.0, 1e-3);
    assert_float_equal(cam.fov_y, 37.5, 1e-4);
    fv_camera_basis b;
    fv_error err;
    assert_int_equal(fv_camera_basis_make(&cam, &b, &err), FV_OK);

    /* The image centre looks straight down +z and meets the tall block's front face, which runs
     * from (265, 296) to (423, 247) in x, z: at x = 278, z = 296 - 49 * 13 / 158 = 291.97. */
    fv_hit h;
    fv_vec3 d = fv_camera_dir(&b, 256.0f, 256.0f);
    assert_float_equal(d.z, 1.0, 1e-6);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, cam.pos, d, 1e30f, &h));
    assert_float_equal(h.p.z, 291.97, 0.02);
    assert_float_equal(h.t, 1091.97, 0.05);
    assert_int_equal(h.mat, fv_scene_find_material(s, "white"));
    assert_true(h.ng.z < 0.0f); /* faces the camera */
    /* Higher up, above the tall block (330), the white back wall at z = 559.2. */
    fv_vec3 wall = fv_v3(278, 400, 559.2f);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, cam.pos, fv_normalize(fv_sub(wall, cam.pos)), 1e30f, &h));
    assert_float_equal(h.p.z, 559.2, 0.01);
    assert_float_equal(h.t, fv_length(fv_sub(wall, cam.pos)), 0.05);
    assert_int_equal(h.mat, fv_scene_find_material(s, "white"));
    assert_true(h.ng.z < -0.99f);

    /* Towards (550, 273, 300): past the tall block's side, onto the red wall near x = 554. */
    int red = fv_scene_find_material(s, "red"), green = fv_scene_find_material(s, "green");
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, cam.pos, fv_sub(fv_v3(550, 273, 300), cam.pos), 1e30f, &h));
    assert_int_equal(h.mat, red);
    assert_true(h.p.x > 552.0f && h.ng.x < 0.0f);
    /* ... and the red wall is on the left of the image, the green one on the right. */
    float px, py;
    assert_true(fv_camera_project(&b, h.p, &px, &py));
    assert_true(px < 128.0f);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, cam.pos, fv_sub(fv_v3(5, 273, 300), cam.pos), 1e30f, &h));
    assert_int_equal(h.mat, green);
    assert_true(h.ng.x > 0.0f);
    assert_true(fv_camera_project(&b, h.p, &px, &py));
    assert_true(px > 384.0f);

    /* Straight up from the middle of the box: the light, facing down, just under the ceiling. */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(278, 400, 280), fv_v3(0, 1, 0), 1e30f, &h));
    assert_int_equal(h.mat, fv_scene_find_material(s, "light"));
    assert_float_equal(h.p.y, 548.7, 0.01);
    assert_true(h.ng.y < -0.99f);
    const fv_material *lm = fv_scene_material(s, h.mat);
    assert_float_equal(lm->emission.x, 17.0, 1e-6);

    /* Straight down onto the short block's top (165) and the tall block's top (330). */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(186, 500, 169), fv_v3(0, -1, 0), 1e30f, &h));
    assert_float_equal(h.p.y, 165.0, 0.01);
    assert_true(h.ng.y > 0.99f);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(368, 500, 351), fv_v3(0, -1, 0), 1e30f, &h));
    assert_float_equal(h.p.y, 330.0, 0.01);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_cornell_glossy(void **st)
{
    (void)st;
    fv_scene *s = build("cornell-glossy", NULL, NULL);
    fv_hit h;
    /* The tall block's top is the copper (glossy) one. */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(368, 500, 351), fv_v3(0, -1, 0), 1e30f, &h));
    const fv_material *m = fv_scene_material(s, h.mat);
    assert_int_equal(m->type, FV_MAT_GLOSSY);
    assert_string_equal(m->name, "copper");
    fv_scene_destroy(s);
}

/* ---- cornell-fpm ---- */

static void test_fpm(void **st)
{
    (void)st;
    fv_view *v;
    fv_scene *s = build("cornell-fpm", &v, NULL);
    assert_int_equal(fv_scene_dynamic_object_count(s), 1);
    assert_true(fv_view_has_camera_path(v));
    int glass = fv_scene_find_material(s, "glass"), mirror = fv_scene_find_material(s, "mirror");
    assert_true(glass >= 0 && mirror >= 0);
    assert_int_equal(fv_scene_material(s, glass)->type, FV_MAT_DIELECTRIC);
    assert_float_equal(fv_scene_material(s, glass)->ior, 1.5, 1e-6);
    assert_int_equal(fv_scene_material(s, mirror)->type, FV_MAT_MIRROR);

    fv_error err;
    fv_hit h;
    fv_vec3 eye = fv_v3(278, 273, -800);
    /* At t = 0 the cube (side 150) is centred at (150, 75, 170), turned 30 degrees. The ray
     * eye + s (-128, -198, 970) towards its centre meets the face whose local z is -75:
     * sin30 (128 - 128 s) + cos30 (-970 + 970 s) = -75  =>  s = 0.90336, z = 76.26. */
    fv_vec3 d = fv_sub(fv_v3(150, 75, 170), eye);
    assert_int_equal(fv_scene_set_time(s, 0.0, &err), FV_OK);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, eye, d, 1e30f, &h));
    assert_int_equal(h.mat, mirror);
    assert_float_equal(h.t, 0.90336, 1e-4);
    assert_float_equal(h.p.z, 76.26, 0.05);
    /* At t = 2 it sits at (270, 75, 150), turned 50 degrees: its footprint's low-x edge runs
     * from (260.8, 44.3) to (164.3, 159.2) in x, z, where the ray is at x = 166.6 and 151.4, so
     * the ray passes on that side (the other corners lie further away) and ends on the floor. */
    assert_int_equal(fv_scene_set_time(s, 2.0, &err), FV_OK);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, eye, d, 1e30f, &h));
    assert_int_not_equal(h.mat, mirror);
    assert_float_equal(h.p.y, 0.0, 0.05);
    /* Dynamic-only rays see the cube's new place: straight down onto its top at y = 150. */
    assert_true(fv_scene_intersect(s, FV_TRACE_DYNAMIC, fv_v3(270, 400, 150), fv_v3(0, -1, 0), 1e30f, &h));
    assert_float_equal(h.p.y, 150.0, 0.05);
    assert_false(fv_scene_intersect(s, FV_TRACE_DYNAMIC, fv_v3(150, 400, 170), fv_v3(0, -1, 0), 1e30f, &h));
    /* At t = 4 it is back where it started. */
    assert_int_equal(fv_scene_set_time(s, 4.0, &err), FV_OK);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, eye, d, 1e30f, &h));
    assert_int_equal(h.mat, mirror);
    assert_float_equal(h.t, 0.90336, 1e-4);

    /* The glass sphere (r = 90 on the floor at x 380, z 350): its top at y = 180. */
    assert_true(fv_scene_intersect(s, FV_TRACE_STATIC, fv_v3(380, 400, 350), fv_v3(0, -1, 0), 1e30f, &h));
    assert_int_equal(h.mat, glass);
    assert_float_equal(h.p.y, 180.0, 0.05);

    /* The camera path: the measured camera at 0 s, the second key at 2 s. */
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 64, 64, &cam);
    assert_float_equal(cam.pos.x, 278.0, 1e-3);
    assert_float_equal(cam.pos.z, -800.0, 1e-3);
    fv_view_camera(v, s, 2.0, 64, 64, &cam);
    assert_float_equal(cam.pos.x, 320.0, 1e-2);
    assert_float_equal(cam.pos.z, -740.0, 1e-2);
    assert_int_equal(cam.width, 64);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* ---- cornell-fir ---- */

static void test_fir(void **st)
{
    (void)st;
    fv_view *v;
    fv_scene *s = build("cornell-fir", &v, NULL);
    /* Diffuse only, lit by exactly one delta light: no material emits, so no triangle does. */
    for (int i = 0; i < fv_scene_material_count(s); i++) {
        const fv_material *m = fv_scene_material(s, i);
        assert_int_equal(m->type, FV_MAT_DIFFUSE);
        assert_float_equal(fv_max3(m->emission), 0.0, 0.0);
    }
    assert_int_equal(fv_scene_light_count(s), 1);
    assert_int_equal(fv_light_delta_count(s), 1);
    assert_true(fv_scene_lights_move(s));
    assert_int_equal(fv_scene_dynamic_object_count(s), 1);
    assert_false(fv_view_has_camera_path(v));
    int cube = fv_scene_find_object(s, "yellow_cube");
    assert_true(cube >= 0 && fv_scene_object_dynamic(s, cube));
    assert_false(fv_scene_object_dynamic(s, fv_scene_find_object(s, "tall_block")));
    assert_int_equal(fv_scene_find_object(s, "short_block"), -1);

    /* The light: on a circle of radius 120 at y = 500 around the ceiling's centre, a quarter turn
     * per second, back at its start after 4 s. */
    fv_error err;
    fv_vec3 p[3], lo[3], hi[3];
    const double t[3] = {0.0, 1.0, 4.0};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(fv_scene_set_time(s, t[k], &err), FV_OK);
        p[k] = fv_light_delta_pos(fv_light_delta_at(s, 0));
        fv_scene_object_bounds(s, cube, &lo[k], &hi[k]);
        assert_float_equal(p[k].y, 500.0, 1e-3);
        assert_float_equal(fv_length(fv_sub(p[k], fv_v3(278, 500, 279.6f))), 120.0, 0.1);
    }
    assert_true(fv_length(fv_sub(p[0], p[1])) > 150.0f); /* a quarter of the circle: 120 sqrt 2 */
    assert_float_equal(fv_length(fv_sub(p[0], p[2])), 0.0, 1e-3);
    /* The cube stands on the floor, inside the box, and has moved by t = 1 (and more by 2). */
    for (int k = 0; k < 3; k++) {
        assert_float_equal(lo[k].y, 0.0, 0.01);
        assert_float_equal(hi[k].y, 160.0, 0.01);
        assert_true(lo[k].x > 20.0f && hi[k].x < 530.0f && lo[k].z > 0.0f && hi[k].z < 247.0f);
    }
    assert_true(lo[1].x - lo[0].x > 50.0f);
    assert_float_equal(lo[2].x, lo[0].x, 1e-2);
    assert_float_equal(hi[2].z, hi[0].z, 1e-2);

    /* The camera is cornell's. */
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 64, 64, &cam);
    assert_float_equal(cam.pos.x, 278.0, 1e-3);
    assert_float_equal(cam.pos.z, -800.0, 1e-3);
    assert_float_equal(cam.fov_y, 37.5, 1e-4);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* fv_scene_make_diffuse (scene/edit.h) on cornell-fpm and cornell-glossy: every material diffuse, a specular one
 * takes albedo + specular up to 0.95, a diffuse one and every emission are untouched. */
static void test_make_diffuse(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    assert_int_equal(fv_builtin_build("cornell-fpm", s, NULL, NULL, &err), FV_OK);
    fv_material white = *fv_scene_material(s, fv_scene_find_material(s, "white"));
    fv_material light = *fv_scene_material(s, fv_scene_find_material(s, "light"));
    assert_int_equal(fv_scene_make_diffuse(s, &err), FV_OK);
    for (int i = 0; i < fv_scene_material_count(s); i++) assert_int_equal(fv_scene_material(s, i)->type, FV_MAT_DIFFUSE);
    const fv_material *g = fv_scene_material(s, fv_scene_find_material(s, "glass"));
    const fv_material *m = fv_scene_material(s, fv_scene_find_material(s, "mirror"));
    assert_float_equal(g->albedo.x, 0.95, 1e-6); /* 0 + 1 */
    assert_float_equal(m->albedo.y, 0.95, 1e-6); /* 0 + 0.95 */
    assert_string_equal(g->name, "glass");
    const fv_material *w = fv_scene_material(s, fv_scene_find_material(s, "white"));
    assert_memory_equal(&w->albedo, &white.albedo, sizeof white.albedo);
    const fv_material *l = fv_scene_material(s, fv_scene_find_material(s, "light"));
    assert_memory_equal(&l->emission, &light.emission, sizeof light.emission);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_make_diffuse(s, &err), FV_ERR_INTERNAL);
    fv_scene_destroy(s);
    /* A glossy plastic keeps its Lambert albedo plus its 4 % F0; the copper its F0. */
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    assert_int_equal(fv_builtin_build("cornell-glossy", s, NULL, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_make_diffuse(s, &err), FV_OK);
    const fv_material *p = fv_scene_material(s, fv_scene_find_material(s, "plastic"));
    const fv_material *c = fv_scene_material(s, fv_scene_find_material(s, "copper"));
    assert_float_equal(p->albedo.x, 0.725 + 0.04, 1e-6);
    assert_float_equal(c->albedo.x, 0.95, 1e-6);
    assert_float_equal(c->albedo.y, 0.64, 1e-6);
    assert_int_equal(p->type, FV_MAT_DIFFUSE);
    fv_scene_destroy(s);
}

/* ---- furnace ---- */

static void test_furnace(void **st)
{
    (void)st;
    fv_view *v;
    fv_scene *s = build("furnace", &v, NULL);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 32, 32, &cam);
    assert_float_equal(fv_length(cam.pos), 0.0, 1e-6);
    /* Closed: rays from the centre in 26 directions all hit the unit sphere (inscribed polygon
     * of 48 x 24 segments: distance between cos(pi/24) = 0.9914 and 1). */
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                if (!dx && !dy && !dz) continue;
                fv_hit h;
                fv_vec3 d = fv_normalize(fv_v3((float)dx, (float)dy + 0.1f, (float)dz));
                assert_true(fv_scene_intersect(s, FV_TRACE_ALL, cam.pos, d, 1e30f, &h));
                assert_true(h.t > 0.99f && h.t < 1.0001f);
                const fv_material *m = fv_scene_material(s, h.mat);
                assert_float_equal(m->albedo.y, 0.5, 1e-6);
                assert_float_equal(m->emission.z, 0.5, 1e-6);
                assert_true(m->two_sided_emission);
                assert_true(fv_dot(h.ng, d) < 0.0f); /* wound to face the centre */
            }
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* ---- city ---- */

static void test_city(void **st)
{
    (void)st;
    double secs;
    fv_view *v;
    fv_scene *a = build("city", &v, &secs);
    fv_scene *b = build("city", NULL, NULL);
    int n = fv_scene_triangle_count(a);
    assert_true(n >= 100000);
    assert_int_equal(fv_scene_triangle_count(b), n); /* deterministic */
    fv_vec3 lo1, hi1, lo2, hi2;
    fv_scene_bounds(a, &lo1, &hi1);
    fv_scene_bounds(b, &lo2, &hi2);
    assert_memory_equal(&hi1, &hi2, sizeof hi1);
    assert_memory_equal(&lo1, &lo2, sizeof lo1);
    /* The ground spans -10..250 in x and z; nothing is taller than 30 plus a lamp. */
    assert_float_equal(lo1.x, -10.0, 1e-3);
    assert_float_equal(hi1.z, 250.0, 1e-3);
    assert_true(hi1.y > 10.0f && hi1.y <= 30.1f);
    assert_true(secs < 1.0);
    /* All four material types are in use, several diffuse and glossy ones. */
    int types[4] = {0, 0, 0, 0};
    for (int i = 0; i < fv_scene_material_count(a); i++) types[fv_scene_material(a, i)->type]++;
    assert_true(types[FV_MAT_DIFFUSE] >= 4 && types[FV_MAT_GLOSSY] >= 3);
    assert_true(types[FV_MAT_MIRROR] >= 1 && types[FV_MAT_DIELECTRIC] >= 1);
    /* 4 delta lights plus two triangles per roof panel. */
    int lights = fv_scene_light_count(a);
    assert_true(lights > 4 && (lights - 4) % 2 == 0);
    /* The point lights hang over street crossings, not inside a tower: straight down from each
     * is the open ground, 6 below. */
    int ground = fv_scene_find_material(a, "ground"), points = 0;
    for (int i = 0; i < a->ndelta; i++) {
        if (a->delta[i].desc.type != FV_LIGHT_POINT) continue;
        points++;
        fv_hit g;
        assert_true(fv_scene_intersect(a, FV_TRACE_ALL, a->delta[i].desc.pos, fv_v3(0, -1, 0), 1e30f, &g));
        assert_int_equal(g.mat, ground);
        assert_float_equal(g.t, 6.0, 1e-3);
    }
    assert_int_equal(points, 3);
    /* The camera's centre ray hits the city. */
    fv_camera cam;
    fv_camera_basis bs;
    fv_error err;
    fv_view_camera(v, a, 0.0, 64, 48, &cam);
    assert_int_equal(fv_camera_basis_make(&cam, &bs, &err), FV_OK);
    fv_hit h;
    assert_true(fv_scene_intersect(a, FV_TRACE_ALL, cam.pos, fv_camera_dir(&bs, 32, 24), 1e30f, &h));
    assert_true(h.p.x > 0.0f && h.p.x < 240.0f && h.p.z > 0.0f && h.p.z < 240.0f);
    fv_view_destroy(v);
    fv_scene_destroy(a);
    fv_scene_destroy(b);
}

/* ---- mesh generators ---- */

static void test_sphere(void **st)
{
    (void)st;
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_vec3 c = fv_v3(1, 2, 3);
    fv_mesh_sphere(&mb, c, 2.0f, 256, 128, false, 7);
    assert_false(mb.oom);
    assert_true(mb.smooth);
    assert_int_equal(mb.nt, 2 * 256 * 127);
    assert_int_equal(mb.nt, fv_mesh_sphere_triangles(256, 128));
    double area = total_area(&mb), want = 4.0 * FV_PI * 4.0;
    assert_true(area < want && area > 0.99 * want); /* inscribed, so slightly smaller */
    for (int t = 0; t < mb.nt; t++) {
        assert_true(fv_dot(tri_normal(&mb, t), fv_sub(tri_centroid(&mb, t), c)) > 0.0f);
        assert_int_equal(mb.mat[t], 7);
    }
    for (int v = 0; v < mb.nv; v++) {
        assert_float_equal(fv_length(fv_sub(mb.pos[v], c)), 2.0, 1e-5);
        assert_float_equal(fv_dot(mb.nrm[v], fv_normalize(fv_sub(mb.pos[v], c))), 1.0, 1e-5);
    }
    /* Inward: same count, every triangle and normal faces the centre. */
    fv_meshbuf_clear(&mb);
    fv_mesh_sphere(&mb, c, 2.0f, 8, 4, true, 0);
    assert_int_equal(mb.nt, 2 * 8 * 3);
    for (int t = 0; t < mb.nt; t++) assert_true(fv_dot(tri_normal(&mb, t), fv_sub(tri_centroid(&mb, t), c)) < 0.0f);
    for (int v = 0; v < mb.nv; v++) assert_true(fv_dot(mb.nrm[v], fv_sub(mb.pos[v], c)) < 0.0f);
    fv_meshbuf_free(&mb);
}

static void test_box(void **st)
{
    (void)st;
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_vec3 c = fv_v3(5, 1, -2), h = fv_v3(1, 2, 3);
    fv_mesh_box(&mb, c, h, 30.0f, 2);
    assert_int_equal(mb.nt, 12);
    assert_false(mb.smooth);
    /* Area 8 (1*2 + 2*3 + 3*1) = 88. */
    assert_float_equal(total_area(&mb), 88.0, 1e-3);
    /* Every face points away from the centre, along one of the box's own axes: x turned 30
     * degrees about +y is (cos 30, 0, -sin 30). */
    fv_vec3 ax = fv_v3(cosf(fv_radians(30.0f)), 0.0f, -sinf(fv_radians(30.0f)));
    int along_x = 0, down = 0;
    for (int t = 0; t < 12; t++) {
        fv_vec3 n = fv_normalize(tri_normal(&mb, t));
        assert_true(fv_dot(n, fv_sub(tri_centroid(&mb, t), c)) > 0.0f);
        if (fabsf(fv_dot(n, ax)) > 0.9999f) along_x++;
        if (n.y < -0.9999f) down++;
    }
    assert_int_equal(along_x, 4);
    assert_int_equal(down, 2);
    /* The open box drops the bottom. */
    fv_meshbuf_clear(&mb);
    fv_mesh_box_open(&mb, c, h, 0.0f, 2);
    assert_int_equal(mb.nt, 10);
    for (int t = 0; t < 10; t++) assert_true(fv_normalize(tri_normal(&mb, t)).y > -0.5f);
    fv_meshbuf_free(&mb);
}

static void test_quads_and_grid(void **st)
{
    (void)st;
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    /* y = 3 plane over z 0..2, x 0..4 facing down: area 8, normal -y. */
    fv_mesh_axis_quad(&mb, 1, 3.0f, 0.0f, 0.0f, 2.0f, 4.0f, -1, 0);
    fv_mesh_axis_quad(&mb, 2, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1, 0);
    assert_int_equal(mb.nt, 4);
    for (int t = 0; t < 2; t++) assert_true(fv_normalize(tri_normal(&mb, t)).y < -0.9999f);
    for (int t = 2; t < 4; t++) assert_true(fv_normalize(tri_normal(&mb, t)).z > 0.9999f);
    assert_float_equal(total_area(&mb), 9.0, 1e-5);
    for (int v = 0; v < 4; v++) assert_float_equal(mb.pos[v].y, 3.0, 0.0);
    fv_meshbuf_clear(&mb);
    fv_mesh_grid(&mb, fv_v3(0, 0, 0), fv_v3(3, 0, 0), fv_v3(0, 0, -2), 6, 4, 1);
    assert_int_equal(mb.nt, 2 * 6 * 4);
    assert_int_equal(mb.nv, 7 * 5);
    assert_float_equal(total_area(&mb), 6.0, 1e-5);
    for (int t = 0; t < mb.nt; t++) assert_true(fv_normalize(tri_normal(&mb, t)).y > 0.9999f);
    /* As a mesh description. */
    fv_mesh_desc d;
    fv_meshbuf_desc(&mb, "grid", &d);
    assert_int_equal(d.triangle_count, 48);
    assert_int_equal(d.vertex_count, 35);
    assert_null(d.normals);
    assert_string_equal(d.name, "grid");
    fv_meshbuf_free(&mb);
}

static void test_oom_contract(void **st)
{
    (void)st;
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_box(&mb, fv_v3(0, 0, 0), fv_v3s(1), 0.0f, 0);
    fv_error err;
    assert_int_equal(fv_meshbuf_check(&mb, "box", &err), FV_OK);
    /* After a failed allocation nothing more is added and the failure is reported once, by name. */
    mb.oom = true;
    assert_int_equal(fv_meshbuf_vertex(&mb, fv_v3(0, 0, 0), fv_v3(0, 1, 0)), -1);
    fv_mesh_sphere(&mb, fv_v3(0, 0, 0), 1.0f, 8, 4, false, 0);
    assert_int_equal(mb.nt, 12);
    assert_int_equal(fv_meshbuf_check(&mb, "box", &err), FV_ERR_NOMEM);
    assert_non_null(strstr(err.msg, "'box'"));
    fv_scene *s;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    assert_int_equal(fv_meshbuf_add(&mb, s, "box", NULL, NULL, &err), FV_ERR_NOMEM);
    fv_scene_destroy(s);
    fv_meshbuf_free(&mb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table),       cmocka_unit_test(test_unknown_name), cmocka_unit_test(test_counts),
        cmocka_unit_test(test_cornell_geometry), cmocka_unit_test(test_cornell_glossy), cmocka_unit_test(test_fpm),
        cmocka_unit_test(test_fir),         cmocka_unit_test(test_make_diffuse),
        cmocka_unit_test(test_furnace),     cmocka_unit_test(test_city),         cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_box),         cmocka_unit_test(test_quads_and_grid), cmocka_unit_test(test_oom_contract),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
