/* Tests of the parameter bag, the stats record and the counter-based random numbers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>
#include "core/rng.h"
#include "core/params_read.h"
#include "fovea/technique.h"

static void test_params_read_and_validate(void **st)
{
    (void)st;
    fv_params *p;
    fv_error err;
    assert_int_equal(fv_params_create(&p, &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "spp=64", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "ratio=0.25", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "filter=off", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "mode=fast", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "spp=128", &err), FV_OK); /* later value wins */
    int i;
    double d;
    bool b;
    assert_int_equal(fv_params_int(p, "spp", 1, 1, 1000, &i, &err), FV_OK);
    assert_int_equal(i, 128);
    assert_int_equal(fv_params_int(p, "absent", 7, 1, 10, &i, &err), FV_OK);
    assert_int_equal(i, 7);
    assert_int_equal(fv_params_float(p, "ratio", 0.5, 0.0, 1.0, &d, &err), FV_OK);
    assert_float_equal(d, 0.25, 0.0);
    assert_int_equal(fv_params_bool(p, "filter", true, &b, &err), FV_OK);
    assert_false(b);
    const char *const modes[] = {"slow", "fast", NULL};
    assert_int_equal(fv_params_choice(p, "mode", 0, modes, &i, &err), FV_OK);
    assert_int_equal(i, 1);
    assert_int_equal(fv_params_check_used(p, "x", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "typo=1", &err), FV_OK);
    assert_int_equal(fv_params_check_used(p, "pt", &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "'typo'"));
    assert_non_null(strstr(err.msg, "'pt'"));
    fv_params_destroy(p);
}

static void test_params_errors(void **st)
{
    (void)st;
    fv_params *p;
    fv_error err;
    fv_params_create(&p, &err);
    assert_int_equal(fv_params_parse(p, "novalue", &err), FV_ERR_INVALID);
    assert_int_equal(fv_params_parse(p, "=3", &err), FV_ERR_INVALID);
    assert_int_equal(fv_params_parse(p, "Bad Key=3", &err), FV_ERR_INVALID);
    fv_params_parse(p, "n=12x", &err);
    fv_params_parse(p, "r=nan", &err);
    fv_params_parse(p, "big=5000", &err);
    fv_params_parse(p, "b=maybe", &err);
    int i;
    double d;
    bool b;
    assert_int_equal(fv_params_int(p, "n", 0, 0, 100, &i, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "n=12x"));
    assert_int_equal(fv_params_float(p, "r", 0, 0, 1, &d, &err), FV_ERR_INVALID);
    assert_int_equal(fv_params_int(p, "big", 0, 0, 100, &i, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "out of range"));
    assert_int_equal(fv_params_bool(p, "b", false, &b, &err), FV_ERR_INVALID);
    fv_params_destroy(p);
}

static void test_stats(void **st)
{
    (void)st;
    fv_stats s;
    fv_stats_clear(&s);
    fv_stats_add_ms(&s, "trace", 1.5);
    fv_stats_add_ms(&s, "trace", 2.0);
    fv_stats_add_count(&s, "rays", 10);
    assert_float_equal(fv_stats_get_ms(&s, "trace"), 3.5, 0.0);
    assert_float_equal(fv_stats_get_count(&s, "rays"), 10, 0.0);
    assert_float_equal(fv_stats_get_count(&s, "absent"), 0, 0.0);
}

/* The generator is a pure function of (seed, pixel, sample, frame, dimension) and its output
 * is uniform: mean 1/2, variance 1/12, and neighbouring streams uncorrelated. */
static void test_rng(void **st)
{
    (void)st;
    fv_rng a = fv_rng_make(1, 2, 3, 4), b = fv_rng_make(1, 2, 3, 4), c = fv_rng_make(1, 2, 3, 5);
    float fa = fv_rng_next(&a);
    assert_float_equal(fa, fv_rng_next(&b), 0.0);
    assert_true(fa != fv_rng_next(&c));
    double sum = 0, sum2 = 0, cross = 0;
    const int n = 1000000;
    for (int i = 0; i < n; i++) {
        fv_rng r = fv_rng_make(9, (uint64_t)i, 0, 0), q = fv_rng_make(9, (uint64_t)i + 1, 0, 0);
        double x = fv_rng_next(&r), y = fv_rng_next(&q);
        assert_true(x >= 0.0 && x < 1.0);
        sum += x;
        sum2 += x * x;
        cross += (x - 0.5) * (y - 0.5);
    }
    double mean = sum / n, var = sum2 / n - mean * mean;
    assert_float_equal(mean, 0.5, 0.002);
    assert_float_equal(var, 1.0 / 12.0, 0.001);
    assert_float_equal(cross / n, 0.0, 0.001);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params_read_and_validate),
        cmocka_unit_test(test_params_errors),
        cmocka_unit_test(test_stats),
        cmocka_unit_test(test_rng),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
