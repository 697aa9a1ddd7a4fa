/* GPU tests (ctest label `gpu`; scripts/gpu-check runs them on an NVIDIA machine): the sphere-tracing
 * family on CUDA against the portable backend, which runs the same kernel source
 * (technique/sdf/ksdf_pixel.h, kpyr.h, launched as sdf_kernels.h declares them) on the CPU and equals the CPU pipeline bit for bit (test_device_sdf):
 * `sdf-gt` and `sdf-relaxed` one frame, `ipr` one frame, `fipr` over a stereo sequence with a moving
 * gaze (its history stays on the GPU between frames, per eye), every frame compared.
 *
 * Bounds, not yet measured on a GPU (none was available when this was written), chosen from what
 * can differ: with --fmad=false the GPU rounds +, -, *, /, sqrtf as the CPU does, so the field and
 * every step are the same; only powf (the Blinn-Phong lobe) and cosf (a spot light's cone) differ
 * in the last bits. That changes a shaded colour by a few ulps and decides nothing in the march,
 * so 99.5% of the pixels must agree within 1e-4 relative (or 1e-6 absolute), the means within
 * 0.01%, and the counters (steps, shadow steps; for ipr and fipr each level's, fipr's mask) exactly;
 * two CUDA runs are bit-identical. (fipr's mask compares a float random number with a probability
 * from double-precision exp and atan, whose last bits may differ on the GPU: a flip needs the number
 * within an ulp of the probability, so the counts are still required to be equal.) A pyramid frame
 * must report one host wait (host_syncs): its passes are launched without any between them. If the GPU
 * shows more, the first run's printout says where, and the bound is revised with that measurement.
 * A stereo frame through fv_technique_render_pair (both eyes' kernels on the stream, one host wait
 * for the pair) must equal the two per-eye CUDA calls bit for bit (the same kernels in the same
 * order) and the portable pair within the bounds above, with host_syncs 1 per pair, fipr's
 * histories carried on the GPU and the scene's lights moving (sdf-columns).
 * Exits 77 (skipped) where CUDA cannot run: a build without CUDA, a machine without a GPU. Built a
 * second time against the CUDA simulator (sim_test_gpu_sdf, tests/gpu/sim_checks.h), where the host's
 * waits are also counted, not only reported, at half the image side (FV_SIM_SIDE: its images equal
 * the portable ones exactly at any size).
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
#include "../unit/testkit.h"
#include "sim_checks.h"

static fv_film *render(const char *method, const char *params, const fv_scene *s, const fv_camera *cam, fv_stats *stats)
{
    fv_params *p = fv_test_params_str(params);
    fv_technique *t = NULL;
    fv_error err;
    if (fv_technique_create(method, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s %s: %s", method, params, err.msg);
    fv_film *film = NULL;
    if (fv_film_create(cam->width, cam->height, FV_AUX_DEPTH | FV_AUX_NORMAL | FV_AUX_ID, &film, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_frame f;
    fv_frame_init(&f, cam);
    f.seed = 3;
    fv_test_render_frames(t, &f, 1, film, stats);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return film;
}

static void compare(const char *scene, const char *method, int w, int h, int spp)
{
    w = FV_SIM_SIDE(w); /* the simulator: half the side (sim_checks.h) */
    h = FV_SIM_SIDE(h);
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, w, h, &cam);
    char pp[64], pc[64];
    snprintf(pp, sizeof pp, "spp=%d device=portable", spp);
    snprintf(pc, sizeof pc, "spp=%d device=cuda", spp);
    fv_stats sp, sc, sc2;
    fv_film *p = render(method, pp, s, &cam, &sp);
    fv_sim_mark m = fv_sim_now();
    fv_film *c1 = render(method, pc, s, &cam, &sc);
    fv_sim_expect(m, 1, 1, method); /* one launch, one synchronize */
    fv_sim_expect_freed(method);
    fv_film *c2 = render(method, pc, s, &cam, &sc2);
    fv_test_agreement r = fv_test_agree(p, c1, 1e-4);
    const float *a = fv_film_color_const(p), *b = fv_film_color_const(c1);
    const size_t n = (size_t)w * h;
    double max_abs = 0.0;
    for (size_t i = 0; i < 3 * n; i++)
        if (fabs((double)a[i] - (double)b[i]) > max_abs) max_abs = fabs((double)a[i] - (double)b[i]);
    printf("%s %s %dx%d spp=%d: %.3f%% of pixels within 1e-4, max |difference| %g, largest mean difference %.3g%%, steps portable %g cuda %g, "
           "shadow steps %g / %g\n",
           method, scene, w, h, spp, 100.0 * r.equal_share, max_abs, 100.0 * r.max_mean_rel, fv_stats_get_count(&sp, "steps"),
           fv_stats_get_count(&sc, "steps"), fv_stats_get_count(&sp, "shadow_steps"), fv_stats_get_count(&sc, "shadow_steps"));
    if (!(r.equal_share >= 0.995)) fail_msg("%s %s: only %.3f%% of pixels agree within 1e-4", method, scene, 100.0 * r.equal_share);
    if (!(r.max_mean_rel <= 1e-4)) fail_msg("%s %s: means differ by %.3g%%", method, scene, 100.0 * r.max_mean_rel);
    static const char *const keys[] = {"rays", "steps", "shadow_rays", "shadow_steps", "normal_evals", "exhausted_rays"};
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
        if (fv_stats_get_count(&sp, keys[k]) != fv_stats_get_count(&sc, keys[k]))
            fail_msg("%s %s: counter %s: portable %g, cuda %g", method, scene, keys[k], fv_stats_get_count(&sp, keys[k]),
                     fv_stats_get_count(&sc, keys[k]));
    if (memcmp(b, fv_film_color_const(c2), 3 * n * sizeof(float)) != 0) fail_msg("%s %s: two CUDA runs differ", method, scene);
    if (memcmp(fv_film_depth(p), fv_film_depth(c1), n * sizeof(float)) != 0) fail_msg("%s %s: the first hit's depth differs", method, scene);
    fv_film_destroy(p);
    fv_film_destroy(c1);
    fv_film_destroy(c2);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* ipr or fipr on portable and twice on CUDA over frames x eyes with a moving gaze. */
