/* Tests of the VPL bookkeeping of Foveated Instant Radiosity (src/technique/vpl/manage.c), with
 * numbers worked by hand:
 *  - Eq. 1: 200k samples fall evenly on 8 equal-area rings and 8 sectors (bounds below), inside the
 *    disc; two points by hand;
 *  - Eq. 2 at C = 1/3, 1/2, 1, 2, 0 and the special inputs;
 *  - resampling: the CDF maps each uniform number to the index a hand walk gives, weights
 *    {0, 1, 0, 3} give exactly {1, 3} and index 3 three times in four, bad weights are ignored,
 *    no index twice and the first-drawn order against a plain re-implementation;
 *  - the density grid: 10 x 5 x 1 cells over a 10 x 5 x 1 box, cells of points in and outside,
 *    counts, and the refusals;
 *  - the selection of Alg. 4 line 4 and Alg. 5 on hand-built cases (each worked out beside it) and
 *    on random inputs for the invariants (never more than total, flags and grid agree);
 *  - interleaved tiles: old ones kept, new ones balanced.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "technique/vpl/manage.h"
#include "testkit.h"

/* ---- Eq. 1 ---- */

static void test_polar(void **state)
{
    (void)state;
    float x, y;
    /* R = sqrt(0.25) = 0.5, theta = 2 pi 0.25 = pi / 2: straight up. */
    fv_vpl_polar_sample(0.25f, 0.25f, &x, &y);
    assert_true(fabsf(x) < 1e-6f && fabsf(y - 0.5f) < 1e-6f);
    /* R = 1, theta = 0. */
    fv_vpl_polar_sample(1.0f, 0.0f, &x, &y);
    assert_true(fabsf(x - 1.0f) < 1e-6f && fabsf(y) < 1e-6f);
    /* R = sqrt(0.5), theta = pi: (-0.7071, 0). */
    fv_vpl_polar_sample(0.5f, 0.5f, &x, &y);
    assert_true(fabsf(x + 0.70710678f) < 1e-6f && fabsf(y) < 1e-6f);
    /* Out-of-range and NaN inputs still land in the disc. */
    fv_vpl_polar_sample(NAN, 2.0f, &x, &y);
    assert_true(isfinite(x) && isfinite(y) && x * x + y * y <= 1.0f + 1e-6f);

    /* Uniform over the disc: ring k = floor(8 R^2) (radii sqrt(k / 8), each 1/8 of the area) and
     * sector floor(8 theta / 2 pi) are independent and uniform, so each of the 64 joint bins
     * expects n / 64 = 3125 and each ring or sector n / 8 = 25000. Bounds:
     *  - a ring or sector within 3% (750) of 25000: its sd is sqrt(25000 * 7/8) = 148, so 5 sd;
     *  - a joint bin within 10% (312) of 3125: sd sqrt(3125 * 63/64) = 55.5, so 5.6 sd (3% would
     *    be 1.7 sd, which about 6 of 64 correct bins miss);
     *  - chi-square of the 64 bins below 103.4, its 0.999 quantile for 63 degrees of freedom.
     * R = u instead of sqrt(u) would put 35% of the points in ring 0, far outside all three. */
    enum { N = 200000 };
    int bins[8][8] = {{0}}, ring[8] = {0}, sector[8] = {0};
    fv_rng rng = fv_rng_make(20240611, 1, 0, 0);
    for (int i = 0; i < N; i++) {
        float u = fv_rng_next(&rng), v = fv_rng_next(&rng);
        fv_vpl_polar_sample(u, v, &x, &y);
        double r2 = (double)x * x + (double)y * y;
        if (!(r2 <= 1.0 + 1e-6)) fail_msg("sample %d (%g, %g) outside the unit disc", i, x, y);
        int k = (int)(8.0 * r2);
        double t = atan2(y, x);
        if (t < 0.0) t += 2.0 * FV_PI_D;
        int s = (int)(8.0 * t / (2.0 * FV_PI_D));
        k = k > 7 ? 7 : k;
        s = s > 7 ? 7 : s;
        bins[k][s]++, ring[k]++, sector[s]++;
    }
    double chi2 = 0.0;
    for (int k = 0; k < 8; k++) {
        if (abs(ring[k] - N / 8) > 750) fail_msg("ring %d holds %d, expected 25000 +- 750", k, ring[k]);
        if (abs(sector[k] - N / 8) > 750) fail_msg("sector %d holds %d, expected 25000 +- 750", k, sector[k]);
        for (int s = 0; s < 8; s++) {
            double d = bins[k][s] - N / 64.0;
            chi2 += d * d / (N / 64.0);
            if (fabs(d) > 312.5) fail_msg("bin (%d, %d) holds %d, expected 3125 +- 312", k, s, bins[k][s]);
        }
    }
    if (!(chi2 < 103.4)) fail_msg("chi-square %.1f of 64 bins above 103.4 (p = 0.001, 63 dof)", chi2);
}

/* ---- Eq. 2 ---- */

