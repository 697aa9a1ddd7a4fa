/* fovea — the instant-radiosity family end to end (Foveated Instant Radiosity): ir's VPL estimator
 * against pt with one bounce, ir-low against ir, the interleaved estimate against the full one,
 * fir's reuse in a still scene (all VPLs kept, E' = 0), VPLs following a moving object, memory flat
 * over 500 frames, and the parameters refused with the key named.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "fovea/fovea.h"
#include "scene/query.h"
#include "technique/vpl/fir.h"
#include "testkit.h"

typedef struct shot {
    fv_film *film;
    fv_stats stats;
} shot;

static fv_scene *load(const char *name, double t, int w, int h, fv_camera *cam)
{
    fv_scene *s;
    fv_view *v;
    fv_error err;
    if (fv_test_load(name, &s, &v) != 0) fail_msg("cannot load %s", name);
    fv_view_camera(v, s, t, w, h, cam);
    fv_view_destroy(v);
    if (fv_scene_set_time(s, t, &err) != FV_OK) fail_msg("set_time: %s", err.msg);
    return s;
}

/* Frames 0 .. frames-1 of `method` (params "k=v k=v"), gaze at the centre, seed 3, two threads, the
 * scene's time left as it is (a still scene): the last frame's film and stats. */
static shot render_n(const char *method, const fv_scene *s, const fv_camera *cam, const char *params, int frames)
{
    shot r;
    fv_error err;
    fv_params *p = fv_test_params_str(params);
    fv_technique *t = NULL;
    if (fv_technique_create(method, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s %s: %s", method, params, err.msg);
    assert_int_equal(fv_film_create(cam->width, cam->height, 0, &r.film, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, cam);
    fr.seed = 3;
    fr.threads = 2;
    fv_test_render_frames(t, &fr, frames, r.film, &r.stats);
    assert_true(fv_stats_get_count(&r.stats, "nan_samples") == 0);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return r;
}

static size_t npix(const shot *a) { return (size_t)fv_film_width(a->film) * fv_film_height(a->film); }
static const float *col(const shot *a) { return fv_film_color_const(a->film); }

static double mean_colour(const shot *a)
{
    double sum = 0.0;
    for (size_t i = 0; i < 3 * npix(a); i++) sum += col(a)[i];
    return sum / (3.0 * (double)npix(a));
}

/* Mean over 8x8 blocks of the relative difference of block means: compares two noisy estimates
 * region by region without being swamped by per-pixel noise. */
static double block_rel_diff(const shot *a, const shot *b)
{
    const int w = fv_film_width(a->film), h = fv_film_height(a->film);
    double sum = 0.0;
    int n = 0;
    for (int by = 0; by + 8 <= h; by += 8)
        for (int bx = 0; bx + 8 <= w; bx += 8) {
            double ma = 0.0, mb = 0.0;
            for (int y = by; y < by + 8; y++)
                for (int x = bx; x < bx + 8; x++)
                    for (int c = 0; c < 3; c++) {
                        ma += col(a)[3 * ((size_t)y * w + x) + c];
                        mb += col(b)[3 * ((size_t)y * w + x) + c];
                    }
            if (ma <= 1e-6) continue;
            sum += fabs(mb - ma) / ma;
            n++;
        }
    return n ? sum / n : 0.0;
}

static void drop(shot *a) { fv_film_destroy(a->film); }

/* ir's VPL estimator before fir builds on it: VPLs on the first light-path vertex only (bounces=1)
 * against pt with direct light plus one bounce (max_depth=2), in the diffuse Cornell box lit by
 * cornell-fir's point light (no area light, so the direct terms are exact in both). */
static void test_ir_vs_pt_one_bounce(void **state)
{
    (void)state;
    fv_camera cam;
    fv_scene *s = load("cornell-fir", 0.0, 48, 48, &cam);
    shot pt = render_n("pt", s, &cam, "spp=1024 max_depth=2", 1);
    shot ir = render_n("ir", s, &cam, "vpls=8000 bounces=1", 1);
    shot ind = render_n("ir", s, &cam, "vpls=8000 bounces=1 show=indirect", 1);
    shot pt1 = render_n("pt", s, &cam, "spp=1024 max_depth=1", 1);
    const double mp = mean_colour(&pt), mi = mean_colour(&ir), m1 = mean_colour(&pt1), mind = mean_colour(&ind);
    const double blocks = block_rel_diff(&pt, &ir);
    print_message("cornell-fir 48x48: pt(depth 2) %.5f, ir(1 bounce) %.5f (%.4f); indirect pt %.5f, ir %.5f; blocks %.4f\n", mp, mi,
                  mi / mp, mp - m1, mind, blocks);
    /* the clamp (3% of the radius) loses a little next to walls; pixel centres vs pt's jitter */
    assert_true(fabs(mi / mp - 1.0) < 0.03);
    assert_true(fabs(mind / (mp - m1) - 1.0) < 0.08);
    assert_true(blocks < 0.10);
    /* ir-low's cube maps against ir's exact rays, same VPLs */
    shot lo = render_n("ir-low", s, &cam, "vpls=8000 bounces=1 cube_size=128", 1);
    print_message("ir-low %.5f vs ir %.5f; blocks %.4f\n", mean_colour(&lo), mi, block_rel_diff(&ir, &lo));
    assert_true(fabs(mean_colour(&lo) / mi - 1.0) < 0.02);
    assert_true(block_rel_diff(&ir, &lo) < 0.03);
    drop(&pt);
    drop(&ir);
    drop(&ind);
    drop(&pt1);
    drop(&lo);
    fv_scene_destroy(s);
}

/* Interleaved sampling (Sec. 3.4) keeps the expected light: each pixel's tile sum is scaled by
 * n / n_tile. fir with 5x5 tiles and with one tile, same VPLs (a still scene, same seed), unfiltered:
 * the image means agree. */
static void test_interleave_unbiased(void **state)
{
    (void)state;
    fv_camera cam;
    fv_scene *s = load("cornell-fir", 0.0, 60, 60, &cam);
    const char *common = "vpls=400 candidates=800 resolution=32 cube_size=32 filter=none show=indirect";
    char p1[256], p5[256];
    snprintf(p1, sizeof p1, "%s tiles_x=1 tiles_y=1", common);
    snprintf(p5, sizeof p5, "%s tiles_x=5 tiles_y=5", common);
    shot one = render_n("fir", s, &cam, p1, 3), five = render_n("fir", s, &cam, p5, 3);
    print_message("fir indirect: 1 tile %.5f, 5x5 tiles %.5f (%.4f)\n", mean_colour(&one), mean_colour(&five),
                  mean_colour(&five) / mean_colour(&one));
    assert_true(mean_colour(&one) > 0.0);
    assert_true(fabs(mean_colour(&five) / mean_colour(&one) - 1.0) < 0.05);
    /* the box filter only moves light between pixels that hit */
    char pb[256];
    snprintf(pb, sizeof pb, "%s tiles_x=5 tiles_y=5", "vpls=400 candidates=800 resolution=32 cube_size=32 filter=box show=indirect");
    shot box = render_n("fir", s, &cam, pb, 3);
    assert_true(fabs(mean_colour(&box) / mean_colour(&five) - 1.0) < 0.03);
    drop(&one);
    drop(&five);
    drop(&box);
    fv_scene_destroy(s);
}

/* A still scene and gaze (Sec. 3.3): once the set is full, every VPL is reused (Eq. 2 gives 1 when
 * the importance does not change), none is new, no map but the 20% refresh is built, and two
 * consecutive frames are identical (E' = 0 with a fixed seed). */
static void test_still_reuse(void **state)
{
    (void)state;
    fv_camera cam;
    fv_scene *s = load("cornell-fir", 0.5, 40, 40, &cam);
    fv_error err;
    fv_params *p = fv_test_params_str("vpls=150 candidates=400 resolution=32 cube_size=16");
    fv_technique *t = NULL;
    assert_int_equal(fv_technique_create("fir", s, p, NULL, &t, &err), FV_OK);
    fv_film *a, *b;
    assert_int_equal(fv_film_create(40, 40, 0, &a, &err), FV_OK);
    assert_int_equal(fv_film_create(40, 40, 0, &b, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, &cam);
    fr.seed = 3;
    fr.threads = 2;
    fv_stats st;
    for (int i = 0; i < 14; i++) {
        fr.index = i;
        fr.prev_camera = i ? &cam : NULL;
        fv_stats_clear(&st);
        assert_int_equal(fv_technique_render(t, &fr, i % 2 ? b : a, &st, &err), FV_OK);
    }
    const double valid = fv_stats_get_count(&st, "valid_vpls"), reused = fv_stats_get_count(&st, "reused_vpls");
    print_message("still: valid %.0f reused %.0f new %.0f dropped %.0f maps %.0f\n", valid, reused,
                  fv_stats_get_count(&st, "new_vpls"), fv_stats_get_count(&st, "dropped_vpls"),
                  fv_stats_get_count(&st, "cube_maps_built"));
    assert_true(valid > 100);
    assert_true(reused == valid);
    assert_true(fv_stats_get_count(&st, "new_vpls") == 0);
    assert_true(fv_stats_get_count(&st, "dropped_vpls") == 0);
    assert_true(fv_stats_get_count(&st, "cube_maps_built") == ceil(0.2 * valid));
    /* E' = 0: frames 12 and 13 alike, to the bit */
    assert_memory_equal(fv_film_color_const(a), fv_film_color_const(b), 3 * 40 * 40 * sizeof(float));
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    fv_scene_destroy(s);
}

/* Sec. 3.3: a VPL on a moving object keeps its place on the object. A point on cornell-fir's cube
 * at t = 0, stored in the cube's space, lands at t = 1 where the cube's own motion takes it; and in
 * a sequence, fir reports VPLs that followed the cube. */
static void test_follow_object(void **state)
{
    (void)state;
    fv_camera cam;
    fv_scene *s = load("cornell-fir", 0.0, 48, 48, &cam);
    fv_error err;
    int cube = -1;
    for (int o = 0; o < fv_scene_object_count(s); o++)
        if (fv_scene_object_dynamic(s, o)) cube = o;
    assert_true(cube >= 0);
    fv_vec3 lo0, hi0, lo1, hi1;
    fv_scene_object_bounds(s, cube, &lo0, &hi0);
    /* a point on the cube's top face: straight down onto the centre of its box */
    const fv_vec3 c0 = fv_scale(fv_add(lo0, hi0), 0.5f);
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(c0.x, 540.0f, c0.z), fv_v3(0, -1, 0), INFINITY, &h));
    assert_int_equal(h.obj, cube);
    fv_xform w2l;
    fv_scene_object_world_to_local(s, cube, &w2l);
    const fv_vec3 lp = fv_xform_point(&w2l, h.p), ln = fv_normalize(fv_xform_vector(&w2l, fv_v3(0, 1, 0)));
    assert_int_equal(fv_scene_set_time(s, 1.0, &err), FV_OK);
    fv_scene_object_bounds(s, cube, &lo1, &hi1);
    fv_vec3 p, n;
    fv_fir_follow(s, cube, lp, ln, &p, &n);
    /* the top face's centre moved with the box (it turns about its vertical axis: the centre stays) */
    const fv_vec3 c1 = fv_scale(fv_add(lo1, hi1), 0.5f);
    print_message("cube centre %.1f,%.1f -> %.1f,%.1f; VPL %.1f,%.1f,%.1f -> %.1f,%.1f,%.1f\n", c0.x, c0.z, c1.x, c1.z, h.p.x, h.p.y,
                  h.p.z, p.x, p.y, p.z);
    assert_true(fabsf(c1.x - c0.x) > 50.0f);
    assert_true(fabsf(p.x - c1.x) < 0.5f && fabsf(p.z - c1.z) < 0.5f && fabsf(p.y - h.p.y) < 0.5f);
    assert_true(n.y > 0.999f);
    /* the point lies on the cube's surface at its new place */
    fv_hit h1;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(p.x, 540.0f, p.z), fv_v3(0, -1, 0), INFINITY, &h1));
    assert_int_equal(h1.obj, cube);
    assert_true(fabsf(h1.p.y - p.y) < 0.5f);

    /* in a sequence (the cube moves between frames), some VPLs follow it and stay valid */
    fv_params *prm = fv_test_params_str("vpls=300 resolution=32 cube_size=16");
    fv_technique *t = NULL;
    assert_int_equal(fv_technique_create("fir", s, prm, NULL, &t, &err), FV_OK);
    fv_film *f;
    assert_int_equal(fv_film_create(48, 48, 0, &f, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, &cam);
    fr.threads = 2;
    double moved = 0.0;
    for (int i = 0; i < 4; i++) {
        assert_int_equal(fv_scene_set_time(s, 0.1 * i, &err), FV_OK);
        fr.index = i;
        fv_stats st;
        fv_stats_clear(&st);
        assert_int_equal(fv_technique_render(t, &fr, f, &st, &err), FV_OK);
        moved += fv_stats_get_count(&st, "moved_vpls");
    }
    print_message("VPLs that followed the cube over 3 frames: %.0f\n", moved);
    assert_true(moved > 0.0);
    fv_film_destroy(f);
    fv_technique_destroy(t);
    fv_params_destroy(prm);
    fv_scene_destroy(s);
}

/* Everything fir keeps is sized at create or with the image: 500 frames of a moving scene use no
 * more memory at the end than after the first 50 (resident set, outside the sanitizers, whose
 * quarantine holds freed blocks). */
static long resident_kb(void)
{
    long pages = 0, rss = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f) return -1;
    if (fscanf(f, "%ld %ld", &pages, &rss) != 2) rss = -1;
    fclose(f);
    return rss < 0 ? -1 : rss * 4;
}

