/* The Visual-Polar family on the portable backend (technique/vpolar/vp_device.h: every stage as
 * kernels, a cell or pixel at a time on the CPU's threads: the trace, technique/vpolar/kvp_trace.h; the
 * denoiser's reprojection and its steps, technique/vpolar/kvp_reproject.h and filter/ksvgf.h; the φ-mipmaps;
 * the map to the screen, technique/vpolar/kvp_map.h; the blur, filter/kblur.h) against the
 * CPU pipeline (Embree packets, vectorised rows), for each of the five methods over four frames of
 * a sequence whose gaze moves and then stays, so the denoiser's history is reprojected from one
 * gaze's space into another's and then accumulated, and the CPU's kept map coordinates are stored
 * and read while the portable backend recomputes them.
 *
 * Everything after the trace is the same arithmetic on both backends (the map kernels are the
 * CPU's own per-pixel steps, the mipmap cells its build, test_phi_mips compares the lookups bit for
 * bit; the denoiser's kernels give the CPU filter's bits, test_kernel_svgf; the blur's likewise,
 * test_blur), and the trace places every sample and draws
 * every random number the same way. What differs is the traversal: Embree's triangle test rounds
 * differently from the flat BVH's (test_traverse), so where a shading normal has a zero component
 * (the Cornell box's axis-aligned walls) an ulp can flip the tangent frame and send a path
 * elsewhere, as in pt's own comparison (test_device_pt: at 1 spp on cornell about half the pixels
 * of pt itself are bit-equal across the two backends; cartesian-full without the denoiser, the
 * same paths, 61%). The denoiser then spreads such a path over its taps. So the bounds are pt's
 * kind, over the four frames:
 *  - every first hit equal (object id, and depth to 1e-4 relative) and the same samples launched;
 *  - the denoiser's history_fraction within 0.01 (measured: equal in every frame; only a position
 *    or normal an ulp apart at a consistency threshold could move a pixel);
 *  - the image's mean within 2% (measured: at most 0.7%, log-polar);
 *  - the RMS colour difference below a quarter of the RMS difference between two CPU renders on
 *    different seeds, the noise of the estimate (measured: 1% to 12% of it, cartesian-full the
 *    highest), which a wrong coordinate, a lost history or a missing sample would exceed.
 * The lines printed per frame are those measurements.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <math.h>
#include "fovea/fovea.h"
#include "testkit.h"

#define AUX (FV_AUX_DEPTH | FV_AUX_NORMAL | FV_AUX_ALBEDO | FV_AUX_ID | FV_AUX_POSITION)

/* Root of the mean squared difference of two colour images. */
static double rms(const float *a, const float *b, size_t n)
{
    double sum = 0.0;
    for (size_t k = 0; k < 3 * n; k++) sum += ((double)a[k] - (double)b[k]) * ((double)a[k] - (double)b[k]);
    return sqrt(sum / (3.0 * (double)n));
}

