/* The per-chunk tap table SVGF's sweeps use on polar grids (filter/svgf_impl.h: chunk_columns,
 * chunk_tap) against the grid's own addressing (filter/grid.h: fv_grid_tap), tap for tap: the
 * same-angle row in a column of another height (its division done in double and corrected), the
 * clamp at both edges of ρ and the wrap of φ, once or several times around a short column, for
 * every pass's spacing (1..16, 5 columns; 1 with the 3 and 7 columns of the prefilter and the
 * moments). Grids: a small triangle and the 833x937 Visual-Polar grid of a 1280x1440 screen
 * (heights rising linearly over its first 131 columns). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <cmocka.h>
#include "filter/svgf_impl.h"

/* Every tap of the table for rows [0, h) in steps of row_step, every chunk, every spacing. */
static void check_grid(const fv_grid *g, int row_step)
{
    (void)k_b3, (void)k_g3;
    const struct {
        int step, ncols;
    } kinds[7] = {{1, 5}, {2, 5}, {4, 5}, {8, 5}, {16, 5}, {1, 7}, {1, 3}};
    chunk_cols cc;
    long checked = 0;
    for (int y = 0; y < g->h; y += row_step)
        for (int x0 = 0; x0 < g->w; x0 += CHUNK) {
            const int nc = imin(CHUNK, g->w - x0);
            for (int kd = 0; kd < 7; kd++) {
                const int step = kinds[kd].step, ncols = kinds[kd].ncols, half = ncols / 2;
                /* A sub-range of the chunk, as the sweeps ask for (the table is only valid there). */
                const int k0 = nc > 3 ? (y + kd) % 3 : 0;
                chunk_columns(g, y, x0, k0, nc, step, ncols, &cc);
                for (int k = k0; k < nc; k++) {
                    const int x = x0 + k;
                    if (y >= fv_grid_col_h(g, x)) continue; /* not a cell: the sweeps never ask */
                    for (int ci = 0; ci < ncols; ci++)
                        for (int j = -half; j <= half; j++) {
                            const int dy = j * step;
                            const long want = fv_grid_tap(g, x, y, (ci - half) * step, dy);
                            const int got = chunk_tap(g, &cc, ci, k, dy);
                            if (got != want)
                                fail_msg("cell (%d, %d), column offset %d, row offset %d: table %d, grid %ld", x, y,
                                         (ci - half) * step, dy, got, want);
                            checked++;
                        }
                }
            }
        }
    assert_true(checked > 0);
}

static void test_triangle(void **st)
{
    (void)st;
    enum { W = 150, H = 72 };
    int col_h[W];
    for (int x = 0; x < W; x++) col_h[x] = 1 + 3 * x < H ? 1 + 3 * x : H;
    const fv_grid g = {W, H, col_h, true};
    check_grid(&g, 1);
}

static void test_visual_polar_size(void **st)
{
    (void)st;
    enum { W = 833, H = 937 };
    const double x_f = 131.1; /* the fovea's edge in columns at 1280x1440 (test_vp_space's layout) */
    int *col_h = malloc(sizeof(int) * W);
    for (int x = 0; x < W; x++) {
        int n = x + 0.5 < x_f ? (int)lround(H * (x + 0.5) / x_f) : H;
        col_h[x] = n < 1 ? 1 : (n > H ? H : n);
    }
    const fv_grid g = {W, H, col_h, true};
    check_grid(&g, 7);
    free(col_h);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle),
        cmocka_unit_test(test_visual_polar_size),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