static void compare_pyramid(const char *scene, const char *method, const char *params, int w, int h, int frames, int eyes)
{
    w = FV_SIM_SIDE(w); /* the simulator: half the side (sim_checks.h) */
    h = FV_SIM_SIDE(h);
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, w, h, &cam);
    char pp[160], pc[160];
    snprintf(pp, sizeof pp, "%s device=portable", params);
    snprintf(pc, sizeof pc, "%s device=cuda", params);
    fv_technique *tp = fv_test_technique(method, pp, s), *tc = fv_test_technique(method, pc, s), *tc2 = fv_test_technique(method, pc, s);
    fv_film *p = NULL, *c1 = NULL, *c2 = NULL;
    fv_error err;
    const int aux = FV_AUX_DEPTH | FV_AUX_NORMAL | FV_AUX_ID;
    if (fv_film_create(w, h, aux, &p, &err) != FV_OK || fv_film_create(w, h, aux, &c1, &err) != FV_OK || fv_film_create(w, h, aux, &c2, &err) != FV_OK)
        fail_msg("%s", err.msg);
    const size_t n = (size_t)w * h;
    const bool fipr = strcmp(method, "fipr") == 0;
    for (int i = 0; i < frames; i++)
        for (int e = 0; e < eyes; e++) {
            fv_frame f;
            fv_frame_init(&f, &cam);
            f.seed = 3;
            f.index = i;
            f.eye = e;
            f.eye_count = eyes;
            f.prev_camera = i > 0 ? &cam : NULL;
            f.gaze.x = 0.3f + 0.1f * (float)i + 0.05f * (float)e;
            f.gaze.y = 0.6f - 0.07f * (float)i;
            fv_stats sp, sc, sc2;
            fv_test_render_fresh(tp, &f, p, &sp);
            fv_sim_mark m = fv_sim_now();
            fv_test_render_fresh(tc, &f, c1, &sc);
            fv_sim_expect(m, 1, -1, method); /* what host_syncs reports (checked below) is what the host did */
            fv_sim_expect_reported(m, &sc, method);
            fv_test_render_fresh(tc2, &f, c2, &sc2);
            fv_test_agreement r = fv_test_agree(p, c1, 1e-4);
            const float *a = fv_film_color_const(p), *b = fv_film_color_const(c1);
            double max_abs = 0.0;
            for (size_t k = 0; k < 3 * n; k++)
                if (fabs((double)a[k] - (double)b[k]) > max_abs) max_abs = fabs((double)a[k] - (double)b[k]);
            char what[256];
            snprintf(what, sizeof what, "%s %s [%s] %dx%d frame %d eye %d", method, scene, params, w, h, i, e);
            printf("%s: %.3f%% of pixels within 1e-4, max |difference| %g, largest mean difference %.3g%%, steps portable %g cuda %g, "
                   "mask pixels %g / %g, host syncs %g\n",
                   what, 100.0 * r.equal_share, max_abs, 100.0 * r.max_mean_rel, fv_stats_get_count(&sp, "steps"), fv_stats_get_count(&sc, "steps"),
                   fv_stats_get_count(&sp, "mask_pixels"), fv_stats_get_count(&sc, "mask_pixels"), fv_stats_get_count(&sc, "host_syncs"));
            if (!(r.equal_share >= 0.995)) fail_msg("%s: only %.3f%% of pixels agree within 1e-4", what, 100.0 * r.equal_share);
            if (!(r.max_mean_rel <= 1e-4)) fail_msg("%s: means differ by %.3g%%", what, 100.0 * r.max_mean_rel);
            static const char *const keys[] = {"rays", "steps", "shadow_rays", "shadow_steps", "normal_evals", "exhausted_rays", "rays_level0",
                                               "steps_level0", "rays_level1", "steps_level1", "rays_level2", "steps_level2", "mask_pixels",
                                               "edge_pixels", "refreshed_pixels"};
            for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
                if (fv_stats_get_count(&sp, keys[k]) != fv_stats_get_count(&sc, keys[k]))
                    fail_msg("%s: counter %s: portable %g, cuda %g", what, keys[k], fv_stats_get_count(&sp, keys[k]), fv_stats_get_count(&sc, keys[k]));
            if (fv_stats_get_count(&sc, "host_syncs") != 1.0) fail_msg("%s: %g host waits in a frame", what, fv_stats_get_count(&sc, "host_syncs"));
            if (memcmp(b, fv_film_color_const(c2), 3 * n * sizeof(float)) != 0) fail_msg("%s: two CUDA runs differ", what);
            if (!fipr && memcmp(fv_film_depth(p), fv_film_depth(c1), n * sizeof(float)) != 0) fail_msg("%s: the first hit's depth differs", what);
        }
    fv_film_destroy(p);
    fv_film_destroy(c1);
    fv_film_destroy(c2);
    fv_technique_destroy(tp);
    fv_technique_destroy(tc);
    fv_technique_destroy(tc2);
    fv_sim_expect_freed(method);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_ipr(void **st)
{
    (void)st;
    compare_pyramid("sdf-primitives", "ipr", "spp=4", 160, 120, 1, 1);
    compare_pyramid("sdf-columns", "ipr", "spp=1 shadow_reuse=true", 160, 120, 1, 1);
    compare_pyramid("sdf-temple", "ipr", "spp=16", 96, 72, 1, 1);
}