static void test_acceptance(void **state)
{
    (void)state;
    /* C = 1/2: 1 - cos(pi / 4) = 1 - 0.7071068 = 0.2928932. */
    assert_float_equal(fv_vpl_acceptance(1.0f, 2.0f), 0.29289322f, 1e-6f);
    /* C = 1/3: 1 - cos(pi / 6) = 1 - 0.8660254 = 0.1339746. */
    assert_float_equal(fv_vpl_acceptance(1.0f, 3.0f), 0.13397460f, 1e-6f);
    /* C = 1/4: 1 - cos(pi / 8) = 1 - 0.9238795 = 0.0761205. */
    assert_float_equal(fv_vpl_acceptance(0.5f, 2.0f), 0.07612047f, 1e-6f);
    assert_float_equal(fv_vpl_acceptance(3.0f, 3.0f), 1.0f, 1e-6f); /* C = 1 */
    assert_true(fv_vpl_acceptance(4.0f, 2.0f) == 1.0f);              /* C = 2 */
    assert_true(fv_vpl_acceptance(0.0f, 2.0f) == 0.0f);              /* C = 0 */
    assert_true(fv_vpl_acceptance(-1.0f, 2.0f) == 0.0f);             /* C < 0 */
    assert_true(fv_vpl_acceptance(5.0f, 0.0f) == 1.0f);              /* nothing to compare with */
    assert_true(fv_vpl_acceptance(5.0f, -1.0f) == 1.0f);
    assert_true(fv_vpl_acceptance(0.0f, 0.0f) == 0.0f);
    assert_true(fv_vpl_acceptance(NAN, 1.0f) == 0.0f);
    assert_true(fv_vpl_acceptance(1.0f, NAN) == 0.0f);
    assert_true(fv_vpl_acceptance(INFINITY, 1.0f) == 0.0f);
    assert_true(fv_vpl_acceptance(1.0f, INFINITY) == 0.0f);
    /* C = 1.5: exactly 1 (1 - cos(3 pi / 4) would be 1.707). */
    assert_true(fv_vpl_acceptance(3.0f, 2.0f) == 1.0f);
    /* Increasing in C up to 1, then exactly 1. */
    float prev = 0.0f;
    for (int i = 1; i <= 400; i++) {
        float a = fv_vpl_acceptance((float)i, 100.0f);
        if (i <= 100 ? !(a > prev && a <= 1.0f) : a != 1.0f) fail_msg("C = %g: acceptance %.8f", i / 100.0, a);
        prev = a;
    }
}

/* ---- Sec. 3.1: resampling ---- */

/* The draw a hand walk gives: the first index whose running sum of cleaned weights exceeds x. */
static int walk_index(const float *w, int count, double x)
{
    double acc = 0.0;
    for (int i = 0; i < count; i++) {
        acc += isfinite(w[i]) && w[i] > 0.0f ? w[i] : 0.0f;
        if (acc > x) return i;
    }
    return -1;
}

static double clean_total(const float *w, int count)
{
    double t = 0.0;
    for (int i = 0; i < count; i++) t += isfinite(w[i]) && w[i] > 0.0f ? w[i] : 0.0f;
    return t;
}

