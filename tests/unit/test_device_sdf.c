/* The sphere-tracing family on the portable backend (technique/sdf/ksdf_pixel.h and kpyr.h, through
 * the kernels of sdf_kernels.h, run a cell at a time on the CPU's threads, the code CUDA runs)
 * against the CPU pipeline
 * (technique/sdf/sdf_pipeline.c: eight rays at a time through the 8-wide field, shading in batches), on
 * the three sphere-tracing scenes: `sdf-gt` and `sdf-relaxed` one frame each; `ipr` one frame with
 * and without shadow_reuse and the min filter, at 3 and 4 levels; `fipr` over a stereo sequence
 * whose gaze moves, so the mask changes and the history kept per eye is refreshed every 1, 2 or 4
 * frames and read in between, with shadow_reuse and pass 5's blur in one of them.
 *
 * The bound is equality, bit for bit, in the colour, in every auxiliary buffer and in every
 * counter. Measured, not assumed: the first renders of the two backends agreed exactly on all six
 * method/scene pairs (0 differing pixels, max |difference| 0, the same steps, shadow steps and
 * normal evaluations). That is what the design gives: both backends step every ray with the same
 * function (technique/sdf/kmarch.h's fv_kmarch_advance), shade every hit with the same steps in the
 * same order (technique/sdf/ksdf_shade.h), and evaluate the world's field with the scalar build of
 * sdf/kernel.h, whose result the CPU's 8-wide lanes equal bit for bit (test_sdf_many checks that
 * with moving objects too); nothing is compiled with FMA contraction. So any difference here is a
 * divergence of the two paths, not rounding, and the test allows none. The same holds for ipr and
 * fipr, whose per-cell steps (start, Sobel, mask, refresh, reconstruction, agreed visibility) the
 * CPU pipeline calls too, and whose counters (each level's rays and steps, fipr's mask, edge and
 * refreshed counts) must match as well. (CUDA against portable,
 * tests/gpu/test_gpu_sdf.c, needs a tolerance: the GPU's powf differs in the last bits.)
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

static fv_film *render(const char *method, const char *params, const fv_scene *s, const fv_camera *cam, fv_stats *stats)
{
    fv_params *p = fv_test_params_str(params);
    fv_technique *t = NULL;
    fv_error err;
    if (fv_technique_create(method, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s %s: %s", method, params, err.msg);
    fv_film *film = NULL;
    if (fv_film_create(cam->width, cam->height, AUX, &film, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_frame f;
    fv_frame_init(&f, cam);
    f.seed = 3;
    fv_test_render_frames(t, &f, 1, film, stats);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return film;
}

static size_t differing(const float *a, const float *b, size_t n, double *max_abs)
{
    size_t d = 0;
    for (size_t i = 0; i < n; i++) {
        if (memcmp(&a[i], &b[i], sizeof(float)) != 0) d++;
        double e = fabs((double)a[i] - (double)b[i]);
        if (e > *max_abs) *max_abs = e; /* inf - inf: NaN, not counted; the bits above are */
    }
    return d;
}

