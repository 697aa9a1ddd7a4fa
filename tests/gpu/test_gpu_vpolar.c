/* GPU tests (ctest label `gpu`; scripts/gpu-check runs them on an NVIDIA machine): the Visual-Polar
 * family on CUDA (technique/vpolar/vp_device.c: trace, reprojection, SVGF, φ-mipmaps, map and blur as
 * kernels on one stream) against the portable backend, which runs the same frame and kernel source
 * on the CPU with the same random numbers (SVGF included: filter/ksvgf.h's steps). Each of the five methods, and vpolar with two paths a sample and
 * every cell traced, cartesian-full without the denoiser, over four frames whose gaze moves and then
 * stays (so the history is reprojected from one gaze's space into another's on the GPU, with the
 * radial table the GPU kept from the frame before), vpolar in stereo (a pipeline per eye), with 0
 * and 2 SVGF passes, and on a moving scene.
 *
 * Bounds, not yet measured on a GPU (none was available when this was written), chosen from what
 * can differ: with --fmad=false the GPU rounds +, -, *, /, sqrtf as the CPU does; the GPU's sinf,
 * cosf, expf and powf differ from the C library's in the last bits (the polar spaces' angle and
 * log-polar's radius, a path's bounce directions), which moves a camera ray by an ulp and may send
 * a rare path elsewhere, and the denoiser spreads such a path over its taps. So, per frame:
 *  - every value finite, the same samples launched (the on-screen mask is the host's; linear
 *    fall-off's kill compares a random number with a probability, a flip needs the two within an
 *    ulp), and one host wait (host_syncs);
 *  - 99.9% of the first hits (object ids) equal, and of the depths within 1e-4 relative (a camera
 *    ray an ulp away changes only a silhouette's pixel);
 *  - the image's mean within 0.5% of the portable one, at least 80% of the pixels within 1e-3
 *    relative, and the RMS difference below a tenth of the noise (the RMS difference between two
 *    portable renders on different seeds);
 *  - the denoiser's history fraction within 0.01 of the portable one;
 *  - two CUDA runs bit-identical (colour and first-hit buffers).
 * If the GPU shows more, the printout says where, and the bounds are revised with that measurement.
 *
 * A stereo frame through fv_technique_render_pair (both eyes' whole frames queued, each on its own
 * pipeline and stream, then one host wait for the pair) must equal the two per-eye CUDA calls bit
 * for bit, every film buffer and counter, over frames whose gaze moves and then stays, with
 * host_syncs 1 per pair against 2 for the two calls; the portable backend's pair (its per-eye
 * calls) likewise. Built a second time against the CUDA simulator (sim_test_gpu_vpolar,
 * tests/gpu/sim_checks.h), where the host's waits are also counted, at half the image side
 * (FV_SIM_SIDE: its images equal the portable ones exactly at any size).
 * Exits 77 (skipped) where CUDA cannot run: a build without CUDA, a machine without a GPU.
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

#define AUX (FV_AUX_DEPTH | FV_AUX_NORMAL | FV_AUX_ALBEDO | FV_AUX_ID | FV_AUX_POSITION)
#define FRAMES 4

static double rms(const float *a, const float *b, size_t n)
{
    double sum = 0.0;
    for (size_t k = 0; k < 3 * n; k++) sum += ((double)a[k] - (double)b[k]) * ((double)a[k] - (double)b[k]);
    return sqrt(sum / (3.0 * (double)n));
}

/* frames x eyes of method on scene, its time dt seconds further each frame (0: still). */
static void compare(const char *scene, const char *method, const char *params, int w, int h, int eyes, double dt)
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
    /* tp and tc draw the same random numbers; tn (portable on another seed) is the noise yardstick */
    fv_technique *tp = fv_test_technique(method, pp, s), *tn = fv_test_technique(method, pp, s), *tc = fv_test_technique(method, pc, s), *tc2 = fv_test_technique(method, pc, s);
    fv_film *p = NULL, *n2 = NULL, *c1 = NULL, *c2 = NULL;
    fv_error err;
    if (fv_film_create(w, h, AUX, &p, &err) != FV_OK || fv_film_create(w, h, AUX, &n2, &err) != FV_OK ||
        fv_film_create(w, h, AUX, &c1, &err) != FV_OK || fv_film_create(w, h, AUX, &c2, &err) != FV_OK)
        fail_msg("%s", err.msg);
    static const float gaze[FRAMES][2] = {{0.3f, 0.4f}, {0.6f, 0.55f}, {0.62f, 0.57f}, {0.62f, 0.57f}};
    const size_t n = (size_t)w * h;
    for (int i = 0; i < FRAMES; i++)
        for (int e = 0; e < eyes; e++) {
            if (fv_scene_set_time(s, dt * i, &err) != FV_OK) fail_msg("%s", err.msg);
            fv_frame f;
            fv_frame_init(&f, &cam);
            f.time = dt * i;
            f.seed = 7;
            f.index = i;
            f.eye = e;
            f.eye_count = eyes;
            f.prev_camera = i > 0 ? &cam : NULL;
            f.gaze.x = gaze[i][0] + 0.03f * (float)e;
            f.gaze.y = gaze[i][1];
            fv_stats sp, sn, sc, sc2;
            char what[256];
            snprintf(what, sizeof what, "%s [%s] %s %dx%d frame %d eye %d", method, params, scene, w, h, i, e);
            fv_test_render_fresh(tp, &f, p, &sp);
            const fv_sim_mark m = fv_sim_now();
            fv_test_render_fresh(tc, &f, c1, &sc);
            fv_sim_expect(m, 1, -1, what); /* one synchronize, and no upload behind a kernel (a hidden wait) */
            fv_sim_expect_reported(m, &sc, what);
            fv_test_render_fresh(tc2, &f, c2, &sc2);
            f.seed = 8;
            fv_test_render_fresh(tn, &f, n2, &sn);
            const float *a = fv_film_color_const(p), *b = fv_film_color_const(c1);
            for (size_t k = 0; k < 3 * n; k++)
                if (!isfinite(a[k]) || !isfinite(b[k])) fail_msg("%s: value %zu not finite (portable %g, cuda %g)", what, k, a[k], b[k]);
            size_t ids = 0, depths = 0;
            for (size_t k = 0; k < n; k++) {
                ids += fv_film_id_const(p)[k] == fv_film_id_const(c1)[k];
                const float za = fv_film_depth(p)[k], zb = fv_film_depth(c1)[k];
                depths += za == zb || fabsf(za - zb) <= 1e-4f * fabsf(za);
            }
            const fv_test_agreement r = fv_test_agree(p, c1, 1e-3);
            const double diff = rms(a, b, n), noise = rms(a, fv_film_color_const(n2), n);
            const double hp = fv_stats_get_count(&sp, "history_fraction"), hc = fv_stats_get_count(&sc, "history_fraction");
            printf("%s: means portable (%.4f %.4f %.4f) cuda (%.4f %.4f %.4f), largest mean difference %.3g%%, %.2f%% of pixels within 1e-3, "
                   "rms difference %.4g (another seed: %.4g), ids equal %zu/%zu, depths %zu, samples %g / %g, history %.4f / %.4f, host syncs %g, "
                   "kernel %.3f ms\n",
                   what, r.mean_a[0], r.mean_a[1], r.mean_a[2], r.mean_b[0], r.mean_b[1], r.mean_b[2], 100.0 * r.max_mean_rel,
                   100.0 * r.equal_share, diff, noise, ids, n, depths, fv_stats_get_count(&sp, "samples"), fv_stats_get_count(&sc, "samples"), hp,
                   hc, fv_stats_get_count(&sc, "host_syncs"), fv_stats_get_ms(&sc, "kernel"));
            if (fv_stats_get_count(&sc, "host_syncs") != 1.0) fail_msg("%s: %g host waits in a frame", what, fv_stats_get_count(&sc, "host_syncs"));
            if (fv_stats_get_count(&sp, "samples") != fv_stats_get_count(&sc, "samples"))
                fail_msg("%s: samples portable %g, cuda %g", what, fv_stats_get_count(&sp, "samples"), fv_stats_get_count(&sc, "samples"));
            if (!(fv_stats_get_count(&sc, "samples") > 0.0)) fail_msg("%s: no sample traced", what);
            if (ids < n - n / 1000 || depths < n - n / 1000) fail_msg("%s: first hits differ (ids %zu, depths %zu of %zu)", what, ids, depths, n);
            if (!(r.max_mean_rel <= 0.005)) fail_msg("%s: means differ by %.3g%%", what, 100.0 * r.max_mean_rel);
            if (!(r.equal_share >= 0.80)) fail_msg("%s: only %.2f%% of pixels within 1e-3", what, 100.0 * r.equal_share);
            if (!(diff < 0.1 * noise)) fail_msg("%s: rms difference %.4g, not below a tenth of the noise %.4g", what, diff, noise);
            if (!(fabs(hp - hc) <= 0.01)) fail_msg("%s: history fraction portable %.4f, cuda %.4f", what, hp, hc);
            if (memcmp(b, fv_film_color_const(c2), 3 * n * sizeof(float)) != 0) fail_msg("%s: two CUDA runs differ", what);
            if (memcmp(fv_film_depth(c1), fv_film_depth(c2), n * sizeof(float)) != 0 ||
                memcmp(fv_film_id_const(c1), fv_film_id_const(c2), n * sizeof(uint32_t)) != 0)
                fail_msg("%s: two CUDA runs' first hits differ", what);
        }
    fv_film_destroy(p);
    fv_film_destroy(n2);
    fv_film_destroy(c1);
    fv_film_destroy(c2);
    fv_technique_destroy(tp);
    fv_technique_destroy(tn);
    fv_technique_destroy(tc);
    fv_technique_destroy(tc2);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_vpolar(void **st)
{
    (void)st;
    compare("cornell", "vpolar", "", 160, 120, 2, 0.0);
    compare("cornell", "vpolar", "spp=2 offscreen=trace", 128, 96, 1, 0.0);
}

