/* How filters address their images (filter/grid.h): filter taps on screen grids (outside -> -1) and
 * on polar grids (columns clamp, rows wrap, the same angle between columns of different heights),
 * and the bilinear lookup (weights sum to 1; hand-worked weights inside, at the screen edge, across
 * the wrap seam at V near 0 and near 1, and between columns of different heights). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>
#include "filter/grid.h"

static void test_helpers(void **st)
{
    (void)st;
    assert_int_equal(fv_grid_wrap_row(0, 6), 0);
    assert_int_equal(fv_grid_wrap_row(6, 6), 0);
    assert_int_equal(fv_grid_wrap_row(-1, 6), 5);
    assert_int_equal(fv_grid_wrap_row(-13, 6), 5);
    assert_int_equal(fv_grid_wrap_row(14, 6), 2);
    assert_int_equal(fv_grid_wrap_row(-3, 1), 0);
    const int col_h[3] = {2, 4, 8};
    fv_grid g = {3, 8, col_h, true};
    assert_int_equal(fv_grid_col_h(&g, 1), 4);
    assert_true(fv_grid_valid(&g, 0, 1));
    assert_false(fv_grid_valid(&g, 0, 2));  /* column 0 holds two rows */
    assert_true(fv_grid_valid(&g, 2, 7));
    assert_false(fv_grid_valid(&g, 3, 0));
    assert_false(fv_grid_valid(&g, -1, 0));
    assert_false(fv_grid_valid(&g, 1, -1));
    /* Centre of row 2 of column 1 (4 rows): X = 1.5, V = 2.5 / 4. */
    float X, V;
    fv_grid_centre(&g, 1, 2, &X, &V);
    assert_float_equal(X, 1.5f, 0.0f);
    assert_float_equal(V, 0.625f, 0.0f);
    fv_grid s = {4, 3, NULL, false};
    assert_int_equal(fv_grid_col_h(&s, 2), 3);
}

/* 4x3 screen grid: pixel (x, y) is index 4y + x; taps outside are -1 (no clamping, no wrap). */
static void test_tap_screen(void **st)
{
    (void)st;
    fv_grid g = {4, 3, NULL, false};
    assert_int_equal(fv_grid_tap(&g, 1, 1, 0, 0), 5);
    assert_int_equal(fv_grid_tap(&g, 1, 1, 1, 1), 10);
    assert_int_equal(fv_grid_tap(&g, 1, 1, -1, -1), 0);
    assert_int_equal(fv_grid_tap(&g, 1, 1, 2, -1), 3);
    assert_int_equal(fv_grid_tap(&g, 0, 0, -1, 0), -1);
    assert_int_equal(fv_grid_tap(&g, 0, 0, 0, -1), -1);
    assert_int_equal(fv_grid_tap(&g, 3, 2, 1, 0), -1);
    assert_int_equal(fv_grid_tap(&g, 3, 2, 0, 1), -1);
    assert_int_equal(fv_grid_tap(&g, 1, 1, 0, 16), -1);
    assert_int_equal(fv_grid_tap(&g, 1, 1, -16, 0), -1);
}

/* 4x6 polar grid, full columns: columns clamp to [0, 4), rows wrap modulo 6. */
static void test_tap_polar(void **st)
{
    (void)st;
    fv_grid g = {4, 6, NULL, true};
    assert_int_equal(fv_grid_tap(&g, 0, 0, -1, 0), 0);       /* column -1 clamps to 0 */
    assert_int_equal(fv_grid_tap(&g, 0, 2, -16, 1), 12);     /* column 0, row 3 */
    assert_int_equal(fv_grid_tap(&g, 3, 5, 2, 1), 3);        /* column 3 (clamped), row 6 -> 0 */
    assert_int_equal(fv_grid_tap(&g, 1, 0, 0, -1), 21);      /* row -1 -> 5: 5 * 4 + 1 */
    assert_int_equal(fv_grid_tap(&g, 1, 2, 0, 13), 13);      /* row 15 -> 3 */
    assert_int_equal(fv_grid_tap(&g, 1, 2, 0, -13), 5);      /* row -11 -> 1 */
    assert_int_equal(fv_grid_tap(&g, 2, 4, 1, -2), 11);      /* column 3, row 2 */
    /* Every tap of every pixel is a valid pixel (never -1). */
    for (int x = 0; x < 4; x++)
        for (int y = 0; y < 6; y++)
            for (int dx = -9; dx <= 9; dx++)
                for (int dy = -20; dy <= 20; dy++) {
                    long q = fv_grid_tap(&g, x, y, dx, dy);
                    assert_true(q >= 0 && q < 24);
                    assert_true(fv_grid_valid(&g, (int)(q % 4), (int)(q / 4)));
                }
}