static void test_memory_flat(void **state)
{
    (void)state;
    fv_camera cam;
    fv_scene *s = load("cornell-fir", 0.0, 24, 24, &cam);
    fv_error err;
    fv_params *p = fv_test_params_str("vpls=100 candidates=200 resolution=16 cube_size=8 area_samples=1 directions=8");
    fv_technique *t = NULL;
    assert_int_equal(fv_technique_create("fir", s, p, NULL, &t, &err), FV_OK);
    fv_film *f;
    assert_int_equal(fv_film_create(24, 24, 0, &f, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, &cam);
    fr.threads = 2;
    long at50 = 0, at500 = 0;
    double valid = 0.0;
    for (int i = 0; i < 500; i++) {
        assert_int_equal(fv_scene_set_time(s, 0.05 * i, &err), FV_OK);
        fr.index = i;
        fv_stats st;
        fv_stats_clear(&st);
        assert_int_equal(fv_technique_render(t, &fr, f, &st, &err), FV_OK);
        valid = fv_stats_get_count(&st, "valid_vpls");
        if (i == 49) at50 = resident_kb();
    }
    at500 = resident_kb();
    print_message("resident %ld kB after 50 frames, %ld kB after 500; %.0f valid VPLs\n", at50, at500, valid);
    assert_true(valid > 0 && valid <= 100);
#if !defined(__SANITIZE_ADDRESS__)
    if (at50 > 0) assert_true(at500 - at50 < 1024);
#endif
    fv_film_destroy(f);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    fv_scene_destroy(s);
}

/* Bad parameters: one line naming the key (exit 2 in the tools, tests/cli/test_fir_cli.sh). */
static void test_bad_params(void **state)
{
    (void)state;
    fv_camera cam;
    fv_scene *s = load("cornell-fir", 0.0, 16, 16, &cam);
    const struct {
        const char *method, *params, *key;
    } cases[] = {
        {"fir", "vpls=0", "vpls"},
        {"fir", "vpls=-5", "vpls"},
        {"ir", "vpls=0", "vpls"},
        {"ir-low", "vpls=0", "vpls"},
        {"fir", "vpls=50 tiles_x=10 tiles_y=10", "tiles_x"},
        {"fir", "tiles_x=0", "tiles_x"},
        {"fir", "radius=0", "radius"},
        {"fir", "radius=1.5", "radius"},
        {"fir", "radius=-0.2", "radius"},
        {"fir", "cube_size=4", "cube_size"},
        {"ir-low", "cube_size=4", "cube_size"},
        {"fir", "resolution=4", "resolution"},
        {"fir", "filter=gauss", "filter"},
        {"fir", "resample=2", "resample"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        fv_params *p = fv_test_params_str(cases[i].params);
        fv_technique *t = NULL;
        fv_error err;
        fv_status st = fv_technique_create(cases[i].method, s, p, NULL, &t, &err);
        fv_test_expect_fail(st, &err, FV_ERR_INVALID, cases[i].key, cases[i].params);
        assert_null(t);
        assert_null(strchr(err.msg, '\n'));
        fv_params_destroy(p);
    }
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ir_vs_pt_one_bounce), cmocka_unit_test(test_interleave_unbiased), cmocka_unit_test(test_still_reuse),
        cmocka_unit_test(test_follow_object),       cmocka_unit_test(test_memory_flat),         cmocka_unit_test(test_bad_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
