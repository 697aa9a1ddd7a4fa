/* The foveated blur (Visual-Polar Sec. 3.5): the sigma profile worked by hand; sigma 0 (and any
 * sigma whose kernel keeps only its centre) leaves pixels bit-identical; constants stay constant
 * under any sigma field, borders included; an impulse spreads with the Gaussian weights worked by
 * hand, keeps its energy and has the variance of the truncated kernel on each axis; the border
 * renormalisation worked by hand on a row and a column; every pixel matches a plain double-precision
 * implementation of the contract (its own rounded sigma in both passes); kernels wider than the
 * table and than the image; the result does not depend on the thread count; bad input is refused
 * with the image untouched. */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/blur.h"
#include "filter/kblur.h"

static float *filled(size_t n, float v)
{
    float *p = malloc(sizeof(float) * n);
    for (size_t i = 0; i < n; i++) p[i] = v;
    return p;
}

/* Uniform in [lo, hi), a fixed LCG so the tests are repeatable. */
static float *noise(size_t n, float lo, float hi, unsigned seed)
{
    float *p = malloc(sizeof(float) * n);
    for (size_t i = 0; i < n; i++) {
        seed = seed * 1664525u + 1013904223u;
        p[i] = lo + (hi - lo) * (float)(seed >> 8) / 16777216.0f;
    }
    return p;
}

/* The paper's field on a w x h image: 0 within `fovea` pixels of (gx, gy), linear to smax at
 * `ramp` pixels, smax beyond. */