static void test_fipr(void **st)
{
    (void)st;
    compare_pyramid("sdf-primitives", "fipr", "spp=4 refresh=2", 160, 120, 3, 2);
    compare_pyramid("sdf-columns", "fipr", "spp=1 refresh=4 shadow_reuse=true", 160, 120, 5, 1);
    compare_pyramid("sdf-temple", "fipr", "spp=16 refresh=4 blur=true", 96, 72, 5, 2);
}

static void test_primitives(void **st)
{
    (void)st;
    compare("sdf-primitives", "sdf-gt", 160, 120, 4);
    compare("sdf-primitives", "sdf-relaxed", 160, 120, 4);
}

static void test_columns(void **st)
{
    (void)st;
    compare("sdf-columns", "sdf-gt", 160, 120, 1);
    compare("sdf-columns", "sdf-relaxed", 160, 120, 1);
}

static void test_temple(void **st)
{
    (void)st;
    compare("sdf-temple", "sdf-gt", 96, 72, 16);
    compare("sdf-temple", "sdf-relaxed", 96, 72, 16);
}

/* A stereo sequence, the scene's time moving 0.1 s a frame: CUDA's pairs against CUDA's per-eye
 * calls (bit for bit) and against portable's pairs (the bounds above); one host wait per pair. */
