/* fovea — textured colours through the denoisers (issue 25, item 1): every method with a filter
 * (SVGF of the Visual-Polar family, fpm-guided's lattice fill and filters, the A-Trous of pm, pm-t and
 * fpm, fir's filter of its interleaved light) renders a small textured scene with its filter and
 * without, and the filtered image must keep the unfiltered one's hue on every saturated texture
 * colour and on the white cells.
 *
 * Scene: tests/data/textured_hue (make.py): a floor quad whose 8x8 texture is a checker of pure red
 * and pure blue (the other channels exactly 0), brown whose blue decodes below 1e-3 (dark wood's) and
 * white; beside it a glossy panel tinted (0, 0.04, 0.02) with specular 0.65 (CesiumMilkTruck's
 * windows). Before the fix, SVGF and fpm-guided's fill divided a channel with albedo below 1e-3 by
 * 1 instead of its albedo, so the red cells took their blue neighbours' light as their colour (and
 * the reverse), and the glossy panel's highlight, divided by its diffuse albedo, bled red and cyan.
 *
 * Pixels are grouped by the film's albedo buffer (the texture's colour at the first hit: the same in
 * both renders, free of noise), each group's colour summed, and its chromaticity (r, g, b) / (r + g +
 * b) compared between the filtered and the unfiltered render of the same method, seed and view.
 */
#include "testkit.h"

#define W 64
#define H 48

/* The bound on each chromaticity coordinate, |filtered - unfiltered| <= 0.03. Why: a filter that
 * smooths light but multiplies each pixel's own albedo back (demodulation) changes a group's
 * colour only through (1) the light's own colour varying across the floor (grey sky, white light:
 * nearly none), (2) the floor of the demodulation (filter/demod.h: a channel gains at most 1e-3 of
 * the light), (3) light averaged across a cell's border into the cell's edge pixels, whose albedo
 * keeps the hue, and (4) the unfiltered image's noise: 1 path per pixel over the ~300 pixels of a
 * group, under 1% of a coordinate here. pm, pm-t and fpm's A-Trous filtered colour until issue 25
 * made it demodulate too: the dark brown cells next to blue ones then gained 0.081 of blue. The bug moved the red and
 * blue cells' chromaticity by 0.15 to 0.4 and the white cells' by up to 0.05 (printed by this test
 * on the code before the fix). */
#define HUE_BOUND 0.03

enum { G_RED, G_BLUE, G_BROWN, G_WHITE, G_COUNT };
static const char *const k_group[G_COUNT] = {"red", "blue", "brown", "white"};

static fv_scene *g_scene;
static fv_view *g_view;

static int setup(void **st)
{
    (void)st;
    char path[512];
    return fv_test_load(fv_test_data("textured_hue/scene.json", path, sizeof path), &g_scene, &g_view);
}

static int teardown(void **st)
{
    (void)st;
    fv_scene_destroy(g_scene);
    fv_view_destroy(g_view);
    return 0;
}

static int group_of(const float *a)
{
    if (a[0] > 0.9f && a[1] < 0.01f && a[2] < 0.01f) return G_RED;
    if (a[2] > 0.9f && a[0] < 0.01f && a[1] < 0.01f) return G_BLUE;
    /* sRGB (150, 70, 3): linear (0.305, 0.061, 0.00091) */
    if (a[0] > 0.25f && a[0] < 0.35f && a[1] > 0.04f && a[1] < 0.08f && a[2] < 0.001f) return G_BROWN;
    if (a[0] > 0.7f && a[1] > 0.7f && a[2] > 0.7f) return G_WHITE;
    return -1;
}