static void test_resample(void **state)
{
    (void)state;
    const float w[4] = {0.0f, 1.0f, 0.0f, 3.0f};
    int *out = malloc(4 * sizeof *out); /* exactly min(draws, count): a write past it is caught */
    fv_rng rng = fv_rng_make(7, 0, 0, 0);

    /* 10000 draws from {0, 1/4, 0, 3/4}: both positive indices appear, each once. */
    uint32_t dim0 = rng.dim;
    int n = fv_vpl_resample(w, 4, 10000, &rng, out);
    assert_int_equal(n, 2);
    assert_true((out[0] == 1 && out[1] == 3) || (out[0] == 3 && out[1] == 1));
    assert_int_equal(rng.dim - dim0, 10000); /* one fv_rng_next per draw */

    /* Each single draw: x = u * 4 falls in [0, 1) -> index 1, [1, 4) -> index 3 (the zero
     * weights own empty intervals). Counted over 40000 draws, index 3 expects 30000 with sd
     * sqrt(40000 * 3/16) = 87: within 1% (400) is 4.6 sd. */
    int threes = 0;
    for (int i = 0; i < 40000; i++) {
        fv_rng peek = rng;
        float u = fv_rng_next(&peek);
        int want = (double)u * 4.0 < 1.0 ? 1 : 3;
        assert_int_equal(fv_vpl_resample(w, 4, 1, &rng, out), 1);
        if (out[0] != want) fail_msg("draw %d: u = %.8f gave index %d, expected %d", i, u, out[0], want);
        threes += out[0] == 3;
    }
    if (abs(threes - 30000) > 400) fail_msg("index 3 drawn %d times of 40000, expected 30000 +- 400", threes);

    /* Nothing to draw from: 0, and the rng untouched. */
    const float zero[4] = {0.0f, 0.0f, -1.0f, 0.0f};
    dim0 = rng.dim;
    assert_int_equal(fv_vpl_resample(zero, 4, 100, &rng, out), 0);
    assert_int_equal(fv_vpl_resample(w, 0, 100, &rng, out), 0);
    assert_int_equal(fv_vpl_resample(w, 4, 0, &rng, out), 0);
    assert_int_equal(fv_vpl_resample(w, 4, -3, &rng, out), 0);
    assert_int_equal(rng.dim, dim0);

    /* Negative and non-finite weights count as 0: only index 2 can be drawn. */
    const float bad[5] = {-5.0f, NAN, 2.0f, INFINITY, -INFINITY};
    int out5[5];
    assert_int_equal(fv_vpl_resample(bad, 5, 100, &rng, out5), 1);
    assert_int_equal(out5[0], 2);
    free(out);

    /* Random weights (a third of them 0), more draws than indices: distinct positive-weight
     * indices, in the order a hand walk with the same numbers first meets them. */
    fv_rng wr = fv_rng_make(99, 0, 0, 0);
    for (int trial = 0; trial < 200; trial++) {
        int count = 1 + (int)(fv_rng_next(&wr) * 60.0f);
        int draws = 1 + (int)(fv_rng_next(&wr) * 150.0f);
        float *ww = malloc((size_t)count * sizeof *ww);
        for (int i = 0; i < count; i++) ww[i] = fv_rng_next(&wr) < 0.33f ? 0.0f : fv_rng_next(&wr) * 10.0f;
        int room = draws < count ? draws : count;
        int *o = malloc((size_t)room * sizeof *o);
        int *want = malloc((size_t)room * sizeof *want);
        bool *seen = calloc((size_t)count, sizeof *seen);
        double total = clean_total(ww, count);
        int nw = 0;
        fv_rng r = fv_rng_make(1000 + (uint64_t)trial, 0, 0, 0), peek = r;
        for (int d = 0; d < draws && total > 0.0; d++) {
            int i = walk_index(ww, count, (double)fv_rng_next(&peek) * total);
            assert_true(i >= 0);
            if (!seen[i]) seen[i] = true, want[nw++] = i;
        }
        int got = fv_vpl_resample(ww, count, draws, &r, o);
        if (got != nw) fail_msg("trial %d: %d indices, expected %d", trial, got, nw);
        for (int k = 0; k < got; k++) {
            if (o[k] != want[k]) fail_msg("trial %d: out[%d] = %d, expected %d", trial, k, o[k], want[k]);
            assert_true(ww[o[k]] > 0.0f);
            for (int m = 0; m < k; m++) assert_int_not_equal(o[k], o[m]);
        }
        free(ww), free(o), free(want), free(seen);
    }
}

/* ---- the density grid ---- */

static fv_density_grid *new_grid(fv_vec3 lo, fv_vec3 hi, int res)
{
    fv_density_grid *g = NULL;
    fv_error err;
    if (fv_density_grid_create(lo, hi, res, &g, &err) != FV_OK) fail_msg("%s", err.msg);
    return g;
}

static void test_density_grid(void **state)
{
    (void)state;
    /* Longest axis 10 over 10 cells: cubes of edge 1, so 10 x 5 x 1. */
    fv_density_grid *g = new_grid(fv_v3(0, 0, 0), fv_v3(10, 5, 1), 10);
    assert_int_equal(fv_density_grid_cells(g), 50);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(9.99f, 4.99f, 0.5f)), 9 + 10 * 4); /* 49: the last */
    assert_int_equal(fv_density_grid_cell(g, fv_v3(0, 0, 0)), 0);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(1.5f, 2.5f, 0.5f)), 1 + 10 * 2);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(10, 5, 1)), 49); /* the far corner is in the box */
    /* Outside: clamped per axis. */
    assert_int_equal(fv_density_grid_cell(g, fv_v3(-3, 7, 9)), 0 + 10 * 4);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(20, -1, -1)), 9);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(INFINITY, -INFINITY, 0.5f)), 9);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(1e30f, 1e30f, 1e30f)), 49);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(5.5f, NAN, 0.5f)), 0); /* NaN: cell 0 */

    /* Counts: two in the cell [0, 1)^3, one clamped into the last. */
    fv_density_grid_add(g, fv_v3(0.5f, 0.5f, 0.5f), 1);
    fv_density_grid_add(g, fv_v3(0.9f, 0.1f, 0.2f), 1);
    fv_density_grid_add(g, fv_v3(50, 50, 50), 1);
    assert_int_equal(fv_density_grid_count(g, fv_v3(0.1f, 0.9f, 0.9f)), 2);
    assert_int_equal(fv_density_grid_count(g, fv_v3(1.1f, 0.5f, 0.5f)), 0);
    assert_int_equal(fv_density_grid_count(g, fv_v3(9.5f, 4.5f, 0.5f)), 1);
    fv_density_grid_add(g, fv_v3(0.5f, 0.5f, 0.5f), -1);
    assert_int_equal(fv_density_grid_count(g, fv_v3(0.5f, 0.5f, 0.5f)), 1);
    fv_density_grid_add(g, fv_v3(0.5f, 0.5f, 0.5f), -5); /* never below 0 */
    assert_int_equal(fv_density_grid_count(g, fv_v3(0.5f, 0.5f, 0.5f)), 0);
    fv_density_grid_clear(g);
    assert_int_equal(fv_density_grid_count(g, fv_v3(9.5f, 4.5f, 0.5f)), 0);
    fv_density_grid_destroy(g);

    /* 4.5 / 1 covers in 5 cells; a flat axis gets one. Offset origin: cell of (-1.5, 2.2, 3) is
     * x 8, y 4 (2.2 + 2 = 4.2). */
    g = new_grid(fv_v3(-10, -2, 3), fv_v3(0, 2.5f, 3), 10);
    assert_int_equal(fv_density_grid_cells(g), 10 * 5 * 1);
    assert_int_equal(fv_density_grid_cell(g, fv_v3(-1.5f, 2.2f, 3)), 8 + 10 * 4);
    fv_density_grid_destroy(g);
    fv_density_grid_destroy(NULL);
}

