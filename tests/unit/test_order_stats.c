/* Order statistics of timings (core/order_stats.h): the nearest-rank percentile a bench row's
 * frame pacing and `fovea bench scaling` report, and the median of a row's repeats, on arrays
 * worked by hand. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>
#include "core/order_stats.h"

/* Ten frame times, shuffled: sorted they are 1 2 3 4 5 6 7 8 9 40. Nearest rank k = ceil(q/100 n):
 * p50: k = 5 -> 5; p90: k = 9 -> 9; p91: k = ceil(9.1) = 10 -> 40; p99: k = 10 -> 40 (over fewer
 * than 100 frames p99 is the worst frame); p10: k = 1 -> 1; p0 and p100: the least and the worst. */
static void test_percentile_ten(void **st)
{
    (void)st;
    const double frames[10] = {7, 3, 40, 1, 9, 5, 2, 8, 4, 6};
    const double q[] = {50, 90, 91, 99, 10, 0, 100, 25};
    const double want[] = {5, 9, 40, 40, 1, 1, 40, 3}; /* p25: k = ceil(2.5) = 3 -> 3 */
    for (size_t i = 0; i < sizeof q / sizeof q[0]; i++) {
        double v[10];
        memcpy(v, frames, sizeof v);
        assert_true(fv_percentile(v, 10, q[i]) == want[i]);
    }
}

/* 200 frames 1..200 in reverse: p50 is the 100th value (100), p99 the 198th (198), p99.5 the
 * 199th; never a value between two frames. Also the sort in place (the caller's array). */
static void test_percentile_200(void **st)
{
    (void)st;
    double v[200];
    for (int i = 0; i < 200; i++) v[i] = 200 - i;
    assert_true(fv_percentile(v, 200, 50.0) == 100.0);
    assert_true(v[0] == 1.0 && v[199] == 200.0);
    assert_true(fv_percentile(v, 200, 99.0) == 198.0);
    assert_true(fv_percentile(v, 200, 99.5) == 199.0);
    double one = 3.25;
    assert_true(fv_percentile(&one, 1, 50.0) == 3.25);
    assert_true(fv_percentile(&one, 1, 99.0) == 3.25);
}

/* The median interpolates where the percentile does not: of 4 values, the mean of the middle two
 * (p50 is the lower one); the input stays in its order. */
static void test_median(void **st)
{
    (void)st;
    double v[4] = {10, 2, 8, 4};
    assert_true(fv_median(v, 4) == 6.0);
    assert_true(v[0] == 10 && v[1] == 2 && v[2] == 8 && v[3] == 4);
    assert_true(fv_percentile(v, 4, 50.0) == 4.0);
    const double odd[3] = {9, 1, 5};
    assert_true(fv_median(odd, 3) == 5.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_percentile_ten),
        cmocka_unit_test(test_percentile_200),
        cmocka_unit_test(test_median),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
