/* Metrics against hand-worked values: MSE/PSNR/E on tiny images, SSIM of constant images, FLIP
 * of uniform images (where only the colour pipeline acts), per-region aggregation, the temporal
 * errors MSE' and E', and the heat map file. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include "fovea/fovea.h"

static float *filled(int w, int h, float r, float g, float b)
{
    float *p = malloc((size_t)w * h * 3 * sizeof *p);
    for (int i = 0; i < w * h; i++) p[3 * i] = r, p[3 * i + 1] = g, p[3 * i + 2] = b;
    return p;
}

static fv_metric_opts linear_opts(void)
{
    fv_metric_opts o;
    fv_metric_opts_default(&o);
    o.linear = true;
    return o;
}

static void test_identical(void **st)
{
    (void)st;
    float *a = filled(40, 30, 0.3f, 0.5f, 0.9f);
    for (int i = 0; i < 40 * 30 * 3; i += 7) a[i] = (float)(i % 13) / 13.0f; /* some structure */
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, a, 40, 30, NULL, NULL, &r, NULL, &err), FV_OK);
    const fv_metric_values *v = &r.region[FV_REGION_ALL];
    assert_int_equal(v->pixels, 1200);
    assert_float_equal(v->mse, 0.0, 0.0);
    assert_float_equal(v->e, 0.0, 0.0);
    assert_true(isinf(v->psnr));
    assert_float_equal(v->ssim, 1.0, 1e-6);
    assert_float_equal(v->flip, 0.0, 1e-7);
    free(a);
}

/* 2x2 image, linear values, one channel of one pixel off by 0.5: squared error 0.25 over
 * 4 pixels x 3 channels = 0.25 / 12 = 0.0208333; E = 0.5 / 12 = 0.0416667;
 * PSNR = 10 log10(1 / 0.0208333) = 16.8124 dB. */
static void test_mse_e_psnr(void **st)
{
    (void)st;
    float *a = filled(2, 2, 0.2f, 0.2f, 0.2f), *b = filled(2, 2, 0.2f, 0.2f, 0.2f);
    b[3 * 3 + 1] = 0.7f;
    fv_metric_opts o = linear_opts();
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, 2, 2, NULL, &o, &r, NULL, &err), FV_OK);
    assert_float_equal(r.region[FV_REGION_ALL].mse, 0.25 / 12, 1e-7);
    assert_float_equal(r.region[FV_REGION_ALL].e, 0.5 / 12, 1e-7);
    assert_float_equal(r.region[FV_REGION_ALL].psnr, 16.8124, 1e-3);
    /* Display mode encodes first: 0.2 -> 0.484529, 0.7 -> 0.854306; (0.369777)^2 / 12 = 0.0113945. */
    fv_metric_opts d;
    fv_metric_opts_default(&d);
    assert_int_equal(fv_metrics_compare(a, b, 2, 2, NULL, &d, &r, NULL, &err), FV_OK);
    assert_float_equal(r.region[FV_REGION_ALL].mse, 0.0113945, 1e-6);
    free(a);
    free(b);
}

/* Constant images: means 0.2 and 0.3, no variance, so SSIM = (2 mu_a mu_b + C1) / (mu_a^2 +
 * mu_b^2 + C1) = (0.12 + 0.0001) / (0.13 + 0.0001) = 0.923136 at every pixel. */
static void test_ssim_constant(void **st)
{
    (void)st;
    float *a = filled(16, 16, 0.2f, 0.2f, 0.2f), *b = filled(16, 16, 0.3f, 0.3f, 0.3f);
    fv_metric_opts o = linear_opts();
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, 16, 16, NULL, &o, &r, NULL, &err), FV_OK);
    assert_float_equal(r.region[FV_REGION_ALL].ssim, 0.923136, 1e-5);
    free(a);
    free(b);
}

