/* φ-only mipmaps (Visual-Polar Sec. 3.4): level heights and counts worked by hand, max_levels
 * respected; the overlap-weighted averages worked by hand for even, odd and single-row columns side
 * by side; constants stay constant at every (X, V, level); level 0 agrees with fv_grid_bilinear
 * everywhere and returns the pixels at their centres (bit for bit where the centres are exact), and
 * every level agrees with fv_grid_bilinear on its own grid; the wrap seam blends
 * the first and last rows of a polar grid and clamps on a screen grid; columns of different heights
 * blend across X; fractional levels blend linearly and clamp; NaN coordinates read 0; the build
 * does not depend on the thread count; bad arguments are refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/phi_mips.h"
#include "technique/vpolar/kvp_map.h"

static const int k_cols[4] = {1, 3, 8, 5};

static float frand(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) / 16777216.0f;
}

/* A 3-channel image on g's storage: channel 0 = v, 1 = 2 v, 2 = -v with v from fn (NULL: random). */
static float *grid_image(const fv_grid *g, float (*fn)(int x, int y), unsigned seed)
{
    float *img = calloc(3 * (size_t)g->w * g->h, sizeof(float));
    for (int y = 0; y < g->h; y++)
        for (int x = 0; x < g->w; x++) {
            float v = fn ? fn(x, y) : frand(&seed);
            size_t i = 3 * ((size_t)y * g->w + x);
            img[i] = v, img[i + 1] = 2.0f * v, img[i + 2] = -v;
        }
    return img;
}

/* Level k, column x, row j, channel 0, read at the pixel's centre. */
static float level_px(const fv_phi_mips *m, int k, int x, int j)
{
    const fv_grid *g = fv_phi_mips_grid(m, k);
    float X, V, out[3];
    fv_grid_centre(g, x, j, &X, &V);
    fv_phi_mips_sample(m, X, V, (float)k, out);
    assert_float_equal(out[1], 2.0f * out[0], 1e-5f * (1.0f + fabsf(out[0])));
    assert_float_equal(out[2], -out[0], 1e-5f * (1.0f + fabsf(out[0])));
    return out[0];
}

/* Columns {1, 3, 8, 5} halve as 8 -> 4 -> 2 -> 1, 5 -> 3 -> 2 -> 1, 3 -> 2 -> 1 -> 1 and 1 -> 1:
 * four levels, storage heights 8, 4, 2, 1 (the tallest column), the same width and wrap flag. A
 * grid without col_h (6 rows) gives 6 -> 3 -> 2 -> 1; a one-row grid has level 0 alone. */
static void test_level_heights(void **st)
{
    (void)st;
    const int want[4][4] = {{1, 3, 8, 5}, {1, 2, 4, 3}, {1, 1, 2, 2}, {1, 1, 1, 1}};
    const int tallest[4] = {8, 4, 2, 1};
    fv_error err;
    for (int wrap = 0; wrap < 2; wrap++) {
        fv_grid g = {4, 8, k_cols, wrap};
        fv_phi_mips *m;
        assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
        assert_int_equal(fv_phi_mips_levels(m), 4);
        for (int k = 0; k < 4; k++) {
            const fv_grid *lg = fv_phi_mips_grid(m, k);
            assert_non_null(lg);
            assert_int_equal(lg->w, 4);
            assert_int_equal(lg->h, tallest[k]);
            assert_int_equal(lg->wrap, wrap);
            for (int x = 0; x < 4; x++) assert_int_equal(fv_grid_col_h(lg, x), want[k][x]);
        }
        assert_ptr_equal(fv_phi_mips_grid(m, 0)->col_h, k_cols); /* level 0 is the caller's grid */
        assert_null(fv_phi_mips_grid(m, 4));
        assert_null(fv_phi_mips_grid(m, -1));
        fv_phi_mips_destroy(m);
    }
    fv_grid full = {3, 6, NULL, true};
    fv_phi_mips *m;
    assert_int_equal(fv_phi_mips_create(&full, 16, &m, &err), FV_OK);
    assert_int_equal(fv_phi_mips_levels(m), 4);
    const int hs[4] = {6, 3, 2, 1};
    for (int k = 0; k < 4; k++) {
        assert_int_equal(fv_phi_mips_grid(m, k)->h, hs[k]);
        for (int x = 0; x < 3; x++) assert_int_equal(fv_grid_col_h(fv_phi_mips_grid(m, k), x), hs[k]);
    }
    fv_phi_mips_destroy(m);
    fv_grid one = {5, 1, NULL, true};
    assert_int_equal(fv_phi_mips_create(&one, 16, &m, &err), FV_OK);
    assert_int_equal(fv_phi_mips_levels(m), 1);
    fv_phi_mips_destroy(m);
}