static void compare(const char *scene, const char *method, int w, int h, int spp)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, w, h, &cam);
    char pc[64], pp[64];
    snprintf(pc, sizeof pc, "spp=%d device=cpu", spp);
    snprintf(pp, sizeof pp, "spp=%d device=portable", spp);
    fv_stats sc, sp;
    fv_film *a = render(method, pc, s, &cam, &sc), *b = render(method, pp, s, &cam, &sp);
    const size_t n = (size_t)w * h;
    double max_abs = 0.0, sum = 0.0;
    const float *ca = fv_film_color_const(a);
    for (size_t i = 0; i < 3 * n; i++) sum += ca[i];
    size_t dc = differing(ca, fv_film_color_const(b), 3 * n, &max_abs);
    size_t dd = differing(fv_film_depth(a), fv_film_depth(b), n, &max_abs);
    size_t dn = differing(fv_film_normal(a), fv_film_normal(b), 3 * n, &max_abs);
    size_t da = differing(fv_film_albedo(a), fv_film_albedo(b), 3 * n, &max_abs);
    size_t dp = differing(fv_film_position(a), fv_film_position(b), 3 * n, &max_abs);
    size_t di = memcmp(fv_film_id(a), fv_film_id(b), n * sizeof(uint32_t)) != 0;
    printf("%s %s %dx%d spp=%d: mean %.5f, %zu colour values differ (max |difference| %g), aux %zu/%zu/%zu/%zu/%zu, steps %g / %g\n", method,
           scene, w, h, spp, sum / (3.0 * (double)n), dc, max_abs, dd, dn, da, dp, di, fv_stats_get_count(&sc, "steps"),
           fv_stats_get_count(&sp, "steps"));
    if (!(sum > 0.0)) fail_msg("%s %s rendered black on the CPU", method, scene);
    if (dc || dd || dn || da || dp || di) fail_msg("%s %s: the portable backend's image differs from the CPU's", method, scene);
    static const char *const keys[] = {"rays", "steps", "shadow_rays", "shadow_steps", "normal_evals", "exhausted_rays", "samples", "nan_samples"};
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
        if (fv_stats_get_count(&sc, keys[k]) != fv_stats_get_count(&sp, keys[k]))
            fail_msg("%s %s: counter %s: cpu %g, portable %g", method, scene, keys[k], fv_stats_get_count(&sc, keys[k]),
                     fv_stats_get_count(&sp, keys[k]));
    if (!(fv_stats_get_count(&sp, "steps") > fv_stats_get_count(&sp, "rays"))) fail_msg("%s %s: no marching counted", method, scene);
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* The counters both backends report for a pyramid method. */
static void compare_counters(const char *what, const fv_stats *sc, const fv_stats *sp, int levels, bool fipr)
{
    char keys[32][32];
    int n = 0;
    static const char *const base[] = {"rays", "steps", "shadow_rays", "shadow_steps", "normal_evals", "exhausted_rays", "samples", "nan_samples"};
    for (size_t k = 0; k < sizeof base / sizeof base[0]; k++) snprintf(keys[n++], sizeof keys[0], "%s", base[k]);
    for (int k = 0; k < levels; k++) {
        snprintf(keys[n++], sizeof keys[0], "rays_level%d", k);
        snprintf(keys[n++], sizeof keys[0], "steps_level%d", k);
    }
    if (fipr) {
        snprintf(keys[n++], sizeof keys[0], "mask_pixels");
        snprintf(keys[n++], sizeof keys[0], "edge_pixels");
        snprintf(keys[n++], sizeof keys[0], "refreshed_pixels");
    }
    for (int k = 0; k < n; k++) {
        if (fv_stats_get_count(sc, keys[k]) != fv_stats_get_count(sp, keys[k]))
            fail_msg("%s: counter %s: cpu %g, portable %g", what, keys[k], fv_stats_get_count(sc, keys[k]), fv_stats_get_count(sp, keys[k]));
    }
}

/* ipr or fipr (params besides the device) on both backends over `frames` frames of `eyes` eyes
 * (1 or 2), the gaze moving from frame to frame; every frame's film and counters must be equal.
 * Returns the last frame's portable stats in *last. */