/* Columns of 2, 4 and 8 rows (storage 3x8, index 3y + x). Row y of a column of n rows sits at the
 * angle v = (y + 0.5) / n, and a tap into another column starts from the row holding that angle,
 * floor(v * n_other), computed exactly as (2y + 1) n_other / (2 n):
 *   (0, 1) -> column 1: v = 0.75,   floor(3.0)  = 3 -> 3*3+1 = 10
 *   (0, 0) -> column 2: v = 0.25,   floor(2.0)  = 2 -> 2*3+2 = 8
 *   (2, 7) -> column 1: v = 15/16,  floor(3.75) = 3 -> 10
 *   (2, 7) -> column 0: v = 15/16,  floor(1.875) = 1 -> 3; one row further wraps to 0 -> 0
 *   (1, 0) -> column 0: v = 1/8,    floor(0.25) = 0; one row back wraps to 1 -> 3
 *   (1, 2) dx = 5 clamps to column 2: v = 5/8, floor(5.0) = 5 -> 17
 *   (2, 3) -> column 1: v = 7/16,   floor(1.75) = 1; two rows on -> 3 -> 10
 *   (1, 3) -> column 0: v = 7/8, floor(1.75) = 1; three rows back -> -2 wraps to 0 -> 0 */
static void test_tap_polar_heights(void **st)
{
    (void)st;
    const int col_h[3] = {2, 4, 8};
    fv_grid g = {3, 8, col_h, true};
    assert_int_equal(fv_grid_tap(&g, 0, 1, 1, 0), 10);
    assert_int_equal(fv_grid_tap(&g, 0, 0, 2, 0), 8);
    assert_int_equal(fv_grid_tap(&g, 2, 7, -1, 0), 10);
    assert_int_equal(fv_grid_tap(&g, 2, 7, -2, 0), 3);
    assert_int_equal(fv_grid_tap(&g, 2, 7, -2, 1), 0);
    assert_int_equal(fv_grid_tap(&g, 1, 0, -1, -1), 3);
    assert_int_equal(fv_grid_tap(&g, 1, 2, 5, 0), 17);
    assert_int_equal(fv_grid_tap(&g, 2, 3, -1, 2), 10);
    assert_int_equal(fv_grid_tap(&g, 1, 3, -1, -3), 0);
    assert_int_equal(fv_grid_tap(&g, 0, 1, -3, 0), 3);   /* clamped onto its own column */
    /* Same column: no remapping, only the wrap. */
    assert_int_equal(fv_grid_tap(&g, 1, 3, 0, 1), 1);
    /* Every tap lands on a valid row of its column (never on the unused rows beyond col_h). */
    for (int x = 0; x < 3; x++)
        for (int y = 0; y < col_h[x]; y++)
            for (int dx = -4; dx <= 4; dx++)
                for (int dy = -17; dy <= 17; dy++) {
                    long q = fv_grid_tap(&g, x, y, dx, dy);
                    assert_true(q >= 0 && q < 24);
                    assert_true(fv_grid_valid(&g, (int)(q % 3), (int)(q / 3)));
                }
}