/* max_levels counts level 0 and caps the chain: 1 -> 1, 2 -> 2, 3 -> 3, 100 -> 4 (all there is). */
static void test_max_levels(void **st)
{
    (void)st;
    fv_grid g = {4, 8, k_cols, true};
    const int ask[4] = {1, 2, 3, 100}, got[4] = {1, 2, 3, 4};
    fv_error err;
    for (int t = 0; t < 4; t++) {
        fv_phi_mips *m;
        assert_int_equal(fv_phi_mips_create(&g, ask[t], &m, &err), FV_OK);
        assert_int_equal(fv_phi_mips_levels(m), got[t]);
        fv_phi_mips_destroy(m);
    }
}

/* The four columns {1, 3, 8, 5} built at once:
 *  - 1 row (7): copied at every level.
 *  - 3 rows (1, 2, 4): level 1 row 0 covers source rows [0, 1.5): (2 * 1 + 1 * 2) / 3 = 4/3, row 1
 *    covers [1.5, 3): (1 * 2 + 2 * 4) / 3 = 10/3; level 2: (4/3 + 10/3) / 2 = 7/3; level 3 copies.
 *  - 8 rows (1, 3, 5, 11, 0, 2, 4, 6): pairs (2, 8, 1, 5), then (5, 3), then 4.
 *  - 5 rows (1, 2, 4, 8, 16): level 1 (3 rows, each 5/3 source rows): (3 * 1 + 2 * 2) / 5 = 1.4,
 *    (1 * 2 + 3 * 4 + 1 * 8) / 5 = 4.4, (2 * 8 + 3 * 16) / 5 = 12.8; level 2 (2 rows, 3/2 each):
 *    (2 * 1.4 + 4.4) / 3 = 2.4, (4.4 + 2 * 12.8) / 3 = 10; level 3: (2.4 + 10) / 2 = 6.2.
 * Every level keeps each column's mean (7/3, 4, 31/5 = 6.2). Rows beyond a column's height hold
 * junk in the source (99) that must not leak in. */
static float hand_value(int x, int y)
{
    static const float c1[3] = {1, 2, 4}, c2[8] = {1, 3, 5, 11, 0, 2, 4, 6}, c3[5] = {1, 2, 4, 8, 16};
    if (y >= k_cols[x]) return 99.0f;
    return x == 0 ? 7.0f : x == 1 ? c1[y] : x == 2 ? c2[y] : c3[y];
}

static void test_averages_by_hand(void **st)
{
    (void)st;
    fv_grid g = {4, 8, k_cols, true};
    fv_phi_mips *m;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
    float *img = grid_image(&g, hand_value, 0);
    fv_phi_mips_build(m, img, 2);
    const float want1[3][4] = {{4.0f / 3, 10.0f / 3}, {2, 8, 1, 5}, {1.4f, 4.4f, 12.8f}};
    const float want2[3][2] = {{7.0f / 3}, {5, 3}, {2.4f, 10}};
    const float want3[3] = {7.0f / 3, 4, 6.2f};
    for (int k = 0; k < 4; k++) assert_float_equal(level_px(m, k, 0, 0), 7.0f, 1e-6f);
    for (int c = 1; c < 4; c++) {
        for (int j = 0; j < k_cols[c]; j++) assert_float_equal(level_px(m, 0, c, j), hand_value(c, j), 1e-5f);
        for (int j = 0; j < fv_grid_col_h(fv_phi_mips_grid(m, 1), c); j++)
            assert_float_equal(level_px(m, 1, c, j), want1[c - 1][j], 1e-5f);
        for (int j = 0; j < fv_grid_col_h(fv_phi_mips_grid(m, 2), c); j++)
            assert_float_equal(level_px(m, 2, c, j), want2[c - 1][j], 1e-5f);
        assert_float_equal(level_px(m, 3, c, 0), want3[c - 1], 1e-5f);
    }
    free(img);
    fv_phi_mips_destroy(m);
}

