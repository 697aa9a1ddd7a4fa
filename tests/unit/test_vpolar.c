/* Visual-Polar path tracing and its baselines end to end on the Cornell box: the launch order and
 * the thread count do not change the image (same samples), the map stage's kept coordinates give
 * the image computed afresh and a moved gaze is mapped afresh, sample counts follow each method's
 * distribution, the denoised sequence converges towards the converged one-bounce path tracer in
 * the fovea, stereo renders both eyes, the space and density views show the layout, a whole-screen
 * fovea (`--gaze-missing widen`) renders the foveated methods as cartesian-full, and bad
 * parameters are refused naming the key. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/metrics.h"
#include "fovea/technique.h"
#include "fovea/view.h"
#include "technique/vpolar/space.h"
#include "testkit.h"

#define W 128
#define H 144

static fv_scene *g_scene;
static fv_view *g_view;

static int setup(void **st)
{
    (void)st;
    return fv_test_load("cornell", &g_scene, &g_view);
}

static int teardown(void **st)
{
    (void)st;
    fv_view_destroy(g_view);
    fv_scene_destroy(g_scene);
    return 0;
}

/* Renders `frames` frames of a still camera and gaze; returns the last image (caller frees) and
 * the last frame's stats. */
static float *render(const char *method, const char *const *kv, int frames, int threads, fv_gaze gaze, fv_stats *stats_out)
{
    fv_error err;
    fv_params *p = fv_test_params(kv);
    fv_technique *t;
    if (fv_technique_create(method, g_scene, p, NULL, &t, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_film *film;
    assert_int_equal(fv_film_create(W, H, FV_AUX_ALL, &film, &err), FV_OK);
    fv_camera cam;
    fv_view_camera(g_view, g_scene, 0.0, W, H, &cam);
    fv_stats stats;
    fv_frame fr;
    fv_frame_init(&fr, &cam);
    fr.seed = 5;
    fr.threads = threads;
    fr.gaze = gaze;
    fv_test_render_frames(t, &fr, frames, film, &stats);
    float *img = malloc(sizeof(float) * 3 * W * H);
    memcpy(img, fv_film_color_const(film), sizeof(float) * 3 * W * H);
    if (stats_out) *stats_out = stats;
    fv_film_destroy(film);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return img;
}

static const fv_gaze k_centre = {0.5f, 0.5f};

/* A missing gaze under `--gaze-missing widen` (docs/gaze.md): with the driver's whole-screen eye
 * model the three foveated methods render as cartesian-full, bit for bit (the same defaults for
 * the path tracing and SVGF), and their own sample space takes over again afterwards. Sequence:
 * frames 0-1 at the gaze, 2-3 widened, 4 at the gaze again; frames 2-3 must be cartesian-full's
 * frames 2-3 of a sequence whose history starts at frame 2, and frame 4 must be the method's own
 * frame 4 rendered without history. */
static void test_widened_is_cartesian_full(void **st)
{
    (void)st;
    fv_eye_model normal, whole;
    fv_eye_model_default(W, H, &normal);
    fv_eye_model_whole_screen(&normal, &whole);
    fv_camera cam;
    fv_view_camera(g_view, g_scene, 0.0, W, H, &cam);
    const char *const methods[] = {"vpolar", "linear-falloff", "log-polar"};
    fv_error err;
    fv_params *p = fv_test_params_str("");
    fv_film *a, *b;
    assert_int_equal(fv_film_create(W, H, 0, &a, &err), FV_OK);
    assert_int_equal(fv_film_create(W, H, 0, &b, &err), FV_OK);
    for (int m = 0; m < 3; m++) {
        fv_technique *t, *full, *fresh;
        assert_int_equal(fv_technique_create(methods[m], g_scene, p, NULL, &t, &err), FV_OK);
        assert_int_equal(fv_technique_create("cartesian-full", g_scene, p, NULL, &full, &err), FV_OK);
        assert_int_equal(fv_technique_create(methods[m], g_scene, p, NULL, &fresh, &err), FV_OK);
        for (int i = 0; i < 5; i++) {
            fv_frame fr;
            fv_frame_init(&fr, &cam);
            fr.index = i;
            fr.prev_camera = i > 0 ? &cam : NULL;
            fr.gaze = (fv_gaze){0.3f, 0.6f};
            fr.eye_model = &normal;
            if (i == 2 || i == 3) fr.gaze = k_centre, fr.eye_model = &whole;
            fv_test_render_frames(t, &fr, 1, a, NULL);
            if (i < 2) continue;
            fv_frame other = fr;
            if (i == 2 || i == 4) other.prev_camera = NULL; /* where that pipeline's history starts */
            fv_test_render_frames(i < 4 ? full : fresh, &other, 1, b, NULL);
            if (memcmp(fv_film_color_const(a), fv_film_color_const(b), sizeof(float) * 3 * W * H) != 0)
                fail_msg("%s frame %d differs from %s", methods[m], i, i < 4 ? "cartesian-full's" : "its own without history");
        }
        fv_technique_destroy(t);
        fv_technique_destroy(full);
        fv_technique_destroy(fresh);
    }
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_params_destroy(p);
}

/* Sec. 6's random launch traces the very same samples: only the order (and the coherence) differs.
 * The thread count does not matter either. */
static void test_order_and_threads(void **st)
{
    (void)st;
    const char *grid[] = {"order=grid", NULL}, *rnd[] = {"order=random", NULL};
    fv_stats a, b;
    float *i1 = render("vpolar", grid, 2, 2, (fv_gaze){0.3f, 0.6f}, &a);
    float *i2 = render("vpolar", rnd, 2, 2, (fv_gaze){0.3f, 0.6f}, &b);
    float *i3 = render("vpolar", grid, 2, 1, (fv_gaze){0.3f, 0.6f}, NULL);
    assert_memory_equal(i1, i2, sizeof(float) * 3 * W * H);
    assert_memory_equal(i1, i3, sizeof(float) * 3 * W * H);
    assert_float_equal(fv_stats_get_count(&a, "rays"), fv_stats_get_count(&b, "rays"), 0.0);
    double sum = 0.0;
    for (int i = 0; i < 3 * W * H; i++) sum += i1[i];
    assert_true(sum > 0.0);
    free(i1), free(i2), free(i3);
}

static double expected_falloff_share(void)
{
    fv_eye_model m;
    fv_eye_model_default(W, H, &m);
    double ppd = fv_eye_px_per_deg(&m), sum = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double e = hypot(x + 0.5 - 0.5 * W, y + 0.5 - 0.5 * H) / ppd;
            sum += fv_acuity_linear(e, 10.0, 20.0, 0.2);
        }
    return sum / (W * H);
}

/* Each method traces what its distribution says: vpolar its grid (39% of the pixels; fewer when
 * off-screen samples are skipped, the default), cartesian the same count, cartesian-full every pixel,
 * linear-falloff the expected survivors, log-polar (W/1.8)(H/1.8). */
static void test_sample_counts(void **st)
{
    (void)st;
    fv_stats s;
    const char *trace[] = {"offscreen=trace", NULL};
    free(render("vpolar", trace, 1, 2, k_centre, &s));
    double grid = fv_stats_get_count(&s, "grid_samples");
    assert_float_equal(fv_stats_get_count(&s, "samples"), grid, 0.0);
    assert_true(fabs(grid / (W * H) - 0.39) < 0.01);
    /* every path: a camera ray, a bounce and a shadow ray per hit: at most four rays */
    assert_true(fv_stats_get_count(&s, "rays") <= 4.0 * grid);
    assert_true(fv_stats_get_count(&s, "rays") >= 2.0 * grid);
    const char *skip[] = {"offscreen=skip", NULL};
    free(render("vpolar", skip, 1, 2, k_centre, &s));
    /* the centre gaze's farthest circles leave the screen: 9% of the samples at 1280x1440; at this
     * size the cells are larger against the screen and the mask, which keeps every cell a screen
     * pixel's lookup can reach (fv_space_onscreen_mask), drops 4% */
    assert_true(fv_stats_get_count(&s, "samples") < 0.98 * grid);
    free(render("vpolar", skip, 1, 2, (fv_gaze){0.0f, 0.0f}, &s));
    assert_true(fv_stats_get_count(&s, "samples") < 0.6 * grid);
    free(render("cartesian", NULL, 1, 2, k_centre, &s));
    assert_true(fabs(fv_stats_get_count(&s, "samples") / grid - 1.0) < 0.01);
    free(render("cartesian-full", NULL, 1, 2, k_centre, &s));
    assert_float_equal(fv_stats_get_count(&s, "samples"), W * H, 0.0);
    free(render("linear-falloff", NULL, 1, 2, k_centre, &s));
    double share = fv_stats_get_count(&s, "samples") / (W * H), expect = expected_falloff_share();
    assert_true(fabs(share - expect) < 0.02);
    assert_true(expect < 0.9);
    free(render("log-polar", NULL, 1, 2, k_centre, &s));
    assert_float_equal(fv_stats_get_count(&s, "samples"), 71.0 * 80.0, 0.0);
}

/* Skipping the off-screen samples changes nothing on the screen: the denoiser ignores those cells
 * in either mode and no screen pixel's lookup reads them (test_vp_space checks the mask), so the
 * images are the same bits, for a centred and an off-centre gaze, over frames with a history. */
static void test_offscreen_skip_same_image(void **st)
{
    (void)st;
    const char *trace[] = {"offscreen=trace", NULL}, *skip[] = {"offscreen=skip", NULL};
    const fv_gaze gazes[2] = {{0.5f, 0.5f}, {0.15f, 0.8f}};
    for (int i = 0; i < 2; i++) {
        fv_stats a, b;
        float *i1 = render("vpolar", trace, 2, 2, gazes[i], &a);
        float *i2 = render("vpolar", skip, 2, 2, gazes[i], &b);
        assert_memory_equal(i1, i2, sizeof(float) * 3 * W * H);
        assert_true(fv_stats_get_count(&b, "samples") < fv_stats_get_count(&a, "samples"));
        free(i1), free(i2);
    }
}

/* With a still camera and gaze the denoiser's history grows and the fovea converges towards the
 * converged one-bounce path tracer (pt with max_depth 2: the same light transport); the denoised
 * 12th frame is much closer than a single noisy frame. */
static void test_converges(void **st)
{
    (void)st;
    const char *ref_kv[] = {"spp=1024", "max_depth=2", NULL};
    float *ref = render("pt", ref_kv, 1, 2, k_centre, NULL);
    const char *raw_kv[] = {"denoise=false", "blur=false", NULL};
    const char *nob_kv[] = {"blur=false", NULL};
    float *raw = render("vpolar", raw_kv, 1, 2, k_centre, NULL);
    float *one = render("vpolar", nob_kv, 1, 2, k_centre, NULL);
    fv_stats s;
    float *many = render("vpolar", nob_kv, 12, 2, k_centre, &s);
    assert_true(fv_stats_get_count(&s, "history_fraction") > 0.9);
    fv_eye_model eye;
    fv_eye_model_default(W, H, &eye);
    uint8_t *labels = malloc(W * H);
    fv_eye_region_labels(&eye, k_centre, labels);
    fv_metric_opts mo;
    fv_metric_opts_default(&mo);
    fv_metric_report r_raw, r_one, r_many;
    fv_error err;
    assert_int_equal(fv_metrics_compare(ref, raw, W, H, labels, &mo, &r_raw, NULL, &err), FV_OK);
    assert_int_equal(fv_metrics_compare(ref, one, W, H, labels, &mo, &r_one, NULL, &err), FV_OK);
    assert_int_equal(fv_metrics_compare(ref, many, W, H, labels, &mo, &r_many, NULL, &err), FV_OK);
    double raw_f = r_raw.region[FV_REGION_FOVEA].mse, one_f = r_one.region[FV_REGION_FOVEA].mse;
    double many_f = r_many.region[FV_REGION_FOVEA].mse;
    print_message("fovea MSE: raw %.5f, denoised 1 frame %.5f, 12 frames %.5f\n", raw_f, one_f, many_f);
    /* Measured: fovea 0.00218 raw, 0.00010 denoised, 0.00008 after 12 frames; periphery 0.00667,
     * 0.00652 (the error there is resolution, not noise), 0.00393 (the jittered samples
     * accumulate: temporal anti-aliasing). */
    double one_p = r_one.region[FV_REGION_PERIPHERY].mse, many_p = r_many.region[FV_REGION_PERIPHERY].mse;
    assert_true(one_f < 0.1 * raw_f);
    assert_true(many_f < one_f);
    assert_true(many_f < 0.0003);
    assert_true(many_p < 0.75 * one_p);
    free(ref), free(raw), free(one), free(many), free(labels);
}

/* Frames [first, n) of vpolar with the parameters kv, a still camera and the gaze gz[i] (with
 * history: every frame after the first has a previous camera, the same); returns the last image
 * (caller frees), the last frame's stats and the lowest history_fraction after the first frame. */
static float *render_gazes(const char *const *kv, const fv_gaze *gz, int n, int first, bool history, fv_stats *stats_out,
                           double *min_history)
{
    fv_error err;
    fv_params *p = fv_test_params(kv);
    fv_technique *t;
    if (fv_technique_create("vpolar", g_scene, p, NULL, &t, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_film *film;
    assert_int_equal(fv_film_create(W, H, FV_AUX_ALL, &film, &err), FV_OK);
    fv_camera cam;
    fv_view_camera(g_view, g_scene, 0.0, W, H, &cam);
    fv_stats stats;
    if (min_history) *min_history = 1.0;
    for (int i = first; i < n; i++) {
        fv_frame fr;
        fv_frame_init(&fr, &cam);
        fr.seed = 5, fr.threads = 2, fr.index = i, fr.gaze = gz[i];
        if (history && i > first) fr.prev_camera = &cam;
        fv_stats_clear(&stats);
        if (fv_technique_render(t, &fr, film, &stats, &err) != FV_OK) fail_msg("frame %d: %s", i, err.msg);
        const double h = fv_stats_get_count(&stats, "history_fraction");
        if (min_history && i > first && h < *min_history) *min_history = h;
    }
    float *img = malloc(sizeof(float) * 3 * W * H);
    memcpy(img, fv_film_color_const(film), sizeof(float) * 3 * W * H);
    if (stats_out) *stats_out = stats;
    fv_film_destroy(film);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return img;
}

/* The map stage keeps its per-pixel coordinates while the gaze stays (from the second frame at
 * one gaze, read from the third): the image read through them is the one computed afresh, and a
 * gaze that moves is mapped afresh. Without the denoiser a frame depends only on its index and
 * gaze, so frame i of a sequence must equal frame i rendered alone. */
static void test_map_keeps_coords_while_gaze_stays(void **st)
{
    (void)st;
    const fv_gaze a = {0.3f, 0.6f}, b = {0.31f, 0.6f};
    const fv_gaze seq[4] = {a, a, a, b};
    const char *nodenoise[] = {"denoise=false", NULL};
    fv_stats s;
    float *kept = render_gazes(nodenoise, seq, 3, 0, false, &s, NULL); /* frame 2: read */
    assert_true(fv_stats_get_count(&s, "map_reused") == 1.0);
    float *fresh = render_gazes(nodenoise, seq, 3, 2, false, &s, NULL);
    assert_true(fv_stats_get_count(&s, "map_reused") == 0.0);
    assert_memory_equal(kept, fresh, sizeof(float) * 3 * W * H);
    free(kept), free(fresh);
    kept = render_gazes(nodenoise, seq, 4, 0, false, &s, NULL); /* frame 3: the gaze moved */
    assert_true(fv_stats_get_count(&s, "map_reused") == 0.0);
    fresh = render_gazes(nodenoise, seq, 4, 3, false, &s, NULL);
    assert_memory_equal(kept, fresh, sizeof(float) * 3 * W * H);
    free(kept), free(fresh);
}

/* The denoiser's history follows the previous frame's gaze: with a still camera and the gaze
 * jumping between the centre and a corner every frame (the space's profile stretches differently
 * for each), each sample's history is looked up in the previous frame's space (the radial table
 * built by that frame's map stage) and found for most samples (measured: 0.82 at least, 0.97 with
 * a still gaze); looked up through this frame's table instead, the columns are off by tens and the
 * consistency tests reject nearly all of it (measured: 0.003). */
static void test_history_follows_gaze(void **st)
{
    (void)st;
    const char *kv[] = {"blur=false", NULL};
    fv_gaze gz[6];
    for (int i = 0; i < 6; i++) gz[i] = i % 2 ? (fv_gaze){0.05f, 0.1f} : (fv_gaze){0.5f, 0.5f};
    double worst;
    free(render_gazes(kv, gz, 6, 0, true, NULL, &worst));
    print_message("gaze jumping every frame: history found for at least %.3f of the samples\n", worst);
    assert_true(worst > 0.6);
}

/* show=space: the grid in the top-left corner, its clipped rows marked; show=density: at least one
 * sample per pixel at the gaze, the reported fovea density, far fewer in the corners. */
static void test_show_modes(void **st)
{
    (void)st;
    const char *sp[] = {"show=space", NULL}, *dn[] = {"show=density", "offscreen=skip", NULL};
    float *img = render("vpolar", sp, 1, 2, k_centre, NULL);
    /* column 0 of Visual-Polar space holds one or two rows: the rows below are clipped */
    assert_float_equal(img[3 * (size_t)(20 * W + 0)], 1e3f, 0.0f);
    assert_true(img[3 * (size_t)(20 * W + 60)] < 1e3f);
    free(img);
    img = render("vpolar", dn, 1, 2, k_centre, NULL);
    fv_eye_model eye;
    fv_eye_model_default(W, H, &eye);
    fv_space_opts o;
    fv_space_opts_default(FV_SPACE_VPOLAR, &o);
    fv_space *s;
    fv_error err;
    assert_int_equal(fv_space_create(&o, W, H, fv_eye_px_per_deg(&eye), &s, &err), FV_OK);
    fv_space_info info;
    fv_space_get_info(s, &info);
    float centre = img[3 * (size_t)(H / 2 * W + W / 2)], corner = img[3 * (size_t)(2 * W + 2)];
    print_message("density: centre %.2f (fovea %.2f), corner %.3f\n", centre, info.fovea_density_centre, corner);
    assert_true(centre >= 1.0f);
    assert_true(fabs(centre / info.fovea_density_centre - 1.0) < 0.15);
    assert_true(corner < 0.25f * centre);
    fv_space_destroy(s);
    free(img);
}

static void test_stereo(void **st)
{
    (void)st;
    fv_error err;
    fv_params *p;
    assert_int_equal(fv_params_create(&p, &err), FV_OK);
    fv_technique *t;
    assert_int_equal(fv_technique_create("vpolar", g_scene, p, NULL, &t, &err), FV_OK);
    fv_film *fl, *fr_;
    assert_int_equal(fv_film_create(W, H, 0, &fl, &err), FV_OK);
    assert_int_equal(fv_film_create(W, H, 0, &fr_, &err), FV_OK);
    fv_camera c, l, r;
    fv_view_camera(g_view, g_scene, 0.0, W, H, &c);
    fv_camera_stereo(&c, 60.0f, &l, &r);
    fv_frame fr;
    fv_frame_init(&fr, NULL);
    fr.camera = &l;
    fr.eye_count = 2;
    fr.gaze = (fv_gaze){0.45f, 0.5f};
    fv_stats stats;
    fv_stats_clear(&stats);
    assert_int_equal(fv_technique_render(t, &fr, fl, &stats, &err), FV_OK);
    fr.eye = 1;
    fr.camera = &r;
    fr.left_camera = &l;
    fr.gaze = (fv_gaze){0.55f, 0.5f};
    assert_int_equal(fv_technique_render(t, &fr, fr_, &stats, &err), FV_OK);
    double sl = 0, sr = 0;
    for (int i = 0; i < 3 * W * H; i++) sl += fv_film_color(fl)[i], sr += fv_film_color(fr_)[i];
    assert_true(sl > 0.0 && sr > 0.0);
    assert_true(fabs(sl / sr - 1.0) < 0.2);
    fv_film_destroy(fl), fv_film_destroy(fr_);
    fv_technique_destroy(t);
    fv_params_destroy(p);
}

static void expect_refused(const char *method, const char *kv, const char *needle)
{
    fv_error err;
    const char *list[] = {kv, NULL};
    fv_params *p = fv_test_params(list);
    fv_technique *t = NULL;
    char what[128];
    snprintf(what, sizeof what, "%s %s", method, kv);
    fv_test_expect_fail(fv_technique_create(method, g_scene, p, NULL, &t, &err), &err, FV_ERR_INVALID, needle, what);
    assert_null(t);
    fv_params_destroy(p);
}

static void test_bad_params(void **st)
{
    (void)st;
    expect_refused("vpolar", "reduction=0", "reduction");
    expect_refused("vpolar", "reduction=1", "reduction");
    expect_refused("vpolar", "reduction=1.5", "reduction");
    expect_refused("vpolar", "reduction=-0.2", "reduction");
    expect_refused("vpolar", "reduction=nan", "reduction");
    expect_refused("vpolar", "blur_sigma=-1", "blur_sigma");
    expect_refused("vpolar", "fit_degree=1", "fit_degree");
    expect_refused("vpolar", "order=spiral", "order");
    expect_refused("vpolar", "blur_ramp_deg=3", "blur_ramp_deg");
    expect_refused("vpolar", "svgf_alpha=0", "alpha");
    expect_refused("vpolar", "sigma_lum=-4", "sigma_lum");
    expect_refused("vpolar", "photons=5", "photons");
    expect_refused("vpolar", "periphery_deg=-1", "periphery_deg");
    expect_refused("vpolar", "periphery_deg=200", "periphery_deg");
    expect_refused("vpolar", "periphery_deg=nan", "periphery_deg");
    expect_refused("vpolar", "periphery_passes=-1", "periphery_passes");
    expect_refused("vpolar", "periphery_passes=11", "periphery_passes");
    expect_refused("cartesian", "periphery_deg=20", "periphery_deg");
    expect_refused("cartesian", "reduction=1", "reduction");
    expect_refused("log-polar", "sigma=1", "sigma");
    expect_refused("log-polar", "sigma=-2", "sigma");
    expect_refused("log-polar", "alpha=0", "alpha");
    expect_refused("linear-falloff", "falloff_probability=0", "falloff_probability");
    expect_refused("linear-falloff", "falloff_periphery_deg=5", "falloff_periphery_deg");
    expect_refused("cartesian-full", "reduction=0.5", "reduction");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_order_and_threads), cmocka_unit_test(test_sample_counts),
        cmocka_unit_test(test_history_follows_gaze), cmocka_unit_test(test_widened_is_cartesian_full),
        cmocka_unit_test(test_offscreen_skip_same_image), cmocka_unit_test(test_converges),
        cmocka_unit_test(test_map_keeps_coords_while_gaze_stays), cmocka_unit_test(test_show_modes),        cmocka_unit_test(test_stereo),        cmocka_unit_test(test_bad_params),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