static float *foveated_sigma(int w, int h, double gx, double gy, double fovea, double ramp, double smax)
{
    float *s = malloc(sizeof(float) * (size_t)w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            s[(size_t)y * w + x] = (float)fv_blur_sigma_at(hypot(x + 0.5 - gx, y + 0.5 - gy), fovea, ramp, smax);
    return s;
}

/* 0 up to the fovea, linear to sigma_max at the ramp's end, held beyond: fovea 5, ramp 30, max 6.8
 * gives 6.8 * 12.5 / 25 = 3.4 at 17.5 degrees and 6.8 * 5 / 25 = 1.36 at 10. */
static void test_sigma_profile(void **st)
{
    (void)st;
    assert_float_equal(fv_blur_sigma_at(0.0, 5.0, 30.0, 6.8), 0.0, 0.0);
    assert_float_equal(fv_blur_sigma_at(4.9, 5.0, 30.0, 6.8), 0.0, 0.0);
    assert_float_equal(fv_blur_sigma_at(5.0, 5.0, 30.0, 6.8), 0.0, 0.0);
    assert_float_equal(fv_blur_sigma_at(10.0, 5.0, 30.0, 6.8), 1.36, 1e-12);
    assert_float_equal(fv_blur_sigma_at(17.5, 5.0, 30.0, 6.8), 3.4, 1e-12);
    assert_float_equal(fv_blur_sigma_at(30.0, 5.0, 30.0, 6.8), 6.8, 1e-12);
    assert_float_equal(fv_blur_sigma_at(45.0, 5.0, 30.0, 6.8), 6.8, 1e-12);
    assert_float_equal(fv_blur_sigma_at(NAN, 5.0, 30.0, 6.8), 0.0, 0.0);
    /* a ramp that ends where the fovea does is a step */
    assert_float_equal(fv_blur_sigma_at(4.0, 5.0, 5.0, 2.0), 0.0, 0.0);
    assert_float_equal(fv_blur_sigma_at(5.5, 5.0, 5.0, 2.0), 2.0, 0.0);
}

/* Sigma 0 everywhere returns the image bit for bit (values of any sign and size). So does sigma
 * 0.3: truncated at 3 sigma = 0.9 pixel its kernel is the centre alone. In a foveated field the
 * pixels whose sigma rounds to 10/32 or less (3 sigma < 1: sigma < 10.5 / 32) keep their bits and
 * the others change. */
static void test_zero_sigma_identity(void **st)
{
    (void)st;
    const int w = 71, h = 45;
    const size_t n = (size_t)w * h;
    float *img = noise(3 * n, -1e3f, 1e3f, 11), *ref = malloc(sizeof(float) * 3 * n);
    memcpy(ref, img, sizeof(float) * 3 * n);
    fv_error err;
    const float flat[3] = {0.0f, 0.04f, 0.3f};
    for (int k = 0; k < 3; k++) {
        float *sig = filled(n, flat[k]);
        assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
        assert_memory_equal(img, ref, sizeof(float) * 3 * n);
        free(sig);
    }
    float *sig = foveated_sigma(w, h, 35.5, 22.5, 6.0, 30.0, 3.0);
    assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
    size_t kept = 0, moved = 0;
    for (size_t i = 0; i < n; i++) {
        if (sig[i] < 10.5f / 32.0f) {
            assert_memory_equal(&img[3 * i], &ref[3 * i], 3 * sizeof(float));
            kept++;
        } else if (memcmp(&img[3 * i], &ref[3 * i], 3 * sizeof(float)) != 0) {
            moved++;
        }
    }
    assert_true(kept > 100);                       /* the disc of radius ~6.7 */
    assert_true(moved > n - kept - n / 100);       /* noise: nearly every blurred pixel changes */
    free(img), free(ref), free(sig);
}

/* A constant stays constant whatever the sigma field, at the borders too (the weights that fall
 * outside the image are dropped and the rest renormalised): random fields with kernels from 0 to
 * 27 taps, the paper's profile with its gaze in a corner, and single rows and columns. */
static void test_constant(void **st)
{
    (void)st;
    const int sizes[][2] = {{40, 33}, {1, 29}, {29, 1}, {3, 2}, {130, 70}};
    fv_error err;
    for (int t = 0; t < 5; t++) {
        const int w = sizes[t][0], h = sizes[t][1];
        const size_t n = (size_t)w * h;
        for (int field = 0; field < 2; field++) {
            float *img = filled(3 * n, 0.37f);
            float *sig = field ? foveated_sigma(w, h, 0.0, 0.0, 3.0, 40.0, 6.8) : noise(n, 0.0f, 9.0f, 5 + t);
            assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
            for (size_t i = 0; i < 3 * n; i++) assert_float_equal(img[i], 0.37f, 2e-7f);
            free(img), free(sig);
        }
    }
}

/* Sigma 1 (on the grid, 3 taps each side): g(d) = exp(-d^2 / 2) = 1, 0.6065307, 0.1353353, 0.0111090,
 * sum 1 + 2 (0.7529750) = 2.5059499, so k = 0.3990503, 0.2420362, 0.0540056, 0.0044330. An impulse
 * in the middle of a 41 x 41 image becomes k(dx) k(dy): centre 0.1592411, one step 0.0965846, one
 * diagonal step 0.0585815, three steps 0.0017690, four steps 0 (beyond 3 sigma), (3, 3) 1.96519e-5.
 * The three channels carry 1, 2 and 4 and stay apart; the energy is kept. */
static void test_impulse_weights(void **st)
{
    (void)st;
    const int w = 41, h = 41, c = 20;
    float *img = filled(3 * (size_t)w * h, 0.0f), *sig = filled((size_t)w * h, 1.0f);
    const size_t ic = (size_t)c * w + c;
    img[3 * ic] = 1.0f, img[3 * ic + 1] = 2.0f, img[3 * ic + 2] = 4.0f;
    fv_error err;
    assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
#define AT(dx, dy, ch) img[3 * ((size_t)(c + (dy)) * w + (size_t)(c + (dx))) + (ch)]
    for (int ch = 0; ch < 3; ch++) {
        const float s = (float)(1 << ch);
        assert_float_equal(AT(0, 0, ch), s * 0.15924113f, s * 2e-7f);
        assert_float_equal(AT(1, 0, ch), s * 0.09658463f, s * 2e-7f);
        assert_float_equal(AT(0, -1, ch), s * 0.09658463f, s * 2e-7f);
        assert_float_equal(AT(-1, 1, ch), s * 0.05858154f, s * 2e-7f);
        assert_float_equal(AT(3, 0, ch), s * 0.00176901f, s * 2e-8f);
        assert_float_equal(AT(0, -3, ch), s * 0.00176901f, s * 2e-8f);
        assert_float_equal(AT(3, 3, ch), s * 1.965192e-5f, s * 1e-10f);
        assert_float_equal(AT(4, 0, ch), 0.0f, 0.0f);
        assert_float_equal(AT(0, 4, ch), 0.0f, 0.0f);
        double e = 0.0;
        for (size_t i = 0; i < (size_t)w * h; i++) e += img[3 * i + ch];
        assert_float_equal(e, s, s * 1e-6);
    }
#undef AT
    free(img), free(sig);
}

/* An impulse away from the border keeps its energy and its centre, and its variance on each axis is
 * that of the truncated, sampled kernel, within 2.5% of sigma^2: sum d^2 g(d) / sum g(d) over |d| <= 3 sigma, g = exp(-d^2 / 2 sigma^2), worked
 * out as 3.951263 for sigma 2 (6 taps each side), 2.196589 for 1.5 (4 taps) and 44.46937 for 6.75
 * (20 taps; 6.8 rounds to 6.75 on the grid of 1/8 pixel between 4 and 8). */
static void test_variance(void **st)
{
    (void)st;
    const float sigma[3] = {2.0f, 1.5f, 6.8f};
    const double want[3] = {3.951263, 2.196589, 44.46937}, s2[3] = {4.0, 2.25, 6.75 * 6.75};
    /* 81 x 81 with the impulse in the middle: no pixel it reaches is within 20 (the widest radius)
     * of the border, where the renormalisation (which keeps constants, not energy) would scale it */
    const int w = 81, h = 81, c = 40;
    fv_error err;
    for (int t = 0; t < 3; t++) {
        float *img = filled(3 * (size_t)w * h, 0.0f), *sig = filled((size_t)w * h, sigma[t]);
        img[3 * ((size_t)c * w + c) + 1] = 1.0f;
        assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
        double e = 0.0, vx = 0.0, vy = 0.0, mx = 0.0, my = 0.0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double v = img[3 * ((size_t)y * w + x) + 1];
                e += v, mx += v * (x - c), my += v * (y - c);
                vx += v * (x - c) * (x - c), vy += v * (y - c) * (y - c);
            }
        assert_float_equal(e, 1.0, 1e-5);
        assert_float_equal(mx, 0.0, 1e-5);
        assert_float_equal(my, 0.0, 1e-5);
        assert_float_equal(vx, want[t], 1e-4 * want[t]);
        assert_float_equal(vy, want[t], 1e-4 * want[t]);
        assert_true(fabs(vx / s2[t] - 1.0) < 0.025);
        free(img), free(sig);
    }
}

