/* ppm (src/technique/photon/ppm.c): progressive photon mapping converges to the truth.
 *  - the radius schedule of Knaus & Zwicker Eq. 15 by hand: alpha = 2/3 gives r_2^2 / r_1^2 = 5/6,
 *    r_3^2 / r_1^2 = 5/6 * 8/9 = 20/27;
 *  - bad parameters are refused in one line naming the key;
 *  - the furnace at the default radius (Eq. 8: 0.625 at 64x64): the image mean is 1 - 0.5^9 (pt's
 *    answer for 8 bounces), and pm's at its default radius too (the gather keeps every photon of
 *    the disc, photon_map.h). Four seeds measured: ppm (16 passes of 50000 photons) 0.9973-0.9983,
 *    sigma 0.07%; pm (4 passes of 100000, no filter) 0.9968-1.0008, sigma 0.17%. Tolerance 0.5%,
 *    about 3 sigma of pm plus its +0.17% mean; before the gather stopped rejecting photons from
 *    below the tangent plane pm gave 0.5 + 0.498 (1 - r^2 / 8) = 0.974 here;
 *  - cornell at 64x64: the mean luminance (the light and the pixels next to it left out: their
 *    jittered samples flip between the light and the ceiling, the largest noise of the mean) of
 *    ppm starting at r_1 = 4 (32 passes of 100000 photons) against pt at 256 spp. Four seeds:
 *    0.9933-0.9972 of pt at 2048 spp (mean 0.9953, sigma 0.18%; pt at 256 spp: sigma 0.1%); the
 *    deficit is the boundary bias of the radii used (r_1 = 8: 0.993, 16: 0.985). Tolerance 1.5%:
 *    the mean deficit and 4 sigma. pm at Eq. 8's radius (173 here) is 20% dark.
 * Under the sanitizers the budgets are 4 to 8 times smaller and the tolerances 3 times wider. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "technique/photon/ppm.h"
#include "testkit.h"

#define W 64
#define H 64

static bool sanitized(void) { return getenv("FOVEA_SANITIZED") != NULL; }

static void test_schedule(void **st)
{
    (void)st;
    double r2 = 1.0;
    r2 = fv_ppm_next_r2(r2, 2.0 / 3.0, 1);
    assert_float_equal(r2, 5.0 / 6.0, 1e-12);
    r2 = fv_ppm_next_r2(r2, 2.0 / 3.0, 2);
    assert_float_equal(r2, 20.0 / 27.0, 1e-12);
    /* alpha = 1/2 from r^2 = 4: 4 * 1.5 / 2 = 3, then 3 * 2.5 / 3 = 2.5 */
    assert_float_equal(fv_ppm_next_r2(fv_ppm_next_r2(4.0, 0.5, 1), 0.5, 2), 2.5, 1e-12);
}

static void test_bad_params(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    assert_int_equal(fv_test_load("cornell", &s, &v), 0);
    static const char *const bad[][2] = {
        {"alpha=0", "alpha"},   {"alpha=1", "alpha"},   {"alpha=1.5", "alpha"}, {"alpha=-0.2", "alpha"},
        {"passes=0", "passes"}, {"passes=-3", "passes"}, {"photons=0", "photons"}, {"radius=0", "radius"},
        {"radius=-1", "radius"}, {"alpha=nan", "alpha"}, {"passes=many", "passes"}, {"max_depth=0", "max_depth"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        fv_params *p = fv_test_params_str(bad[i][0]);
        fv_technique *t = NULL;
        fv_error err;
        fv_test_expect_fail(fv_technique_create("ppm", s, p, NULL, &t, &err), &err, FV_ERR_INVALID, bad[i][1], bad[i][0]);
        if (strchr(err.msg, '\n')) fail_msg("%s: message on more than one line: %s", bad[i][0], err.msg);
        assert_null(t);
        fv_params_destroy(p);
    }
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* The colour of one frame of `method` with `params`, seen by the scene's camera at W x H; the
 * caller frees it. */
static float *render(const char *name, const char *method, const char *params, uint64_t seed)
{
    fv_scene *s;
    fv_view *v;
    assert_int_equal(fv_test_load(name, &s, &v), 0);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, W, H, &cam);
    fv_film *film = fv_test_render_once(method, params, s, &cam, seed);
    float *out = malloc(sizeof(float) * 3 * W * H);
    assert_non_null(out);
    memcpy(out, fv_film_color_const(film), sizeof(float) * 3 * W * H);
    fv_film_destroy(film);
    fv_view_destroy(v);
    fv_scene_destroy(s);
    return out;
}

static double lum(const float *c, int i) { return 0.2126 * c[3 * i] + 0.7152 * c[3 * i + 1] + 0.0722 * c[3 * i + 2]; }

/* Mean luminance over the pixels `keep` marks (all when NULL). */
static double mean_lum(const float *c, const bool *keep)
{
    double s = 0.0;
    int n = 0;
    for (int i = 0; i < W * H; i++)
        if (!keep || keep[i]) s += lum(c, i), n++;
    return s / n;
}

static void test_furnace(void **st)
{
    (void)st;
    const double want = 1.0 - pow(0.5, 9), tol = sanitized() ? 0.015 : 0.005;
    float *ppm = render("furnace", "ppm", sanitized() ? "passes=4,photons=25000" : "passes=16,photons=50000", 1);
    float *pm = render("furnace", "pm", sanitized() ? "passes=2,photons=50000,filter=false" : "passes=4,photons=100000,filter=false", 1);
    const double m_ppm = mean_lum(ppm, NULL), m_pm = mean_lum(pm, NULL);
    print_message("furnace at Eq. 8's radius: ppm %.5f, pm %.5f (exact %.5f)\n", m_ppm, m_pm, want);
    assert_float_equal(m_ppm, want, tol * want);
    assert_float_equal(m_pm, want, tol * want);
    free(ppm);
    free(pm);
}

static void test_cornell_converges(void **st)
{
    (void)st;
    float *pt = render("cornell", "pt", sanitized() ? "spp=32" : "spp=256", 1);
    float *ppm = render("cornell", "ppm", sanitized() ? "radius=4,passes=8,photons=50000" : "radius=4,passes=32,photons=100000", 2);
    float *pm = render("cornell", "pm", "photons=100000,filter=false", 3);
    /* The light: luminance above 1 in pt (walls stay below 0.7), grown by a pixel. */
    bool keep[W * H];
    for (int i = 0; i < W * H; i++) keep[i] = true;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            if (lum(pt, y * W + x) > 1.0)
                for (int yy = y > 0 ? y - 1 : 0; yy <= y + 1 && yy < H; yy++)
                    for (int xx = x > 0 ? x - 1 : 0; xx <= x + 1 && xx < W; xx++) keep[yy * W + xx] = false;
    const double m_pt = mean_lum(pt, keep), m_ppm = mean_lum(ppm, keep), m_pm = mean_lum(pm, keep);
    print_message("cornell 64x64, light left out: ppm/pt %.4f, pm/pt %.4f (pt %.5f)\n", m_ppm / m_pt, m_pm / m_pt, m_pt);
    assert_float_equal(m_ppm / m_pt, 1.0, sanitized() ? 0.045 : 0.015);
    assert_true(m_pm / m_pt < 0.9); /* what the shrinking radius removes */
    free(pt);
    free(ppm);
    free(pm);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_schedule),
        cmocka_unit_test(test_bad_params),
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_cornell_converges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