static void test_refusals(void **state)
{
    (void)state;
    fv_density_grid *g = (fv_density_grid *)&g; /* must come back NULL */
    fv_error err;
    const fv_vec3 lo = fv_v3(0, 0, 0), hi = fv_v3(1, 1, 1);
    fv_test_expect_fail(fv_density_grid_create(lo, hi, 0, &g, &err), &err, FV_ERR_INVALID, "density_grid", "resolution 0");
    assert_null(g);
    fv_test_expect_fail(fv_density_grid_create(lo, hi, 300, &g, &err), &err, FV_ERR_INVALID, "density_grid", "resolution 300");
    fv_test_expect_fail(fv_density_grid_create(lo, hi, -1, &g, &err), &err, FV_ERR_INVALID, "density_grid", "resolution -1");
    fv_test_expect_fail(fv_density_grid_create(fv_v3(NAN, 0, 0), hi, 8, &g, &err), &err, FV_ERR_INVALID, "density_grid", "NaN lo");
    fv_test_expect_fail(fv_density_grid_create(lo, fv_v3(1, INFINITY, 1), 8, &g, &err), &err, FV_ERR_INVALID, "density_grid", "inf hi");
    fv_test_expect_fail(fv_density_grid_create(hi, lo, 8, &g, &err), &err, FV_ERR_INVALID, "density_grid", "hi < lo");
    fv_test_expect_fail(fv_density_grid_create(lo, lo, 8, &g, &err), &err, FV_ERR_INVALID, "density_grid", "a point");
    assert_null(g);
    /* The bounds themselves are accepted. */
    g = new_grid(lo, hi, 1);
    assert_int_equal(fv_density_grid_cells(g), 1);
    fv_density_grid_destroy(g);
    g = new_grid(lo, hi, 256);
    assert_int_equal(fv_density_grid_cells(g), 256 * 256 * 256);
    fv_density_grid_destroy(g);
}

/* ---- Alg. 4 line 4 and Alg. 5 ---- */

/* The selection cases share a row of four unit cells along x: [0, 4] x [0, 1] x [0, 1] at
 * resolution 4, and CELL(k) is the centre of cell k. */
#define CELL(k) fv_v3((float)(k) + 0.5f, 0.5f, 0.5f)

typedef struct sel_result {
    int n, reused, left;
    bool keep[16], take[16];
} sel_result;

static sel_result run_select(const fv_vpl_select_in *in, int total, int limit, float c, fv_density_grid *g)
{
    sel_result r;
    memset(&r, 0, sizeof r);
    /* Poison the flags: the call must write every one. */
    memset(r.keep, 0x5a, sizeof r.keep);
    memset(r.take, 0x5a, sizeof r.take);
    fv_vpl_select_opts o = {total, limit, c, NULL};
    fv_density_grid_clear(g);
    r.n = fv_vpl_select(in, &o, g, r.keep, r.take, &r.reused, &r.left);
    for (int i = 0; i < in->n_old; i++) assert_true(r.keep[i] == true || r.keep[i] == false);
    for (int i = 0; i < in->n_cand; i++) assert_true(r.take[i] == true || r.take[i] == false);
    return r;
}

static void expect_flags(const bool *got, const int *want, int n, const char *what)
{
    for (int i = 0; i < n; i++)
        if (got[i] != (want[i] != 0)) fail_msg("%s[%d] = %d, expected %d", what, i, got[i], want[i]);
}