static void compare_pyramid(const char *scene, const char *method, const char *params, int w, int h, int frames, int eyes, fv_stats *last)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, w, h, &cam);
    char pc[160], pp[160];
    snprintf(pc, sizeof pc, "%s device=cpu", params);
    snprintf(pp, sizeof pp, "%s device=portable", params);
    fv_technique *tc = fv_test_technique(method, pc, s), *tp = fv_test_technique(method, pp, s);
    fv_film *a = NULL, *b = NULL;
    fv_error err;
    if (fv_film_create(w, h, AUX, &a, &err) != FV_OK || fv_film_create(w, h, AUX, &b, &err) != FV_OK) fail_msg("%s", err.msg);
    const size_t n = (size_t)w * h;
    const bool fipr = strcmp(method, "fipr") == 0;
    int levels = 3;
    const char *lv = strstr(params, "levels=");
    if (lv) levels = atoi(lv + 7);
    for (int i = 0; i < frames; i++)
        for (int e = 0; e < eyes; e++) {
            fv_frame f;
            fv_frame_init(&f, &cam);
            f.seed = 3;
            f.index = i;
            f.eye = e;
            f.eye_count = eyes;
            f.prev_camera = i > 0 ? &cam : NULL;
            /* a gaze that wanders, so the mask and the pixels it reconstructs change */
            f.gaze.x = 0.3f + 0.1f * (float)i + 0.05f * (float)e;
            f.gaze.y = 0.6f - 0.07f * (float)i;
            fv_stats sc, sp;
            fv_test_render_fresh(tc, &f, a, &sc);
            fv_test_render_fresh(tp, &f, b, &sp);
            double max_abs = 0.0, sum = 0.0;
            const float *ca = fv_film_color_const(a);
            for (size_t k = 0; k < 3 * n; k++) sum += ca[k];
            size_t dc = differing(ca, fv_film_color_const(b), 3 * n, &max_abs);
            size_t dd = differing(fv_film_depth(a), fv_film_depth(b), n, &max_abs);
            size_t dn = differing(fv_film_normal(a), fv_film_normal(b), 3 * n, &max_abs);
            size_t da = differing(fv_film_albedo(a), fv_film_albedo(b), 3 * n, &max_abs);
            size_t dp = differing(fv_film_position(a), fv_film_position(b), 3 * n, &max_abs);
            size_t di = memcmp(fv_film_id(a), fv_film_id(b), n * sizeof(uint32_t)) != 0;
            char what[256];
            snprintf(what, sizeof what, "%s %s [%s] %dx%d frame %d eye %d", method, scene, params, w, h, i, e);
            if (i == frames - 1 || dc || dd || dn || da || dp || di)
                printf("%s: mean %.5f, %zu colour values differ (max |difference| %g), aux %zu/%zu/%zu/%zu/%zu, steps %g / %g%s%g\n", what,
                       sum / (3.0 * (double)n), dc, max_abs, dd, dn, da, dp, di, fv_stats_get_count(&sc, "steps"),
                       fv_stats_get_count(&sp, "steps"), fipr ? ", mask pixels " : ", level-0 rays ",
                       fv_stats_get_count(&sp, fipr ? "mask_pixels" : "rays_level0"));
            if (!(sum > 0.0)) fail_msg("%s rendered black on the CPU", what);
            if (dc || dd || dn || da || dp || di) fail_msg("%s: the portable backend's image differs from the CPU's", what);
            compare_counters(what, &sc, &sp, levels, fipr);
            if (!(fv_stats_get_count(&sp, "rays_level0") > 0)) fail_msg("%s: the tip traced nothing", what);
            if (last) *last = sp;
        }
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_technique_destroy(tc);
    fv_technique_destroy(tp);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_ipr(void **st)
{
    (void)st;
    compare_pyramid("sdf-primitives", "ipr", "spp=4", 64, 48, 1, 1, NULL);
    compare_pyramid("sdf-columns", "ipr", "spp=1 levels=4 shadow_reuse=true", 56, 40, 1, 1, NULL);
    compare_pyramid("sdf-temple", "ipr", "spp=16 shadow_reuse=true", 32, 24, 1, 1, NULL);
    compare_pyramid("sdf-temple", "ipr", "spp=4 min_filter=false relax=1.5", 40, 30, 1, 1, NULL);
}

/* fipr over sequences: the history is refreshed every frame, every other frame or every fourth,
 * per eye; in between the pixels outside the mask read colours shaded in earlier frames. */
static void test_fipr(void **st)
{
    (void)st;
    fv_stats last;
    compare_pyramid("sdf-primitives", "fipr", "spp=4 refresh=1", 64, 48, 3, 1, &last);
    compare_pyramid("sdf-columns", "fipr", "spp=1 refresh=2 levels=4", 64, 48, 4, 2, &last);
    /* refresh 4: the last frame shades only a quarter of the middle level, so most of the
     * reconstructed pixels read colours kept from earlier frames */
    compare_pyramid("sdf-temple", "fipr", "spp=4 refresh=4 shadow_reuse=true blur=true", 48, 36, 5, 2, &last);
    const double mid = (double)(48 * 2 / 2) * (36 * 2 / 2);
    if (!(fv_stats_get_count(&last, "refreshed_pixels") < 0.3 * mid)) fail_msg("refresh=4 refreshed %g of %g middle rays", fv_stats_get_count(&last, "refreshed_pixels"), mid);
    if (!(fv_stats_get_count(&last, "mask_pixels") < 0.9 * 48 * 36)) fail_msg("the mask covers %g of %d pixels: nothing reconstructed", fv_stats_get_count(&last, "mask_pixels"), 48 * 36);
}

static void test_primitives(void **st)
{
    (void)st;
    compare("sdf-primitives", "sdf-gt", 64, 48, 4);
    compare("sdf-primitives", "sdf-relaxed", 64, 48, 4);
}

