/* The colour map of heat maps (film/colormap.h), the font its labels use (film/font.h) and heat
 * map files with a colour bar: the ramp's ends and its lightness, which never falls; the bar's
 * ends are the ramp's ends; a map too narrow for the bar is padded; two heat maps given the same
 * vmax draw the same error in the same colour, and their metadata says the scale. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include "film/colormap.h"
#include "film/font.h"
#include "fovea/fovea.h"

/* CIE L* of a display (sRGB-encoded) colour. */
static double lightness(const float *srgb)
{
    double y = 0.2126 * fv_srgb_decode(srgb[0]) + 0.7152 * fv_srgb_decode(srgb[1]) + 0.0722 * fv_srgb_decode(srgb[2]);
    return y > 216.0 / 24389.0 ? 116.0 * cbrt(y) - 16.0 : y * 24389.0 / 27.0;
}

static void test_ramp_ends_and_lightness(void **st)
{
    (void)st;
    float c[3];
    /* the ends are the first and last control points */
    fv_colormap_ramp(0.0f, c);
    assert_float_equal(c[0], 0.0f, 1e-6);
    assert_float_equal(c[1], 0.0f, 1e-6);
    assert_float_equal(c[2], 0.02f, 1e-6);
    fv_colormap_ramp(1.0f, c);
    assert_float_equal(c[0], 0.99f, 1e-6);
    assert_float_equal(c[1], 0.98f, 1e-6);
    assert_float_equal(c[2], 0.75f, 1e-6);
    /* halfway between the 2nd and 3rd control points (t = 0.3): their mean */
    fv_colormap_ramp(0.3f, c);
    assert_float_equal(c[0], 0.5f * (0.23f + 0.55f), 1e-5);
    assert_float_equal(c[2], 0.5f * (0.43f + 0.50f), 1e-5);
    /* outside [0,1] and NaN clamp to the ends */
    float lo[3], hi[3], nan_c[3];
    fv_colormap_ramp(-3.0f, lo);
    fv_colormap_ramp(7.0f, hi);
    fv_colormap_ramp(NAN, nan_c);
    assert_float_equal(lo[2], 0.02f, 1e-6);
    assert_float_equal(nan_c[2], 0.02f, 1e-6);
    assert_float_equal(hi[2], 0.75f, 1e-6);
    /* lightness rises strictly from end to end (a larger error always looks brighter) */
    double prev = -1.0;
    for (int i = 0; i <= 1000; i++) {
        fv_colormap_ramp((float)i / 1000.0f, c);
        double l = lightness(c);
        assert_true(l > prev);
        prev = l;
    }
    fv_colormap_ramp(0.0f, c);
    assert_true(lightness(c) < 1.0);
    assert_true(prev > 95.0);
}

static void test_font(void **st)
{
    (void)st;
    /* '1': the foot 0x0E is columns 1..3 of the bottom row, the stem column 2 */
    assert_false(fv_font_lit('1', 0, 6));
    assert_true(fv_font_lit('1', 1, 6) && fv_font_lit('1', 2, 6) && fv_font_lit('1', 3, 6));
    assert_false(fv_font_lit('1', 4, 6));
    assert_true(fv_font_lit('1', 2, 3));
    assert_false(fv_font_lit('1', -1, 3));
    assert_false(fv_font_lit('1', 2, 7));
    /* a space lights nothing; a byte outside ASCII draws '?' */
    int lit_space = 0, same = 1;
    for (int y = 0; y < FV_FONT_H; y++)
        for (int x = 0; x < FV_FONT_W; x++) {
            lit_space += fv_font_lit(' ', x, y);
            same &= fv_font_lit(200, x, y) == fv_font_lit('?', x, y);
        }
    assert_int_equal(lit_space, 0);
    assert_true(same);
    /* widths: 6 columns per character less the last blank one, times the scale */
    assert_int_equal(fv_font_text_width("", 1), 0);
    assert_int_equal(fv_font_text_width("0.5", 1), 17);
    assert_int_equal(fv_font_text_width("ab", 2), 22);
    /* drawing at scale 2: the foot of '1' at (0,0) covers columns 2..7 of rows 12..13, clipped */
    float img[10 * 14 * 3];
    for (int i = 0; i < 10 * 14 * 3; i++) img[i] = 0.5f;
    const float red[3] = {1.0f, 0.0f, 0.0f};
    assert_int_equal(fv_font_draw_rgb(img, 10, 14, 0, 0, 2, red, "1"), 12);
    assert_float_equal(img[3 * (13 * 10 + 2)], 1.0f, 0.0);
    assert_float_equal(img[3 * (13 * 10 + 7) + 1], 0.0f, 0.0);
    assert_float_equal(img[3 * (13 * 10 + 1)], 0.5f, 0.0);
    assert_float_equal(img[3 * (13 * 10 + 8)], 0.5f, 0.0);
}

