/* LDR-FLIP (src/metrics/flip.c) beyond the grey cases of test_metric_values.c: chromatic uniform
 * images worked out by hand through the colour pipeline, exact symmetry, the range of the map,
 * the effect of the viewing distance (pixels per degree), and bad arguments. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <cmocka.h>
#include "fovea/fovea.h"

static float *filled(int w, int h, float r, float g, float b)
{
    float *p = malloc((size_t)w * h * 3 * sizeof *p);
    for (int i = 0; i < w * h; i++) p[3 * i] = r, p[3 * i + 1] = g, p[3 * i + 2] = b;
    return p;
}

/* Deterministic pseudo-random values in [0, 1). */
static float next(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) / 16777216.0f;
}

static float *noise(int w, int h, unsigned seed)
{
    float *p = malloc((size_t)w * h * 3 * sizeof *p);
    for (int i = 0; i < 3 * w * h; i++) p[i] = next(&seed);
    return p;
}

static double mean(const float *m, int n)
{
    double s = 0.0;
    for (int i = 0; i < n; i++) s += m[i];
    return s / n;
}

/* Uniform images: the CSF kernels sum to one and leave them as they are, and there are no
 * features, so FLIP is the compressed Hunt-adjusted HyAB distance. The largest distance, green
 * vs blue, is 203.297 -> ^0.7 = cmax = 41.2755, and pc * cmax = 16.5102.
 *
 * Red vs green (display = linear for 0 and 1): CIELab red (53.2408, 80.0925, 67.2032), green
 * (87.7347, -86.1827, 83.1793); Hunt (a, b x L/100): red (53.2408, 42.6419, 35.7795), green
 * (87.7347, -75.6122, 72.9771). HyAB = 34.4939 + sqrt(118.2541^2 + 37.1977^2) = 34.4939 +
 * 123.9665 = 158.4604 -> ^0.7 = 34.6693 > 16.5102, so
 * FLIP = 0.95 + (34.6693 - 16.5102) / (41.2755 - 16.5102) * 0.05 = 0.986662.
 *
 * Dark blues, display 0.2 vs 0.3 (linear 0.0331048 vs 0.0732474), where CIELab's linear branch
 * below (6/29)^3 applies: Hunt Lab (2.15828, 0.32733, -0.64885) vs (4.77484, 1.46509, -2.10802);
 * HyAB = 2.61656 + sqrt(1.13776^2 + 1.45917^2) = 2.61656 + 1.85032 = 4.46688 -> ^0.7 = 2.85104
 * < 16.5102, so FLIP = 0.95 / 16.5102 * 2.85104 = 0.164049. */
static void test_uniform_chromatic(void **st)
{
    (void)st;
    const int w = 24, h = 24;
    float *red = filled(w, h, 1, 0, 0), *green = filled(w, h, 0, 1, 0);
    float *b2 = filled(w, h, 0, 0, 0.2f), *b3 = filled(w, h, 0, 0, 0.3f);
    float *map = malloc(sizeof(float) * w * h);
    fv_error err;
    assert_int_equal(fv_metrics_flip_map(red, green, w, h, 67.0f, map, &err), FV_OK);
    assert_float_equal(map[0], 0.986662, 1e-4);
    assert_float_equal(map[w * h - 1], 0.986662, 1e-4);
    assert_float_equal(map[12 * w + 5], 0.986662, 1e-4);
    assert_int_equal(fv_metrics_flip_map(b2, b3, w, h, 67.0f, map, &err), FV_OK);
    assert_float_equal(map[0], 0.164049, 2e-4);
    assert_float_equal(map[7 * w + 19], 0.164049, 2e-4);
    /* Uniform images at another viewing distance: the CSF is normalised, nothing changes. */
    assert_int_equal(fv_metrics_flip_map(b2, b3, w, h, 12.0f, map, &err), FV_OK);
    assert_float_equal(map[7 * w + 19], 0.164049, 2e-4);
    free(red), free(green), free(b2), free(b3), free(map);
}

/* Every step of FLIP treats the two images alike (per-image filtering, |differences|), so
 * swapping them gives the same map; the map stays within [0, 1]. */
static void test_symmetric_and_bounded(void **st)
{
    (void)st;
    const int w = 40, h = 28;
    float *a = noise(w, h, 1), *b = noise(w, h, 2);
    float *m1 = malloc(sizeof(float) * w * h), *m2 = malloc(sizeof(float) * w * h);
    fv_error err;
    assert_int_equal(fv_metrics_flip_map(a, b, w, h, 67.0f, m1, &err), FV_OK);
    assert_int_equal(fv_metrics_flip_map(b, a, w, h, 67.0f, m2, &err), FV_OK);
    for (int i = 0; i < w * h; i++) {
        assert_float_equal(m1[i], m2[i], 1e-5);
        assert_true(m1[i] >= 0.0f && m1[i] <= 1.0f);
    }
    /* Two unrelated noise images are clearly different, though not everywhere maximally. */
    double mu = mean(m1, w * h);
    assert_true(mu > 0.2 && mu < 0.95);
    free(a), free(b), free(m1), free(m2);
}