/* The border renormalisation worked by hand on a 5-pixel row with sigma 1 (g = 1, 0.6065307,
 * 0.1353353, 0.0111090) and an impulse at pixel 0; each pixel divides by the weights of the taps
 * that fall inside [0, 4]:
 *   x=0 sees d = 0..3:   1 / (1 + 0.6065307 + 0.1353353 + 0.0111090)          = 0.5704588
 *   x=1 sees d = -1..3:  0.6065307 / (2 * 0.6065307 + 1 + 0.1353353 + 0.0111090) = 0.2570584
 *   x=2 sees d = -2..2:  0.1353353 / (1 + 2 * 0.6065307 + 2 * 0.1353353)     = 0.0544887
 *   x=3 sees d = -3..1:  0.0111090 / (0.0111090 + 0.1353353 + 2 * 0.6065307 + 1) = 0.0047082
 *   x=4: the impulse is 4 pixels away, beyond 3 sigma                         = 0
 * The same on a 5-pixel column. A single row has no other row to mix with: the vertical pass keeps
 * it (to rounding). */
static void test_border_by_hand(void **st)
{
    (void)st;
    const float want[5] = {0.5704588f, 0.2570584f, 0.0544887f, 0.0047082f, 0.0f};
    fv_error err;
    for (int vertical = 0; vertical < 2; vertical++) {
        float img[15] = {0}, sig[5] = {1, 1, 1, 1, 1};
        img[0] = img[1] = img[2] = 1.0f;
        assert_int_equal(fv_blur_variable(img, vertical ? 1 : 5, vertical ? 5 : 1, sig, 1, &err), FV_OK);
        for (int i = 0; i < 5; i++)
            for (int ch = 0; ch < 3; ch++) assert_float_equal(img[3 * i + ch], want[i], 2e-7f);
    }
}