/* A constant grid samples to the constant at any (X, V, level), in range or not, wrapping or not,
 * for columns of every height from 1 to 13. */
static float constant(int x, int y)
{
    (void)x, (void)y;
    return 0.25f;
}

static void test_constant(void **st)
{
    (void)st;
    int cols[37];
    unsigned s = 5;
    for (int x = 0; x < 37; x++) cols[x] = 1 + (int)(frand(&s) * 13.0f);
    fv_error err;
    for (int wrap = 0; wrap < 2; wrap++) {
        fv_grid g = {37, 13, cols, wrap};
        fv_phi_mips *m;
        assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
        float *img = grid_image(&g, constant, 0);
        fv_phi_mips_build(m, img, 2);
        for (int i = 0; i < 20000; i++) {
            float X = -1.0f + 39.0f * frand(&s), V = -2.0f + 4.0f * frand(&s), L = -1.0f + 7.0f * frand(&s), out[3];
            fv_phi_mips_sample(m, X, V, L, out);
            assert_float_equal(out[0], 0.25f, 1e-6f);
            assert_float_equal(out[1], 0.5f, 2e-6f);
            assert_float_equal(out[2], -0.25f, 1e-6f);
        }
        free(img);
        fv_phi_mips_destroy(m);
    }
}

/* The lookup agrees with fv_grid_bilinear (the shared addressing of filter/grid.h) on the level's
 * own grid: at level 0 against the source image, at every level against that level's pixels read
 * back at their centres. Random (X, V) in range, and pixel centres, which return the pixel. */
static void check_bilinear(const fv_phi_mips *m, int k, const float *img, unsigned s)
{
    /* level 0 repeats fv_grid_bilinear's arithmetic; the pixels of higher levels were read back at
     * their centres, a few ulp off */
    const float tol = k ? 4e-6f : 1e-6f;
    const fv_grid *g = fv_phi_mips_grid(m, k);
    for (int i = 0; i < 5000; i++) {
        float X = (float)g->w * frand(&s), V = frand(&s), out[3];
        long idx[4];
        float wt[4];
        fv_grid_bilinear(g, X, V, idx, wt);
        fv_phi_mips_sample(m, X, V, (float)k, out);
        for (int c = 0; c < 3; c++) {
            float want = 0.0f;
            for (int t = 0; t < 4; t++) want += wt[t] * img[3 * idx[t] + c];
            assert_float_equal(out[c], want, tol);
        }
    }
    for (int x = 0; x < g->w; x++)
        for (int y = 0; y < fv_grid_col_h(g, x); y++) {
            float X, V, out[3];
            fv_grid_centre(g, x, y, &X, &V);
            fv_phi_mips_sample(m, X, V, (float)k, out);
            /* (y + 0.5) / n rounds, so V n - 0.5 may miss y by a few ulp of n */
            for (int c = 0; c < 3; c++) assert_float_equal(out[c], img[3 * ((size_t)y * g->w + x) + c], 1e-5f);
        }
}

static void test_matches_grid_bilinear(void **st)
{
    (void)st;
    int cols[23];
    unsigned s = 17;
    for (int x = 0; x < 23; x++) cols[x] = 1 + (int)(frand(&s) * 40.0f);
    fv_error err;
    for (int wrap = 0; wrap < 2; wrap++) {
        fv_grid g = {23, 40, cols, wrap};
        fv_phi_mips *m;
        assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
        float *img = grid_image(&g, NULL, 3 + wrap);
        fv_phi_mips_build(m, img, 2);
        check_bilinear(m, 0, img, 100);
        for (int k = 1; k < fv_phi_mips_levels(m); k++) {
            const fv_grid *lg = fv_phi_mips_grid(m, k);
            float *li = calloc(3 * (size_t)lg->w * lg->h, sizeof(float));
            for (int x = 0; x < lg->w; x++)
                for (int y = 0; y < fv_grid_col_h(lg, x); y++) {
                    float X, V;
                    fv_grid_centre(lg, x, y, &X, &V);
                    fv_phi_mips_sample(m, X, V, (float)k, &li[3 * ((size_t)y * lg->w + x)]);
                }
            check_bilinear(m, k, li, 200 + k);
            free(li);
        }
        free(img);
        fv_phi_mips_destroy(m);
    }
}

