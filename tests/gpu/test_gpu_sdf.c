/* GPU tests (ctest label `gpu`; scripts/gpu-check runs them on an NVIDIA machine): `sdf-gt` and
 * `sdf-relaxed` on CUDA against the portable backend, which runs the same kernel source
 * (kernel/sdf_pixel.h) on the CPU and equals the CPU pipeline bit for bit (test_device_sdf).
 *
 * Bounds, not yet measured on a GPU (none was available when this was written), chosen from what
 * can differ: with --fmad=false the GPU rounds +, -, *, /, sqrtf as the CPU does, so the field and
 * every step are the same; only powf (the Blinn-Phong lobe) and cosf (a spot light's cone) differ
 * in the last bits. That changes a shaded colour by a few ulps and decides nothing in the march,
 * so 99.5% of the pixels must agree within 1e-4 relative (or 1e-6 absolute), the means within
 * 0.01%, and the counters (steps, shadow steps) exactly; two CUDA runs are bit-identical. If the GPU
 * shows more, the first run's printout says where, and the bound is revised with that measurement.
 * Exits 77 (skipped) where CUDA cannot run: a build without CUDA, a machine without a GPU.
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
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, w, h, &cam);
    char pp[64], pc[64];
    snprintf(pp, sizeof pp, "spp=%d device=portable", spp);
    snprintf(pc, sizeof pc, "spp=%d device=cuda", spp);
    fv_stats sp, sc, sc2;
    fv_film *p = render(method, pp, s, &cam, &sp), *c1 = render(method, pc, s, &cam, &sc), *c2 = render(method, pc, s, &cam, &sc2);
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

int main(void)
{
    char why[256];
    if (!fv_device_available(FV_DEVICE_CUDA, why, sizeof why)) {
        printf("skipped: %s\n", why);
        return 77;
    }
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_primitives), cmocka_unit_test(test_columns), cmocka_unit_test(test_temple)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