static void compare_pair(const char *scene, const char *method, const char *params, int w, int h, int frames)
{
    w = FV_SIM_SIDE(w); /* the simulator: half the side (sim_checks.h) */
    h = FV_SIM_SIDE(h);
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera centre, cam[2];
    fv_view_camera(v, s, 0.0, w, h, &centre);
    fv_camera_stereo(&centre, 0.08f, &cam[0], &cam[1]);
    char pp[160], pc[160];
    snprintf(pp, sizeof pp, "%s device=portable", params);
    snprintf(pc, sizeof pc, "%s device=cuda", params);
    fv_technique *tp = fv_test_technique(method, pp, s), *pair = fv_test_technique(method, pc, s), *each = fv_test_technique(method, pc, s);
    fv_film *p[2], *c[2], *e1[2];
    fv_error err;
    const int aux = FV_AUX_DEPTH | FV_AUX_NORMAL | FV_AUX_ID;
    for (int e = 0; e < 2; e++)
        if (fv_film_create(w, h, aux, &p[e], &err) != FV_OK || fv_film_create(w, h, aux, &c[e], &err) != FV_OK ||
            fv_film_create(w, h, aux, &e1[e], &err) != FV_OK)
            fail_msg("%s", err.msg);
    const size_t n = (size_t)w * h;
    for (int i = 0; i < frames; i++) {
        const double time = 0.1 * i;
        if (fv_scene_set_time(s, time, &err) != FV_OK) fail_msg("%s", err.msg);
        fv_frame f[2];
        fv_test_stereo_frames(cam, time, i, 5, i > 0, f);
        for (int e = 0; e < 2; e++) {
            f[e].left_camera = e == 1 ? &cam[0] : NULL;
            f[e].gaze.x = 0.35f + 0.12f * (float)i + 0.04f * (float)e;
            f[e].gaze.y = 0.55f - 0.08f * (float)i;
            fv_film_clear(c[e]);
            float *col = fv_film_color(c[e]);
            for (size_t k = 0; k < 3 * n; k++) col[k] = NAN;
        }
        fv_stats sp, sc, se;
        fv_stats_clear(&sp);
        fv_stats_clear(&sc);
        fv_stats_clear(&se);
        if (fv_technique_render_pair(tp, f, p, &sp, &err) != FV_OK || fv_technique_render_pair(pair, f, c, &sc, &err) != FV_OK)
            fail_msg("%s: pair %d: %s", method, i, err.msg);
        for (int e = 0; e < 2; e++)
            if (fv_technique_render(each, &f[e], e1[e], &se, &err) != FV_OK) fail_msg("%s: frame %d eye %d: %s", method, i, e, err.msg);
        char what[256];
        snprintf(what, sizeof what, "%s %s [%s] %dx%d stereo frame %d", method, scene, params, w, h, i);
        for (int e = 0; e < 2; e++) {
            fv_test_agreement r = fv_test_agree(p[e], c[e], 1e-4);
            printf("%s eye %d: %.3f%% of pixels within 1e-4 of portable, largest mean difference %.3g%%, host syncs %g (per-eye calls %g)\n", what, e,
                   100.0 * r.equal_share, 100.0 * r.max_mean_rel, fv_stats_get_count(&sc, "host_syncs"), fv_stats_get_count(&se, "host_syncs"));
            if (!(r.equal_share >= 0.995)) fail_msg("%s eye %d: only %.3f%% of pixels agree within 1e-4", what, e, 100.0 * r.equal_share);
            if (!(r.max_mean_rel <= 1e-4)) fail_msg("%s eye %d: means differ by %.3g%%", what, e, 100.0 * r.max_mean_rel);
            if (memcmp(fv_film_color_const(c[e]), fv_film_color_const(e1[e]), 3 * n * sizeof(float)) != 0 ||
                memcmp(fv_film_depth(c[e]), fv_film_depth(e1[e]), n * sizeof(float)) != 0)
                fail_msg("%s eye %d: the pair differs from the per-eye calls", what, e);
        }
        static const char *const keys[] = {"rays", "steps", "shadow_rays", "shadow_steps", "normal_evals", "exhausted_rays", "mask_pixels",
                                           "edge_pixels", "refreshed_pixels"};
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
            if (fv_stats_get_count(&sp, keys[k]) != fv_stats_get_count(&sc, keys[k]) || fv_stats_get_count(&se, keys[k]) != fv_stats_get_count(&sc, keys[k]))
                fail_msg("%s: counter %s: portable %g, cuda pair %g, cuda per eye %g", what, keys[k], fv_stats_get_count(&sp, keys[k]),
                         fv_stats_get_count(&sc, keys[k]), fv_stats_get_count(&se, keys[k]));
        if (fv_stats_get_count(&sc, "host_syncs") != 1.0) fail_msg("%s: %g host waits for the pair", what, fv_stats_get_count(&sc, "host_syncs"));
        if (fv_stats_get_count(&se, "host_syncs") != 2.0) fail_msg("%s: %g host waits for two eyes", what, fv_stats_get_count(&se, "host_syncs"));
    }
    for (int e = 0; e < 2; e++) {
        fv_film_destroy(p[e]);
        fv_film_destroy(c[e]);
        fv_film_destroy(e1[e]);
    }
    fv_technique_destroy(tp);
    fv_technique_destroy(pair);
    fv_technique_destroy(each);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_pair(void **st)
{
    (void)st;
    compare_pair("sdf-primitives", "sdf-gt", "spp=4", 160, 120, 2);
    compare_pair("sdf-columns", "sdf-relaxed", "spp=1", 160, 120, 3);
    compare_pair("sdf-temple", "ipr", "spp=4 shadow_reuse=true", 96, 72, 2);
    compare_pair("sdf-columns", "fipr", "spp=1 refresh=2", 160, 120, 4);
    compare_pair("sdf-temple", "fipr", "spp=16 refresh=4 shadow_reuse=true blur=true", 96, 72, 5);
}

#ifdef FOVEA_CUDA_SIM
/* The simulator only: every device allocation of the sphere tracers' backend (counters, stream,
 * world, film, pyramid, fipr's history) failing in turn, as on a full GPU. */
static void test_out_of_memory(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load("sdf-primitives", &s, &v) != 0) fail_msg("cannot load sdf-primitives");
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 32, 24, &cam);
    static const char *const methods[][2] = {{"sdf-gt", "spp=1 device=cuda"},
                                             {"ipr", "spp=1 shadow_reuse=true device=cuda"},
                                             {"fipr", "spp=1 refresh=2 device=cuda"}};
    for (size_t i = 0; i < sizeof methods / sizeof methods[0]; i++) {
        fv_sim_frames r = {s, &cam, methods[i][0], methods[i][1], 2, 0.0};
        if (fv_sim_walk_allocation_failures(fv_sim_run_frames, &r, methods[i][0]) < 5) fail_msg("%s: too few device allocations", methods[i][0]);
    }
    fv_view_destroy(v);
    fv_scene_destroy(s);
}
#endif

int main(void)
{
    char why[256];
    if (!fv_device_available(FV_DEVICE_CUDA, why, sizeof why)) {
        printf("skipped: %s\n", why);
        return FV_GPU_TEST_NO_DEVICE;
    }
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_primitives), cmocka_unit_test(test_columns), cmocka_unit_test(test_temple),
                                       cmocka_unit_test(test_ipr), cmocka_unit_test(test_fipr), cmocka_unit_test(test_pair),
#ifdef FOVEA_CUDA_SIM
                                       cmocka_unit_test(test_out_of_memory)
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