/* Where the pixel centres are exact in float (column heights 1, 2, 4, 8, 16), sampling a centre at
 * level 0 returns the pixel's bits, in a wrapping and in a screen grid. */
static void test_centres_exact(void **st)
{
    (void)st;
    const int cols[5] = {1, 2, 4, 8, 16};
    fv_error err;
    for (int wrap = 0; wrap < 2; wrap++) {
        fv_grid g = {5, 16, cols, wrap};
        fv_phi_mips *m;
        assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
        float *img = grid_image(&g, NULL, 8 + wrap);
        fv_phi_mips_build(m, img, 2);
        for (int x = 0; x < 5; x++)
            for (int y = 0; y < cols[x]; y++) {
                float X, V, out[3];
                fv_grid_centre(&g, x, y, &X, &V);
                fv_phi_mips_sample(m, X, V, 0.0f, out);
                assert_memory_equal(out, &img[3 * ((size_t)y * 5 + x)], sizeof out);
            }
        free(img);
        fv_phi_mips_destroy(m);
    }
}

/* One column of 4 rows (10, 20, 30, 40), row y centred at V = (y + 0.5) / 4.
 * Wrapping (polar) grid: V = 0 lies between the last row and the first: (40 + 10) / 2 = 25;
 * V = 1/16 is a quarter row before row 0's centre: 0.25 * 40 + 0.75 * 10 = 17.5; V = 15/16:
 * 0.75 * 40 + 0.25 * 10 = 32.5; V = -1/16 and 1 + 1/16 are those angles again.
 * Screen grid: the same V clamp to the edge rows (10 below row 0's centre, 40 beyond row 3's). */
static void test_wrap_seam(void **st)
{
    (void)st;
    const int cols[1] = {4};
    const float V[6] = {0.0f, 1.0f / 16, 15.0f / 16, -1.0f / 16, 17.0f / 16, 1.0f};
    const float want_wrap[6] = {25.0f, 17.5f, 32.5f, 32.5f, 17.5f, 25.0f};
    const float want_clamp[6] = {10.0f, 10.0f, 40.0f, 10.0f, 40.0f, 40.0f};
    fv_error err;
    for (int wrap = 0; wrap < 2; wrap++) {
        fv_grid g = {1, 4, cols, wrap};
        fv_phi_mips *m;
        assert_int_equal(fv_phi_mips_create(&g, 1, &m, &err), FV_OK);
        float img[12];
        for (int y = 0; y < 4; y++) img[3 * y] = img[3 * y + 1] = img[3 * y + 2] = 10.0f * (float)(y + 1);
        fv_phi_mips_build(m, img, 1);
        for (int t = 0; t < 6; t++) {
            float out[3];
            fv_phi_mips_sample(m, 0.5f, V[t], 0.0f, out);
            assert_float_equal(out[0], wrap ? want_wrap[t] : want_clamp[t], 1e-5f);
        }
        fv_phi_mips_destroy(m);
    }
}

/* Columns of 2 rows (0, 100) and 4 rows (10, 20, 30, 40): at X = 1 (halfway between the column
 * centres 0.5 and 1.5) and V = 0.5, column 0 is halfway between its rows (50) and column 1 halfway
 * between rows 1 and 2 (25): 37.5. Beyond the last column X clamps: X = 5 reads column 1 alone. */
