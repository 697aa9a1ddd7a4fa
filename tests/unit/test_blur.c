/* The foveated blur (Visual-Polar Sec. 3.5): the sigma profile worked by hand, sigma 0 leaves the
 * image bit-identical, constants stay constant up to the border, an impulse spreads with variance
 * sigma^2 on each axis, keeps its energy and its peak within 15% of the Gaussian's (three boxes), the result does not
 * depend on the thread count, and bad input is refused with the image untouched. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/blur.h"

static float *filled(int n, float v)
{
    float *p = malloc(sizeof(float) * (size_t)n);
    for (int i = 0; i < n; i++) p[i] = v;
    return p;
}

/* 0 up to the fovea, linear to sigma_max at the ramp's end, held beyond: fovea 5, ramp 30, max 6.8
 * gives 6.8 * 12.5 / 25 = 3.4 at 17.5 degrees and 6.8 * 5 / 25 = 1.36 at 10. */
static void test_sigma_profile(void **st)
{
    (void)st;
    assert_float_equal(fv_blur_sigma_at(0.0, 5.0, 30.0, 6.8), 0.0, 0.0);
    assert_float_equal(fv_blur_sigma_at(5.0, 5.0, 30.0, 6.8), 0.0, 0.0);
    assert_float_equal(fv_blur_sigma_at(10.0, 5.0, 30.0, 6.8), 1.36, 1e-12);
    assert_float_equal(fv_blur_sigma_at(17.5, 5.0, 30.0, 6.8), 3.4, 1e-12);
    assert_float_equal(fv_blur_sigma_at(30.0, 5.0, 30.0, 6.8), 6.8, 1e-12);
    assert_float_equal(fv_blur_sigma_at(70.0, 5.0, 30.0, 6.8), 6.8, 1e-12);
}

static void test_zero_sigma_identity(void **st)
{
    (void)st;
    const int w = 31, h = 17;
    float *img = malloc(sizeof(float) * 3 * w * h), *ref = malloc(sizeof(float) * 3 * w * h);
    for (int i = 0; i < 3 * w * h; i++) img[i] = ref[i] = (float)((i * 37) % 101) / 7.0f;
    float *sig = filled(w * h, 0.0f);
    fv_error err;
    assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
    assert_memory_equal(img, ref, sizeof(float) * 3 * w * h);
    free(img), free(ref), free(sig);
}

/* A constant image stays constant whatever the sigma field, borders included (renormalised boxes). */
static void test_constant(void **st)
{
    (void)st;
    const int w = 40, h = 33;
    float *img = filled(3 * w * h, 0.37f), *sig = malloc(sizeof(float) * w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) sig[y * w + x] = (float)fv_blur_sigma_at(hypot(x - 20.0, y - 16.0), 3.0, 18.0, 6.8);
    fv_error err;
    assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
    for (int i = 0; i < 3 * w * h; i++) assert_float_equal(img[i], 0.37f, 2e-6f);
    free(img), free(sig);
}

/* An impulse under a constant sigma: energy kept, variance sigma^2 on each axis (three boxes whose
 * variances add up exactly), the peak within 15% of the 2-D Gaussian's 1 / (2 pi sigma^2) and the
 * profile symmetric. */
