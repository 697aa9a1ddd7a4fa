/* Photon mapping (Foveated Photon Mapping, Sec. 3): Eq. 1 on a hand-built photon set, Eq. 8,
 * negative photons cancelling the light a dynamic occluder blocks, temporal photon management
 * (full reuse for a still view, deletion and retracing when the gaze moves), bounded memory over
 * a long moving sequence, and parameter checking. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "technique/photon/foveated.h"
#include "technique/photon/photon_trace.h"
#include "testkit.h"

/* Eq. 8 for the Cornell box (0..556, 0..548.8, 0..559.2) at 1080x1200: mean extent
 * (556 + 548.8 + 559.2) / 3 = 554.667, over (1080 + 1200) / 2 = 1140, times 20 = 9.73099. */
static void test_eq8(void **st)
{
    (void)st;
    assert_float_equal(fv_photon_radius_eq8(fv_v3(0, 0, 0), fv_v3(556.0f, 548.8f, 559.2f), 1080, 1200), 9.73099, 1e-4);
}

/* Eq. 1 on a hand-built photon set: a diffuse floor (albedo 0.5, f_r = 0.5 / pi), two pixels
 * seeing it at A = (0,0,0) and B = (10,0,0), photons stored by hand. Gather radius 1:
 *   A: light photon of flux 2 at 0.5 from A, foveated photon of flux 1 at 0.3 from A;
 *   B: light photon of flux 6, foveated photon of flux 6; a negative light photon of flux -4
 *      next to B is left out of the sums (Eq. 1 sums positive flux).
 * Gathered luminance is flux * 0.5 / pi, and eta is a ratio, so the f_r factor cancels:
 *   eta over {A} = 2 / (2 + 1) = 0.666667;  eta over {A, B} = (2 + 6) / (2 + 6 + 1 + 6) = 0.533333. */
static void sum_y(void *ctx, const fv_photon *ph, float d2)
{
    (void)d2;
    *(double *)ctx += ph->flux.y;
}

static void test_eta(void **st)
{
    (void)st;
    fv_photon_map light, fov;
    fv_photon_map_init(&light);
    fv_photon_map_init(&fov);
    fv_error err;
    const fv_vec3 n = {0, 1, 0}, d = {0, -1, 0};
    fv_photon p[3] = {{{0.5f, 0, 0}, d, {2, 2, 2}, n}, {{10.2f, 0, 0}, d, {6, 6, 6}, n}, {{10.0f, 0, 0.4f}, d, {-4, -4, -4}, n}};
    fv_photon q[2] = {{{0, 0, 0.3f}, d, {1, 1, 1}, n}, {{9.8f, 0, 0}, d, {6, 6, 6}, n}};
    assert_int_equal(fv_photon_map_append(&light, p, 2, &err), FV_OK); /* the negative one goes in separately below */
    assert_int_equal(fv_photon_map_append(&fov, q, 2, &err), FV_OK);
    fv_photon_map neg;
    fv_photon_map_init(&neg);
    assert_int_equal(fv_photon_map_append(&neg, &p[2], 1, &err), FV_OK);
    assert_int_equal(fv_photon_map_build(&light, 1.0f, &err), FV_OK);
    assert_int_equal(fv_photon_map_build(&fov, 1.0f, &err), FV_OK);
    assert_int_equal(fv_photon_map_build(&neg, 1.0f, &err), FV_OK);
    const fv_vec3 px[2] = {{0, 0, 0}, {10, 0, 0}};
    float l[2], f[2];
    for (int i = 0; i < 2; i++) {
        double sl = 0, sf = 0, sn = 0;
        fv_photon_map_query(&light, px[i], 1.0f, sum_y, &sl);
        fv_photon_map_query(&fov, px[i], 1.0f, sum_y, &sf);
        fv_photon_map_query(&neg, px[i], 1.0f, sum_y, &sn);
        const double fr = 0.5 / FV_PI;
        l[i] = (float)(fr * (sl + (sn > 0 ? sn : 0)));
        f[i] = (float)(fr * sf);
    }
    const uint8_t only_a[2] = {1, 0}, both[2] = {1, 1};
    assert_float_equal(fv_foveated_eta(l, f, only_a, 2), 2.0 / 3.0, 1e-6);
    assert_float_equal(fv_foveated_eta(l, f, both, 2), 8.0 / 15.0, 1e-6);
    const float none[2] = {0, 0};
    assert_float_equal(fv_foveated_eta(l, none, both, 2), 1.0, 0.0); /* no foveated flux: eta = 1 */
    const float negf[2] = {-3, -3};
    assert_float_equal(fv_foveated_eta(l, negf, both, 2), 1.0, 0.0);
    fv_photon_map_free(&light);
    fv_photon_map_free(&fov);
    fv_photon_map_free(&neg);
}