static void test_columns_blend(void **st)
{
    (void)st;
    const int cols[2] = {2, 4};
    fv_grid g = {2, 4, cols, true};
    fv_phi_mips *m;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 1, &m, &err), FV_OK);
    float img[24] = {0};
    const float c0[2] = {0, 100}, c1[4] = {10, 20, 30, 40};
    for (int y = 0; y < 4; y++) {
        if (y < 2) img[3 * (y * 2)] = c0[y];
        img[3 * (y * 2 + 1)] = c1[y];
    }
    fv_phi_mips_build(m, img, 1);
    float out[3];
    fv_phi_mips_sample(m, 1.0f, 0.5f, 0.0f, out);
    assert_float_equal(out[0], 37.5f, 1e-5f);
    fv_phi_mips_sample(m, 5.0f, 0.5f, 0.0f, out);
    assert_float_equal(out[0], 25.0f, 1e-5f);
    fv_phi_mips_sample(m, -3.0f, 0.5f, 0.0f, out);
    assert_float_equal(out[0], 50.0f, 1e-5f);
    fv_phi_mips_destroy(m);
}

/* One wrapping column (1, 2, 3, 4): level 1 = (1.5, 3.5), level 2 = 2.5. At V = 1/8 (row 0's
 * centre at level 0): level 0 gives 1; level 1 (2 rows, V * 2 - 0.5 = -0.25) blends row 1 and
 * row 0: 0.25 * 3.5 + 0.75 * 1.5 = 2; level 2 gives 2.5. Fractional levels blend linearly:
 * 0.25 -> 0.75 * 1 + 0.25 * 2 = 1.25, 1.5 -> (2 + 2.5) / 2 = 2.25; levels clamp to [0, 2]
 * (7 -> 2.5, -3 -> 1) and NaN reads level 0. */
static void test_fractional_levels(void **st)
{
    (void)st;
    const int cols[1] = {4};
    fv_grid g = {1, 4, cols, true};
    fv_phi_mips *m;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 8, &m, &err), FV_OK);
    assert_int_equal(fv_phi_mips_levels(m), 3);
    float img[12];
    for (int y = 0; y < 4; y++) img[3 * y] = img[3 * y + 1] = img[3 * y + 2] = (float)(y + 1);
    fv_phi_mips_build(m, img, 1);
    const float L[8] = {0.0f, 1.0f, 2.0f, 0.25f, 1.5f, 7.0f, -3.0f, NAN};
    const float want[8] = {1.0f, 2.0f, 2.5f, 1.25f, 2.25f, 2.5f, 1.0f, 1.0f};
    for (int t = 0; t < 8; t++) {
        float out[3];
        fv_phi_mips_sample(m, 0.5f, 0.125f, L[t], out);
        assert_float_equal(out[0], want[t], 1e-6f);
    }
    fv_phi_mips_destroy(m);
}

/* NaN coordinates read 0 (X = 0: the first column's edge; V = 0; level 0) instead of indexing
 * with garbage, and infinite V on a polar grid reads V = 0. */
static void test_nan_coordinates(void **st)
{
    (void)st;
    fv_grid g = {4, 8, k_cols, true};
    fv_phi_mips *m;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
    float *img = grid_image(&g, NULL, 5);
    fv_phi_mips_build(m, img, 1);
    float a[3], b[3];
    fv_phi_mips_sample(m, NAN, 0.3f, 1.5f, a);
    fv_phi_mips_sample(m, 0.0f, 0.3f, 1.5f, b);
    assert_memory_equal(a, b, sizeof a);
    fv_phi_mips_sample(m, 2.7f, NAN, 1.5f, a);
    fv_phi_mips_sample(m, 2.7f, 0.0f, 1.5f, b);
    assert_memory_equal(a, b, sizeof a);
    fv_phi_mips_sample(m, 2.7f, INFINITY, 1.5f, a);
    assert_memory_equal(a, b, sizeof a);
    fv_phi_mips_sample(m, 2.7f, 0.3f, NAN, a);
    fv_phi_mips_sample(m, 2.7f, 0.3f, 0.0f, b);
    assert_memory_equal(a, b, sizeof a);
    free(img);
    fv_phi_mips_destroy(m);
}

