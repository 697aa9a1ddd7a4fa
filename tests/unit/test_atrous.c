/* The edge-avoiding À-Trous filter: constants stay constant, noise on one surface is smoothed,
 * an edge between two surfaces survives, background pixels are untouched, and one iteration
 * without guides is the B3-spline convolution (worked by hand). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/atrous.h"

static float *image(int w, int h, float v)
{
    float *p = malloc(sizeof(float) * 3 * w * h);
    for (int i = 0; i < 3 * w * h; i++) p[i] = v;
    return p;
}

static float *normals(int w, int h, float nx, float ny, float nz)
{
    float *p = malloc(sizeof(float) * 3 * w * h);
    for (int i = 0; i < w * h; i++) p[3 * i] = nx, p[3 * i + 1] = ny, p[3 * i + 2] = nz;
    return p;
}

static void test_constant(void **st)
{
    (void)st;
    float *c = image(37, 23, 0.42f), *n = normals(37, 23, 0, 0, 1);
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, n, NULL, 37, 23, NULL, &err), FV_OK);
    for (int i = 0; i < 3 * 37 * 23; i++) assert_float_equal(c[i], 0.42f, 1e-6f);
    free(c), free(n);
}

static double variance(const float *c, int n)
{
    double m = 0, v = 0;
    for (int i = 0; i < n; i++) m += c[3 * i];
    m /= n;
    for (int i = 0; i < n; i++) v += (c[3 * i] - m) * (c[3 * i] - m);
    return v / n;
}

/* Uniform noise in [0.3, 0.7] on one flat surface: the variance drops by far more than 4x. */
static void test_noise(void **st)
{
    (void)st;
    const int w = 64, h = 64;
    float *c = image(w, h, 0), *n = normals(w, h, 0, 1, 0);
    unsigned s = 1;
    for (int i = 0; i < w * h; i++) {
        s = s * 1664525u + 1013904223u;
        float v = 0.3f + 0.4f * (float)(s >> 8) / 16777216.0f;
        c[3 * i] = c[3 * i + 1] = c[3 * i + 2] = v;
    }
    double before = variance(c, w * h);
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, n, NULL, w, h, NULL, &err), FV_OK);
    double after = variance(c, w * h);
    assert_true(after < before / 4);
    free(c), free(n);
}

/* Left half bright (0.9) facing +z, right half dark (0.1) facing +x: the edge stays. */
static void test_edge(void **st)
{
    (void)st;
    const int w = 40, h = 20;
    float *c = image(w, h, 0), *n = normals(w, h, 0, 0, 1);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            float v = x < 20 ? 0.9f : 0.1f;
            c[3 * i] = c[3 * i + 1] = c[3 * i + 2] = v;
            if (x >= 20) n[3 * i] = 1, n[3 * i + 2] = 0;
        }
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, n, NULL, w, h, NULL, &err), FV_OK);
    for (int y = 0; y < h; y++) {
        assert_float_equal(c[3 * (y * w + 17)], 0.9f, 0.01f);
        assert_float_equal(c[3 * (y * w + 22)], 0.1f, 0.01f);
    }
    free(c), free(n);
}

/* One iteration on a 5x1 image (1, 0, 0, 0, 0) with a huge colour sigma and no guides is the
 * B3 kernel cut at the border and renormalised. Pixel 0 sees taps 0, 1, 2 with weights 3/8, 1/4,
 * 1/16 (sum 11/16): value (3/8) / (11/16) = 6/11 = 0.545455. Pixel 2 sees all five: 1/16. */
static void test_one_iteration(void **st)
{
    (void)st;
    float c[15] = {1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    fv_atrous_opts o;
    fv_atrous_opts_default(&o);
    o.iterations = 1;
    o.sigma_color = 1e6f;
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, NULL, NULL, 5, 1, &o, &err), FV_OK);
    assert_float_equal(c[0], 6.0f / 11.0f, 1e-5f);
    assert_float_equal(c[6], 1.0f / 16.0f, 1e-6f);
    float one[3] = {0.5f, 0.25f, 0.125f};
    assert_int_equal(fv_atrous_filter(one, NULL, NULL, 1, 1, NULL, &err), FV_OK);
    assert_float_equal(one[1], 0.25f, 0.0f);
}

/* Background pixels (zero normal) keep their value and do not leak into surface pixels. */
static void test_background(void **st)
{
    (void)st;
    const int w = 16, h = 16;
    float *c = image(w, h, 0.5f), *n = normals(w, h, 0, 0, 1);
    for (int x = 0; x < w; x++) {
        size_t i = (size_t)8 * w + x;
        c[3 * i] = 100.0f;
        n[3 * i] = n[3 * i + 1] = n[3 * i + 2] = 0.0f;
    }
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, n, NULL, w, h, NULL, &err), FV_OK);
    assert_float_equal(c[3 * (8 * w + 3)], 100.0f, 0.0f);
    assert_float_equal(c[3 * (7 * w + 3)], 0.5f, 1e-6f);
    fv_atrous_opts o;
    fv_atrous_opts_default(&o);
    o.sigma_color = -1;
    assert_int_equal(fv_atrous_filter(c, n, NULL, w, h, &o, &err), FV_ERR_INVALID);
    free(c), free(n);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant), cmocka_unit_test(test_noise),      cmocka_unit_test(test_edge),
        cmocka_unit_test(test_one_iteration), cmocka_unit_test(test_background),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