static void test_cartesian(void **st)
{
    (void)st;
    compare("cornell", "cartesian", "", 160, 120, 1, 0.0);
}

static void test_cartesian_full(void **st)
{
    (void)st;
    compare("cornell", "cartesian-full", "", 160, 120, 1, 0.0);
    compare("cornell", "cartesian-full", "denoise=false", 128, 96, 1, 0.0);
}

static void test_linear_falloff(void **st)
{
    (void)st;
    compare("cornell", "linear-falloff", "", 160, 120, 1, 0.0);
}

static void test_logpolar(void **st)
{
    (void)st;
    compare("cornell", "log-polar", "", 160, 120, 1, 0.0);
}

/* SVGF without a pass (its remodulation a launch of its own) and with few passes, one of them in
 * the periphery. */
static void test_svgf_passes(void **st)
{
    (void)st;
    compare("cornell", "vpolar", "svgf_iterations=0", 96, 64, 1, 0.0);
    compare("cornell", "vpolar", "svgf_iterations=2 periphery_passes=1", 96, 64, 1, 0.0);
}

/* A moving object: the scene's moving instances copied to the GPU when its time moves. */
static void test_moving(void **st)
{
    (void)st;
    compare("cornell-fpm", "vpolar", "", 128, 96, 1, 0.25);
}

