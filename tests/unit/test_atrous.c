/* The edge-avoiding À-Trous filter: constants stay constant, noise on one surface is smoothed,
 * an edge between two surfaces survives, background pixels are untouched, one and two iterations
 * without guides are the B3-spline convolution with holes (worked by hand), degenerate sizes work,
 * the position guide separates surfaces, and the result is exposure- and thread-count-independent. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <omp.h>
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

/* Uniform noise in [0.3, 0.7] on one flat surface (variance 0.4^2/12 = 0.0133). Measured with the
 * defaults: 0.000501 after five passes (1/26.7); one pass alone leaves 0.30 of it, so the bound of
 * 1/10 also fails if the coarser passes stop contributing. */
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
    assert_true(before > 0.0130 && before < 0.0137);
    assert_true(after < before / 10);
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
    /* Columns 18 and 21 are two pixels from the crease (between 19 and 20): every tap across it
     * carries e^-22 from the normal term and a colour difference of 0.8 against a sigma of
     * 0.8 * 0.5 = 0.4 (mean luminance 0.5), so a few % is a generous bound. */
    for (int y = 0; y < h; y++) {
        assert_float_equal(c[3 * (y * w + 18)], 0.9f, 0.02f);
        assert_float_equal(c[3 * (y * w + 21)], 0.1f, 0.002f);
        assert_float_equal(c[3 * (y * w + 17)], 0.9f, 0.01f);
        assert_float_equal(c[3 * (y * w + 22)], 0.1f, 0.01f);
    }
    /* A faint step (0.50 | 0.55) on the same crease: the colour term alone would let it through
     * (3 * 0.05^2 / (0.8 * 0.525)^2 = 0.043, weight 0.96), so only the normal term (e^-22) keeps
     * the two sides apart; next to the crease each side keeps its value. */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            c[3 * i] = c[3 * i + 1] = c[3 * i + 2] = x < 20 ? 0.50f : 0.55f;
        }
    assert_int_equal(fv_atrous_filter(c, n, NULL, w, h, NULL, &err), FV_OK);
    for (int y = 0; y < h; y++) {
        assert_float_equal(c[3 * (y * w + 19)], 0.50f, 1e-5f);
        assert_float_equal(c[3 * (y * w + 20)], 0.55f, 1e-5f);
    }
    free(c), free(n);
}

/* Options for the hand-worked cases: no colour stopping to speak of (sigma_color 1e6 times a
 * mean luminance >= 0.2 makes every colour term < 1e-10, so expf gives exactly 1). */
static fv_atrous_opts plain(int iterations)
{
    fv_atrous_opts o;
    fv_atrous_opts_default(&o);
    o.iterations = iterations;
    o.sigma_color = 1e6f;
    return o;
}

/* One iteration on a 5x1 image with no guides is the B3 kernel (1/16, 1/4, 3/8, 1/4, 1/16) cut at
 * the border and renormalised by the weights that remain.
 * Impulse (1, 0, 0, 0, 0):
 *   x=0 sees offsets 0..+2: weights 3/8, 1/4, 1/16 (sum 11/16); value (3/8)/(11/16)  = 6/11
 *   x=1 sees offsets -1..+2: 1/4, 3/8, 1/4, 1/16 (sum 15/16); value (1/4)/(15/16)   = 4/15
 *   x=2 sees all five (sum 1);                           value 1/16
 *   x=3, x=4: the impulse is 3 and 4 pixels away, outside the kernel      = 0
 * Ramp (1, 2, 3, 4, 5):
 *   x=0: (3/8*1 + 1/4*2 + 1/16*3) / (11/16) = (6 + 8 + 3)/16 * 16/11     = 17/11
 *   x=1: (1/4*1 + 3/8*2 + 1/4*3 + 1/16*4) / (15/16) = (4+12+12+4)/15     = 32/15
 *   x=2: symmetric kernel on a line                                       = 3
 *   x=3, x=4 by symmetry: 6 - 32/15 = 58/15, 6 - 17/11 = 49/11 */