/* Adding noise of growing amplitude lowers SSIM and raises MSE and FLIP. */
static void test_monotone_in_noise(void **st)
{
    (void)st;
    const int w = 48, h = 48;
    float *a = filled(w, h, 0, 0, 0);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) a[3 * (y * w + x) + c] = 0.1f + 0.6f * (float)((x / 8 + y / 8) % 2); /* checkerboard */
    double prev_ssim = 1.1, prev_mse = -1, prev_flip = -1;
    for (int k = 1; k <= 4; k++) {
        float amp = 0.05f * k;
        float *b = malloc(sizeof(float) * 3 * w * h);
        unsigned s = 12345;
        for (int i = 0; i < 3 * w * h; i++) {
            s = s * 1103515245u + 12345u;
            float n = ((s >> 8) & 0xffff) / 65535.0f - 0.5f;
            b[i] = a[i] + amp * n;
        }
        fv_metric_report r;
        fv_error err;
        assert_int_equal(fv_metrics_compare(a, b, w, h, NULL, NULL, &r, NULL, &err), FV_OK);
        const fv_metric_values *v = &r.region[FV_REGION_ALL];
        assert_true(v->ssim < prev_ssim);
        assert_true(v->mse > prev_mse);
        assert_true(v->flip > prev_flip);
        prev_ssim = v->ssim, prev_mse = v->mse, prev_flip = v->flip;
        free(b);
    }
    free(a);
}

/* Uniform images: the CSF filters are normalised and leave them unchanged, and there are no
 * edges or points, so FLIP is the compressed colour error alone.
 * Black vs white: Hunt-adjusted HyAB = |0 - 100| = 100 -> 100^0.7 = 25.1189. The largest
 * distance (green vs blue) is 203.297 -> ^0.7 = 41.2755; 25.1189 > 0.4 * 41.2755 = 16.5102, so
 * FLIP = 0.95 + (25.1189 - 16.5102) / (41.2755 - 16.5102) * 0.05 = 0.967381.
 * Grey 0.5 vs 0.6 (display): L* = 53.389 vs 63.223, dL = 9.8336 -> ^0.7 = 4.9537 < 16.5102, so
 * FLIP = 0.95 / 16.5102 * 4.9537 = 0.285017. */
static void test_flip_uniform(void **st)
{
    (void)st;
    float *k = filled(32, 32, 0, 0, 0), *wht = filled(32, 32, 1, 1, 1);
    float *map = malloc(sizeof(float) * 32 * 32);
    fv_error err;
    assert_int_equal(fv_metrics_flip_map(k, wht, 32, 32, 67.0f, map, &err), FV_OK);
    assert_float_equal(map[0], 0.967381, 1e-4);
    assert_float_equal(map[16 * 32 + 16], 0.967381, 1e-4);
    float *g5 = filled(32, 32, 0.5f, 0.5f, 0.5f), *g6 = filled(32, 32, 0.6f, 0.6f, 0.6f);
    assert_int_equal(fv_metrics_flip_map(g5, g6, 32, 32, 67.0f, map, &err), FV_OK);
    assert_float_equal(map[300], 0.285017, 1e-4);
    assert_int_equal(fv_metrics_flip_map(g5, g6, 32, 32, 0.0f, map, &err), FV_ERR_INVALID);
    free(k), free(wht), free(g5), free(g6), free(map);
}

/* A one-pixel shift of a sharp edge: the colour error alone would be zero almost everywhere but
 * the edge pixels; the feature term raises FLIP there. FLIP is larger for a larger shift. */
static void test_flip_edges(void **st)
{
    (void)st;
    const int w = 64, h = 16;
    float *a = filled(w, h, 0, 0, 0), *b = filled(w, h, 0, 0, 0), *c = filled(w, h, 0, 0, 0);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++) {
                a[3 * (y * w + x) + k] = x >= 32 ? 0.8f : 0.1f;
                b[3 * (y * w + x) + k] = x >= 33 ? 0.8f : 0.1f;
                c[3 * (y * w + x) + k] = x >= 36 ? 0.8f : 0.1f;
            }
    fv_metric_report r1, r2;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, w, h, NULL, NULL, &r1, NULL, &err), FV_OK);
    assert_int_equal(fv_metrics_compare(a, c, w, h, NULL, NULL, &r2, NULL, &err), FV_OK);
    assert_true(r1.region[FV_REGION_ALL].flip > 0.0);
    assert_true(r2.region[FV_REGION_ALL].flip > r1.region[FV_REGION_ALL].flip);
    free(a), free(b), free(c);
}

/* Labels: left half fovea, right half periphery, no transition. The test image differs by 0.1
 * in every channel on the right only (linear): fovea MSE 0, periphery MSE 0.01, all 0.005. */