/* A floor (albedo 0.5) under a 20x20 area light at height 100, and a dynamic 20x20x20 box at
 * height 40..60 between them. One bounce only, so all light on the floor is direct and the static
 * map plus the dynamic map (negative photons behind the box) must match a full retrace. */
static fv_scene *occluder_scene(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE), e = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.5f);
    e.albedo = fv_v3s(0.0f);
    e.emission = fv_v3s(10.0f);
    int mm, em;
    assert_int_equal(fv_scene_add_material(s, &m, &mm, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &e, &em, &err), FV_OK);
    const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
    const fv_vec3 fl[4] = {{-100, 0, -100}, {-100, 0, 100}, {100, 0, 100}, {100, 0, -100}};
    fv_mesh_desc floor = {"floor", fl, 4, NULL, quad, 2, NULL, mm, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &floor, NULL, NULL, &err), FV_OK);
    const fv_vec3 lv[4] = {{-10, 100, -10}, {10, 100, -10}, {10, 100, 10}, {-10, 100, 10}};
    fv_mesh_desc light = {"light", lv, 4, NULL, quad, 2, NULL, em, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &light, NULL, NULL, &err), FV_OK);
    fv_vec3 bv[8];
    for (int k = 0; k < 8; k++) bv[k] = fv_v3(k & 1 ? 10.0f : -10.0f, k & 2 ? 10.0f : -10.0f, k & 4 ? 10.0f : -10.0f);
    const uint32_t bi[36] = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
    fv_mesh_desc box = {"box", bv, 8, NULL, bi, 12, NULL, mm, NULL};
    int obj;
    assert_int_equal(fv_scene_add_mesh(s, &box, NULL, &obj, &err), FV_OK);
    fv_anim_key keys[2] = {{0.0, {0, 50, 0}, {0, 0, 0, 1}, {1, 1, 1}}, {1.0, {0, 50, 0}, {0, 0, 0, 1}, {1, 1, 1}}};
    assert_int_equal(fv_scene_animate_object(s, obj, keys, 2, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_set_time(s, 0.0, &err), FV_OK);
    return s;
}

static void add_flux(void *ctx, const fv_photon *ph, float d2)
{
    (void)d2;
    *(double *)ctx += ph->flux.y;
}

static double irradiance(const fv_photon_map *m, fv_vec3 x, float r)
{
    double sum = 0.0;
    fv_photon_map_query(m, x, r, add_flux, &sum);
    return sum / (FV_PI * r * r);
}

static void test_negative_photons(void **st)
{
    (void)st;
    fv_scene *s = occluder_scene();
    fv_error err;
    fv_photon_map all, ls, ld;
    fv_photon_map_init(&all);
    fv_photon_map_init(&ls);
    fv_photon_map_init(&ld);
    fv_photon_job job = {s, 400000, 7, 0, 1, 0, 0, NULL, NULL, NULL, NULL};
    assert_int_equal(fv_photon_trace_lights(&job, FV_TRACE_ALL, &all, NULL, &err), FV_OK);
    job.stream = 1;
    assert_int_equal(fv_photon_trace_lights(&job, FV_TRACE_STATIC, &ls, NULL, &err), FV_OK);
    fv_dyn_dirs *dirs;
    assert_int_equal(fv_dyn_dirs_create(&dirs, &err), FV_OK);
    assert_int_equal(fv_dyn_dirs_build(dirs, s, &err), FV_OK);
    assert_int_equal(fv_dyn_dirs_count(dirs), 1);
    job.stream = 2;
    job.count = 100000;
    assert_int_equal(fv_photon_trace_dynamic(&job, dirs, &ld, NULL, &err), FV_OK);
    const float r = 8.0f; /* ~2500 photons in the disc under the light: 2% noise */
    assert_int_equal(fv_photon_map_build(&all, r, &err), FV_OK);
    assert_int_equal(fv_photon_map_build(&ls, r, &err), FV_OK);
    assert_int_equal(fv_photon_map_build(&ld, r, &err), FV_OK);
    /* Irradiance on the floor from the light, worked out as E = Le * F * pi with the point-to-
     * parallel-square form factor (side 20 at height 100, X = 0.1): F = 4 * (1/2pi) * 2 * c atan(c),
     * c = 0.1 / sqrt(1.01) = 0.0995037, atan(c) = 0.0991773 -> F = 0.0125634; E = 10 * pi * F
     * = 0.394690 at the point under the light when nothing blocks it. */
    double lit_static = irradiance(&ls, fv_v3(0, 0, 0), r);
    assert_float_equal(lit_static, 0.394690, 0.06 * 0.394690);
    /* Under the box (full umbra): the full retrace is dark, the static map is lit, the negative
     * photons cancel it. */
    double full = irradiance(&all, fv_v3(0, 0, 0), r), dyn = irradiance(&ld, fv_v3(0, 0, 0), r);
    assert_true(fabs(full) < 0.01);
    assert_true(dyn < -0.8 * lit_static);
    assert_float_equal(lit_static + dyn, full, 0.08 * lit_static);
    /* Well away from the shadow the dynamic photons change nothing. */
    double far_full = irradiance(&all, fv_v3(60, 0, 0), r), far_sum = irradiance(&ls, fv_v3(60, 0, 0), r) + irradiance(&ld, fv_v3(60, 0, 0), r);
    assert_float_equal(far_sum, far_full, 0.08 * far_full);
    fv_dyn_dirs_destroy(dirs);
    fv_photon_map_free(&all);
    fv_photon_map_free(&ls);
    fv_photon_map_free(&ld);
    fv_scene_destroy(s);
}