static void test_select_reuse(void **state)
{
    (void)state;
    fv_density_grid *g = new_grid(fv_v3(0, 0, 0), fv_v3(4, 1, 1), 4);

    /* (a) Importance up or equal for all three old VPLs: Eq. 2 gives 1 > any u, so all are kept;
     * total = 3 is then reached and neither candidate (however important) is taken. */
    {
        const fv_vec3 op[3] = {CELL(0), CELL(1), CELL(2)}, cp[2] = {CELL(3), CELL(3)};
        const float prev[3] = {1, 1, 1}, now[3] = {2, 1, 5}, u[3] = {0.99f, 0.5f, 0.0f}, ci[2] = {10, 10};
        fv_vpl_select_in in = {3, op, prev, now, u, 2, cp, ci};
        sel_result r = run_select(&in, 3, 10, 1.0f, g);
        assert_int_equal(r.n, 3);
        assert_int_equal(r.reused, 3);
        assert_int_equal(r.left, 0);
        expect_flags(r.keep, (const int[]){1, 1, 1}, 3, "keep_old");
        expect_flags(r.take, (const int[]){0, 0}, 2, "take_cand");
        /* The grid holds the three reused ones. */
        assert_int_equal(fv_density_grid_count(g, CELL(0)), 1);
        assert_int_equal(fv_density_grid_count(g, CELL(2)), 1);
        assert_int_equal(fv_density_grid_count(g, CELL(3)), 0);
    }

    /* (b) Importance halved (2 -> 1): Eq. 2 = 0.29289. u = 0.29 keeps VPL 0, u = 0.30 leaves VPL 1;
     * with no candidate N = 0 and the left one is dropped. */
    {
        const fv_vec3 op[2] = {CELL(0), CELL(0)};
        const float prev[2] = {2, 2}, now[2] = {1, 1}, u[2] = {0.29f, 0.30f};
        fv_vpl_select_in in = {2, op, prev, now, u, 0, NULL, NULL};
        sel_result r = run_select(&in, 10, 10, 1.0f, g);
        assert_int_equal(r.n, 1);
        assert_int_equal(r.reused, 1);
        assert_int_equal(r.left, 0);
        expect_flags(r.keep, (const int[]){1, 0}, 2, "keep_old");
        assert_int_equal(fv_density_grid_count(g, CELL(0)), 1);
    }

    /* Step 1 stops at total, in index order: five reusable, total 3 -> the first three. */
    {
        const fv_vec3 op[5] = {CELL(0), CELL(1), CELL(2), CELL(3), CELL(0)};
        const float prev[5] = {1, 1, 1, 1, 1}, now[5] = {1, 1, 1, 1, 1}, u[5] = {0};
        fv_vpl_select_in in = {5, op, prev, now, u, 0, NULL, NULL};
        sel_result r = run_select(&in, 3, 10, 1.0f, g);
        assert_int_equal(r.n, 3);
        assert_int_equal(r.reused, 3);
        expect_flags(r.keep, (const int[]){1, 1, 1, 0, 0}, 5, "keep_old");
    }
    fv_density_grid_destroy(g);
}

