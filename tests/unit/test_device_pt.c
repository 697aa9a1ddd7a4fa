/* `pt` on the portable backend (the device kernels on the CPU, over the flat scene and its BVH)
 * against `pt` on the CPU (Embree): the same estimator drawing the same random numbers, so the two
 * images agree pixel by pixel except where the two traversals' last bits send a path elsewhere.
 * Checked on the built-in cornell (area light) and city (environment, many objects), a scene with
 * a moving object at a later time, a textured mesh, an SDF scene and an SDF union of 81 children
 * (its culled chain runs in the kernel's evaluator, issue 29); plus the auxiliary buffers,
 * and the refusals of devices a method or build lacks.
 *
 * The two traversals find the same surfaces at the same distances to within a few float ulps
 * (test_traverse), but not bit for bit: Embree's triangle test rounds differently. Most paths
 * therefore match to float precision, and a few turn elsewhere: where a shading normal has a zero
 * component (the axis-aligned walls of a Cornell box), an ulp decides the sign of that zero and
 * with it the tangent frame fv_basis builds, so the same random numbers pick another, equally
 * likely direction. The bounds are statistical, as the issue states them: each channel's mean
 * within 0.5%, and the per-pixel RMS difference within the noise of the sample count, measured as
 * the RMS difference between two CPU renders on different seeds (independent estimates): the
 * shared random numbers must keep it below half of that.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"

/* Renders scene `name` (at `time`, after `frames` frames) on both devices and checks the bounds
 * of the banner. */