static void films_equal(fv_film *a, fv_film *b, const char *what)
{
    const size_t n = (size_t)fv_film_width(a) * fv_film_height(a);
    if (memcmp(fv_film_color_const(a), fv_film_color_const(b), 3 * n * sizeof(float)) != 0 ||
        memcmp(fv_film_depth(a), fv_film_depth(b), n * sizeof(float)) != 0 || memcmp(fv_film_normal(a), fv_film_normal(b), 3 * n * sizeof(float)) != 0 ||
        memcmp(fv_film_albedo(a), fv_film_albedo(b), 3 * n * sizeof(float)) != 0 ||
        memcmp(fv_film_position(a), fv_film_position(b), 3 * n * sizeof(float)) != 0 ||
        memcmp(fv_film_id_const(a), fv_film_id_const(b), n * sizeof(uint32_t)) != 0)
        fail_msg("%s: the pair differs from the per-eye calls", what);
}

/* frames stereo frames of method on device: its pairs (fv_technique_render_pair) against its
 * per-eye calls (another technique, the same random numbers), bit for bit, host_syncs 1 a pair on
 * cuda (2 for the two calls). The gaze moves over the first frames, then stays. */
static void compare_pair(const char *method, const char *params, const char *device, int w, int h, int frames)
{
    w = FV_SIM_SIDE(w); /* the simulator: half the side (sim_checks.h) */
    h = FV_SIM_SIDE(h);
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load("cornell", &s, &v) != 0) fail_msg("cannot load cornell");
    fv_camera centre, cam[2];
    fv_view_camera(v, s, 0.0, w, h, &centre);
    fv_camera_stereo(&centre, 0.08f, &cam[0], &cam[1]);
    char pc[160];
    snprintf(pc, sizeof pc, "%s device=%s", params, device);
    const bool cuda = strcmp(device, "cuda") == 0;
    fv_technique *pair = fv_test_technique(method, pc, s), *each = fv_test_technique(method, pc, s);
    fv_film *c[2], *e1[2];
    fv_error err;
    for (int e = 0; e < 2; e++)
        if (fv_film_create(w, h, AUX, &c[e], &err) != FV_OK || fv_film_create(w, h, AUX, &e1[e], &err) != FV_OK) fail_msg("%s", err.msg);
    static const float gaze[][2] = {{0.3f, 0.4f}, {0.6f, 0.55f}, {0.62f, 0.57f}, {0.62f, 0.57f}};
    const int ngaze = (int)(sizeof gaze / sizeof gaze[0]);
    const size_t n = (size_t)w * h;
    for (int i = 0; i < frames; i++) {
        fv_frame f[2];
        fv_test_stereo_frames(cam, 0.0, i, 7, i > 0, f);
        for (int e = 0; e < 2; e++) {
            f[e].left_camera = e == 1 ? &cam[0] : NULL;
            f[e].gaze.x = gaze[i < ngaze ? i : ngaze - 1][0] + 0.03f * (float)e;
            f[e].gaze.y = gaze[i < ngaze ? i : ngaze - 1][1];
            fv_film_clear(c[e]);
            fv_film_clear(e1[e]);
            float *cc = fv_film_color(c[e]), *ce = fv_film_color(e1[e]);
            for (size_t k = 0; k < 3 * n; k++) cc[k] = ce[k] = NAN;
        }
        char what[256];
        snprintf(what, sizeof what, "%s [%s] on %s %dx%d stereo frame %d", method, params, device, w, h, i);
        fv_stats sc, se;
        fv_stats_clear(&sc);
        fv_stats_clear(&se);
        fv_sim_mark m = fv_sim_now();
        if (fv_technique_render_pair(pair, f, c, &sc, &err) != FV_OK) fail_msg("%s: %s", what, err.msg);
        if (cuda) {
            fv_sim_expect(m, 1, -1, what); /* what host_syncs reports (checked below) is what the host did */
            fv_sim_expect_sync_calls(m, 1, what); /* one synchronize, not one per eye's stream */
            fv_sim_expect_reported(m, &sc, what);
        }
        m = fv_sim_now();
        for (int e = 0; e < 2; e++)
            if (fv_technique_render(each, &f[e], e1[e], &se, &err) != FV_OK) fail_msg("%s eye %d: %s", what, e, err.msg);
        if (cuda) {
            fv_sim_expect(m, 2, -1, what);
            fv_sim_expect_sync_calls(m, 2, what);
            fv_sim_expect_reported(m, &se, what);
        }
        printf("%s: host syncs %g for the pair, %g for two calls; samples %g, history %.4f\n", what, fv_stats_get_count(&sc, "host_syncs"),
               fv_stats_get_count(&se, "host_syncs"), fv_stats_get_count(&sc, "samples"), fv_stats_get_count(&sc, "history_fraction"));
        for (int e = 0; e < 2; e++) {
            char we[280];
            snprintf(we, sizeof we, "%s eye %d", what, e);
            films_equal(c[e], e1[e], we);
            const float *col = fv_film_color_const(c[e]);
            for (size_t k = 0; k < 3 * n; k++)
                if (!isfinite(col[k])) fail_msg("%s: value %zu not finite (%g)", we, k, col[k]);
        }
        static const char *const keys[] = {"rays", "samples", "grid_samples", "sample_share", "nan_samples", "history_fraction", "map_reused"};
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
            if (fv_stats_get_count(&sc, keys[k]) != fv_stats_get_count(&se, keys[k]))
                fail_msg("%s: counter %s: pair %g, per eye %g", what, keys[k], fv_stats_get_count(&sc, keys[k]), fv_stats_get_count(&se, keys[k]));
        if (!(fv_stats_get_count(&sc, "samples") > 0.0)) fail_msg("%s: no sample traced", what);
        if (i > 0 && strstr(params, "denoise=false") == NULL && !(fv_stats_get_count(&sc, "history_fraction") > 0.0))
            fail_msg("%s: no history reused", what);
        const double want_pair = cuda ? 1.0 : 0.0, want_each = cuda ? 2.0 : 0.0;
        if (fv_stats_get_count(&sc, "host_syncs") != want_pair) fail_msg("%s: %g host waits for the pair", what, fv_stats_get_count(&sc, "host_syncs"));
        if (fv_stats_get_count(&se, "host_syncs") != want_each)
            fail_msg("%s: %g host waits for two eyes", what, fv_stats_get_count(&se, "host_syncs"));
    }
    for (int e = 0; e < 2; e++) {
        fv_film_destroy(c[e]);
        fv_film_destroy(e1[e]);
    }
    fv_technique_destroy(pair);
    fv_technique_destroy(each);
    if (cuda) fv_sim_expect_freed(method);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* Stereo pairs: vpolar (the gaze moving, so each eye's history is reprojected from one gaze's space
 * into another's), linear-falloff (its killed samples) and cartesian (no mipmaps' levels beyond
 * one) on cuda; vpolar's pair on portable. */