static void test_columns(void **st)
{
    (void)st;
    compare("sdf-columns", "sdf-gt", 56, 40, 1);
    compare("sdf-columns", "sdf-relaxed", 56, 40, 1);
}

static void test_temple(void **st)
{
    (void)st;
    compare("sdf-temple", "sdf-gt", 32, 24, 16);
    compare("sdf-temple", "sdf-relaxed", 32, 24, 16);
}

/* Over-relaxation with another factor, shadows off, an ambient term and a low step limit that
 * exhausts rays: every branch of the step rule and the shading on both backends. */
static void test_options(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    assert_int_equal(fv_test_load("sdf-temple", &s, &v), 0);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 40, 30, &cam);
    const char *opts[] = {"relax=1.9 max_steps=12", "shadows=false ambient=0.3", "hit=2 max_steps=40"};
    for (int i = 0; i < 3; i++) {
        char pc[96], pp[96];
        snprintf(pc, sizeof pc, "%s device=cpu", opts[i]);
        snprintf(pp, sizeof pp, "%s device=portable", opts[i]);
        fv_stats sc, sp;
        fv_film *a = render("sdf-relaxed", pc, s, &cam, &sc), *b = render("sdf-relaxed", pp, s, &cam, &sp);
        if (memcmp(fv_film_color_const(a), fv_film_color_const(b), (size_t)3 * 40 * 30 * sizeof(float)) != 0)
            fail_msg("sdf-relaxed %s: portable differs from cpu", opts[i]);
        if (fv_stats_get_count(&sc, "exhausted_rays") != fv_stats_get_count(&sp, "exhausted_rays"))
            fail_msg("sdf-relaxed %s: exhausted rays differ", opts[i]);
        if (i == 0 && !(fv_stats_get_count(&sp, "exhausted_rays") > 0)) fail_msg("max_steps=12 exhausted no ray");
        if (i == 1 && fv_stats_get_count(&sp, "shadow_rays") != 0) fail_msg("shadows=false traced shadow rays");
        fv_film_destroy(a);
        fv_film_destroy(b);
    }
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* Colour NaN first, so a pixel a render leaves unwritten cannot pass. */
static void poison(fv_film *film)
{
    fv_film_clear(film);
    float *col = fv_film_color(film);
    for (size_t k = 0, m = (size_t)3 * fv_film_width(film) * fv_film_height(film); k < m; k++) col[k] = NAN;
}

static size_t film_diff(fv_film *a, fv_film *b)
{
    const size_t n = (size_t)fv_film_width(a) * fv_film_height(a);
    double max_abs = 0.0;
    return differing(fv_film_color_const(a), fv_film_color_const(b), 3 * n, &max_abs) +
           differing(fv_film_depth(a), fv_film_depth(b), n, &max_abs) + differing(fv_film_normal(a), fv_film_normal(b), 3 * n, &max_abs) +
           differing(fv_film_albedo(a), fv_film_albedo(b), 3 * n, &max_abs) +
           differing(fv_film_position(a), fv_film_position(b), 3 * n, &max_abs) +
           (memcmp(fv_film_id(a), fv_film_id(b), n * sizeof(uint32_t)) != 0);
}

/* A stereo sequence on the portable backend, each frame as a pair (fv_technique_render_pair: the
 * world built once, both eyes' passes) and as two per-eye calls on another instance, the scene's
 * time moving 0.1 s a frame: every eye's film and every counter equal, bit for bit, frame after
 * frame (fipr's history per eye carried through both paths), and the pair's films equal to the CPU
 * pipeline's (which builds its world afresh each frame). The world is built once for a scene
 * where nothing moves and once a frame where something does (sdf-columns' lights), whichever path
 * asks for it. */