static void test_regions(void **st)
{
    (void)st;
    const int w = 20, h = 10;
    float *a = filled(w, h, 0.4f, 0.4f, 0.4f), *b = filled(w, h, 0.4f, 0.4f, 0.4f);
    uint8_t lab[200];
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            lab[y * w + x] = x < 10 ? FV_REGION_FOVEA : FV_REGION_PERIPHERY;
            if (x >= 10)
                for (int c = 0; c < 3; c++) b[3 * (y * w + x) + c] = 0.5f;
        }
    fv_metric_opts o = linear_opts();
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, w, h, lab, &o, &r, NULL, &err), FV_OK);
    assert_int_equal(r.region[FV_REGION_FOVEA].pixels, 100);
    assert_int_equal(r.region[FV_REGION_PERIPHERY].pixels, 100);
    assert_int_equal(r.region[FV_REGION_TRANSITION].pixels, 0);
    assert_true(isnan(r.region[FV_REGION_TRANSITION].mse));
    assert_float_equal(r.region[FV_REGION_FOVEA].mse, 0.0, 1e-12);
    assert_float_equal(r.region[FV_REGION_PERIPHERY].mse, 0.01, 1e-7);
    assert_float_equal(r.region[FV_REGION_ALL].mse, 0.005, 1e-7);
    assert_float_equal(r.region[FV_REGION_PERIPHERY].e, 0.1, 1e-6);
    free(a), free(b);
}

/* Frames 0, 0.1, 0.3 (linear, uniform): pair MSEs 0.01 and 0.04 -> MSE' = 0.025 (Eq. 9);
 * pair Es 0.1 and 0.2 -> E' = 0.15 (Eq. 4). */
static void test_temporal(void **st)
{
    (void)st;
    fv_metric_opts o = linear_opts();
    fv_temporal *t;
    fv_error err;
    assert_int_equal(fv_temporal_create(4, 4, &o, &t, &err), FV_OK);
    const float v[3] = {0.0f, 0.1f, 0.3f};
    double mse, e;
    for (int i = 0; i < 3; i++) {
        float *f = filled(4, 4, v[i], v[i], v[i]);
        assert_int_equal(fv_temporal_push(t, f, NULL, &err), FV_OK);
        free(f);
        if (i == 0) {
            fv_temporal_result(t, FV_REGION_ALL, &mse, &e);
            assert_float_equal(mse, 0.0, 0.0);
        }
    }
    fv_temporal_result(t, FV_REGION_ALL, &mse, &e);
    assert_float_equal(mse, 0.025, 1e-7);
    assert_float_equal(e, 0.15, 1e-7);
    assert_int_equal(fv_temporal_frames(t), 3);
    fv_temporal_destroy(t);
}

static void test_heatmap(void **st)
{
    (void)st;
    char path[64];
    snprintf(path, sizeof path, "/tmp/fovea-heat-%d.png", (int)getpid());
    float map[12 * 8];
    for (int i = 0; i < 96; i++) map[i] = (float)i / 95.0f;
    fv_eye_model eye;
    fv_eye_model_default(12, 8, &eye);
    fv_error err;
    const fv_heatmap_opts ho = {1.0f, &eye, {0.5f, 0.5f}, NULL};
    assert_int_equal(fv_heatmap_write(path, map, 12, 8, &ho, &err), FV_OK);
    fv_image img;
    assert_int_equal(fv_image_read(path, &img, &err), FV_OK);
    assert_int_equal(img.width, 12);
    assert_int_equal(img.height, 8);
    /* Zero error is the ramp's first colour (near black), the largest the last (pale yellow). */
    assert_true(img.rgb[0] < 0.01f && img.rgb[2] < 0.01f);
    assert_true(img.rgb[3 * 95] > 0.9f && img.rgb[3 * 95 + 1] > 0.9f);
    fv_image_free(&img);
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_identical),     cmocka_unit_test(test_mse_e_psnr), cmocka_unit_test(test_ssim_constant),
        cmocka_unit_test(test_monotone_in_noise), cmocka_unit_test(test_flip_uniform), cmocka_unit_test(test_flip_edges),
        cmocka_unit_test(test_regions),       cmocka_unit_test(test_temporal),  cmocka_unit_test(test_heatmap),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