/* The bar drawn into a float image: ends, middle, frame, a tick and the label. */
static void test_colorbar_draw(void **st)
{
    (void)st;
    const int w = 200, s = 1, hb = fv_colorbar_height(s), h = 10 + hb;
    assert_true(fv_colorbar_min_width(s, 1.0f, "FLIP") <= w);
    float *img = malloc(sizeof(float) * 3 * w * h);
    for (int i = 0; i < 3 * w * h; i++) img[i] = -1.0f; /* the map above the strip: untouched */
    fv_colorbar_draw(img, w, h, 10, s, 1.0f, "FLIP");
    fv_colorbar_layout L;
    fv_colorbar_layout_of(w, 10, s, 1.0f, "FLIP", &L);
    assert_true(L.x0 > fv_font_text_width("FLIP", 1) && L.x1 < w - 1 && (L.x1 - L.x0) % 2 == 0);
    assert_int_equal(L.bar_y1 - L.bar_y0 + 1, 8);
    assert_int_equal(L.height, hb);
    for (int i = 0; i < 3 * w * 10; i++) assert_float_equal(img[i], -1.0f, 0.0);
    float c0[3], c1[3], cm[3];
    fv_colormap_ramp(0.0f, c0);
    fv_colormap_ramp(1.0f, c1);
    fv_colormap_ramp(0.5f, cm);
    for (int y = L.bar_y0; y <= L.bar_y1; y++)
        for (int k = 0; k < 3; k++) {
            assert_float_equal(img[3 * (y * w + L.x0) + k], fv_srgb_decode(c0[k]), 1e-6);
            assert_float_equal(img[3 * (y * w + L.x1) + k], fv_srgb_decode(c1[k]), 1e-6);
            assert_float_equal(img[3 * (y * w + (L.x0 + L.x1) / 2) + k], fv_srgb_decode(cm[k]), 1e-6);
        }
    /* the frame around the ramp is grey; the strip's corner white; the tick under x0 black */
    const float *frame = img + 3 * (L.bar_y0 * w + L.x0 - 1), *corner = img + 3 * (10 * w), *tick = img + 3 * ((L.bar_y1 + 2) * w + L.x0);
    assert_float_equal(frame[0], fv_srgb_decode(0.45f), 1e-6);
    assert_float_equal(corner[0], 1.0f, 0.0);
    assert_float_equal(tick[0], 0.0f, 0.0);
    /* the label is drawn left of the ramp: some black pixels there */
    int black = 0;
    for (int y = L.bar_y0; y <= L.bar_y1; y++)
        for (int x = 0; x < L.x0 - 1; x++) black += img[3 * (y * w + x)] == 0.0f;
    assert_true(black > 10);
    free(img);
}

/* The 8-bit byte a PNG holds for linear value v: what a heat map's pixel reads back as. */
static int byte_of(float linear) { return (int)lrintf(255.0f * fv_srgb_encode(linear)); }

static void assert_ramp_pixel(const fv_image *img, int x, int y, float t)
{
    float c[3];
    fv_colormap_ramp(t, c);
    for (int k = 0; k < 3; k++) assert_int_equal(byte_of(img->rgb[3 * ((size_t)y * img->width + x) + k]), (int)lrintf(255.0f * c[k]));
}

static const char *meta_value(const char *path, const char *key, char *buf, size_t n)
{
    fv_params *m = NULL;
    fv_error err;
    buf[0] = '\0';
    if (fv_image_read_meta(path, &m, &err) != FV_OK) return NULL;
    const char *found = NULL;
    for (int i = 0; i < fv_params_count(m); i++)
        if (!strcmp(fv_params_key(m, i), key)) {
            snprintf(buf, n, "%s", fv_params_value(m, i));
            found = buf;
        }
    fv_params_destroy(m);
    return found;
}

/* Heat map files: the bar below the map (its ends the ramp's ends), the scale in the metadata,
 * one vmax for two maps gives one colour per error, and a narrow map gets a wider canvas. */