/* Building with 1 or 3 threads gives the same bits at every level (read at every pixel centre). */
static void test_threads(void **st)
{
    (void)st;
    int cols[160];
    for (int x = 0; x < 160; x++) cols[x] = x < 100 ? 1 + x * 2 : 200; /* a clipped triangle */
    fv_grid g = {160, 200, cols, true};
    fv_phi_mips *a, *b;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 12, &a, &err), FV_OK);
    assert_int_equal(fv_phi_mips_create(&g, 12, &b, &err), FV_OK);
    float *img = grid_image(&g, NULL, 77);
    fv_phi_mips_build(a, img, 1);
    fv_phi_mips_build(b, img, 3);
    for (int k = 0; k < fv_phi_mips_levels(a); k++) {
        const fv_grid *lg = fv_phi_mips_grid(a, k);
        for (int x = 0; x < lg->w; x++)
            for (int y = 0; y < fv_grid_col_h(lg, x); y++) {
                float X, V, pa[3], pb[3];
                fv_grid_centre(lg, x, y, &X, &V);
                fv_phi_mips_sample(a, X, V, (float)k, pa);
                fv_phi_mips_sample(b, X, V, (float)k, pb);
                assert_memory_equal(pa, pb, sizeof pa);
            }
    }
    free(img);
    fv_phi_mips_destroy(a);
    fv_phi_mips_destroy(b);
}

/* Bad arguments: FV_ERR_INVALID with a message naming the value, and no chain. */
static void test_bad_arguments(void **st)
{
    (void)st;
    fv_error err;
    static char sentinel;
    fv_phi_mips *m = (fv_phi_mips *)(void *)&sentinel; /* must be reset to NULL */
    fv_grid g = {4, 8, k_cols, true};
    assert_int_equal(fv_phi_mips_create(NULL, 4, &m, &err), FV_ERR_INVALID);
    assert_null(m);
    assert_int_equal(fv_phi_mips_create(&g, 4, NULL, &err), FV_ERR_INVALID);
    assert_int_equal(fv_phi_mips_create(&g, 0, &m, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "max_levels 0"));
    assert_null(m);
    fv_grid empty = {0, 8, NULL, true};
    assert_int_equal(fv_phi_mips_create(&empty, 4, &m, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "0x8"));
    const int zero_col[4] = {1, 0, 8, 5}, tall_col[4] = {1, 3, 9, 5};
    fv_grid bad = {4, 8, zero_col, true};
    assert_int_equal(fv_phi_mips_create(&bad, 4, &m, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "column 1"));
    bad.col_h = tall_col;
    assert_int_equal(fv_phi_mips_create(&bad, 4, &m, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "column 2 has 9 rows"));
    assert_null(m);
    fv_phi_mips_destroy(NULL);
    assert_int_equal(fv_phi_mips_levels(NULL), 0);
}

/* The map stage's nearest cell: column clamped to the grid, row to its column (hand-worked on the
 * {1, 3, 8, 5} columns). */
static void test_nearest_cell(void **st)
{
    (void)st;
    assert_int_equal(fv_kvp_nearest_cell(k_cols, 4, 8, 2.7f, 0.5f), 4 * 4 + 2);  /* column 2: 8 rows, row 4 */
    assert_int_equal(fv_kvp_nearest_cell(k_cols, 4, 8, 1.2f, 0.99f), 2 * 4 + 1); /* column 1: 3 rows, row 2 */
    assert_int_equal(fv_kvp_nearest_cell(k_cols, 4, 8, -3.0f, 0.7f), 0);         /* column 0: one row */
    assert_int_equal(fv_kvp_nearest_cell(k_cols, 4, 8, 9.0f, 1.5f), 4 * 4 + 3);   /* column 3: 5 rows, clamped to 4 */
    assert_int_equal(fv_kvp_nearest_cell(NULL, 4, 8, 3.5f, 0.3f), 2 * 4 + 3);     /* every column 8 rows */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_level_heights),     cmocka_unit_test(test_max_levels),
        cmocka_unit_test(test_averages_by_hand),  cmocka_unit_test(test_constant),
        cmocka_unit_test(test_matches_grid_bilinear), cmocka_unit_test(test_centres_exact),
        cmocka_unit_test(test_wrap_seam),
        cmocka_unit_test(test_columns_blend),     cmocka_unit_test(test_fractional_levels),
        cmocka_unit_test(test_nan_coordinates),
        cmocka_unit_test(test_threads),           cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_nearest_cell),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