static void test_select_pairs(void **state)
{
    (void)state;
    fv_density_grid *g = new_grid(fv_v3(0, 0, 0), fv_v3(4, 1, 1), 4);
    /* An old VPL that is left: importance 4 -> 1, Eq. 2 = 1 - cos(pi / 8) = 0.076 < u = 0.9. Its
     * score with C = 1 in an empty cell is 1 + 1 / (0 + 1) = 2. */
    const float prev1[1] = {4}, now1[1] = {1}, u1[1] = {0.9f};
    const fv_vec3 op1[1] = {CELL(0)};

    /* (c) A candidate in the empty cell 1 with importance 2: score 2 + 1 = 3 > 2 and 0 < limit 2,
     * so the candidate replaces the left VPL. */
    {
        const fv_vec3 cp[1] = {CELL(1)};
        const float ci[1] = {2};
        fv_vpl_select_in in = {1, op1, prev1, now1, u1, 1, cp, ci};
        sel_result r = run_select(&in, 5, 2, 1.0f, g);
        assert_int_equal(r.n, 1);
        assert_int_equal(r.reused, 0);
        assert_int_equal(r.left, 0);
        assert_false(r.keep[0]);
        assert_true(r.take[0]);
        assert_int_equal(fv_density_grid_count(g, CELL(1)), 1);
        assert_int_equal(fv_density_grid_count(g, CELL(0)), 0);
    }
    /* Importance 1: score 1 + 1 = 2, a tie is not "better" (strict <): the left VPL stays. */
    {
        const fv_vec3 cp[1] = {CELL(1)};
        const float ci[1] = {1};
        fv_vpl_select_in in = {1, op1, prev1, now1, u1, 1, cp, ci};
        sel_result r = run_select(&in, 5, 2, 1.0f, g);
        assert_int_equal(r.n, 1);
        assert_int_equal(r.left, 1);
        assert_true(r.keep[0]);
        assert_false(r.take[0]);
        assert_int_equal(fv_density_grid_count(g, CELL(0)), 1);
    }
    /* (c) The candidate's cell already holds density_limit = 2 VPLs (two reused old ones, u = 0 <
     * Eq. 2 = 1): its score 100 + 1 / (2 + 1) beats 2, but vd_c = 2 is not < 2, so the left VPL 2
     * is kept. 3 selected: 2 reused + 1 left. */
    {
        const fv_vec3 op[3] = {CELL(1), CELL(1), CELL(0)}, cp[1] = {CELL(1)};
        const float prev[3] = {1, 1, 4}, now[3] = {1, 1, 1}, u[3] = {0, 0, 0.9f}, ci[1] = {100};
        fv_vpl_select_in in = {3, op, prev, now, u, 1, cp, ci};
        sel_result r = run_select(&in, 10, 2, 1.0f, g);
        assert_int_equal(r.n, 3);
        assert_int_equal(r.reused, 2);
        assert_int_equal(r.left, 1);
        expect_flags(r.keep, (const int[]){1, 1, 1}, 3, "keep_old");
        assert_false(r.take[0]);
        assert_int_equal(fv_density_grid_count(g, CELL(1)), 2);
        /* With limit 3 the same candidate replaces it. */
        r = run_select(&in, 10, 3, 1.0f, g);
        assert_int_equal(r.n, 3);
        assert_int_equal(r.left, 0);
        expect_flags(r.keep, (const int[]){1, 1, 0}, 3, "keep_old");
        assert_true(r.take[0]);
    }

    /* Sorting and current densities. Three left VPLs (u = 0.99 > Eq. 2 of 100 -> imp), C = 1,
     * all cells empty after step 1, so score = imp + 1:
     *   old 0 cell 0 imp 5   -> 6         cand 0 cell 3 imp 2   -> 3
     *   old 1 cell 1 imp 1   -> 2         cand 1 cell 3 imp 6   -> 7
     *   old 2 cell 2 imp 3.2 -> 4.2       cand 2 cell 3 imp 3.6 -> 4.6
     *                                     cand 3 cell 3 imp 0.1 -> 1.1
     * Left ascending: old 1, old 2, old 0; candidates descending: cand 1, cand 2, cand 0, cand 3.
     *   pair 0: old 1 (2) vs cand 1 (7): cand 1 taken, cell 3 holds 1.
     *   pair 1: old 2 (4.2) vs cand 2 at vd 1: 3.6 + 1/2 = 4.1 < 4.2: old 2 kept (with the
     *           density of the ranking, 4.6, cand 2 would have won).
     *   pair 2: old 0 (6) vs cand 0 at vd 1: 2.5: old 0 kept.
     * Step 3 starts after the N = 3 pairs: cand 3 (vd 1 < 10) taken; cand 0, which lost its
     * pair, is not tried again. 4 selected. In index order instead of sorted, pair 0 would set
     * old 0 against cand 0 and keep old 0, a different selection. */
    {
        const fv_vec3 op[3] = {CELL(0), CELL(1), CELL(2)}, cp[4] = {CELL(3), CELL(3), CELL(3), CELL(3)};
        const float prev[3] = {100, 100, 100}, now[3] = {5, 1, 3.2f}, u[3] = {0.99f, 0.99f, 0.99f};
        const float ci[4] = {2, 6, 3.6f, 0.1f};
        fv_vpl_select_in in = {3, op, prev, now, u, 4, cp, ci};
        sel_result r = run_select(&in, 10, 10, 1.0f, g);
        assert_int_equal(r.n, 4);
        assert_int_equal(r.reused, 0);
        assert_int_equal(r.left, 2);
        expect_flags(r.keep, (const int[]){1, 0, 1}, 3, "keep_old");
        expect_flags(r.take, (const int[]){0, 1, 0, 1}, 4, "take_cand");
        assert_int_equal(fv_density_grid_count(g, CELL(3)), 2);
        assert_int_equal(fv_density_grid_count(g, CELL(1)), 0);

        /* (e) total = 2: pair 0 (cand 1) and pair 1 (old 2) fill it; pair 2 and step 3 are skipped. */
        r = run_select(&in, 2, 10, 1.0f, g);
        assert_int_equal(r.n, 2);
        assert_int_equal(r.left, 1);
        expect_flags(r.keep, (const int[]){0, 0, 1}, 3, "keep_old");
        expect_flags(r.take, (const int[]){0, 1, 0, 0}, 4, "take_cand");
    }

    /* More left VPLs than candidates: the left ones past N are dropped. Left scores (C = 1): 2, 4,
     * 3 -> ascending old 0, old 2, old 1; one candidate, score 0.5 + 1 = 1.5 < 2: old 0 kept,
     * old 2 and old 1 dropped. */
    {
        const fv_vec3 op[3] = {CELL(0), CELL(1), CELL(2)}, cp[1] = {CELL(3)};
        const float prev[3] = {100, 100, 100}, now[3] = {1, 3, 2}, u[3] = {0.99f, 0.99f, 0.99f}, ci[1] = {0.5f};
        fv_vpl_select_in in = {3, op, prev, now, u, 1, cp, ci};
        sel_result r = run_select(&in, 10, 10, 1.0f, g);
        assert_int_equal(r.n, 1);
        assert_int_equal(r.left, 1);
        expect_flags(r.keep, (const int[]){1, 0, 0}, 3, "keep_old");
        assert_false(r.take[0]);
    }
    fv_density_grid_destroy(g);
}