static void test_pair(void **st)
{
    (void)st;
    compare_pair("vpolar", "", "cuda", 80, 48, 4);
    compare_pair("linear-falloff", "", "cuda", 64, 48, 3);
    compare_pair("cartesian", "denoise=false", "cuda", 64, 48, 3);
    compare_pair("vpolar", "", "portable", 64, 48, 3);
}

/* The diagnostics that draw the sample grid need its host copy, which cuda does not keep: refused in
 * one line at creation, before anything is allocated on the GPU. */
static void test_refusals(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    assert_int_equal(fv_test_load("cornell", &s, &v), 0);
    const struct {
        const char *method, *params, *needle;
    } cases[] = {
        {"vpolar", "device=cuda show=space", "parameter show=space: device cuda renders the image only (devices cpu and portable draw diagnostics)"},
        {"log-polar", "device=cuda show=density", "parameter show=density: device cuda renders the image only (devices cpu and portable draw diagnostics)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        fv_test_expect_refusal(cases[i].method, cases[i].params, s, cases[i].needle);
        fv_sim_expect_freed(cases[i].method);
    }
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

#ifdef FOVEA_CUDA_SIM
/* The simulator only: every device allocation of vpolar's backend (the scene at create; the grid,
 * SVGF's buffers, the mipmaps, the blur's and the film's buffers and the host's tables at the first
 * frame; the moving scene's update and the history's reprojection at the second) failing in turn,
 * as on a full GPU: each run ends in a one-line CUDA error with nothing left on the device, and the
 * run after it, in the same process, succeeds (CUDA keeps a failed call's error for
 * cudaGetLastError: a frame must not report it as its own launch's). */
static void test_out_of_memory(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load("cornell-fpm", &s, &v) != 0) fail_msg("cannot load cornell-fpm");
    fv_camera cam;
    fv_view_camera(v, s, 0.7, 32, 24, &cam);
    fv_sim_frames r = {s, &cam, "vpolar", "device=cuda", 2, 0.7};
    if (fv_sim_walk_allocation_failures(fv_sim_run_frames, &r, "vpolar") < 30) fail_msg("vpolar: fewer device allocations than its buffers");
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
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_vpolar),         cmocka_unit_test(test_cartesian), cmocka_unit_test(test_cartesian_full),
                                       cmocka_unit_test(test_linear_falloff), cmocka_unit_test(test_logpolar),  cmocka_unit_test(test_svgf_passes),
                                       cmocka_unit_test(test_moving),         cmocka_unit_test(test_pair),
                                       cmocka_unit_test(test_refusals),
#ifdef FOVEA_CUDA_SIM
                                       cmocka_unit_test(test_out_of_memory)
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