static void check_bilinear(const fv_grid *g, float X, float V, const long want_idx[4], const float want_wt[4])
{
    long idx[4];
    float wt[4];
    fv_grid_bilinear(g, X, V, idx, wt);
    for (int k = 0; k < 4; k++) {
        assert_int_equal(idx[k], want_idx[k]);
        assert_float_equal(wt[k], want_wt[k], 1e-6f);
    }
}

/* Screen grid 4x4 (index 4y + x). At X = 1.25, V = 0.3: fx = X - 0.5 = 0.75 -> columns 0, 1 with
 * 0.25, 0.75; fy = 4V - 0.5 = 0.7 -> rows 0, 1 with 0.3, 0.7. At the corner X = 0.2, V = 0.05 both
 * axes clamp: columns -1, 0 and rows -1, 0 all become pixel 0, weights still 0.3/0.7 splits. */
static void test_bilinear_screen(void **st)
{
    (void)st;
    fv_grid g = {4, 4, NULL, false};
    const long i1[4] = {0, 4, 1, 5};
    const float w1[4] = {0.25f * 0.3f, 0.25f * 0.7f, 0.75f * 0.3f, 0.75f * 0.7f};
    check_bilinear(&g, 1.25f, 0.3f, i1, w1);
    const long i2[4] = {0, 0, 0, 0};
    const float w2[4] = {0.3f * 0.3f, 0.3f * 0.7f, 0.7f * 0.3f, 0.7f * 0.7f};
    check_bilinear(&g, 0.2f, 0.05f, i2, w2);
    /* The far corner: X = 4, V = 1 -> fx = 3.5 (columns 3 and 4 -> 3), fy = 3.5 (rows 3, 4 -> 3). */
    const long i3[4] = {15, 15, 15, 15};
    const float w3[4] = {0.25f, 0.25f, 0.25f, 0.25f};
    check_bilinear(&g, 4.0f, 1.0f, i3, w3);
}

/* Polar grid 2x4, full columns (index 2y + x), X = 1 (columns 0 and 1, half each).
 * V = 0.05: fy = 4 * 0.05 - 0.5 = -0.3 -> rows -1 (wraps to 3) and 0, ty = 0.7: row 3 gets 0.3 and
 * row 0 gets 0.7 (V = 0.05 is 0.175 from row 3's centre at -0.125 and 0.075 from row 0's at 0.125).
 * V = 0.95: fy = 3.3 -> rows 3 and 4 (wraps to 0), ty = 0.3: row 3 gets 0.7, row 0 gets 0.3. */
static void test_bilinear_seam(void **st)
{
    (void)st;
    fv_grid g = {2, 4, NULL, true};
    const long i1[4] = {6, 0, 7, 1};
    const float w1[4] = {0.5f * 0.3f, 0.5f * 0.7f, 0.5f * 0.3f, 0.5f * 0.7f};
    check_bilinear(&g, 1.0f, 0.05f, i1, w1);
    const long i2[4] = {6, 0, 7, 1};
    const float w2[4] = {0.5f * 0.7f, 0.5f * 0.3f, 0.5f * 0.7f, 0.5f * 0.3f};
    check_bilinear(&g, 1.0f, 0.95f, i2, w2);
    /* Exactly on the seam (V = 0): halfway between rows 3 and 0. */
    const long i3[4] = {6, 0, 7, 1};
    const float w3[4] = {0.25f, 0.25f, 0.25f, 0.25f};
    check_bilinear(&g, 1.0f, 0.0f, i3, w3);
    /* Columns clamp on a polar grid too: X = 0.2 reads column 0 twice (0.3 and 0.7 of it). */
    const long i4[4] = {6, 0, 6, 0};
    const float w4[4] = {0.3f * 0.3f, 0.3f * 0.7f, 0.7f * 0.3f, 0.7f * 0.7f};
    check_bilinear(&g, 0.2f, 0.05f, i4, w4);
}