static void test_one_iteration(void **st)
{
    (void)st;
    const float impulse[5] = {1, 0, 0, 0, 0}, ramp[5] = {1, 2, 3, 4, 5};
    const float want_impulse[5] = {6.0f / 11, 4.0f / 15, 1.0f / 16, 0, 0};
    const float want_ramp[5] = {17.0f / 11, 32.0f / 15, 3, 58.0f / 15, 49.0f / 11};
    fv_atrous_opts o = plain(1);
    fv_error err;
    /* 5x1 (a row) and 1x5 (a column) must agree: the kernel is the same along both axes. */
    for (int vertical = 0; vertical < 2; vertical++) {
        float a[15], b[15];
        for (int i = 0; i < 5; i++)
            for (int k = 0; k < 3; k++) a[3 * i + k] = impulse[i], b[3 * i + k] = ramp[i];
        int w = vertical ? 1 : 5, h = vertical ? 5 : 1;
        assert_int_equal(fv_atrous_filter(a, NULL, NULL, w, h, &o, &err), FV_OK);
        assert_int_equal(fv_atrous_filter(b, NULL, NULL, w, h, &o, &err), FV_OK);
        for (int i = 0; i < 5; i++)
            for (int k = 0; k < 3; k++) {
                assert_float_equal(a[3 * i + k], want_impulse[i], 1e-6f);
                assert_float_equal(b[3 * i + k], want_ramp[i], 1e-5f);
            }
    }
}

/* The second pass spreads its taps 2 pixels apart. From the impulse's first pass
 * a = (6/11, 4/15, 1/16, 0, 0):
 *   x=0 sees x=0, 2, 4 at offsets 0, +1, +2: (3/8*6/11 + 1/4*1/16 + 0) / (11/16)
 *       = (18/88 + 1/64) * 16/11 = 155/704 * 16/11 = 155/484 = 0.320248
 *   x=2 sees x=0, 2, 4 at offsets -1, 0, +1 (x=-2 and 6 fall outside), weights sum 7/8:
 *       (1/4*6/11 + 3/8*1/16) / (7/8) = (3/22 + 3/128) * 8/7 = 225/1408 * 8/7 = 225/1232 = 0.182630
 *   x=4 sees x=0, 2, 4 at offsets -2, -1, 0: (1/16*6/11 + 1/4*1/16) / (11/16) = (6/11 + 1/4)/11
 *       = 35/484 = 0.072314 */
static void test_two_iterations(void **st)
{
    (void)st;
    float c[15] = {1, 1, 1};
    memset(c + 3, 0, 12 * sizeof(float));
    fv_atrous_opts o = plain(2);
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, NULL, NULL, 5, 1, &o, &err), FV_OK);
    assert_float_equal(c[0], 155.0f / 484, 1e-6f);
    assert_float_equal(c[6], 225.0f / 1232, 1e-6f);
    assert_float_equal(c[12], 35.0f / 484, 1e-6f);
}

/* The colour sigma halves at the second pass. A 5x1 image whose only surfaces are x=0 (value 0)
 * and x=4 (value 1), with background (zero normal) between: pass 1 (taps 1 apart) finds no other
 * surface within 2 pixels and changes nothing; pass 2 (taps 2 apart) lets x=0 see x=4 at offset +2
 * (B3 weight 1/16). Mean luminance 1/2, so sigma_1 = sigma_color * 1/2 * 2^-1 = sigma_color/4 and
 * the colour term is |c_0 - c_4|^2 / sigma_1^2 = 3 * 16 / sigma_color^2. With
 * sigma_color^2 = 48 / ln 2 that is ln 2: the tap weighs 1/16 * 1/2 = 1/32, and
 *   x=0: (3/8 * 0 + 1/32 * 1) / (3/8 + 1/32) = 1/13,   x=4: (3/8 * 1) / (13/32) = 12/13.
 * (Without the halving the term would be ln2/4 and x=0 would come out at 0.123.) */
static void test_color_sigma_halves(void **st)
{
    (void)st;
    float c[15], n[15];
    for (int i = 0; i < 5; i++) {
        float v = i == 4 ? 1.0f : i == 0 ? 0.0f : 100.0f;
        c[3 * i] = c[3 * i + 1] = c[3 * i + 2] = v;
        n[3 * i] = n[3 * i + 1] = 0, n[3 * i + 2] = i == 0 || i == 4 ? 1.0f : 0.0f;
    }
    fv_atrous_opts o;
    fv_atrous_opts_default(&o);
    o.iterations = 2;
    o.sigma_color = sqrtf(48.0f / logf(2.0f));
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, n, NULL, 5, 1, &o, &err), FV_OK);
    assert_float_equal(c[0], 1.0f / 13, 1e-6f);
    assert_float_equal(c[12], 12.0f / 13, 1e-6f);
    assert_float_equal(c[6], 100.0f, 0.0f);
}

