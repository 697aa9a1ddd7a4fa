/* The eye model drawn over images (gaze/overlay.h) and where the tool draws it: the marks sit at
 * the radii fv_eye_fovea_radius_px / fv_eye_transition_radius_px around the gaze; `fovea render
 * --overlay` puts them in the PNG where the eye model of the render puts the fovea, and changes
 * nothing else; each eye of a stereo pair gets its own gaze; `fovea compare --heatmap-max` gives
 * two heat maps one scale, with the colour bar below. The tool is run as a user runs it and its
 * files read back with the library's image reader. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>
#include "film/colormap.h"
#include "fovea/fovea.h"
#include "gaze/overlay.h"

/* ---- the shapes ---- */

static void test_marks(void **st)
{
    (void)st;
    fv_eye_model m;
    fv_eye_model_default(256, 144, &m);
    const double rf = fv_eye_fovea_radius_px(&m), rt = fv_eye_transition_radius_px(&m);
    assert_true(rf > 10 && rt > rf + 5);
    const fv_gaze g = {0.25f, 0.5f}; /* (64, 72) */
    fv_overlay_shape s;
    fv_overlay_shape_of(&m, g, 0.0, 0.0, 1.0, 1, &s);
    assert_float_equal(s.cx, 64.0, 1e-9);
    assert_float_equal(s.cy, 72.0, 1e-9);
    int x0, y0, x1, y1;
    fv_overlay_bounds(&s, &x0, &y0, &x1, &y1);
    int counts[FV_MARK_COUNT] = {0};
    for (int y = -100; y < 300; y++)
        for (int x = -100; x < 300; x++) {
            fv_overlay_mark k = fv_overlay_mark_at(&s, x, y);
            counts[k]++;
            if (k == FV_MARK_NONE) continue;
            /* nothing marked outside the bounds */
            assert_true(x >= x0 && x <= x1 && y >= y0 && y <= y1);
            const double d = hypot(x + 0.5 - 64.0, y + 0.5 - 72.0);
            if (k == FV_MARK_FOVEA) assert_true(fabs(d - rf) <= 1.0);
            if (k == FV_MARK_TRANSITION) assert_true(fabs(d - rt) <= 1.0);
            if (k == FV_MARK_GAZE) assert_true((y == 72 && abs(x - 64) >= 2 && abs(x - 64) <= 6) || (x == 64 && abs(y - 72) >= 2 && abs(y - 72) <= 6));
        }
    /* a ring 2 px wide has about 2 x 2 pi r pixels; the cross 4 arms of 5 */
    assert_true(fabs(counts[FV_MARK_FOVEA] - 4.0 * M_PI * rf) < 0.1 * 4.0 * M_PI * rf);
    assert_true(fabs(counts[FV_MARK_TRANSITION] - 4.0 * M_PI * rt) < 0.1 * 4.0 * M_PI * rt);
    assert_int_equal(counts[FV_MARK_GAZE], 20);
    /* the gaze pixel itself and the pixels right inside and outside a ring are unmarked */
    assert_int_equal(fv_overlay_mark_at(&s, 64, 72), FV_MARK_NONE);
    assert_int_equal(fv_overlay_mark_at(&s, 64 + (int)floor(rf) - 2, 72 - 1), FV_MARK_NONE);
    assert_int_equal(fv_overlay_mark_at(&s, 64 + (int)ceil(rf) + 2, 72 - 1), FV_MARK_NONE);
    /* on a panel twice as large, offset by (10, 20): the same rings, scaled */
    fv_overlay_shape_of(&m, g, 10.0, 20.0, 2.0, 1, &s);
    assert_float_equal(s.cx, 138.0, 1e-9);
    assert_float_equal(s.r_fovea, 2.0 * rf, 1e-9);
    /* the palettes: the viewer's colours over images, none of the ramp's over heat maps */
    uint8_t c[3];
    fv_overlay_color(FV_OVERLAY_ON_IMAGE, FV_MARK_FOVEA, c);
    assert_true(c[0] == 255 && c[1] == 0 && c[2] == 255);
    fv_overlay_color(FV_OVERLAY_ON_HEATMAP, FV_MARK_FOVEA, c);
    assert_true(c[0] == 0 && c[1] == 255 && c[2] == 255);
    assert_int_equal(fv_overlay_line_width(320, 180), 1);
    assert_int_equal(fv_overlay_line_width(1920, 1080), 3);
}

/* ---- through the tool ---- */

static char g_dir[64];

static int run(const char *args)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s' %s >/dev/null 2>'%s/err'", FOVEA_CLI, args, g_dir);
    int rc = system(cmd);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

static fv_image read_png(const char *name)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    fv_image img = {0};
    fv_error err;
    if (fv_image_read(path, &img, &err) != FV_OK) fail_msg("%s", err.msg);
    return img;
}

/* The 8-bit colour of pixel (x, y), as the PNG holds it. */
static void bytes_at(const fv_image *img, int x, int y, int out[3])
{
    for (int k = 0; k < 3; k++) out[k] = (int)lrintf(255.0f * fv_srgb_encode(img->rgb[3 * ((size_t)y * img->width + x) + k]));
}