static void test_select_fill(void **state)
{
    (void)state;
    fv_density_grid *g = new_grid(fv_v3(0, 0, 0), fv_v3(4, 1, 1), 4);
    /* (d) No old VPLs, so N = 0 and only the fill loop runs. Scores (C = 1, empty grid) 6, 5, 4,
     * 3, 2 keep the index order. limit 1, total 3:
     *   cand 0 (cell 0) taken; cand 1 (cell 0, now full) skipped; cand 2 (cell 1) taken;
     *   cand 3 (cell 2) taken: 3 = total, so cand 4 (cell 3, empty) is not looked at. */
    const fv_vec3 cp[5] = {CELL(0), CELL(0), CELL(1), CELL(2), CELL(3)};
    const float ci[5] = {5, 4, 3, 2, 1};
    fv_vpl_select_in in = {0, NULL, NULL, NULL, NULL, 5, cp, ci};
    sel_result r = run_select(&in, 3, 1, 1.0f, g);
    assert_int_equal(r.n, 3);
    assert_int_equal(r.reused, 0);
    assert_int_equal(r.left, 0);
    expect_flags(r.take, (const int[]){1, 0, 1, 1, 0}, 5, "take_cand");
    assert_int_equal(fv_density_grid_count(g, CELL(0)), 1);
    assert_int_equal(fv_density_grid_count(g, CELL(3)), 0);
    /* total 10: the full cell is still skipped, cand 4 now fits. */
    r = run_select(&in, 10, 1, 1.0f, g);
    assert_int_equal(r.n, 4);
    expect_flags(r.take, (const int[]){1, 0, 1, 1, 1}, 5, "take_cand");
    /* Equal scores: lower index first. All five in cell 0 with importance 1, limit 2: 0 and 1. */
    const fv_vec3 same[5] = {CELL(0), CELL(0), CELL(0), CELL(0), CELL(0)};
    const float ones[5] = {1, 1, 1, 1, 1};
    fv_vpl_select_in tie = {0, NULL, NULL, NULL, NULL, 5, same, ones};
    r = run_select(&tie, 10, 2, 1.0f, g);
    assert_int_equal(r.n, 2);
    expect_flags(r.take, (const int[]){1, 1, 0, 0, 0}, 5, "take_cand");
    /* Nothing allowed: total 0 or limit 0. */
    assert_int_equal(run_select(&in, 0, 1, 1.0f, g).n, 0);
    assert_int_equal(run_select(&in, 10, 0, 1.0f, g).n, 0);
    fv_density_grid_destroy(g);
}

/* (e) Random inputs: whatever the mix, never more than total, the counts agree with the flags and
 * with the grid, step 1 keeps exactly the first `total` reusable old VPLs, and a candidate is
 * only taken into a cell that held fewer than density_limit before it. */
static void test_select_random(void **state)
{
    (void)state;
    enum { MAXN = 40 };
    fv_density_grid *g = new_grid(fv_v3(0, 0, 0), fv_v3(4, 4, 4), 4);
    fv_rng r = fv_rng_make(4242, 0, 0, 0);
    fv_vec3 op[MAXN], cp[MAXN];
    float prev[MAXN], now[MAXN], u[MAXN], ci[MAXN];
    bool keep[MAXN], take[MAXN];
    for (int trial = 0; trial < 2000; trial++) {
        int n_old = (int)(fv_rng_next(&r) * MAXN), n_cand = (int)(fv_rng_next(&r) * MAXN);
        int total = (int)(fv_rng_next(&r) * 50.0f), limit = (int)(fv_rng_next(&r) * 5.0f);
        for (int i = 0; i < n_old; i++) {
            op[i] = fv_v3(fv_rng_next(&r) * 4.0f, fv_rng_next(&r) * 4.0f, fv_rng_next(&r) * 4.0f);
            prev[i] = fv_rng_next(&r) * 3.0f;
            now[i] = fv_rng_next(&r) * 3.0f;
            u[i] = fv_rng_next(&r);
        }
        for (int i = 0; i < n_cand; i++) {
            /* Mostly in a corner so cells fill up. */
            cp[i] = fv_v3(fv_rng_next(&r) * 1.5f, fv_rng_next(&r) * 1.5f, fv_rng_next(&r) * 4.0f);
            ci[i] = fv_rng_next(&r) * 3.0f;
        }
        fv_vpl_select_in in = {n_old, op, prev, now, u, n_cand, cp, ci};
        fv_vpl_select_opts o = {total, limit, 0.5f, NULL};
        fv_density_grid_clear(g);
        int reused = -1, left = -1;
        int n = fv_vpl_select(&in, &o, g, keep, take, &reused, &left);
        if (n > total) fail_msg("trial %d: %d selected, total %d", trial, n, total);
        int nk = 0, nt = 0, first = 0;
        for (int i = 0; i < n_old; i++) nk += keep[i];
        for (int i = 0; i < n_cand; i++) nt += take[i];
        assert_int_equal(nk + nt, n);
        assert_int_equal(reused + left, nk);
        /* Step 1 by hand. */
        for (int i = 0; i < n_old; i++) {
            bool reusable = u[i] < fv_vpl_acceptance(now[i], prev[i]) && first < total;
            if (reusable) {
                first++;
                if (!keep[i]) fail_msg("trial %d: reusable old %d not kept", trial, i);
            }
        }
        assert_int_equal(first, reused);
        /* The grid holds exactly the selected VPLs. */
        int cells[64] = {0};
        for (int i = 0; i < n_old; i++) cells[fv_density_grid_cell(g, op[i])] += keep[i];
        for (int i = 0; i < n_cand; i++) cells[fv_density_grid_cell(g, cp[i])] += take[i];
        int sum = 0;
        for (int i = 0; i < n_old; i++) assert_int_equal(fv_density_grid_count(g, op[i]), cells[fv_density_grid_cell(g, op[i])]);
        for (int i = 0; i < n_cand; i++) assert_int_equal(fv_density_grid_count(g, cp[i]), cells[fv_density_grid_cell(g, cp[i])]);
        for (int c = 0; c < 64; c++) sum += cells[c];
        assert_int_equal(sum, n);
        /* A cell with a taken candidate: the candidates alone never exceed the limit (each was
         * taken while the cell held fewer than `limit` VPLs of any kind). */
        int cand_cells[64] = {0};
        for (int i = 0; i < n_cand; i++) cand_cells[fv_density_grid_cell(g, cp[i])] += take[i];
        for (int c = 0; c < 64; c++)
            if (cand_cells[c] > limit) fail_msg("trial %d: cell %d took %d candidates, limit %d", trial, c, cand_cells[c], limit);
    }
    fv_density_grid_destroy(g);
}

