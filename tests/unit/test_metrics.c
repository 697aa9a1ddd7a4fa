/* Metrics (src/metrics/) beyond test_metric_values.c: the SSIM map against hand-worked values,
 * also at the border where the window is cut; exposure and clamping of display values;
 * non-finite pixels; temporal errors with a moving gaze; heat map colours and rings; bad input. */
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

/* When b = a + c, both windows have the same variance and their covariance equals it, so the
 * contrast-structure factor (2 s_ab + C2) / (s_a^2 + s_b^2 + C2) is 1 and
 * SSIM = (2 mu (mu + c) + C1) / (mu^2 + (mu + c)^2 + C1) with mu the window mean of a.
 * a = 0.2 + 0.01 x (grey, so Y = a), c = 0.1.
 * Inside, the symmetric window's mean of a linear ramp is its centre value: at x = 20, mu = 0.4,
 * SSIM = (0.4 + 0.0001) / (0.41 + 0.0001) = 0.975616.
 * At x = 0 the window keeps offsets 0..5 with weights exp(-d^2 / 4.5) = 1, 0.800737, 0.411112,
 * 0.135335, 0.028566, 0.003866 (sum 2.379616), renormalised: mean offset 0.908785, mu =
 * 0.2090878, SSIM = (2 mu (mu + 0.1) + C1) / (mu^2 + (mu + 0.1)^2 + C1) = 0.928240. */
static void test_ssim_offset_ramp(void **st)
{
    (void)st;
    const int w = 40, h = 15;
    float *a = malloc(sizeof(float) * 3 * w * h), *b = malloc(sizeof(float) * 3 * w * h), *map = malloc(sizeof(float) * w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                a[3 * (y * w + x) + c] = 0.2f + 0.01f * (float)x;
                b[3 * (y * w + x) + c] = 0.3f + 0.01f * (float)x;
            }
    fv_error err;
    assert_int_equal(fv_metrics_ssim_map(a, b, w, h, map, &err), FV_OK);
    assert_float_equal(map[7 * w + 20], 0.975616, 1e-4);
    assert_float_equal(map[0 * w + 20], 0.975616, 1e-4); /* cut vertically only: same mean */
    assert_float_equal(map[7 * w + 0], 0.928240, 1e-4);
    assert_float_equal(map[14 * w + 0], 0.928240, 1e-4);
    /* An image against itself is 1 everywhere, borders included. */
    assert_int_equal(fv_metrics_ssim_map(a, a, w, h, map, &err), FV_OK);
    for (int i = 0; i < w * h; i++) assert_float_equal(map[i], 1.0, 1e-5);
    free(a), free(b), free(map);
}

/* Display values: exposure first, then clamp to [0, 1], then sRGB encoding.
 * 0.25 and 0.5 under exposure 2 show as encode(0.5) = 0.735357 and encode(1) = 1:
 * MSE = 0.264643^2 = 0.0700359, E = 0.264643. Linear mode compares 0.5 and 1: MSE 0.25, E 0.5.
 * 1 and 3 both show as white: no error. */
static void test_exposure_and_clamp(void **st)
{
    (void)st;
    float *a = filled(3, 3, 0.25f, 0.25f, 0.25f), *b = filled(3, 3, 0.5f, 0.5f, 0.5f);
    fv_metric_opts o;
    fv_metric_opts_default(&o);
    o.exposure = 2.0f;
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, 3, 3, NULL, &o, &r, NULL, &err), FV_OK);
    assert_float_equal(r.region[FV_REGION_ALL].mse, 0.0700359, 1e-5);
    assert_float_equal(r.region[FV_REGION_ALL].e, 0.264643, 1e-5);
    o.linear = true;
    assert_int_equal(fv_metrics_compare(a, b, 3, 3, NULL, &o, &r, NULL, &err), FV_OK);
    assert_float_equal(r.region[FV_REGION_ALL].mse, 0.25, 1e-7);
    assert_float_equal(r.region[FV_REGION_ALL].e, 0.5, 1e-7);
    float *w1 = filled(3, 3, 1, 1, 1), *w3 = filled(3, 3, 3, 3, 3);
    fv_metric_opts_default(&o);
    assert_int_equal(fv_metrics_compare(w1, w3, 3, 3, NULL, &o, &r, NULL, &err), FV_OK);
    assert_float_equal(r.region[FV_REGION_ALL].mse, 0.0, 0.0);
    assert_true(isinf(r.region[FV_REGION_ALL].psnr));
    o.exposure = -1.0f;
    assert_int_equal(fv_metrics_compare(a, b, 3, 3, NULL, &o, &r, NULL, &err), FV_ERR_INVALID);
    free(a), free(b), free(w1), free(w3);
}

/* A NaN or infinite pixel counts as black instead of turning every mean into NaN. 2x1 image,
 * linear: pixel 0 is (NaN, 0, 0) vs black, pixel 1 is (0.5, 0.5, 0.5) vs black:
 * MSE = 3 x 0.25 / 6 = 0.125. */