/* The contract in double precision, one pixel at a time: sigma rounded to the grid (1/32 below 2
 * pixels, 32 values per octave above), taps at |d| <= 3 sigma and inside the image, weights
 * exp(-d^2 / 2 sigma^2) divided by their sum; the horizontal pass with each pixel's own sigma, then
 * the vertical pass over its results with each output pixel's own sigma; a pixel whose kernel is
 * its centre alone is copied. */
static double grid_sigma(double s)
{
    if (s < 2.0) return floor(s * 32.0 + 0.5) / 32.0;
    double o = ldexp(1.0, (int)floor(log2(s))), step = o / 32.0;
    return o + floor((s - o) / step + 0.5) * step;
}

static void reference(const float *in, float *out, int w, int h, const float *sigma)
{
    const int rcap = (w > h ? w : h) - 1;
    double *tmp = malloc(sizeof(double) * 3 * (size_t)w * h);
    for (int pass = 0; pass < 2; pass++)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x;
                double s = grid_sigma(sigma[i]);
                const int r = floor(3.0 * s) < rcap ? (int)floor(3.0 * s) : rcap;
                for (int c = 0; c < 3; c++) {
                    double sum = 0.0, wsum = 0.0;
                    for (int d = -r; d <= r; d++) {
                        int xx = pass ? x : x + d, yy = pass ? y + d : y;
                        if (xx < 0 || xx >= w || yy < 0 || yy >= h) continue;
                        size_t j = (size_t)yy * w + xx;
                        double g = r ? exp(-0.5 * d * d / (s * s)) : 1.0;
                        sum += g * (pass ? tmp[3 * j + c] : in[3 * j + c]);
                        wsum += g;
                    }
                    if (pass == 0) tmp[3 * i + c] = sum / wsum;
                    else out[3 * i + c] = r ? (float)(sum / wsum) : in[3 * i + c];
                }
            }
    free(tmp);
}

static void check_against_reference(int w, int h, float *sig, unsigned seed, int threads)
{
    const size_t n = (size_t)w * h;
    float *img = noise(3 * n, 0.0f, 1.0f, seed), *want = malloc(sizeof(float) * 3 * n);
    reference(img, want, w, h, sig);
    fv_error err;
    assert_int_equal(fv_blur_variable(img, w, h, sig, threads, &err), FV_OK);
    for (size_t i = 0; i < 3 * n; i++) assert_float_equal(img[i], want[i], 2e-6f);
    free(img), free(want);
}

/* Fields that exercise every path: noise (a new kernel at nearly every pixel, short runs), the
 * paper's profile (long runs, the fovea skipped), rounding just below and above grid points, sigma
 * steps inside a row and near the borders, images several strips wide, and a tall image whose rows
 * go through the blur in several batches, on one thread and on three. */