static void compare_method(const char *scene, const char *method, const char *params, int w, int h)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, w, h, &cam);
    char pc[160], pp[160];
    snprintf(pc, sizeof pc, "%s device=cpu", params);
    snprintf(pp, sizeof pp, "%s device=portable", params);
    /* tc and tp draw the same random numbers; tn (the CPU on another seed) is the noise yardstick */
    fv_technique *tc = fv_test_technique(method, pc, s), *tp = fv_test_technique(method, pp, s), *tn = fv_test_technique(method, pc, s);
    fv_film *a = NULL, *b = NULL, *c = NULL;
    fv_error err;
    if (fv_film_create(w, h, AUX, &a, &err) != FV_OK || fv_film_create(w, h, AUX, &b, &err) != FV_OK ||
        fv_film_create(w, h, AUX, &c, &err) != FV_OK)
        fail_msg("%s", err.msg);
    static const float gaze[4][2] = {{0.3f, 0.4f}, {0.6f, 0.55f}, {0.62f, 0.57f}, {0.62f, 0.57f}};
    const size_t n = (size_t)w * h;
    double rms_same = 0.0, rms_noise = 0.0, sum_a = 0.0, sum_b = 0.0;
    for (int i = 0; i < 4; i++) {
        fv_frame f;
        fv_frame_init(&f, &cam);
        f.seed = 7;
        f.index = i;
        f.prev_camera = i > 0 ? &cam : NULL;
        f.gaze.x = gaze[i][0];
        f.gaze.y = gaze[i][1];
        fv_stats sc, sp, sn;
        fv_test_render_fresh(tc, &f, a, &sc);
        fv_test_render_fresh(tp, &f, b, &sp);
        f.seed = 8;
        fv_test_render_fresh(tn, &f, c, &sn);
        const float *ca = fv_film_color_const(a), *cb = fv_film_color_const(b);
        size_t exact = 0, ids = 0, depths = 0;
        for (size_t k = 0; k < 3 * n; k++) {
            if (!isfinite(ca[k]) || !isfinite(cb[k])) fail_msg("%s frame %d: value %zu not finite", method, i, k);
            sum_a += ca[k], sum_b += cb[k];
        }
        for (size_t k = 0; k < n; k++) {
            exact += memcmp(&ca[3 * k], &cb[3 * k], 3 * sizeof(float)) == 0;
            ids += fv_film_id_const(a)[k] == fv_film_id_const(b)[k];
            const float za = fv_film_depth(a)[k], zb = fv_film_depth(b)[k];
            depths += za == zb || fabsf(za - zb) <= 1e-4f * fabsf(za);
        }
        const double same = rms(ca, cb, n), noise = rms(ca, fv_film_color_const(c), n);
        rms_same += same, rms_noise += noise;
        const double hc = fv_stats_get_count(&sc, "history_fraction"), hp = fv_stats_get_count(&sp, "history_fraction");
        printf("%s %s %dx%d frame %d: %zu/%zu pixels equal bit for bit, rms difference %.4g (another seed: %.4g), ids equal %zu, "
               "depths equal %zu, samples %g / %g, history %.6f / %.6f\n",
               method, params, w, h, i, exact, n, same, noise, ids, depths, fv_stats_get_count(&sc, "samples"), fv_stats_get_count(&sp, "samples"),
               hc, hp);
        if (fabs(hc - hp) > 0.01) fail_msg("%s frame %d: history_fraction cpu %g, portable %g", method, i, hc, hp);
        if (ids != n || depths != n) fail_msg("%s frame %d: first hits differ (ids %zu, depths %zu of %zu)", method, i, ids, depths, n);
        /* the same samples were launched: the skip and the kill are the same arithmetic */
        if (fv_stats_get_count(&sc, "samples") != fv_stats_get_count(&sp, "samples"))
            fail_msg("%s frame %d: samples cpu %g, portable %g", method, i, fv_stats_get_count(&sc, "samples"), fv_stats_get_count(&sp, "samples"));
    }
    const double mean_a = sum_a / (12.0 * (double)n), mean_b = sum_b / (12.0 * (double)n);
    printf("%s %s: mean %.5f / %.5f, rms difference %.4g against %.4g between seeds\n", method, params, mean_a, mean_b, rms_same / 4,
           rms_noise / 4);
    if (!(mean_a > 0.0)) fail_msg("%s rendered black on the CPU", method);
    if (fabs(mean_b - mean_a) > 0.02 * mean_a) fail_msg("%s: mean %.5f on the CPU, %.5f on portable", method, mean_a, mean_b);
    if (!(rms_same < 0.25 * rms_noise)) fail_msg("%s: rms difference %.4g, not below a quarter of the noise %.4g", method, rms_same / 4, rms_noise / 4);
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_film_destroy(c);
    fv_technique_destroy(tc);
    fv_technique_destroy(tp);
    fv_technique_destroy(tn);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_vpolar(void **st)
{
    (void)st;
    compare_method("cornell", "vpolar", "", 64, 48);
}
static void test_cartesian(void **st)
{
    (void)st;
    compare_method("cornell", "cartesian", "", 64, 48);
}
static void test_cartesian_full(void **st)
{
    (void)st;
    compare_method("cornell", "cartesian-full", "", 64, 48);
    compare_method("cornell", "cartesian-full", "denoise=false", 64, 48);
    compare_method("cornell", "vpolar", "denoise=false blur=false", 64, 48);
}
static void test_linear_falloff(void **st)
{
    (void)st;
    compare_method("cornell", "linear-falloff", "", 64, 48);
}
static void test_logpolar(void **st)
{
    (void)st;
    compare_method("cornell", "log-polar", "", 64, 48);
}
/* Two paths a sample and offscreen=trace: the spp loop and every cell traced. */
static void test_vpolar_spp2(void **st)
{
    (void)st;
    compare_method("cornell", "vpolar", "spp=2 offscreen=trace", 64, 48);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_vpolar),         cmocka_unit_test(test_cartesian), cmocka_unit_test(test_cartesian_full),
        cmocka_unit_test(test_linear_falloff), cmocka_unit_test(test_logpolar),  cmocka_unit_test(test_vpolar_spp2),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