static void test_non_finite_pixels(void **st)
{
    (void)st;
    float a[6] = {NAN, 0, 0, 0.5f, 0.5f, 0.5f}, b[6] = {0, 0, 0, 0, 0, 0};
    fv_metric_opts o;
    fv_metric_opts_default(&o);
    o.linear = true;
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, 2, 1, NULL, &o, &r, NULL, &err), FV_OK);
    assert_float_equal(r.region[FV_REGION_ALL].mse, 0.125, 1e-7);
    assert_true(isfinite(r.region[FV_REGION_ALL].ssim) && isfinite(r.region[FV_REGION_ALL].flip));
}

/* Regions come from the labels; the flip_map argument receives the per-pixel FLIP whose region
 * means are the reported values. Left column fovea, middle transition, right periphery. */
static void test_region_means_of_flip_map(void **st)
{
    (void)st;
    const int w = 30, h = 10;
    float *a = filled(w, h, 0.2f, 0.2f, 0.2f), *b = filled(w, h, 0.2f, 0.2f, 0.2f), *map = malloc(sizeof(float) * w * h);
    uint8_t lab[300];
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            lab[y * w + x] = x < 10 ? FV_REGION_FOVEA : x < 20 ? FV_REGION_TRANSITION : FV_REGION_PERIPHERY;
            b[3 * (y * w + x)] = 0.2f + 0.02f * (float)(x % 7) + 0.01f * (float)y;
        }
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, w, h, lab, NULL, &r, map, &err), FV_OK);
    double s[FV_REGION_COUNT] = {0};
    for (int i = 0; i < w * h; i++) {
        s[lab[i]] += map[i];
        s[FV_REGION_ALL] += map[i];
    }
    const int regs[3] = {FV_REGION_FOVEA, FV_REGION_TRANSITION, FV_REGION_PERIPHERY};
    double mse_sum = 0.0;
    for (int k = 0; k < 3; k++) {
        int g = regs[k];
        assert_int_equal(r.region[g].pixels, 100);
        assert_float_equal(r.region[g].flip, s[g] / 100.0, 1e-6);
        assert_true(r.region[g].mse > 0.0);
        mse_sum += r.region[g].mse;
    }
    assert_int_equal(r.region[FV_REGION_ALL].pixels, 300);
    assert_float_equal(r.region[FV_REGION_ALL].flip, s[FV_REGION_ALL] / 300.0, 1e-6);
    /* Three regions of equal size: the whole image's mean is the mean of theirs. */
    assert_float_equal(r.region[FV_REGION_ALL].mse, mse_sum / 3.0, 1e-9);
    free(a), free(b), free(map);
}

/* Temporal errors with a moving gaze, 4x2 linear frames, each pair split with the LATER frame's
 * labels. f0 = 0; f1 = 0.2 on the left half; f2 = f1 plus 0.1 on the right half.
 * Pair (f0, f1), labels all fovea: fovea MSE = 4 x 0.04 / 8 = 0.02, E = 0.1; no periphery.
 * Pair (f1, f2), left fovea / right periphery: fovea 0 and 0; periphery MSE 0.01, E 0.1;
 * whole image MSE 0.005, E 0.05.
 * MSE' fovea = (0.02 + 0) / 2 = 0.01, E' = 0.05; periphery, present in one pair: 0.01 and 0.1;
 * all: (0.02 + 0.005) / 2 = 0.0125, E' = 0.075; the transition never had pixels: NaN.
 * (With the earlier frame's labels the fovea would get (0.02 + 0.005) / 2 instead.) */
static void test_temporal_moving_gaze(void **st)
{
    (void)st;
    float f0[24] = {0}, f1[24] = {0}, f2[24];
    uint8_t all_fovea[8], split[8];
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 4; x++) {
            int i = y * 4 + x;
            all_fovea[i] = FV_REGION_FOVEA;
            split[i] = x < 2 ? FV_REGION_FOVEA : FV_REGION_PERIPHERY;
            for (int c = 0; c < 3; c++) {
                f1[3 * i + c] = x < 2 ? 0.2f : 0.0f;
                f2[3 * i + c] = x < 2 ? 0.2f : 0.1f;
            }
        }
    fv_metric_opts o;
    fv_metric_opts_default(&o);
    o.linear = true;
    fv_temporal *t;
    fv_error err;
    assert_int_equal(fv_temporal_create(4, 2, &o, &t, &err), FV_OK);
    assert_int_equal(fv_temporal_push(t, f0, split, &err), FV_OK); /* the first frame's labels are unused */
    assert_int_equal(fv_temporal_push(t, f1, all_fovea, &err), FV_OK);
    assert_int_equal(fv_temporal_push(t, f2, split, &err), FV_OK);
    double mse, e;
    fv_temporal_result(t, FV_REGION_FOVEA, &mse, &e);
    assert_float_equal(mse, 0.01, 1e-7);
    assert_float_equal(e, 0.05, 1e-7);
    fv_temporal_result(t, FV_REGION_PERIPHERY, &mse, &e);
    assert_float_equal(mse, 0.01, 1e-7);
    assert_float_equal(e, 0.1, 1e-7);
    fv_temporal_result(t, FV_REGION_ALL, &mse, &e);
    assert_float_equal(mse, 0.0125, 1e-7);
    assert_float_equal(e, 0.075, 1e-7);
    fv_temporal_result(t, FV_REGION_TRANSITION, &mse, &e);
    assert_true(isnan(mse) && isnan(e));
    assert_int_equal(fv_temporal_push(t, NULL, NULL, &err), FV_ERR_INVALID);
    fv_temporal_destroy(t);
    assert_int_equal(fv_temporal_create(0, 2, &o, &t, &err), FV_ERR_INVALID);
}