static fv_technique *make(const fv_scene *s, const char *method, const char *const *kv)
{
    fv_error err;
    fv_params *p = fv_test_params(kv);
    fv_technique *t = NULL;
    fv_status rc = fv_technique_create(method, s, p, NULL, &t, &err);
    if (rc != FV_OK) fail_msg("%s", err.msg);
    fv_params_destroy(p);
    return t;
}

static void frame_stats(fv_technique *t, fv_scene *s, fv_film *f, const fv_camera *cam, const fv_camera *prev, fv_gaze g, int index,
                        fv_stats *stats)
{
    fv_error err;
    fv_frame fr;
    fv_frame_init(&fr, NULL);
    fr.camera = cam;
    fr.prev_camera = prev;
    fr.index = index;
    fr.seed = 3;
    fr.gaze = g;
    fr.time = fv_scene_time(s);
    fv_stats_clear(stats);
    fv_status rc = fv_technique_render(t, &fr, f, stats, &err);
    if (rc != FV_OK) fail_msg("%s", err.msg);
}

/* Alg. 2: with the camera and gaze still, every stored path is reused and none is deleted; when
 * the gaze jumps to the other side, the paths of the old focus region are deleted and new ones
 * traced. */
static void test_tpm_reuse(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell", NULL, &s, &v, &err), FV_OK);
    const char *kv[] = {"photons=40000", "filter=false", "paths_per_pixel=2", NULL};
    fv_technique *t = make(s, "fpm", kv);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 48, 48, &cam);
    fv_film *f;
    assert_int_equal(fv_film_create(48, 48, 0, &f, &err), FV_OK);
    fv_stats a, b, c;
    fv_gaze g = {0.3f, 0.5f};
    frame_stats(t, s, f, &cam, NULL, g, 0, &a);
    double stored = fv_stats_get_count(&a, "paths_stored");
    assert_true(stored > 100);
    frame_stats(t, s, f, &cam, &cam, g, 1, &b);
    assert_float_equal(fv_stats_get_count(&b, "paths_reused"), stored, 0.0);
    assert_float_equal(fv_stats_get_count(&b, "paths_deleted"), 0.0, 0.0);
    assert_true(fv_stats_get_count(&b, "reuse_rate") > 0.5);
    fv_gaze g2 = {0.8f, 0.5f};
    frame_stats(t, s, f, &cam, &cam, g2, 2, &c);
    assert_true(fv_stats_get_count(&c, "paths_deleted") > 0);
    assert_true(fv_stats_get_count(&c, "paths_traced") > 0);
    assert_true(fv_stats_get_count(&c, "paths_reused") < stored);
    /* Without temporal photon management nothing is reused. */
    const char *kv2[] = {"photons=40000", "filter=false", "paths_per_pixel=2", "tpm=false", NULL};
    fv_technique *t2 = make(s, "fpm", kv2);
    frame_stats(t2, s, f, &cam, NULL, g, 0, &a);
    frame_stats(t2, s, f, &cam, &cam, g, 1, &b);
    assert_float_equal(fv_stats_get_count(&b, "paths_reused"), 0.0, 0.0);
    fv_technique_destroy(t);
    fv_technique_destroy(t2);
    fv_film_destroy(f);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* 500 frames along cornell-fpm's camera path with a wandering gaze: the live paths and the pool
 * stop growing once the focus region has been filled. */
