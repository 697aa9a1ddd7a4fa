/* φ-only mipmaps (Visual-Polar Sec. 3.4): level heights and overlap-weighted averages worked by
 * hand, constants stay constant everywhere, level 0 returns the pixels, the wrap seam blends the
 * first and last rows of a polar grid and clamps on a screen grid, fractional levels blend
 * linearly, max_levels is respected and bad arguments are refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/phi_mips.h"

static const int k_cols[4] = {1, 3, 8, 5};

/* Grid of 4 columns with heights {1, 3, 8, 5}: column heights per level 8 -> 4 -> 2 -> 1,
 * 5 -> 3 -> 2 -> 1, 3 -> 2 -> 1 -> 1, 1 -> 1. */
static void test_level_heights(void **st)
{
    (void)st;
    fv_grid g = {4, 8, k_cols, true};
    fv_phi_mips *m;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
    assert_int_equal(fv_phi_mips_levels(m), 4);
    const int expect[4][4] = {{1, 3, 8, 5}, {1, 2, 4, 3}, {1, 1, 2, 2}, {1, 1, 1, 1}};
    const int hmax[4] = {8, 4, 2, 1};
    for (int k = 0; k < 4; k++) {
        const fv_grid *lg = fv_phi_mips_grid(m, k);
        assert_int_equal(lg->w, 4);
        assert_int_equal(lg->h, hmax[k]);
        assert_true(lg->wrap);
        for (int x = 0; x < 4; x++) assert_int_equal(fv_grid_col_h(lg, x), expect[k][x]);
    }
    fv_phi_mips_destroy(m);
    assert_int_equal(fv_phi_mips_create(&g, 2, &m, &err), FV_OK);
    assert_int_equal(fv_phi_mips_levels(m), 2);
    fv_phi_mips_destroy(m);
}

/* Column of 8 rows 0..7: level 1 = {0.5, 2.5, 4.5, 6.5}. Column of 5 rows {1, 2, 3, 4, 5}: level 1
 * has 3 rows whose spans, in source rows, are [0, 5/3), [5/3, 10/3), [10/3, 5):
 * (1 + 2/3 * 2) / (5/3) = 1.4; (1/3 * 2 + 3 + 1/3 * 4) / (5/3) = 3.0; (2/3 * 4 + 5) / (5/3) = 4.6. */
static void test_averages(void **st)
{
    (void)st;
    fv_grid g = {4, 8, k_cols, true};
    float *img = calloc(3 * 4 * 8, sizeof(float));
    for (int y = 0; y < 8; y++) img[3 * (y * 4 + 2)] = (float)y;
    for (int y = 0; y < 5; y++) img[3 * (y * 4 + 3)] = (float)(y + 1);
    fv_phi_mips *m;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
    fv_phi_mips_build(m, img, 2);
    /* Sample at row centres of level 1 (V = (j + 0.5) / h, X at the column centre). */
    float out[3];
    const float c2[4] = {0.5f, 2.5f, 4.5f, 6.5f};
    for (int j = 0; j < 4; j++) {
        fv_phi_mips_sample(m, 2.5f, (j + 0.5f) / 4.0f, 1.0f, out);
        assert_float_equal(out[0], c2[j], 1e-5f);
    }
    const float c3[3] = {1.4f, 3.0f, 4.6f};
    for (int j = 0; j < 3; j++) {
        fv_phi_mips_sample(m, 3.5f, (j + 0.5f) / 3.0f, 1.0f, out);
        assert_float_equal(out[0], c3[j], 1e-5f);
    }
    /* the top level is the column mean: 3.5 and 3 */
    fv_phi_mips_sample(m, 2.5f, 0.5f, 3.0f, out);
    assert_float_equal(out[0], 3.5f, 1e-5f);
    fv_phi_mips_sample(m, 3.5f, 0.2f, 3.0f, out);
    assert_float_equal(out[0], 3.0f, 1e-5f);
    /* level 0 at a pixel centre is the pixel */
    fv_phi_mips_sample(m, 2.5f, 5.5f / 8.0f, 0.0f, out);
    assert_float_equal(out[0], 5.0f, 1e-6f);
    /* half way between levels 0 and 1 at row 5's centre: (5 + level 1's bilinear value) / 2;
     * level 1 at V = 5.5/8 is between rows 2 (4.5) and 3 (6.5) at 0.25: 5.0 -> blend 5.0 */
    fv_phi_mips_sample(m, 2.5f, 5.5f / 8.0f, 0.5f, out);
    assert_float_equal(out[0], 5.0f, 1e-5f);
    fv_phi_mips_sample(m, 2.5f, 4.5f / 8.0f, 0.5f, out);
    /* level 0: 4; level 1 at V = 4.5/8: rows 1 (2.5) and 2 (4.5) at 0.75 -> 4.0; blend 4.0 */
    assert_float_equal(out[0], 4.0f, 1e-5f);
    fv_phi_mips_sample(m, 2.5f, 0.5f / 8.0f, 0.25f, out);
    /* level 0: 0 at row 0; level 1 at V = 1/16: between row 3 (6.5, wrapped) and row 0 (0.5) at
     * 0.75: 2.0; blend 0.25: 0.5 */
    assert_float_equal(out[0], 0.5f, 1e-5f);
    free(img);
    fv_phi_mips_destroy(m);
}