/* A distortion of growing strength raises FLIP: blend the reference towards a noise image. */
static void test_increasing_with_distortion(void **st)
{
    (void)st;
    const int w = 48, h = 32;
    float *ref = filled(w, h, 0.5f, 0.4f, 0.3f), *nz = noise(w, h, 9);
    for (int y = 0; y < h; y++) /* some smooth structure in the reference */
        for (int x = 0; x < w; x++) ref[3 * (y * w + x)] = 0.2f + 0.6f * (float)x / (float)w;
    float *test = malloc(sizeof(float) * 3 * w * h), *map = malloc(sizeof(float) * w * h);
    fv_error err;
    double prev = 0.0;
    for (int k = 1; k <= 5; k++) {
        float t = 0.08f * (float)k;
        for (int i = 0; i < 3 * w * h; i++) test[i] = (1.0f - t) * ref[i] + t * nz[i];
        assert_int_equal(fv_metrics_flip_map(ref, test, w, h, 67.0f, map, &err), FV_OK);
        double mu = mean(map, w * h);
        assert_true(mu > prev);
        prev = mu;
    }
    free(ref), free(nz), free(test), free(map);
}

/* Pixel-sized noise is harder to see from further away: at more pixels per degree both the CSF
 * (wider in pixels) and the feature detectors (sigma = 0.041 deg x ppd) smooth it out more. */
static void test_viewing_distance(void **st)
{
    (void)st;
    const int w = 48, h = 48;
    float *ref = filled(w, h, 0.5f, 0.5f, 0.5f), *test = malloc(sizeof(float) * 3 * w * h);
    float *map = malloc(sizeof(float) * w * h);
    unsigned s = 77;
    for (int i = 0; i < 3 * w * h; i++) test[i] = 0.5f + 0.3f * (next(&s) - 0.5f);
    fv_error err;
    double prev = 2.0;
    const float ppd[] = {10.0f, 30.0f, 67.0f, 120.0f};
    for (int k = 0; k < 4; k++) {
        assert_int_equal(fv_metrics_flip_map(ref, test, w, h, ppd[k], map, &err), FV_OK);
        double mu = mean(map, w * h);
        assert_true(mu < prev);
        prev = mu;
    }
    free(ref), free(test), free(map);
}

/* FLIP judges display values: in fv_metrics_compare it uses them even with linear = true, and
 * the exposure applies before the display encoding (0.25 x 2 = 0.5 shows like 0.5 x 1). */
static void test_compare_display_values(void **st)
{
    (void)st;
    const int w = 16, h = 16;
    float *a = filled(w, h, 0.25f, 0.25f, 0.25f), *b = filled(w, h, 0.3f, 0.3f, 0.3f);
    float *a2 = filled(w, h, 0.5f, 0.5f, 0.5f), *b2 = filled(w, h, 0.6f, 0.6f, 0.6f);
    fv_metric_opts o;
    fv_metric_opts_default(&o);
    o.exposure = 2.0f;
    fv_metric_report r1, r2;
    fv_error err;
    assert_int_equal(fv_metrics_compare(a, b, w, h, NULL, &o, &r1, NULL, &err), FV_OK);
    o.exposure = 1.0f;
    o.linear = true;
    assert_int_equal(fv_metrics_compare(a2, b2, w, h, NULL, &o, &r2, NULL, &err), FV_OK);
    /* Both pairs show as display 0.735357 vs 0.797738; only the second compares linear values for
     * MSE: 0.01 against (0.062381)^2 = 0.00389. */
    assert_float_equal(r1.region[FV_REGION_ALL].flip, r2.region[FV_REGION_ALL].flip, 1e-6);
    assert_true(r1.region[FV_REGION_ALL].mse < r2.region[FV_REGION_ALL].mse);
    free(a), free(b), free(a2), free(b2);
}

static void test_bad_arguments(void **st)
{
    (void)st;
    float *a = filled(4, 4, 0, 0, 0), map[16];
    fv_error err;
    assert_int_equal(fv_metrics_flip_map(a, a, 4, 4, NAN, map, &err), FV_ERR_INVALID);
    assert_int_equal(fv_metrics_flip_map(a, a, 4, 4, -3.0f, map, &err), FV_ERR_INVALID);
    assert_int_equal(fv_metrics_flip_map(a, a, 0, 4, 67.0f, map, &err), FV_ERR_INVALID);
    fv_metric_opts o;
    fv_metric_opts_default(&o);
    o.ppd = 0.0f;
    fv_metric_report r;
    assert_int_equal(fv_metrics_compare(a, a, 4, 4, NULL, &o, &r, NULL, &err), FV_ERR_INVALID);
    /* A 1x1 image still works: the kernels are clamped to the single pixel. */
    assert_int_equal(fv_metrics_flip_map(a, a, 1, 1, 67.0f, map, &err), FV_OK);
    assert_float_equal(map[0], 0.0, 1e-7);
    free(a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_uniform_chromatic),       cmocka_unit_test(test_symmetric_and_bounded),
        cmocka_unit_test(test_increasing_with_distortion), cmocka_unit_test(test_viewing_distance),
        cmocka_unit_test(test_compare_display_values),  cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