static float luma(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

/* The ramp brightens steadily, vmax <= 0 scales to the map's maximum, and the rings are drawn
 * where the distance to the gaze equals the foveal radius. */
static void test_heatmap_ramp_and_rings(void **st)
{
    (void)st;
    char path[64];
    snprintf(path, sizeof path, "/tmp/fovea-heat2-%d.png", (int)getpid());
    const int w = 64, h = 48;
    float *map = malloc(sizeof(float) * w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) map[y * w + x] = 4.0f * (float)x / (float)(w - 1); /* 0..4 */
    fv_error err;
    assert_int_equal(fv_heatmap_write(path, map, w, h, NULL, &err), FV_OK);
    fv_image img;
    assert_int_equal(fv_image_read(path, &img, &err), FV_OK);
    assert_int_equal(img.width, w);
    assert_int_equal(img.height, h);
    /* Luminance never drops along a row (allowing 8-bit rounding), and the largest value reaches
     * the ramp's end, pale yellow, although vmax was not given. */
    for (int x = 1; x < w; x++) assert_true(luma(img.rgb + 3 * x) >= luma(img.rgb + 3 * (x - 1)) - 0.004f);
    assert_true(img.rgb[3 * (w - 1)] > 0.9f && img.rgb[3 * (w - 1) + 1] > 0.9f);
    assert_true(luma(img.rgb) < 0.01f);
    fv_image_free(&img);

    /* Rings: a pixel whose centre is at the foveal radius from the gaze has the heat-map palette's
     * fovea colour (cyan, gaze/overlay.h), the gaze pixel itself keeps its error colour. */
    fv_eye_model eye;
    fv_eye_model_default(w, h, &eye);
    double rf = fv_eye_fovea_radius_px(&eye);
    assert_true(rf > 1.5 && rf < w / 2 - 1); /* the centre pixel (0.71 px away) is off the ring */
    int xr = (int)floor(w / 2 + rf); /* its centre is within 0.5 px (plus a little for the half-pixel row offset) of rf */
    for (int i = 0; i < w * h; i++) map[i] = 0.0f;
    const fv_heatmap_opts ho = {1.0f, &eye, {0.5f, 0.5f}, NULL};
    assert_int_equal(fv_heatmap_write(path, map, w, h, &ho, &err), FV_OK);
    assert_int_equal(fv_image_read(path, &img, &err), FV_OK);
    const float *ring = img.rgb + 3 * ((h / 2) * w + xr), *centre = img.rgb + 3 * ((h / 2) * w + w / 2);
    assert_float_equal(ring[0], 0.0, 0.01);
    assert_float_equal(ring[1], 1.0, 0.01);
    assert_float_equal(ring[2], 1.0, 0.01);
    assert_true(luma(centre) < 0.01f);
    fv_image_free(&img);
    unlink(path);

    /* An unwritable place is a file problem. */
    assert_int_equal(fv_heatmap_write("/nonexistent-dir/heat.png", map, w, h, NULL, &err), FV_ERR_IO);
    free(map);
}

static void test_bad_sizes(void **st)
{
    (void)st;
    float a[3] = {0, 0, 0}, m[1];
    fv_metric_report r;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, a, 0, 1, NULL, NULL, &r, NULL, &err), FV_ERR_INVALID);
    assert_int_equal(fv_metrics_ssim_map(a, a, 1, -1, m, &err), FV_ERR_INVALID);
    assert_int_equal(fv_metrics_ssim_map(a, a, 1, 1, m, &err), FV_OK);
    assert_float_equal(m[0], 1.0, 1e-6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ssim_offset_ramp),       cmocka_unit_test(test_exposure_and_clamp),
        cmocka_unit_test(test_non_finite_pixels),      cmocka_unit_test(test_region_means_of_flip_map),
        cmocka_unit_test(test_temporal_moving_gaze),   cmocka_unit_test(test_heatmap_ramp_and_rings),
        cmocka_unit_test(test_bad_sizes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