static void compare_scene(const char *name, int w, int h, double time, int frames, const char *extra)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(name, &s, &v) != 0) fail_msg("cannot load %s", name);
    fv_error err;
    if (fv_scene_set_time(s, time, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_camera cam;
    fv_view_camera(v, s, time, w, h, &cam);
    char pc[128], pp[128];
    snprintf(pc, sizeof pc, "spp=16 device=cpu %s", extra);
    snprintf(pp, sizeof pp, "spp=16 device=portable %s", extra);
    fv_film *a = fv_test_render_pt(s, &cam, pc, time, frames, 7), *b = fv_test_render_pt(s, &cam, pp, time, frames, 7);
    fv_film *other = fv_test_render_pt(s, &cam, pc, time, frames, 8);
    fv_test_agreement r = fv_test_agree(a, b, 1e-3), noise = fv_test_agree(a, other, 1e-3);
    printf("%s: means cpu (%.4f %.4f %.4f) portable (%.4f %.4f %.4f), largest mean difference %.3g%%, %.1f%% of pixels equal, "
           "RMS difference %.3g%% of the mean (two CPU seeds: %.3g%%)\n",
           name, r.mean_a[0], r.mean_a[1], r.mean_a[2], r.mean_b[0], r.mean_b[1], r.mean_b[2], 100.0 * r.max_mean_rel, 100.0 * r.equal_share,
           100.0 * r.rms_rel, 100.0 * noise.rms_rel);
    if (!(r.mean_a[0] + r.mean_a[1] + r.mean_a[2] > 0.0)) fail_msg("%s rendered black on the CPU", name);
    if (!(r.max_mean_rel <= 0.005)) fail_msg("%s: means differ by %.3g%%", name, 100.0 * r.max_mean_rel);
    /* Paths that share their random numbers differ far less than independent ones: a kernel that
     * decorrelated them (a broken stream, a wrong estimator) would reach the noise itself. */
    if (!(r.rms_rel <= 0.5 * noise.rms_rel))
        fail_msg("%s: RMS difference %.3g%% is not well within the noise (%.3g%%)", name, 100.0 * r.rms_rel, 100.0 * noise.rms_rel);
    fv_film_destroy(other);

    /* The first hit's buffers: the same surface in (nearly) every pixel. */
    const float *da = fv_film_depth(a), *db = fv_film_depth(b);
    const uint32_t *ia = fv_film_id(a), *ib = fv_film_id(b);
    const float *na = fv_film_normal(a), *nb = fv_film_normal(b), *aa = fv_film_albedo(a), *ab = fv_film_albedo(b);
    size_t n = (size_t)w * h, same = 0;
    for (size_t i = 0; i < n; i++) {
        bool ok = ia[i] == ib[i] && (isinf(da[i]) ? isinf(db[i]) : fabsf(db[i] - da[i]) <= 1e-4f * fabsf(da[i]));
        for (int c = 0; c < 3 && ok; c++) ok = fabsf(nb[3 * i + c] - na[3 * i + c]) <= 1e-3f && fabsf(ab[3 * i + c] - aa[3 * i + c]) <= 1e-4f;
        same += ok;
    }
    if (!((double)same >= 0.995 * (double)n)) fail_msg("%s: the first hit differs in %zu of %zu pixels", name, n - same, n);
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_cornell(void **st)
{
    (void)st;
    compare_scene("cornell", 64, 64, 0.0, 1, "");
}

static void test_city(void **st)
{
    (void)st;
    compare_scene("city", 80, 48, 0.0, 1, "");
}

/* cornell-fpm's box moves: the portable backend's top level follows the scene's time. */
static void test_moving_object(void **st)
{
    (void)st;
    compare_scene("cornell-fpm", 48, 48, 0.7, 2, "max_depth=3");
}

static void test_textured_mesh(void **st)
{
    (void)st;
    char path[4096];
    compare_scene(fv_test_data("textured/box.glb", path, sizeof path), 48, 48, 0.0, 1, "");
}

/* A floor lit only by a panel whose emission is a texture: the light table's emission texture
 * (kernel/klight.h) read through the exported scene's textures. */
static void test_emission_texture(void **st)
{
    (void)st;
    char path[512];
    compare_scene(fv_test_data("emissive_tex/lit.json", path, sizeof path), 48, 36, 0.0, 1, "");
}

static void test_sdf_scene(void **st)
{
    (void)st;
    compare_scene("sdf-primitives", 48, 48, 0.0, 1, "max_depth=3");
}

static void test_sdf_union_81(void **st)
{
    (void)st;
    char path[512];
    compare_scene(fv_test_source("scenes/sdf-grid81.json", path, sizeof path), 48, 27, 0.0, 1, "max_depth=3");
}

/* Devices a method or the build lacks are refused in one line, before anything renders. */
static void test_refusals(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    assert_int_equal(fv_test_load("cornell", &s, &v), 0);
    const struct {
        const char *method, *params, *needle;
    } cases[] = {
        {"fpm", "device=cuda", "method 'fpm' does not run on device cuda (methods that do: pt, vpolar, cartesian, cartesian-full, linear-falloff, log-polar, sdf-gt, sdf-relaxed, ipr, fipr)"},
        {"fpm", "device=portable", "method 'fpm' does not run on device portable (methods that do: pt, vpolar, cartesian, cartesian-full, linear-falloff, log-polar, sdf-gt, sdf-relaxed, ipr, fipr)"},
        {"pt", "device=gpu", "device"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) fv_test_expect_refusal(cases[i].method, cases[i].params, s, cases[i].needle);
    /* CUDA: this build lacks it, or this machine has no GPU; on a GPU machine it is created. */
    fv_params *p = fv_test_params_str("device=cuda spp=1");
    fv_technique *t = NULL;
    fv_error err;
    char why[256];
    bool can = fv_device_available(FV_DEVICE_CUDA, why, sizeof why);
    fv_status got = fv_technique_create("pt", s, p, NULL, &t, &err);
    if (can) {
        assert_int_equal(got, FV_OK);
    } else {
        assert_int_equal(got, FV_ERR_INVALID);
        if (!strstr(err.msg, "built without CUDA") && !strstr(err.msg, "no CUDA device")) fail_msg("refusal '%s' names no cause", err.msg);
        assert_non_null(strstr(err.msg, why));
    }
    fv_technique_destroy(t);
    fv_params_destroy(p);
    fv_device d;
    fv_test_expect_fail(fv_device_check("nope", "cpu", &d, &err), &err, FV_ERR_INVALID, "unknown method 'nope'", "device_check nope");
    fv_test_expect_fail(fv_device_check(NULL, "cpu", &d, &err), &err, FV_ERR_INVALID, "unknown method '(null)'", "device_check NULL");
    assert_int_equal(fv_device_check("fir", "cpu", &d, &err), FV_OK);
    assert_int_equal(d, FV_DEVICE_CPU);
    /* auto: CUDA when it can run, else the CPU; a method without CUDA stays on the CPU. */
    assert_int_equal(fv_device_parse("auto", "fpm", &d, &err), FV_OK);
    assert_int_equal(d, FV_DEVICE_CPU);
    assert_int_equal(fv_device_parse("auto", "vpolar", &d, &err), FV_OK);
    assert_int_equal(d, can ? FV_DEVICE_CUDA : FV_DEVICE_CPU);
    assert_int_equal(fv_device_parse("auto", "pt", &d, &err), FV_OK);
    assert_int_equal(d, can ? FV_DEVICE_CUDA : FV_DEVICE_CPU);
    assert_true(fv_technique_has_device(fv_technique_index("pt"), FV_DEVICE_PORTABLE));
    assert_false(fv_technique_has_device(fv_technique_index("fir"), FV_DEVICE_CUDA));
    assert_true(fv_technique_has_device(fv_technique_index("fir"), FV_DEVICE_CPU));
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* A moving scene's stereo frames through fv_technique_render_pair (pt's pair: the flat scene
 * updated once, then each eye) on portable, and through two render calls on cpu and portable: the
 * pair equals the portable per-eye calls bit for bit, film and counters; on cpu the registry's
 * fallback is the two calls. */
static void test_pair(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load("cornell-fpm", &s, &v) != 0) fail_msg("cannot load cornell-fpm");
    fv_camera centre, cam[2];
    fv_view_camera(v, s, 0.0, 40, 30, &centre);
    fv_camera_stereo(&centre, 0.06f, &cam[0], &cam[1]);
    const char *params[2] = {"spp=2 device=portable", "spp=2 device=cpu"};
    for (int d = 0; d < 2; d++) {
        fv_params *p = fv_test_params_str(params[d]);
        fv_technique *pair = NULL, *each = NULL;
        fv_error err;
        if (fv_technique_create("pt", s, p, NULL, &pair, &err) != FV_OK || fv_technique_create("pt", s, p, NULL, &each, &err) != FV_OK)
            fail_msg("%s", err.msg);
        fv_film *a[2], *b[2];
        for (int e = 0; e < 2; e++)
            if (fv_film_create(40, 30, FV_AUX_DEPTH | FV_AUX_ID, &a[e], &err) != FV_OK || fv_film_create(40, 30, FV_AUX_DEPTH | FV_AUX_ID, &b[e], &err) != FV_OK)
                fail_msg("%s", err.msg);
        for (int i = 0; i < 2; i++) {
            const double time = 0.25 * i;
            if (fv_scene_set_time(s, time, &err) != FV_OK) fail_msg("%s", err.msg);
            fv_frame f[2];
            fv_test_stereo_frames(cam, time, i, 9, false, f);
            fv_stats sp, se;
            fv_stats_clear(&sp);
            fv_stats_clear(&se);
            if (fv_technique_render_pair(pair, f, b, &sp, &err) != FV_OK) fail_msg("%s: pair %d: %s", params[d], i, err.msg);
            for (int e = 0; e < 2; e++)
                if (fv_technique_render(each, &f[e], a[e], &se, &err) != FV_OK) fail_msg("%s: frame %d eye %d: %s", params[d], i, e, err.msg);
            for (int e = 0; e < 2; e++)
                if (memcmp(fv_film_color_const(a[e]), fv_film_color_const(b[e]), (size_t)3 * 40 * 30 * sizeof(float)) != 0 ||
                    memcmp(fv_film_depth(a[e]), fv_film_depth(b[e]), (size_t)40 * 30 * sizeof(float)) != 0)
                    fail_msg("%s: frame %d eye %d: the pair differs from the per-eye call", params[d], i, e);
            static const char *const keys[] = {"rays", "nan_samples", "samples"};
            for (size_t k = 0; k < 3; k++)
                if (fv_stats_get_count(&sp, keys[k]) != fv_stats_get_count(&se, keys[k]))
                    fail_msg("%s: frame %d: counter %s: pair %g, per eye %g", params[d], i, keys[k], fv_stats_get_count(&sp, keys[k]),
                             fv_stats_get_count(&se, keys[k]));
            if (!(fv_stats_get_count(&sp, "rays") > 0)) fail_msg("%s: nothing traced", params[d]);
        }
        for (int e = 0; e < 2; e++) {
            fv_film_destroy(a[e]);
            fv_film_destroy(b[e]);
        }
        fv_technique_destroy(pair);
        fv_technique_destroy(each);
        fv_params_destroy(p);
    }
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell),       cmocka_unit_test(test_city),      cmocka_unit_test(test_moving_object),
        cmocka_unit_test(test_textured_mesh), cmocka_unit_test(test_sdf_scene), cmocka_unit_test(test_sdf_union_81), cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_emission_texture), cmocka_unit_test(test_pair),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