/* Degenerate sizes: one pixel (its only tap is itself), and a 1x7 column with all five passes,
 * whose coarse taps (8 and 16 apart) all fall outside the image: a constant stays constant and
 * the column stays symmetric. */
static void test_small_images(void **st)
{
    (void)st;
    fv_error err;
    float one[3] = {0.5f, 0.25f, 0.125f};
    float n1[3] = {0, 0, 1};
    assert_int_equal(fv_atrous_filter(one, NULL, NULL, 1, 1, NULL, &err), FV_OK);
    assert_int_equal(fv_atrous_filter(one, n1, one, 1, 1, NULL, &err), FV_OK);
    assert_float_equal(one[0], 0.5f, 0.0f);
    assert_float_equal(one[1], 0.25f, 0.0f);
    assert_float_equal(one[2], 0.125f, 0.0f);

    float *c = image(1, 7, 2.0f), *n = normals(1, 7, 0, 0, 1);
    assert_int_equal(fv_atrous_filter(c, n, NULL, 1, 7, NULL, &err), FV_OK);
    for (int i = 0; i < 21; i++) assert_float_equal(c[i], 2.0f, 1e-6f);
    const float v[7] = {0.1f, 0.3f, 0.2f, 0.6f, 0.2f, 0.3f, 0.1f};
    for (int i = 0; i < 7; i++) c[3 * i] = c[3 * i + 1] = c[3 * i + 2] = v[i];
    fv_atrous_opts o = plain(5);
    assert_int_equal(fv_atrous_filter(c, n, NULL, 1, 7, &o, &err), FV_OK);
    for (int i = 0; i < 3; i++) assert_float_equal(c[3 * i], c[3 * (6 - i)], 1e-6f);
    assert_true(c[9] < 0.6f && c[9] > 0.2f); /* the peak was smoothed, not left alone */
    free(c), free(n);
}

/* The position guide alone (normal NULL) separates two surfaces 10 units apart: with
 * sigma_position 0.5 a tap across them weighs e^-400 = 0 in float, so each half keeps its value
 * exactly; without the guide the halves mix at the seam. */
static void test_position_guide(void **st)
{
    (void)st;
    const int w = 8;
    float c[24], x[24];
    for (int i = 0; i < w; i++) {
        float v = i < 4 ? 0.2f : 0.8f;
        c[3 * i] = c[3 * i + 1] = c[3 * i + 2] = v;
        x[3 * i] = (float)i * 0.01f, x[3 * i + 1] = 0, x[3 * i + 2] = i < 4 ? 0.0f : 10.0f;
    }
    float d[24];
    memcpy(d, c, sizeof c);
    fv_atrous_opts o = plain(3);
    o.sigma_position = 0.5f;
    fv_error err;
    assert_int_equal(fv_atrous_filter(c, NULL, x, w, 1, &o, &err), FV_OK);
    for (int i = 0; i < w; i++) assert_float_equal(c[3 * i], i < 4 ? 0.2f : 0.8f, 1e-6f);
    assert_int_equal(fv_atrous_filter(d, NULL, NULL, w, 1, &o, &err), FV_OK);
    assert_true(d[3 * 3] > 0.3f && d[3 * 4] < 0.7f);
}

/* sigma_color is relative to the mean luminance, so scaling the image by 1024 scales the result
 * by 1024; a power of two scales every intermediate exactly (the colour term dc/sigma^2 is
 * unchanged bit for bit), so the match is exact. The result does not depend on the thread count. */