/* Columns of 2 and 4 rows (storage 2x4, index 2y + x), X = 1 (half each):
 * V = 0.6: column 0: fy = 1.2 - 0.5 = 0.7 -> rows 0 (0.3) and 1 (0.7);
 *          column 1: fy = 2.4 - 0.5 = 1.9 -> rows 1 (0.1) and 2 (0.9).
 * V = 0.1: column 0: fy = -0.3 -> rows 1 (wrapped, 0.3) and 0 (0.7);
 *          column 1: fy = -0.1 -> rows 3 (wrapped, 0.1) and 0 (0.9). */
static void test_bilinear_heights(void **st)
{
    (void)st;
    const int col_h[2] = {2, 4};
    fv_grid g = {2, 4, col_h, true};
    const long i1[4] = {0, 2, 3, 5};
    const float w1[4] = {0.5f * 0.3f, 0.5f * 0.7f, 0.5f * 0.1f, 0.5f * 0.9f};
    check_bilinear(&g, 1.0f, 0.6f, i1, w1);
    const long i2[4] = {2, 0, 7, 1};
    const float w2[4] = {0.5f * 0.3f, 0.5f * 0.7f, 0.5f * 0.1f, 0.5f * 0.9f};
    check_bilinear(&g, 1.0f, 0.1f, i2, w2);
}

/* At a pixel's centre the lookup returns that pixel with weight 1 (up to the rounding of
 * V = (y + 0.5) / n): the identity reprojection of a static scene reads back its own history. */
static void test_bilinear_centre(void **st)
{
    (void)st;
    const int col_h[5] = {1, 3, 7, 7, 5};
    fv_grid grids[2] = {{5, 7, col_h, true}, {5, 7, NULL, false}};
    for (int k = 0; k < 2; k++) {
        const fv_grid *g = &grids[k];
        for (int x = 0; x < 5; x++)
            for (int y = 0; y < fv_grid_col_h(g, x); y++) {
                float X, V;
                fv_grid_centre(g, x, y, &X, &V);
                long idx[4];
                float wt[4];
                fv_grid_bilinear(g, X, V, idx, wt);
                float own = 0.0f;
                for (int i = 0; i < 4; i++)
                    if (idx[i] == (long)y * 5 + x) own += wt[i];
                assert_float_equal(own, 1.0f, 1e-5f);
            }
    }
}

/* Weights sum to 1 and every tap is a valid pixel, anywhere in range (and beyond it on a screen
 * grid, which clamps). */
static void test_bilinear_sum(void **st)
{
    (void)st;
    const int col_h[6] = {1, 2, 3, 5, 8, 8};
    fv_grid grids[3] = {{6, 8, col_h, true}, {6, 8, NULL, true}, {6, 8, NULL, false}};
    uint32_t s = 12345;
    for (int k = 0; k < 3; k++)
        for (int t = 0; t < 20000; t++) {
            s = s * 1664525u + 1013904223u;
            float X = -1.0f + 8.0f * (float)(s >> 8) / 16777216.0f;
            s = s * 1664525u + 1013904223u;
            float V = (float)(s >> 8) / 16777216.0f;
            if (!grids[k].wrap) V = 1.4f * V - 0.2f;
            long idx[4];
            float wt[4];
            fv_grid_bilinear(&grids[k], X, V, idx, wt);
            float sum = 0.0f;
            for (int i = 0; i < 4; i++) {
                assert_true(wt[i] >= 0.0f);
                assert_true(fv_grid_valid(&grids[k], (int)(idx[i] % 6), (int)(idx[i] / 6)));
                sum += wt[i];
            }
            assert_float_equal(sum, 1.0f, 1e-6f);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_helpers),          cmocka_unit_test(test_tap_screen),
        cmocka_unit_test(test_tap_polar),        cmocka_unit_test(test_tap_polar_heights),
        cmocka_unit_test(test_bilinear_screen),  cmocka_unit_test(test_bilinear_seam),
        cmocka_unit_test(test_bilinear_heights), cmocka_unit_test(test_bilinear_centre),
        cmocka_unit_test(test_bilinear_sum),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