static void test_impulse(void **st)
{
    (void)st;
    const int w = 81, h = 81;
    const float sigmas[3] = {0.7f, 2.5f, 6.8f};
    for (int k = 0; k < 3; k++) {
        float s = sigmas[k];
        float *img = filled(3 * w * h, 0.0f), *sig = filled(w * h, s);
        img[3 * (40 * w + 40) + 1] = 1.0f;
        fv_error err;
        assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
        double e = 0.0, vx = 0.0, vy = 0.0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double v = img[3 * (y * w + x) + 1];
                assert_float_equal(img[3 * (y * w + x)], 0.0f, 0.0f); /* channels stay apart */
                e += v, vx += v * (x - 40) * (x - 40), vy += v * (y - 40) * (y - 40);
            }
        assert_float_equal(e, 1.0, 1e-5);
        assert_float_equal(vx, (double)s * s, 0.01 * s * s + 1e-4);
        assert_float_equal(vy, (double)s * s, 0.01 * s * s + 1e-4);
        double peak = img[3 * (40 * w + 40) + 1], gauss = 1.0 / (2.0 * M_PI * s * s);
        print_message("sigma %.1f: peak %.5f, Gaussian %.5f\n", s, peak, gauss);
        if (s > 1.0f) assert_true(fabs(peak / gauss - 1.0) < 0.15);
        assert_float_equal(img[3 * (40 * w + 43) + 1], img[3 * (40 * w + 37) + 1], 1e-7f);
        assert_float_equal(img[3 * (43 * w + 40) + 1], img[3 * (40 * w + 43) + 1], 1e-7f);
        free(img), free(sig);
    }
}

/* Only pixels with a sigma move: a step edge inside a sigma-0 region stays sharp while the same
 * edge where sigma > 0 is smoothed. */
static void test_fovea_untouched(void **st)
{
    (void)st;
    const int w = 64, h = 8;
    float *img = malloc(sizeof(float) * 3 * w * h), *sig = malloc(sizeof(float) * w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float v = (x % 32) < 16 ? 0.0f : 1.0f;
            img[3 * (y * w + x)] = img[3 * (y * w + x) + 1] = img[3 * (y * w + x) + 2] = v;
            sig[y * w + x] = x < 32 ? 0.0f : 3.0f;
        }
    fv_error err;
    assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
    assert_float_equal(img[3 * (4 * w + 15)], 0.0f, 0.0f);
    assert_float_equal(img[3 * (4 * w + 16)], 1.0f, 0.0f);
    assert_true(img[3 * (4 * w + 47)] > 0.2f && img[3 * (4 * w + 48)] < 0.8f);
    free(img), free(sig);
}

static void test_threads(void **st)
{
    (void)st;
    const int w = 120, h = 90;
    float *a = malloc(sizeof(float) * 3 * w * h), *b = malloc(sizeof(float) * 3 * w * h), *sig = malloc(sizeof(float) * w * h);
    for (int i = 0; i < 3 * w * h; i++) a[i] = b[i] = (float)((i * 7919) % 1000) / 1000.0f;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) sig[y * w + x] = (float)fv_blur_sigma_at(hypot(x - 60.0, y - 45.0) / 2.0, 4.0, 30.0, 6.8);
    fv_error err;
    assert_int_equal(fv_blur_variable(a, w, h, sig, 1, &err), FV_OK);
    assert_int_equal(fv_blur_variable(b, w, h, sig, 2, &err), FV_OK);
    assert_memory_equal(a, b, sizeof(float) * 3 * w * h);
    free(a), free(b), free(sig);
}

static void test_bad_input(void **st)
{
    (void)st;
    const int w = 8, h = 8;
    float *img = filled(3 * w * h, 0.5f), *sig = filled(w * h, 1.0f);
    fv_error err;
    assert_int_equal(fv_blur_variable(NULL, w, h, sig, 1, &err), FV_ERR_INVALID);
    assert_int_equal(fv_blur_variable(img, w, h, NULL, 1, &err), FV_ERR_INVALID);
    assert_int_equal(fv_blur_variable(img, 0, h, sig, 1, &err), FV_ERR_INVALID);
    sig[13] = -1.0f;
    assert_int_equal(fv_blur_variable(img, w, h, sig, 1, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "sigma"));
    sig[13] = NAN;
    assert_int_equal(fv_blur_variable(img, w, h, sig, 1, &err), FV_ERR_INVALID);
    for (int i = 0; i < 3 * w * h; i++) assert_float_equal(img[i], 0.5f, 0.0f);
    free(img), free(sig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sigma_profile), cmocka_unit_test(test_zero_sigma_identity), cmocka_unit_test(test_constant),
        cmocka_unit_test(test_impulse),       cmocka_unit_test(test_fovea_untouched),     cmocka_unit_test(test_threads),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