static void test_matches_reference(void **st)
{
    (void)st;
    {
        const int w = 45, h = 330;
        float *sig = noise((size_t)w * h, 1.0f, 7.0f, 4);
        check_against_reference(w, h, sig, 24, 1);
        check_against_reference(w, h, sig, 25, 3);
        free(sig);
    }
    {
        const int w = 67, h = 53;
        float *sig = noise((size_t)w * h, 0.0f, 5.0f, 3);
        check_against_reference(w, h, sig, 21, 2);
        free(sig);
    }
    {
        const int w = 150, h = 97;
        float *sig = foveated_sigma(w, h, 40.0, 60.0, 8.0, 70.0, 6.8);
        check_against_reference(w, h, sig, 22, 2);
        free(sig);
    }
    {
        const int w = 90, h = 40;
        float *sig = malloc(sizeof(float) * (size_t)w * h);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                /* blocks of 7 pixels with sigma 0, 0.34, 1.01, 2.49, 3.97, 4.0625, 7.9 ... */
                static const float v[8] = {0.0f, 0.34f, 1.01f, 2.49f, 3.97f, 4.0625f, 7.9f, 0.5f};
                sig[(size_t)y * w + x] = v[((x / 7) + (y / 5)) % 8];
            }
        check_against_reference(w, h, sig, 23, 2);
        free(sig);
    }
}

/* Sigma beyond the kernel table (40 px) and far beyond the image (1e6 and FLT_MAX px: every tap of
 * the row or column, all weighing nearly the same) on a 30 x 20 image: the reference's numbers, and
 * constants stay constant. */
static void test_wide_kernels(void **st)
{
    (void)st;
    const int w = 30, h = 20;
    const size_t n = (size_t)w * h;
    const float wide[3] = {40.0f, 1e6f, FLT_MAX};
    fv_error err;
    for (int t = 0; t < 3; t++) {
        float *sig = filled(n, wide[t]);
        check_against_reference(w, h, sig, 30 + t, 2);
        float *img = filled(3 * n, 2.5f);
        assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_OK);
        for (size_t i = 0; i < 3 * n; i++) assert_float_equal(img[i], 2.5f, 2e-6f);
        free(sig), free(img);
    }
}

/* 1, 2 and 3 threads (one slab of rows each) give the same bits, for the paper's field on an image
 * large enough for every thread to get many batches of rows, and for a noisy field. */
static void test_threads(void **st)
{
    (void)st;
    const int w = 300, h = 400;
    const size_t n = (size_t)w * h;
    fv_error err;
    for (int field = 0; field < 2; field++) {
        float *sig = field ? noise(n, 0.0f, 6.0f, 9) : foveated_sigma(w, h, 120.0, 150.0, 20.0, 150.0, 6.8);
        float *a = noise(3 * n, 0.0f, 1.0f, 40), *b = malloc(sizeof(float) * 3 * n), *c = malloc(sizeof(float) * 3 * n);
        memcpy(b, a, sizeof(float) * 3 * n);
        memcpy(c, a, sizeof(float) * 3 * n);
        assert_int_equal(fv_blur_variable(a, w, h, sig, 1, &err), FV_OK);
        assert_int_equal(fv_blur_variable(b, w, h, sig, 2, &err), FV_OK);
        assert_int_equal(fv_blur_variable(c, w, h, sig, 3, &err), FV_OK);
        assert_memory_equal(a, b, sizeof(float) * 3 * n);
        assert_memory_equal(a, c, sizeof(float) * 3 * n);
        free(a), free(b), free(c), free(sig);
    }
}

/* Bad input: no image, no sigma, empty sizes, a negative, NaN or infinite sigma at one pixel. Each
 * is FV_ERR_INVALID with a message naming the problem, and the image is left as it was. */