static bool is(const fv_image *img, int x, int y, int r, int g, int b)
{
    int c[3];
    bytes_at(img, x, y, c);
    return c[0] == r && c[1] == g && c[2] == b;
}

/* The eye model `fovea render cornell --size WxH` gives its frames: the driver's. */
static fv_eye_model render_eye_model(int w, int h)
{
    fv_scene *scene = NULL;
    fv_view *view = NULL;
    fv_driver *d = NULL;
    fv_error err;
    if (fv_scene_open("cornell", NULL, &scene, &view, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = w, o.height = h;
    if (fv_driver_create(scene, view, &o, &d, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_eye_model m = *fv_driver_eye_model(d);
    fv_driver_destroy(d);
    fv_scene_destroy(scene);
    fv_view_destroy(view);
    return m;
}

/* Checks that `over` is `bare` with the rings and cross of m around gaze g: magenta at the foveal
 * radius, cyan at the transition radius, yellow on the cross, everything away from them
 * unchanged. Returns how many pixels were checked to be magenta. */
static int check_overlay(const fv_image *over, const fv_image *bare, const fv_eye_model *m, fv_gaze g)
{
    const int w = over->width, h = over->height;
    const double rf = fv_eye_fovea_radius_px(m), rt = fv_eye_transition_radius_px(m);
    const double gx = g.x * w, gy = g.y * h;
    const int px = (int)floor(gx), py = (int)floor(gy);
    int magenta = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const double d = hypot(x + 0.5 - gx, y + 0.5 - gy);
            const bool near_cross = abs(x - px) <= 7 && abs(y - py) <= 7;
            if (near_cross) continue;
            if (fabs(d - rf) <= 0.5) {
                if (!is(over, x, y, 255, 0, 255)) fail_msg("pixel (%d, %d), %.2f px from the gaze (r_f %.2f), is not magenta", x, y, d, rf);
                magenta++;
            } else if (fabs(d - rt) <= 0.5) {
                if (!is(over, x, y, 0, 255, 255)) fail_msg("pixel (%d, %d), %.2f px from the gaze (r_t %.2f), is not cyan", x, y, d, rt);
            } else if (fabs(d - rf) > 1.5 && fabs(d - rt) > 1.5) {
                int a[3], b[3];
                bytes_at(over, x, y, a);
                bytes_at(bare, x, y, b);
                if (a[0] != b[0] || a[1] != b[1] || a[2] != b[2])
                    fail_msg("pixel (%d, %d), %.2f px from the gaze, away from the rings (%.2f, %.2f), differs from the render without --overlay",
                             x, y, d, rf, rt);
            }
        }
    /* the cross: yellow 4 px right of and below the gaze pixel, the gaze pixel itself the render's */
    assert_true(is(over, px + 4, py, 255, 255, 0));
    assert_true(is(over, px, py + 4, 255, 255, 0));
    int a[3], b[3];
    bytes_at(over, px, py, a);
    bytes_at(bare, px, py, b);
    assert_memory_equal(a, b, sizeof a);
    return magenta;
}

static void test_render_overlay(void **st)
{
    (void)st;
    const int w = 160, h = 96;
    const char *common = "render cornell --size 160x96 --spp 2 --threads 2 --seed 3 --quiet";
    char args[1024];
    snprintf(args, sizeof args, "%s --gaze 0.3,0.55 --overlay --out '%s/over.png'", common, g_dir);
    assert_int_equal(run(args), 0);
    snprintf(args, sizeof args, "%s --gaze 0.3,0.55 --out '%s/bare.png'", common, g_dir);
    assert_int_equal(run(args), 0);
    fv_image over = read_png("over.png"), bare = read_png("bare.png");
    assert_int_equal(over.width, w);
    assert_int_equal(over.height, h);
    fv_eye_model m = render_eye_model(w, h);
    assert_true(fv_eye_fovea_radius_px(&m) > 8.0 && fv_eye_transition_radius_px(&m) < 0.5 * h); /* both rings within the frame */
    assert_true(check_overlay(&over, &bare, &m, (fv_gaze){0.3f, 0.55f}) > 20);
    fv_image_free(&over);
    fv_image_free(&bare);

    /* A stereo pair: each eye's file has the rings around its own gaze (the trace's left and right
     * columns), not the other eye's. */
    char trace[128];
    snprintf(trace, sizeof trace, "%s/two.csv", g_dir);
    FILE *f = fopen(trace, "w");
    assert_non_null(f);
    fprintf(f, "time,xl,yl,xr,yr\n0,0.25,0.5,0.75,0.45\n1,0.25,0.5,0.75,0.45\n");
    fclose(f);
    snprintf(args, sizeof args, "%s --stereo 0.06 --gaze-trace '%s' --overlay --out '%s/st.png'", common, trace, g_dir);
    assert_int_equal(run(args), 0);
    snprintf(args, sizeof args, "%s --stereo 0.06 --gaze-trace '%s' --out '%s/stb.png'", common, trace, g_dir);
    assert_int_equal(run(args), 0);
    const fv_gaze gl = {0.25f, 0.5f}, gr = {0.75f, 0.45f};
    const char *names[2][2] = {{"st_left.png", "stb_left.png"}, {"st_right.png", "stb_right.png"}};
    for (int e = 0; e < 2; e++) {
        over = read_png(names[e][0]);
        bare = read_png(names[e][1]);
        fv_gaze own = e ? gr : gl, other = e ? gl : gr;
        assert_true(check_overlay(&over, &bare, &m, own) > 20);
        /* at the other eye's foveal radius (on its row, away from this eye's rings): the render */
        int x = (int)floor(other.x * w + fv_eye_fovea_radius_px(&m)), y = (int)floor(other.y * h);
        if (e) x = (int)floor(other.x * w - fv_eye_fovea_radius_px(&m));
        assert_false(is(&over, x, y, 255, 0, 255));
        fv_image_free(&over);
        fv_image_free(&bare);
    }

    /* Over linear data it refuses, exit 2, and writes nothing. */
    snprintf(args, sizeof args, "%s --overlay --out '%s/data.exr'", common, g_dir);
    assert_int_equal(run(args), 2);
    snprintf(args, sizeof args, "%s/data.exr", g_dir);
    assert_int_equal(access(args, F_OK), -1);
}

/* Two comparisons, their heat maps on one scale (--heatmap-max 1): the error 0.25 has one colour
 * in both, the ramp's at 0.25; each has the bar below, its ends the ramp's ends. Alone, each
 * would be scaled to its own largest error (0.5 and 1) and the same error would differ. */
static void test_compare_shared_scale(void **st)
{
    (void)st;
    const int w = 65, h = 40;
    float *ref = calloc((size_t)w * h * 3, sizeof(float)), *a = malloc(sizeof(float) * w * h * 3), *b = malloc(sizeof(float) * w * h * 3);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++) {
                a[3 * (y * w + x) + k] = 0.5f * (float)x / 64.0f;
                b[3 * (y * w + x) + k] = 1.0f * (float)x / 64.0f;
            }
    char path[256];
    fv_error err;
    const char *names[3] = {"ref.pfm", "a.pfm", "b.pfm"};
    const float *img[3] = {ref, a, b};
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", g_dir, names[i]);
        assert_int_equal(fv_image_write(path, img[i], w, h, 1.0f, &err), FV_OK);
    }
    /* E on linear values is |difference|; tiny rings at the centre stay off row 3 */
    const char *opts = "--linear --heatmap-metric e --gaze 0.5,0.5 --fovea-frac 0.01 --transition-frac 0.02";
    char args[1024];
    for (int shared = 1; shared >= 0; shared--) {
        for (int i = 1; i <= 2; i++) {
            snprintf(args, sizeof args, "compare '%s/ref.pfm' '%s/%s' %s %s --heatmap '%s/heat%d.png'", g_dir, g_dir, names[i], opts,
                     shared ? "--heatmap-max 1" : "", g_dir, i);
            assert_int_equal(run(args), 0);
        }
        fv_image ha = read_png("heat1.png"), hb = read_png("heat2.png");
        int ca[3], cb[3];
        bytes_at(&ha, 32, 3, ca); /* a's error 0.25 */
        bytes_at(&hb, 16, 3, cb); /* b's error 0.25 */
        float want[3];
        fv_colormap_ramp(shared ? 0.25f : 0.5f, want);
        for (int k = 0; k < 3; k++) assert_int_equal(ca[k], (int)lrintf(255.0f * want[k]));
        if (shared) assert_memory_equal(ca, cb, sizeof ca);
        else assert_true(memcmp(ca, cb, sizeof ca) != 0);
        /* the colour bar of each: 0 and its vmax at the ends of the ramp */
        const float vmax[2] = {shared ? 1.0f : 0.5f, 1.0f};
        const fv_image *hm[2] = {&ha, &hb};
        for (int i = 0; i < 2; i++) {
            const int s = fv_colorbar_scale(h);
            assert_int_equal(hm[i]->height, h + fv_colorbar_height(s));
            fv_colorbar_layout L;
            fv_colorbar_layout_of(hm[i]->width, h, s, vmax[i], "E", &L);
            float lo[3], hi[3];
            fv_colormap_ramp(0.0f, lo);
            fv_colormap_ramp(1.0f, hi);
            for (int y = L.bar_y0; y <= L.bar_y1; y++) {
                int c0[3], c1[3];
                bytes_at(hm[i], L.x0, y, c0);
                bytes_at(hm[i], L.x1, y, c1);
                for (int k = 0; k < 3; k++) {
                    assert_int_equal(c0[k], (int)lrintf(255.0f * lo[k]));
                    assert_int_equal(c1[k], (int)lrintf(255.0f * hi[k]));
                }
            }
        }
        fv_image_free(&ha);
        fv_image_free(&hb);
    }
    free(ref);
    free(a);
    free(b);
}

static int setup(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "/tmp/fovea-overlay-XXXXXX");
    return mkdtemp(g_dir) ? 0 : -1;
}

static int teardown(void **st)
{
    (void)st;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_marks),
        cmocka_unit_test(test_render_overlay),
        cmocka_unit_test(test_compare_shared_scale),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