static void compare_pair(const char *scene, const char *method, const char *params, int w, int h, int frames, bool moves)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera centre, cam[2];
    fv_view_camera(v, s, 0.0, w, h, &centre);
    fv_camera_stereo(&centre, 0.08f, &cam[0], &cam[1]);
    char pp[160], pc[160];
    snprintf(pp, sizeof pp, "%s device=portable", params);
    snprintf(pc, sizeof pc, "%s device=cpu", params);
    fv_technique *each = fv_test_technique(method, pp, s), *pair = fv_test_technique(method, pp, s), *cpu = fv_test_technique(method, pc, s);
    fv_film *a[2], *b[2], *c[2];
    fv_error err;
    for (int e = 0; e < 2; e++)
        if (fv_film_create(w, h, AUX, &a[e], &err) != FV_OK || fv_film_create(w, h, AUX, &b[e], &err) != FV_OK ||
            fv_film_create(w, h, AUX, &c[e], &err) != FV_OK)
            fail_msg("%s", err.msg);
    double builds[2] = {0.0, 0.0};
    for (int i = 0; i < frames; i++) {
        const double time = 0.1 * i;
        if (fv_scene_set_time(s, time, &err) != FV_OK) fail_msg("%s", err.msg);
        fv_frame f[2];
        fv_test_stereo_frames(cam, time, i, 5, i > 0, f);
        for (int e = 0; e < 2; e++) {
            f[e].left_camera = e == 1 ? &cam[0] : NULL;
            f[e].gaze.x = 0.35f + 0.12f * (float)i + 0.04f * (float)e;
            f[e].gaze.y = 0.55f - 0.08f * (float)i;
            poison(a[e]);
            poison(b[e]);
            poison(c[e]);
        }
        fv_stats sa, sb, sc;
        fv_stats_clear(&sa);
        fv_stats_clear(&sb);
        fv_stats_clear(&sc);
        for (int e = 0; e < 2; e++)
            if (fv_technique_render(each, &f[e], a[e], &sa, &err) != FV_OK || fv_technique_render(cpu, &f[e], c[e], &sc, &err) != FV_OK)
                fail_msg("%s: frame %d eye %d: %s", method, i, e, err.msg);
        if (fv_technique_render_pair(pair, f, b, &sb, &err) != FV_OK) fail_msg("%s: pair %d: %s", method, i, err.msg);
        char what[256];
        snprintf(what, sizeof what, "%s %s [%s] %dx%d frame %d", method, scene, params, w, h, i);
        for (int e = 0; e < 2; e++) {
            size_t d = film_diff(a[e], b[e]);
            if (d) fail_msg("%s eye %d: the pair's film differs from the per-eye call's in %zu values", what, e, d);
            if ((d = film_diff(c[e], b[e]))) fail_msg("%s eye %d: the pair's film differs from the CPU's in %zu values", what, e, d);
        }
        if (!(fv_stats_get_count(&sa, "rays") > 0)) fail_msg("%s: nothing traced", what);
        /* every counter of the per-eye calls but the parallel regions, and the CPU's counters */
        if (sa.n_counters != sb.n_counters) fail_msg("%s: %d counters per eye, %d for the pair", what, sa.n_counters, sb.n_counters);
        for (int k = 0; k < sa.n_counters; k++) {
            const char *key = sa.counter[k].name;
            if (strcmp(key, "parallel_regions") == 0) continue;
            if (sa.counter[k].value != fv_stats_get_count(&sb, key))
                fail_msg("%s: counter %s: per eye %g, pair %g", what, key, sa.counter[k].value, fv_stats_get_count(&sb, key));
        }
        compare_counters(what, &sc, &sb, strcmp(method, "ipr") == 0 || strcmp(method, "fipr") == 0 ? 3 : 1, strcmp(method, "fipr") == 0);
        builds[0] += fv_stats_get_count(&sa, "world_builds");
        builds[1] += fv_stats_get_count(&sb, "world_builds");
        if (i == frames - 1)
            printf("%s: both eyes equal (and the CPU's), %g rays, world built %g times per eye, %g for the pairs\n", what,
                   fv_stats_get_count(&sb, "rays"), builds[0], builds[1]);
    }
    const double want = moves ? frames : 1;
    if (builds[0] != want || builds[1] != want)
        fail_msg("%s %s: the world built %g (per eye) and %g (pairs) times over %d frames, expected %g", method, scene, builds[0], builds[1], frames, want);
    for (int e = 0; e < 2; e++) {
        fv_film_destroy(a[e]);
        fv_film_destroy(b[e]);
        fv_film_destroy(c[e]);
    }
    fv_technique_destroy(each);
    fv_technique_destroy(pair);
    fv_technique_destroy(cpu);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_pair(void **st)
{
    (void)st;
    compare_pair("sdf-primitives", "sdf-gt", "spp=4", 48, 36, 2, false);
    compare_pair("sdf-columns", "sdf-relaxed", "spp=1", 40, 30, 3, true);
    compare_pair("sdf-temple", "ipr", "spp=4 shadow_reuse=true", 40, 30, 2, false);
    /* fipr: each eye's history carried over 3 and 5 frames, refreshed every other and every
     * fourth, under moving lights and with pass 5 */
    compare_pair("sdf-columns", "fipr", "spp=1 refresh=2", 48, 36, 3, true);
    compare_pair("sdf-temple", "fipr", "spp=4 refresh=4 shadow_reuse=true blur=true", 40, 30, 5, false);
}