static void test_bad_input(void **st)
{
    (void)st;
    const int w = 8, h = 6;
    float *img = noise(3 * (size_t)w * h, 0.0f, 1.0f, 1), *ref = malloc(sizeof(float) * 3 * w * h);
    float *sig = filled((size_t)w * h, 1.5f);
    memcpy(ref, img, sizeof(float) * 3 * w * h);
    fv_error err;
    assert_int_equal(fv_blur_variable(NULL, w, h, sig, 1, &err), FV_ERR_INVALID);
    assert_int_equal(fv_blur_variable(img, w, h, NULL, 1, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "sigma"));
    assert_int_equal(fv_blur_variable(img, 0, h, sig, 1, &err), FV_ERR_INVALID);
    assert_int_equal(fv_blur_variable(img, w, -1, sig, 1, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "8x-1"));
    const float bad[3] = {-0.5f, NAN, INFINITY};
    for (int t = 0; t < 3; t++) {
        sig[13] = bad[t];
        assert_int_equal(fv_blur_variable(img, w, h, sig, 2, &err), FV_ERR_INVALID);
        assert_non_null(strstr(err.msg, "pixel (5, 1)"));
        assert_memory_equal(img, ref, sizeof(float) * 3 * w * h);
    }
    free(img), free(ref), free(sig);
}

/* The kernels' two passes (filter/kblur.h, a pixel at a time: what the portable backend and CUDA
 * run) against fv_blur_variable (runs of pixels, vectors, slabs of rows), bit for bit. */
static void kernel_against_filter(int w, int h, const float *sig, unsigned seed)
{
    const size_t n = (size_t)w * h;
    float *img = noise(3 * n, 0.0f, 4.0f, seed), *want = malloc(sizeof(float) * 3 * n), *tmp = malloc(sizeof(float) * 3 * n),
          *got = malloc(sizeof(float) * 3 * n);
    memcpy(want, img, sizeof(float) * 3 * n);
    fv_error err;
    assert_int_equal(fv_blur_variable(want, w, h, sig, 2, &err), FV_OK);
    float smax = 0.0f;
    for (size_t i = 0; i < n; i++) smax = sig[i] > smax ? sig[i] : smax;
    int nq;
    size_t nk;
    fv_blur_table_size(smax, w, h, &nq, &nk);
    int *off = malloc(sizeof(int) * (size_t)nq);
    float *k = malloc(sizeof(float) * nk);
    fv_blur_table_fill(w, h, nq, off, k);
    fv_kblur_table t = {w, h, (w > h ? w : h) - 1, nq, off, k};
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) fv_kblur_h_pixel(&t, sig, img, tmp, x, y);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) fv_kblur_v_pixel(&t, sig, tmp, got, x, y);
    for (size_t i = 0; i < 3 * n; i++)
        if (memcmp(&want[i], &got[i], sizeof(float)) != 0)
            fail_msg("%dx%d: value %zu (pixel %zu, sigma %g): filter %.9g, kernels %.9g", w, h, i, i / 3, (double)sig[i / 3], (double)want[i],
                     (double)got[i]);
    free(img), free(want), free(tmp), free(got), free(off), free(k);
}

static void test_kernel_passes(void **st)
{
    (void)st;
    float *sig = noise(45 * 330, 1.0f, 7.0f, 4);
    kernel_against_filter(45, 330, sig, 1);
    free(sig);
    sig = noise(67 * 53, 0.0f, 5.0f, 3);
    kernel_against_filter(67, 53, sig, 2);
    free(sig);
    sig = foveated_sigma(150, 97, 40.0, 60.0, 8.0, 70.0, 6.8);
    kernel_against_filter(150, 97, sig, 3);
    free(sig);
    sig = filled(30 * 20, 40.0f); /* beyond the filter's kernel table */
    kernel_against_filter(30, 20, sig, 4);
    free(sig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sigma_profile),     cmocka_unit_test(test_zero_sigma_identity),
        cmocka_unit_test(test_constant),          cmocka_unit_test(test_impulse_weights),
        cmocka_unit_test(test_variance),          cmocka_unit_test(test_border_by_hand),
        cmocka_unit_test(test_matches_reference), cmocka_unit_test(test_wide_kernels),
        cmocka_unit_test(test_threads),           cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_kernel_passes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