static void test_heatmap_colorbar_and_shared_scale(void **st)
{
    (void)st;
    char pa[64], pb[64], buf[64];
    snprintf(pa, sizeof pa, "/tmp/fovea-cmap-a-%d.png", (int)getpid());
    snprintf(pb, sizeof pb, "/tmp/fovea-cmap-b-%d.png", (int)getpid());
    const int w = 161, h = 40;
    float *a = malloc(sizeof(float) * w * h), *b = malloc(sizeof(float) * w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            a[y * w + x] = 0.5f * (float)x / (float)(w - 1); /* errors 0..0.5 */
            b[y * w + x] = 1.0f * (float)x / (float)(w - 1); /* errors 0..1 */
        }
    fv_error err;
    fv_heatmap_opts o = {1.0f, NULL, {0.5f, 0.5f}, "MSE"};
    assert_int_equal(fv_heatmap_write(pa, a, w, h, &o, &err), FV_OK);
    assert_int_equal(fv_heatmap_write(pb, b, w, h, &o, &err), FV_OK);
    fv_image ia, ib;
    assert_int_equal(fv_image_read(pa, &ia, &err), FV_OK);
    assert_int_equal(fv_image_read(pb, &ib, &err), FV_OK);
    const int s = fv_colorbar_scale(h);
    assert_int_equal(ia.width, w);
    assert_int_equal(ia.height, h + fv_colorbar_height(s));
    /* error 0.25 is column 80 of a and column 40 of b: one colour, ramp(0.25) */
    for (int k = 0; k < 3; k++) assert_int_equal(byte_of(ia.rgb[3 * (5 * w + 80) + k]), byte_of(ib.rgb[3 * (5 * w + 40) + k]));
    assert_ramp_pixel(&ia, 80, 5, 0.25f);
    /* the bar of each: 0 at x0, vmax at x1 */
    fv_colorbar_layout L;
    fv_colorbar_layout_of(w, h, s, 1.0f, "MSE", &L);
    for (int y = L.bar_y0; y <= L.bar_y1; y++) {
        assert_ramp_pixel(&ia, L.x0, y, 0.0f);
        assert_ramp_pixel(&ia, L.x1, y, 1.0f);
        assert_ramp_pixel(&ib, L.x1, y, 1.0f);
    }
    assert_string_equal(meta_value(pa, "heatmap_max", buf, sizeof buf), "1");
    assert_string_equal(meta_value(pa, "heatmap", buf, sizeof buf), "MSE");
    assert_null(meta_value(pa, "overlay", buf, sizeof buf)); /* no rings asked for */
    fv_image_free(&ia);
    /* Each on its own scale (vmax 0: the map's largest), a's 0.25 is halfway up its ramp: the two
     * colours of one error then differ, which is what a shared scale prevents. */
    o.vmax = 0.0f;
    assert_int_equal(fv_heatmap_write(pa, a, w, h, &o, &err), FV_OK);
    assert_int_equal(fv_image_read(pa, &ia, &err), FV_OK);
    assert_ramp_pixel(&ia, 80, 5, 0.5f);
    assert_true(byte_of(ia.rgb[3 * (5 * w + 80)]) != byte_of(ib.rgb[3 * (5 * w + 40)]));
    assert_string_equal(meta_value(pa, "heatmap_max", buf, sizeof buf), "0.5");
    assert_true(fv_heatmap_scale(a, w, h) == 0.5f);
    fv_image_free(&ia);
    fv_image_free(&ib);

    /* A 12 px wide map: the canvas is as wide as the bar needs; the map keeps its pixels at the
     * top left, white beside it. Values above vmax draw as the ramp's top. */
    float small[12 * 8];
    for (int i = 0; i < 96; i++) small[i] = 3.0f;
    o.vmax = 1.0f;
    o.label = "FLIP";
    assert_int_equal(fv_heatmap_write(pa, small, 12, 8, &o, &err), FV_OK);
    assert_int_equal(fv_image_read(pa, &ia, &err), FV_OK);
    assert_int_equal(ia.width, fv_colorbar_min_width(1, 1.0f, "FLIP"));
    assert_true(ia.width > 12);
    assert_int_equal(ia.height, 8 + fv_colorbar_height(1));
    assert_ramp_pixel(&ia, 11, 7, 1.0f);
    assert_int_equal(byte_of(ia.rgb[3 * (7 * ia.width + 12)]), 255);
    fv_colorbar_layout_of(ia.width, 8, 1, 1.0f, "FLIP", &L);
    assert_ramp_pixel(&ia, L.x0, L.bar_y0, 0.0f);
    assert_ramp_pixel(&ia, L.x1, L.bar_y1, 1.0f);
    fv_image_free(&ia);
    /* an eye model of another size is refused, naming both sizes */
    fv_eye_model eye;
    fv_eye_model_default(16, 8, &eye);
    o.eye = &eye;
    assert_int_equal(fv_heatmap_write(pa, small, 12, 8, &o, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "16x8"));
    unlink(pa);
    unlink(pb);
    free(a);
    free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ramp_ends_and_lightness),
        cmocka_unit_test(test_font),
        cmocka_unit_test(test_colorbar_draw),
        cmocka_unit_test(test_heatmap_colorbar_and_shared_scale),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
