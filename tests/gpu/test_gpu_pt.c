/* GPU tests (ctest label `gpu`; scripts/gpu-check runs them on an NVIDIA machine): `pt` on CUDA
 * against `pt` on the portable backend, which runs the same kernel source on the CPU with the same
 * random numbers, so the images agree pixel by pixel within float tolerance (the GPU's cosf and
 * sinf differ from the C library's in the last bits, which may send a rare path elsewhere); two
 * CUDA runs are bit-identical; the first-hit buffers agree. A stereo frame through
 * fv_technique_render_pair (both eyes' kernels, one host wait) equals the two per-eye calls bit for
 * bit, with host_syncs 1 for the pair. Exits 77 (skipped) where CUDA cannot
 * run: a build without CUDA, a machine without a GPU. Built a second time against the CUDA
 * simulator (sim_test_gpu_pt, tests/gpu/sim_checks.h), where it also counts the host's waits.
 */
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

static void compare_scene(const char *name, int w, int h, double time, int frames)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(name, &s, &v) != 0) fail_msg("cannot load %s", name);
    fv_error err;
    if (fv_scene_set_time(s, time, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_camera cam;
    fv_view_camera(v, s, time, w, h, &cam);
    fv_film *p = fv_test_render_pt(s, &cam, "spp=4 device=portable", time, frames, 11);
    fv_sim_mark m = fv_sim_now();
    fv_film *c1 = fv_test_render_pt(s, &cam, "spp=4 device=cuda", time, frames, 11);
    fv_sim_expect(m, (uint64_t)frames, frames, name); /* a frame: one launch, one synchronize (after the copies back) */
    fv_sim_expect_freed(name);
    fv_film *c2 = fv_test_render_pt(s, &cam, "spp=4 device=cuda", time, frames, 11);
    fv_test_agreement r = fv_test_agree(p, c1, 1e-3);
    printf("%s: portable (%.4f %.4f %.4f) cuda (%.4f %.4f %.4f): largest mean difference %.3g%%, %.2f%% of pixels equal within 1e-3, "
           "RMS %.3g%% of the mean\n",
           name, r.mean_a[0], r.mean_a[1], r.mean_a[2], r.mean_b[0], r.mean_b[1], r.mean_b[2], 100.0 * r.max_mean_rel, 100.0 * r.equal_share,
           100.0 * r.rms_rel);
    if (!(r.max_mean_rel <= 0.005)) fail_msg("%s: means differ by %.3g%%", name, 100.0 * r.max_mean_rel);
    if (!(r.equal_share >= 0.95)) fail_msg("%s: only %.2f%% of pixels equal", name, 100.0 * r.equal_share);
    if (!(r.rms_rel <= 0.05)) fail_msg("%s: RMS difference %.3g%% of the mean", name, 100.0 * r.rms_rel);
    size_t n = (size_t)w * h;
    if (memcmp(fv_film_color_const(c1), fv_film_color_const(c2), 3 * n * sizeof(float)) != 0) fail_msg("%s: two CUDA runs differ", name);
    const uint32_t *ip = fv_film_id(p), *ic = fv_film_id(c1);
    size_t same = 0;
    for (size_t i = 0; i < n; i++) same += ip[i] == ic[i];
    if (!((double)same >= 0.995 * (double)n)) fail_msg("%s: the first hit's object differs in %zu of %zu pixels", name, n - same, n);
    fv_film_destroy(p);
    fv_film_destroy(c1);
    fv_film_destroy(c2);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_cornell(void **st)
{
    (void)st;
    compare_scene("cornell", 128, 128, 0.0, 1);
}

static void test_city(void **st)
{
    (void)st;
    compare_scene("city", 160, 96, 0.0, 1);
}

static void test_moving(void **st)
{
    (void)st;
    compare_scene("cornell-fpm", 96, 96, 0.7, 3);
}

static void test_textured(void **st)
{
    (void)st;
    char path[4096];
    compare_scene(fv_test_data("textured/box.glb", path, sizeof path), 96, 96, 0.0, 1);
}

static void test_sdf(void **st)
{
    (void)st;
    compare_scene("sdf-primitives", 96, 96, 0.0, 1);
}

/* A moving scene's stereo frames on CUDA as pairs and as per-eye calls: the same bits, one host
 * wait per pair (two for the per-eye calls). */
static void test_pair(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load("cornell-fpm", &s, &v) != 0) fail_msg("cannot load cornell-fpm");
    fv_camera centre, cam[2];
    fv_view_camera(v, s, 0.0, 96, 72, &centre);
    fv_camera_stereo(&centre, 0.06f, &cam[0], &cam[1]);
    fv_params *p = fv_test_params_str("spp=4 device=cuda");
    fv_technique *pair = NULL, *each = NULL;
    fv_error err;
    if (fv_technique_create("pt", s, p, NULL, &pair, &err) != FV_OK || fv_technique_create("pt", s, p, NULL, &each, &err) != FV_OK)
        fail_msg("%s", err.msg);
    fv_film *a[2], *b[2];
    for (int e = 0; e < 2; e++)
        if (fv_film_create(96, 72, FV_AUX_DEPTH | FV_AUX_ID, &a[e], &err) != FV_OK || fv_film_create(96, 72, FV_AUX_DEPTH | FV_AUX_ID, &b[e], &err) != FV_OK)
            fail_msg("%s", err.msg);
    for (int i = 0; i < 3; i++) {
        const double time = 0.2 * i;
        if (fv_scene_set_time(s, time, &err) != FV_OK) fail_msg("%s", err.msg);
        fv_frame f[2];
        fv_test_stereo_frames(cam, time, i, 11, false, f);
        fv_stats sp, se;
        fv_stats_clear(&sp);
        fv_stats_clear(&se);
        const fv_sim_mark m = fv_sim_now();
        if (fv_technique_render_pair(pair, f, b, &sp, &err) != FV_OK) fail_msg("pair %d: %s", i, err.msg);
        fv_sim_expect_reported(m, &sp, "pt pair");
        for (int e = 0; e < 2; e++)
            if (fv_technique_render(each, &f[e], a[e], &se, &err) != FV_OK) fail_msg("frame %d eye %d: %s", i, e, err.msg);
        printf("pt cornell-fpm stereo frame %d: rays %g (per eye %g), host syncs %g (per eye %g)\n", i, fv_stats_get_count(&sp, "rays"),
               fv_stats_get_count(&se, "rays"), fv_stats_get_count(&sp, "host_syncs"), fv_stats_get_count(&se, "host_syncs"));
        for (int e = 0; e < 2; e++)
            if (memcmp(fv_film_color_const(a[e]), fv_film_color_const(b[e]), (size_t)3 * 96 * 72 * sizeof(float)) != 0 ||
                memcmp(fv_film_depth(a[e]), fv_film_depth(b[e]), (size_t)96 * 72 * sizeof(float)) != 0)
                fail_msg("frame %d eye %d: the pair differs from the per-eye call", i, e);
        if (fv_stats_get_count(&sp, "rays") != fv_stats_get_count(&se, "rays")) fail_msg("frame %d: the pair counts other rays", i);
        if (fv_stats_get_count(&sp, "host_syncs") != 1.0 || fv_stats_get_count(&se, "host_syncs") != 2.0)
            fail_msg("frame %d: %g host waits for the pair, %g for two eyes", i, fv_stats_get_count(&sp, "host_syncs"), fv_stats_get_count(&se, "host_syncs"));
    }
    for (int e = 0; e < 2; e++) {
        fv_film_destroy(a[e]);
        fv_film_destroy(b[e]);
    }
    fv_technique_destroy(pair);
    fv_technique_destroy(each);
    fv_params_destroy(p);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

#ifdef FOVEA_CUDA_SIM
/* The simulator only: every device allocation of pt's backend (the scene at create, the film and
 * counters, the moving scene's update) failing in turn, as on a full GPU. */
static void test_out_of_memory(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load("cornell-fpm", &s, &v) != 0) fail_msg("cannot load cornell-fpm");
    fv_camera cam;
    fv_view_camera(v, s, 0.7, 24, 16, &cam);
    fv_sim_frames r = {s, &cam, "pt", "spp=1 device=cuda", 2, 0.7};
    if (fv_sim_walk_allocation_failures(fv_sim_run_frames, &r, "pt") < 10) fail_msg("pt: fewer device allocations than the scene has arrays");
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
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_cornell), cmocka_unit_test(test_city), cmocka_unit_test(test_moving),
                                       cmocka_unit_test(test_textured), cmocka_unit_test(test_sdf), cmocka_unit_test(test_pair),
#ifdef FOVEA_CUDA_SIM
                                       cmocka_unit_test(test_out_of_memory)
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