/* fv_technique_render_pair refuses frames that are not one stereo frame's eyes, naming what. */
static void test_pair_refusals(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    assert_int_equal(fv_test_load("sdf-primitives", &s, &v), 0);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 16, 12, &cam);
    fv_technique *t = fv_test_technique("sdf-gt", "device=portable", s);
    fv_film *films[2];
    fv_error err;
    for (int e = 0; e < 2; e++) assert_int_equal(fv_film_create(16, 12, 0, &films[e], &err), FV_OK);
    fv_frame f[2];
    for (int e = 0; e < 2; e++) {
        fv_frame_init(&f[e], &cam);
        f[e].eye = e;
        f[e].eye_count = 2;
    }
    fv_stats stats;
    fv_stats_clear(&stats);
    assert_int_equal(fv_technique_render_pair(t, f, films, &stats, &err), FV_OK);
    f[1].eye = 0;
    fv_test_expect_fail(fv_technique_render_pair(t, f, films, &stats, &err), &err, FV_ERR_INVALID,
                        "render: a stereo pair's frame 1 is eye 0 of 2 (expected eye 1 of 2)", "two left eyes");
    f[1].eye = 1;
    f[1].index = 1;
    fv_test_expect_fail(fv_technique_render_pair(t, f, films, &stats, &err), &err, FV_ERR_INVALID,
                        "render: a stereo pair's eyes differ in frame index (0, 1) or time (0, 0)", "two frames");
    f[1].index = 0;
    f[0].eye_count = 1;
    fv_test_expect_fail(fv_technique_render_pair(t, f, films, &stats, &err), &err, FV_ERR_INVALID,
                        "render: a stereo pair's frame 0 is eye 0 of 1 (expected eye 0 of 2)", "a mono frame");
    for (int e = 0; e < 2; e++) fv_film_destroy(films[e]);
    fv_technique_destroy(t);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* What the device backends refuse: diagnostics, and methods without a device form. */
static void test_refusals(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    assert_int_equal(fv_test_load("sdf-primitives", &s, &v), 0);
    const struct {
        const char *method, *params, *needle;
    } cases[] = {
        {"sdf-gt", "device=portable show=steps", "parameter show=steps: only the cpu device draws diagnostics (device portable renders the image)"},
        {"fipr", "device=portable show=mask", "parameter show=mask: only the cpu device draws diagnostics (device portable renders the image)"},
        {"ipr", "device=portable show=level", "parameter show=level: only the cpu device draws diagnostics (device portable renders the image)"},
        {"fpm", "device=portable", "method 'fpm' does not run on device portable (methods that do: pt, vpolar, cartesian, cartesian-full, linear-falloff, log-polar, sdf-gt, sdf-relaxed, ipr, fipr)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) fv_test_expect_refusal(cases[i].method, cases[i].params, s, cases[i].needle);
    /* CUDA: refused where it cannot run (this build or this machine), created where it can. */
    fv_params *p = fv_test_params_str("device=cuda");
    fv_technique *t = NULL;
    fv_error err;
    bool can = fv_device_available(FV_DEVICE_CUDA, NULL, 0);
    fv_status got = fv_technique_create("sdf-gt", s, p, NULL, &t, &err);
    if (can) {
        assert_int_equal(got, FV_OK);
    } else {
        assert_int_equal(got, FV_ERR_INVALID);
        if (!strstr(err.msg, "built without CUDA") && !strstr(err.msg, "no CUDA device")) fail_msg("refusal '%s' names no cause", err.msg);
    }
    fv_technique_destroy(t);
    fv_params_destroy(p);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_primitives), cmocka_unit_test(test_columns), cmocka_unit_test(test_temple),
                                       cmocka_unit_test(test_options), cmocka_unit_test(test_ipr),
                                       cmocka_unit_test(test_fipr), cmocka_unit_test(test_pair), cmocka_unit_test(test_pair_refusals),
                                       cmocka_unit_test(test_refusals)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
