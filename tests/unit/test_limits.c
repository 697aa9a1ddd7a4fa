/* The coordinate and intensity limits (fovea/limits.h): one range, the same verdict for a double a
 * reader parsed and for the float it became, and messages that name what is out of range. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"

static void test_coords(void **st)
{
    (void)st;
    fv_error err;
    double ok[3] = {FV_COORD_MAX, -FV_COORD_MAX, 0.0};
    assert_int_equal(fv_limit_coords("p", ok, 3, &err), FV_OK);
    /* The float a bound value becomes passes too (float(1e9) is exact, float(1e20) above). */
    assert_int_equal(fv_limit_vec3("p", fv_v3((float)FV_COORD_MAX, -(float)FV_COORD_MAX, 0), &err), FV_OK);
    double far[2] = {1.0, 1e19};
    assert_int_equal(fv_limit_coords("--camera-pos 1,1e19", far, 2, &err), FV_ERR_INVALID);
    assert_string_equal(err.msg, "--camera-pos 1,1e19: coordinate 1e+19 is beyond +-1e+09, the range the ray kernels take");
    /* Embree's own limit, 1.844e18, is refused with nine orders of margin. */
    double embree = 1.844e18;
    assert_int_equal(fv_limit_coords("x", &embree, 1, &err), FV_ERR_INVALID);
    double nan = NAN;
    assert_int_equal(fv_limit_coords("x", &nan, 1, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "is not finite"));
}

static void test_intensity(void **st)
{
    (void)st;
    fv_error err;
    double v[3] = {0.0, 1.0, FV_INTENSITY_MAX};
    assert_int_equal(fv_limit_intensity("i", v, 3, &err), FV_OK);
    assert_int_equal(fv_limit_intensity3("i", fv_v3s((float)FV_INTENSITY_MAX), &err), FV_OK);
    assert_int_equal(fv_limit_intensity3("light", fv_v3(1, 3e38f, 1), &err), FV_ERR_INVALID);
    assert_string_equal(err.msg, "light: intensity 3e+38 is outside [0, 1e+20]");
    double neg = -1.0;
    assert_int_equal(fv_limit_intensity("i", &neg, 1, &err), FV_ERR_INVALID);
}

/* The camera check reports an overflowing position as what it is. */
static void test_camera_messages(void **st)
{
    (void)st;
    fv_error err;
    fv_camera_basis b;
    fv_camera c = {{1e38f, 1e38f, 1e38f}, {0, 0, 0}, {0, 1, 0}, 40, 8, 8};
    assert_int_equal(fv_camera_basis_make(&c, &b, &err), FV_ERR_INVALID);
    assert_string_equal(err.msg, "camera: position: coordinate 1e+38 is beyond +-1e+09, the range the ray kernels take");
    c.pos = fv_v3(0, 0, 5);
    c.up = fv_v3(0, 0, 0);
    assert_int_equal(fv_camera_basis_make(&c, &b, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "up vector is zero"));
}

/* A message stays one line whatever it quotes. */
static void test_one_line(void **st)
{
    (void)st;
    fv_error err;
    fv_error_set(&err, FV_ERR_INVALID, "key '%s'", "a\nb\x01");
    assert_string_equal(err.msg, "key 'a\\nb\\x01'");
    fv_error_prefix(&err, "%s: ", "f\r");
    assert_string_equal(err.msg, "f\\r: key 'a\\nb\\x01'");
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_coords), cmocka_unit_test(test_intensity), cmocka_unit_test(test_camera_messages),
                                       cmocka_unit_test(test_one_line)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