/* ---- Sec. 3.4: tiles ---- */

static void test_tiles(void **state)
{
    (void)state;
    /* Tile loads {3, 0, 0}: VPL 3 -> tile 1 {3,1,0}, VPL 4 -> tile 2 {3,1,1}, VPL 5 -> tile 1 (the
     * lower of two at 1). */
    int t1[6] = {0, 0, 0, -1, -1, -1};
    fv_vpl_assign_tiles(t1, 6, 3);
    const int w1[6] = {0, 0, 0, 1, 2, 1};
    for (int i = 0; i < 6; i++) assert_int_equal(t1[i], w1[i]);

    /* 5 >= 3 tiles counts as new. Loads {0, 1, 1}: VPL 1 -> 0 {1,1,1}, VPL 2 -> 0 {2,1,1},
     * VPL 3 -> 1. */
    int t2[5] = {2, -1, 5, -1, 1};
    fv_vpl_assign_tiles(t2, 5, 3);
    const int w2[5] = {2, 0, 0, 1, 1};
    for (int i = 0; i < 5; i++) assert_int_equal(t2[i], w2[i]);

    /* No tiles: unchanged. */
    int t3[2] = {-1, 4};
    fv_vpl_assign_tiles(t3, 2, 0);
    assert_int_equal(t3[0], -1);
    assert_int_equal(t3[1], 4);

    /* All new, many tiles (past the stack table): 4000 over 2000 tiles is 2 each, in round robin. */
    enum { NT = 2000, NV = 4000 };
    int *t4 = malloc(NV * sizeof *t4);
    for (int i = 0; i < NV; i++) t4[i] = -1;
    fv_vpl_assign_tiles(t4, NV, NT);
    int *load = calloc(NT, sizeof *load);
    for (int i = 0; i < NV; i++) {
        assert_int_equal(t4[i], i % NT);
        load[t4[i]]++;
    }
    for (int t = 0; t < NT; t++) assert_int_equal(load[t], 2);
    free(t4), free(load);

    /* Old ones unbalanced (10 in tile 0 of 4), 20 new: tile 0 is never the least loaded, so the
     * new ones go round tiles 1-3, ending at 7, 7 and 6. */
    int t5[30];
    for (int i = 0; i < 30; i++) t5[i] = i < 10 ? 0 : -1;
    fv_vpl_assign_tiles(t5, 30, 4);
    int l5[4] = {0};
    for (int i = 0; i < 30; i++) {
        assert_true(t5[i] >= 0 && t5[i] < 4);
        if (i >= 10) assert_int_not_equal(t5[i], 0);
        l5[t5[i]]++;
    }
    for (int t = 0; t < 4; t++) assert_int_equal(l5[t], t == 0 ? 10 : 20 / 3 + (t <= 20 % 3));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_polar),        cmocka_unit_test(test_acceptance),  cmocka_unit_test(test_resample),
        cmocka_unit_test(test_density_grid), cmocka_unit_test(test_refusals),    cmocka_unit_test(test_select_reuse),
        cmocka_unit_test(test_select_pairs), cmocka_unit_test(test_select_fill), cmocka_unit_test(test_select_random),
        cmocka_unit_test(test_tiles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