static void test_exposure_and_threads(void **st)
{
    (void)st;
    const int w = 24, h = 16;
    float *a = image(w, h, 0), *b = image(w, h, 0), *c1 = image(w, h, 0), *n = normals(w, h, 0, 0, 1);
    unsigned s = 7;
    for (int i = 0; i < 3 * w * h; i++) {
        s = s * 1664525u + 1013904223u;
        a[i] = (float)(s >> 8) / 16777216.0f;
        b[i] = 1024.0f * a[i];
        c1[i] = a[i];
    }
    fv_error err;
    assert_int_equal(fv_atrous_filter(a, n, NULL, w, h, NULL, &err), FV_OK);
    assert_int_equal(fv_atrous_filter(b, n, NULL, w, h, NULL, &err), FV_OK);
    for (int i = 0; i < 3 * w * h; i++) assert_float_equal(b[i], 1024.0f * a[i], 0.0f);
    int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    assert_int_equal(fv_atrous_filter(c1, n, NULL, w, h, NULL, &err), FV_OK);
    omp_set_num_threads(saved);
    assert_memory_equal(a, c1, sizeof(float) * 3 * w * h);
    free(a), free(b), free(c1), free(n);
}

/* A workspace reused across images of other sizes (a larger one first, so the smaller one reads
 * buffers holding its leftovers) and an explicit thread count give the bytes of a call with its
 * own scratch. */
static void test_workspace(void **st)
{
    (void)st;
    fv_error err;
    fv_atrous *ws;
    assert_int_equal(fv_atrous_create(&ws, &err), FV_OK);
    const int sizes[3][2] = {{31, 23}, {12, 9}, {40, 30}};
    for (int k = 0; k < 3; k++) {
        const int w = sizes[k][0], h = sizes[k][1];
        float *a = image(w, h, 0), *b = image(w, h, 0), *n = normals(w, h, 0, 0, 1);
        unsigned s = 11u + (unsigned)k;
        for (int i = 0; i < 3 * w * h; i++) {
            s = s * 1664525u + 1013904223u;
            a[i] = b[i] = (float)(s >> 8) / 16777216.0f;
        }
        fv_atrous_opts o;
        fv_atrous_opts_default(&o);
        assert_int_equal(fv_atrous_filter(a, n, NULL, w, h, &o, &err), FV_OK);
        o.workspace = ws;
        o.threads = 1 + k % 2;
        assert_int_equal(fv_atrous_filter(b, n, NULL, w, h, &o, &err), FV_OK);
        assert_memory_equal(a, b, sizeof(float) * 3 * w * h);
        free(a), free(b), free(n);
    }
    fv_atrous_destroy(ws);
    fv_atrous_destroy(NULL);
}

/* Bad arguments fail with FV_ERR_INVALID and a message naming the field; a non-finite pixel is
 * not used by its neighbours. */
static void test_invalid_and_nonfinite(void **st)
{
    (void)st;
    float c[12] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    fv_error err;
    fv_atrous_opts o;
    fv_atrous_opts_default(&o);
    o.iterations = -1;
    assert_int_equal(fv_atrous_filter(c, NULL, NULL, 4, 1, &o, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "iterations -1"));
    fv_atrous_opts_default(&o);
    o.sigma_normal = 0.0f;
    assert_int_equal(fv_atrous_filter(c, NULL, NULL, 4, 1, &o, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "sigma_normal"));
    assert_int_equal(fv_atrous_filter(c, NULL, NULL, 0, 1, NULL, &err), FV_ERR_INVALID);
    assert_int_equal(fv_atrous_filter(NULL, NULL, NULL, 4, 1, NULL, &err), FV_ERR_INVALID);
    c[3] = NAN;
    assert_int_equal(fv_atrous_filter(c, NULL, NULL, 4, 1, NULL, &err), FV_OK);
    assert_float_equal(c[0], 0.5f, 1e-6f);
    assert_float_equal(c[6], 0.5f, 1e-6f);
    assert_float_equal(c[9], 0.5f, 1e-6f);
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
    /* Again with colour and normal terms that let everything through: only the zero-normal rule
     * keeps the 100s out of row 7. */
    fv_atrous_opts wide;
    fv_atrous_opts_default(&wide);
    wide.sigma_color = 1e9f;
    wide.sigma_normal = 1e9f;
    assert_int_equal(fv_atrous_filter(c, n, NULL, w, h, &wide, &err), FV_OK);
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
        cmocka_unit_test(test_one_iteration), cmocka_unit_test(test_two_iterations),
        cmocka_unit_test(test_color_sigma_halves), cmocka_unit_test(test_small_images),
        cmocka_unit_test(test_position_guide), cmocka_unit_test(test_exposure_and_threads), cmocka_unit_test(test_workspace),
        cmocka_unit_test(test_invalid_and_nonfinite), cmocka_unit_test(test_background),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