static void test_constant(void **st)
{
    (void)st;
    fv_grid g = {4, 8, k_cols, true};
    float *img = malloc(sizeof(float) * 3 * 4 * 8);
    for (int i = 0; i < 3 * 32; i++) img[i] = 0.25f;
    fv_phi_mips *m;
    fv_error err;
    assert_int_equal(fv_phi_mips_create(&g, 16, &m, &err), FV_OK);
    fv_phi_mips_build(m, img, 1);
    float out[3];
    for (int i = 0; i < 200; i++) {
        float X = (float)(i % 23) * 0.2f - 0.3f, V = (float)(i % 17) / 17.0f, level = (float)(i % 9) * 0.4f;
        fv_phi_mips_sample(m, X, V, level, out);
        for (int c = 0; c < 3; c++) assert_float_equal(out[c], 0.25f, 1e-6f);
    }
    fv_phi_mips_sample(m, 1.0f, 0.3f, NAN, out);
    assert_float_equal(out[0], 0.25f, 1e-6f);
    free(img);
    fv_phi_mips_destroy(m);
}

/* The seam: at V = 0 a polar column blends its last and first rows half and half; a screen grid
 * clamps to the first row. */
static void test_seam(void **st)
{
    (void)st;
    const int h = 6;
    float *img = calloc(3 * 2 * h, sizeof(float));
    for (int y = 0; y < h; y++) img[3 * (y * 2)] = img[3 * (y * 2 + 1)] = (float)(y + 1);
    fv_error err;
    for (int wrap = 0; wrap < 2; wrap++) {
        fv_grid g = {2, h, NULL, wrap == 1};
        fv_phi_mips *m;
        assert_int_equal(fv_phi_mips_create(&g, 1, &m, &err), FV_OK);
        assert_int_equal(fv_phi_mips_levels(m), 1);
        fv_phi_mips_build(m, img, 1);
        float out[3];
        fv_phi_mips_sample(m, 1.0f, 0.0f, 0.0f, out);
        assert_float_equal(out[0], wrap ? 3.5f : 1.0f, 1e-6f);
        fv_phi_mips_sample(m, 1.0f, 0.999999f, 0.0f, out);
        assert_float_equal(out[0], wrap ? 3.5f : 6.0f, 1e-3f);
        fv_phi_mips_destroy(m);
    }
    free(img);
}

static void test_bad_args(void **st)
{
    (void)st;
    fv_phi_mips *m = (fv_phi_mips *)1;
    fv_error err;
    fv_grid g = {4, 8, k_cols, true};
    assert_int_equal(fv_phi_mips_create(&g, 0, &m, &err), FV_ERR_INVALID);
    assert_null(m);
    fv_grid e = {0, 8, NULL, true};
    assert_int_equal(fv_phi_mips_create(&e, 4, &m, &err), FV_ERR_INVALID);
    assert_int_equal(fv_phi_mips_create(NULL, 4, &m, &err), FV_ERR_INVALID);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_level_heights), cmocka_unit_test(test_averages), cmocka_unit_test(test_constant),
        cmocka_unit_test(test_seam),          cmocka_unit_test(test_bad_args),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