/* One frame of method with params into sums[group][channel] and the pixel counts. */
static void render_groups(const char *method, const char *params, double sums[G_COUNT][3], int count[G_COUNT])
{
    fv_camera cam;
    fv_view_camera(g_view, g_scene, 0.0, W, H, &cam);
    fv_params *p = fv_test_params_str(params);
    fv_technique *t = NULL;
    fv_error err;
    if (fv_technique_create(method, g_scene, p, NULL, &t, &err) != FV_OK) fail_msg("%s %s: %s", method, params, err.msg);
    fv_film *film = NULL;
    if (fv_film_create(W, H, FV_AUX_ALBEDO, &film, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_frame f;
    fv_frame_init(&f, &cam);
    f.seed = 7;
    f.threads = 0;
    fv_test_render_frames(t, &f, 1, film, NULL);
    const float *c = fv_film_color_const(film), *a = fv_film_aux_const(film, FV_AUX_ALBEDO);
    memset(sums, 0, sizeof(double) * G_COUNT * 3);
    memset(count, 0, sizeof(int) * G_COUNT);
    for (int i = 0; i < W * H; i++) {
        int g = group_of(&a[3 * i]);
        if (g < 0) continue;
        count[g]++;
        for (int k = 0; k < 3; k++) sums[g][k] += c[3 * i + k];
    }
    fv_film_destroy(film);
    fv_technique_destroy(t);
    fv_params_destroy(p);
}

/* method with `on` and with `off` (the same other parameters `common`): every group's chromaticity
 * within HUE_BOUND. */
static void expect_hue_within(const char *method, const char *common, const char *on, const char *off, double bound)
{
    char pon[256], poff[256];
    snprintf(pon, sizeof pon, "%s %s", common, on);
    snprintf(poff, sizeof poff, "%s %s", common, off);
    double s1[G_COUNT][3], s0[G_COUNT][3];
    int n1[G_COUNT], n0[G_COUNT];
    render_groups(method, pon, s1, n1);
    render_groups(method, poff, s0, n0);
    double worst = 0.0;
    int worst_g = 0;
    for (int g = 0; g < G_COUNT; g++) {
        assert_int_equal(n1[g], n0[g]);
        if (n0[g] < 10) fail_msg("%s: only %d pixels of %s: the view misses the texture", method, n0[g], k_group[g]);
        double t1 = s1[g][0] + s1[g][1] + s1[g][2], t0 = s0[g][0] + s0[g][1] + s0[g][2];
        if (!(t0 > 0.0 && t1 > 0.0)) fail_msg("%s: %s is black", method, k_group[g]);
        for (int k = 0; k < 3; k++) {
            double d = fabs(s1[g][k] / t1 - s0[g][k] / t0);
            if (d > worst) worst = d, worst_g = g;
        }
        print_message("%-15s %-6s %4d px  filtered rgb %.3f %.3f %.3f  unfiltered %.3f %.3f %.3f\n", method, k_group[g], n0[g],
                      s1[g][0] / t1, s1[g][1] / t1, s1[g][2] / t1, s0[g][0] / t0, s0[g][1] / t0, s0[g][2] / t0);
    }
    if (worst > bound)
        fail_msg("%s (%s vs %s): the %s cells' chromaticity moves by %.3f (bound %.2f)", method, on, off, k_group[worst_g], worst,
                 bound);
}

static void expect_hue_kept(const char *method, const char *common, const char *on, const char *off)
{
    expect_hue_within(method, common, on, off, HUE_BOUND);
}

static void test_svgf_family(void **st)
{
    (void)st;
    const char *m[] = {"vpolar", "cartesian", "cartesian-full", "linear-falloff", "log-polar"};
    for (int i = 0; i < 5; i++) expect_hue_kept(m[i], "", "denoise=true", "denoise=false");
}

static void test_fpm_guided(void **st)
{
    (void)st;
    expect_hue_kept("fpm-guided", "photons=20000", "filter=true", "filter=false");
    /* The lattice fill runs with filter=false too: against every pixel gathered (no lattice). */
    expect_hue_kept("fpm-guided", "photons=20000 filter=false", "periphery_step=2", "periphery_step=1");
}

static void test_photon_atrous(void **st)
{
    (void)st;
    const char *m[] = {"pm", "pm-t", "fpm"};
    for (int i = 0; i < 3; i++) expect_hue_kept(m[i], "photons=20000", "filter=true", "filter=false");
}

static void test_fir(void **st)
{
    (void)st;
    expect_hue_kept("fir", "vpls=200 candidates=200", "filter=box", "filter=none");
    expect_hue_kept("fir", "vpls=200 candidates=200", "filter=atrous", "filter=none");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_svgf_family),
        cmocka_unit_test(test_fpm_guided),
        cmocka_unit_test(test_photon_atrous),
        cmocka_unit_test(test_fir),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