static void test_memory_flat(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell-fpm", NULL, &s, &v, &err), FV_OK);
    const char *kv[] = {"photons=6000", "filter=false", "paths_per_pixel=2", NULL};
    fv_technique *t = make(s, "fpm", kv);
    fv_film *f;
    assert_int_equal(fv_film_create(24, 24, 0, &f, &err), FV_OK);
    fv_camera cam, prev;
    fv_stats stats;
    double cap_early = 0, cap_late = 0, live_max = 0;
    const int frames = 500;
    for (int i = 0; i < frames; i++) {
        double time = 4.0 * i / frames;
        assert_int_equal(fv_scene_set_time(s, time, &err), FV_OK);
        fv_view_camera(v, s, time, 24, 24, &cam);
        fv_gaze g = {0.5f + 0.3f * sinf(0.05f * i), 0.5f + 0.2f * cosf(0.03f * i)};
        frame_stats(t, s, f, &cam, i ? &prev : NULL, g, i, &stats);
        prev = cam;
        if (i == 50) cap_early = fv_stats_get_count(&stats, "path_capacity");
        cap_late = fv_stats_get_count(&stats, "path_capacity");
        live_max = fmax(live_max, fv_stats_get_count(&stats, "paths_live"));
    }
    /* At most N paths per pixel are ever alive; the pool never needs more than twice that. */
    assert_true(live_max <= 2 * 24 * 24);
    assert_true(cap_late <= 2 * cap_early || cap_late <= 4 * 24 * 24);
    fv_technique_destroy(t);
    fv_film_destroy(f);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* Sec. 3.3: the right eye reuses the left eye's colours wherever its pixel shows the same surface.
 * With an eye separation of 0 both views coincide: every pixel that sees a surface is copied, so the
 * right image equals the left one there; with a real separation most pixels are still copied. */
static void test_stereo_reprojection(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell", NULL, &s, &v, &err), FV_OK);
    const char *kv[] = {"photons=20000", "filter=false", NULL};
    fv_technique *t = make(s, "fpm", kv);
    fv_camera c, l, r;
    fv_view_camera(v, s, 0.0, 40, 40, &c);
    fv_film *fl, *fr;
    assert_int_equal(fv_film_create(40, 40, 0, &fl, &err), FV_OK);
    assert_int_equal(fv_film_create(40, 40, 0, &fr, &err), FV_OK);
    for (int k = 0; k < 2; k++) {
        fv_camera_stereo(&c, k == 0 ? 0.0f : 6.4f, &l, &r);
        fv_frame f;
        fv_frame_init(&f, NULL);
        f.camera = &l;
        f.eye_count = 2;
        f.seed = 1;
        f.gaze = (fv_gaze){0.5f, 0.5f};
        fv_stats stats;
        fv_stats_clear(&stats);
        assert_int_equal(fv_technique_render(t, &f, fl, &stats, &err), FV_OK);
        f.eye = 1;
        f.camera = &r;
        f.left_camera = &l;
        assert_int_equal(fv_technique_render(t, &f, fr, &stats, &err), FV_OK);
        double copied = fv_stats_get_count(&stats, "reprojected_fraction");
        if (k == 0) {
            assert_true(copied > 0.95);
            assert_memory_equal(fv_film_color(fl), fv_film_color(fr), 40 * 40 * 3 * sizeof(float));
        } else {
            assert_true(copied > 0.6 && copied < 1.0);
        }
    }
    fv_technique_destroy(t);
    fv_film_destroy(fl);
    fv_film_destroy(fr);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_bad_params(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell", NULL, &s, NULL, &err), FV_OK);
    const char *cases[][2] = {{"fpm", "photons=-5"},       {"fpm", "fov_fraction=1.5"}, {"fpm", "fov_fraction=-0.1"},
                              {"pm", "radius=0"},           {"pm-t", "radius=-2"},       {"fpm", "paths_per_pixel=100"},
                              {"pm", "max_depth=0"},        {"pm-t", "dyn_fraction=2"},  {"pm", "fov_fraction=0.4"},
                              {"fpm", "tpm=maybe"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *kv[] = {cases[i][1], NULL};
        fv_params *p = fv_test_params(kv);
        fv_technique *t = NULL;
        char key[32], what[64];
        snprintf(key, sizeof key, "%.*s", (int)strcspn(cases[i][1], "="), cases[i][1]);
        snprintf(what, sizeof what, "%s %s", cases[i][0], cases[i][1]);
        fv_test_expect_fail(fv_technique_create(cases[i][0], s, p, NULL, &t, &err), &err, FV_ERR_INVALID, key, what);
        assert_null(t);
        fv_params_destroy(p);
    }
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eq8),       cmocka_unit_test(test_eta),         cmocka_unit_test(test_negative_photons),
        cmocka_unit_test(test_tpm_reuse), cmocka_unit_test(test_memory_flat), cmocka_unit_test(test_stereo_reprojection),
        cmocka_unit_test(test_bad_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
