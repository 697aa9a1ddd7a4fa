/* The eye model and acuity equations against values worked out by hand (each comment shows the
 * arithmetic), and gaze paths / trace files including malformed ones. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include "fovea/gaze.h"

/* HTC Vive defaults: D = b * PPI = 18 mm / 25.4 mm/in * 615 px/in = 435.827 px.
 * Eq. 7: r_f = tan(9.78 deg) * 435.827 = 0.172374 * 435.827 = 75.124 px;
 * r_t = tan(19.56 deg) * 435.827 = 0.355296 * 435.827 = 154.848 px. */
static void test_eq7_radii(void **st)
{
    (void)st;
    fv_eye_model m;
    fv_eye_model_default(1080, 1200, &m);
    fv_error err;
    assert_int_equal(fv_eye_model_validate(&m, &err), FV_OK);
    assert_float_equal(fv_eye_view_dist_px(&m), 435.827, 1e-3);
    /* pixels per degree at the gaze: 435.827 * pi / 180 = 7.60662 */
    assert_float_equal(fv_eye_px_per_deg(&m), 7.60662, 1e-4);
    assert_float_equal(fv_eye_fovea_radius_px(&m), 75.124, 1e-3);
    assert_float_equal(fv_eye_transition_radius_px(&m), 154.848, 1e-3);
    /* The same panel rendered 270 px wide: ppi 615/4, every radius a quarter. */
    fv_eye_model_default(270, 300, &m);
    assert_float_equal(fv_eye_fovea_radius_px(&m), 75.124 / 4, 1e-3);
}

/* Eccentricity is the inverse of Eq. 7: a pixel D pixels from the gaze is at atan(1) = 45 deg; a
 * pixel r_f away is at e_f. Field-of-view mode: width 1000, fov 90 -> D = 500 / tan(45) = 500. */
static void test_eccentricity(void **st)
{
    (void)st;
    fv_eye_model m;
    fv_eye_model_default(1000, 800, &m);
    fv_gaze g = {0.5f, 0.5f};
    double d = fv_eye_view_dist_px(&m);
    assert_float_equal(fv_eye_eccentricity_deg(&m, g, 500.0 + d, 400.0), 45.0, 1e-9);
    assert_float_equal(fv_eye_eccentricity_deg(&m, g, 500.0, 400.0 + fv_eye_fovea_radius_px(&m)), 9.78, 1e-4);
    assert_float_equal(fv_eye_eccentricity_deg(&m, g, 500.0, 400.0), 0.0, 0.0);
    m.fov_x_deg = 90.0f;
    assert_float_equal(fv_eye_view_dist_px(&m), 500.0, 1e-9);
    /* 3-4-5 triangle: (300, 400) px from the gaze = 500 px = D -> 45 degrees. */
    assert_float_equal(fv_eye_eccentricity_deg(&m, g, 800.0, 800.0), 45.0, 1e-9);
}

/* Width mode (Foveated Instant Radiosity: 25% of the width): 1000 px wide -> r_f = 250, r_t = 375.
 * Eq. 6 halfway between them (d = 312.5) gives b = 0.5. */
static void test_regions_and_blend(void **st)
{
    (void)st;
    fv_eye_model m;
    fv_eye_model_default(1000, 500, &m);
    m.mode = FV_FOVEA_WIDTH;
    fv_gaze g = {0.5f, 0.5f};
    assert_float_equal(fv_eye_fovea_radius_px(&m), 250.0, 1e-9);
    assert_float_equal(fv_eye_transition_radius_px(&m), 375.0, 1e-9);
    assert_float_equal(fv_eye_blend(&m, g, 500.0 + 312.5, 250.0), 0.5, 1e-9);
    assert_float_equal(fv_eye_blend(&m, g, 500.0 + 100.0, 250.0), 0.0, 0.0);
    assert_float_equal(fv_eye_blend(&m, g, 0.0, 0.0), 1.0, 0.0);
    /* Pixel (x, y) is judged at its centre: x = 749 -> 249.5 px away (fovea); x = 750 -> 250.5. */
    assert_int_equal(fv_eye_region(&m, g, 749, 249), FV_REGION_FOVEA);
    assert_int_equal(fv_eye_region(&m, g, 750, 249), FV_REGION_TRANSITION);
    assert_int_equal(fv_eye_region(&m, g, 874, 249), FV_REGION_TRANSITION);
    assert_int_equal(fv_eye_region(&m, g, 875, 249), FV_REGION_PERIPHERY);
    uint8_t *lab = malloc(1000 * 500);
    fv_eye_region_labels(&m, g, lab);
    /* Fovea disc of radius 250 is cut by the image at y in [0,500): about pi r^2 = 196350 pixels. */
    long count[3] = {0, 0, 0};
    for (int i = 0; i < 1000 * 500; i++) count[lab[i]]++;
    assert_true(labs(count[0] - 196350) < 400);
    assert_int_equal(lab[249 * 1000 + 875], FV_REGION_PERIPHERY);
    free(lab);
    assert_string_equal(fv_region_name(FV_REGION_TRANSITION), "transition");
}

static void test_validate(void **st)
{
    (void)st;
    fv_eye_model m;
    fv_error err;
    fv_eye_model_default(100, 100, &m);
    m.fovea_deg = 30.0f; /* above the transition (19.56) */
    assert_int_equal(fv_eye_model_validate(&m, &err), FV_ERR_INVALID);
    fv_eye_model_default(100, 100, &m);
    m.ppi = NAN;
    assert_int_equal(fv_eye_model_validate(&m, &err), FV_ERR_INVALID);
    fv_eye_model_default(0, 100, &m);
    assert_int_equal(fv_eye_model_validate(&m, &err), FV_ERR_INVALID);
    fv_eye_model_default(100, 100, &m);
    m.fov_x_deg = 200.0f;
    assert_int_equal(fv_eye_model_validate(&m, &err), FV_ERR_INVALID);
}

/* Visual-Polar Eq. 1: V = 60 up to 5.79 deg; V(10) = 449.4 / (3 + 1)^2 = 28.0875;
 * V(20) = 449.4 / 49 = 9.17143. Continuity: 449.4 / (0.3*5.79 + 1)^2 = 449.4 / 7.4912 = 59.99. */
static void test_acuity_v(void **st)
{
    (void)st;
    assert_float_equal(fv_acuity_v(0.0), 60.0, 0.0);
    assert_float_equal(fv_acuity_v(5.79), 60.0, 0.0);
    assert_float_equal(fv_acuity_v(10.0), 28.0875, 1e-9);
    assert_float_equal(fv_acuity_v(20.0), 9.171429, 1e-6);
    assert_float_equal(fv_acuity_v(5.7901), 60.0, 0.02);
}

/* Eq. 2: at d = 0: (1 + ln 1) 166.4 pi - 612.3 = 522.761 - 612.3 = -89.539;
 * at d = 10: (1/4 + ln 4) 166.4 pi - 612.3 = 1.636294 * 522.761 - 612.3 = 243.091.
 * Eq. 3: p = 0 -> 3.232; p = 1 -> 25.09 + 0.168 + 27.61 + 23.87 + 3.232 = 79.97;
 * p = 0.5 -> 1.568125 + 0.021 + 6.9025 + 11.935 + 3.232 = 23.658625. */
static void test_acuity_cdf(void **st)
{
    (void)st;
    assert_float_equal(fv_acuity_cdf(0.0), -89.539, 1e-3);
    assert_float_equal(fv_acuity_cdf(10.0), 243.091, 1e-3);
    assert_true(fv_acuity_cdf(20.0) > fv_acuity_cdf(10.0));
    assert_float_equal(fv_acuity_cdf_inv_fit(0.0), 3.232, 1e-12);
    assert_float_equal(fv_acuity_cdf_inv_fit(1.0), 79.97, 1e-9);
    assert_float_equal(fv_acuity_cdf_inv_fit(0.5), 23.658625, 1e-9);
}

/* Inverted pyramid Eq. 1 (negative exponent): p(10) = 0.90964 e^(-10/2.9661) + 0.00792
 * = 0.90964 * 0.034355 + 0.00792 = 0.039157. Inside a 7.5 deg fovea p = 1; beyond the outer
 * limit p = 0. Linear: e = 15 between 10 and 30 with floor 0.2 -> 1 - 0.8 * 5/20 = 0.8. */
static void test_acuity_falloffs(void **st)
{
    (void)st;
    assert_float_equal(fv_acuity_hyperbolic(10.0, 7.5, 0.0), 0.039157, 1e-6);
    assert_float_equal(fv_acuity_hyperbolic(5.0, 7.5, 0.0), 1.0, 0.0);
    assert_float_equal(fv_acuity_hyperbolic(31.0, 7.5, 30.0), 0.0, 0.0);
    assert_true(fv_acuity_hyperbolic(8.0, 7.5, 0.0) > fv_acuity_hyperbolic(12.0, 7.5, 0.0));
    assert_float_equal(fv_acuity_linear(15.0, 10.0, 30.0, 0.2), 0.8, 1e-12);
    assert_float_equal(fv_acuity_linear(5.0, 10.0, 30.0, 0.2), 1.0, 0.0);
    assert_float_equal(fv_acuity_linear(50.0, 10.0, 30.0, 0.2), 0.2, 0.0);
}

static void test_gaze_keys(void **st)
{
    (void)st;
    fv_gaze_key k[3] = {{0.0, {0.0f, 0.0f}, {0.1f, 0.0f}}, {2.0, {1.0f, 0.5f}, {1.0f, 0.5f}}, {3.0, {0.5f, 0.5f}, {0.5f, 0.5f}}};
    fv_gaze_path *p;
    fv_error err;
    assert_int_equal(fv_gaze_path_create_keys(k, 3, &p, &err), FV_OK);
    fv_gaze l, r;
    fv_gaze_path_eval(p, 1.0, &l, &r); /* halfway between keys 0 and 1 */
    assert_float_equal(l.x, 0.5f, 1e-6f);
    assert_float_equal(l.y, 0.25f, 1e-6f);
    assert_float_equal(r.x, 0.55f, 1e-6f);
    fv_gaze_path_eval(p, -5.0, &l, NULL);
    assert_float_equal(l.x, 0.0f, 0.0f);
    fv_gaze_path_eval(p, 99.0, &l, NULL);
    assert_float_equal(l.x, 0.5f, 0.0f);
    fv_gaze_path_eval(p, 2.5, &l, NULL);
    assert_float_equal(l.x, 0.75f, 1e-6f);
    fv_gaze_path_destroy(p);
    k[1].time = 0.0;
    assert_int_equal(fv_gaze_path_create_keys(k, 3, &p, &err), FV_ERR_INVALID);
    k[1].time = 2.0;
    k[2].left.x = 1.5f;
    assert_int_equal(fv_gaze_path_create_keys(k, 3, &p, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "outside [0,1]"));
    fv_gaze bad = {NAN, 0.5f};
    assert_int_equal(fv_gaze_path_create_fixed(bad, &p, &err), FV_ERR_INVALID);
}

static const char *write_tmp(const char *text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/fovea-gaze-%d.csv", (int)getpid());
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
    return path;
}

static void test_gaze_csv(void **st)
{
    (void)st;
    fv_gaze_path *p;
    fv_error err;
    const char *path = write_tmp("# recorded trace\ntime,x,y\n0, 0.2, 0.4\n\n0.5,0.4,0.4\r\n1.0 ,0.4, 0.8\n");
    assert_int_equal(fv_gaze_path_load_csv(path, &p, &err), FV_OK);
    assert_int_equal(fv_gaze_path_key_count(p), 3);
    fv_gaze l, r;
    fv_gaze_path_eval(p, 0.25, &l, &r);
    assert_float_equal(l.x, 0.3f, 1e-6f);
    assert_float_equal(r.x, 0.3f, 1e-6f); /* monocular trace: right follows left */
    fv_gaze_path_eval(p, 0.75, &l, NULL);
    assert_float_equal(l.y, 0.6f, 1e-6f);
    fv_gaze_path_destroy(p);

    path = write_tmp("0,0.1,0.1,0.2,0.2\n1,0.3,0.3,0.4,0.4\n");
    assert_int_equal(fv_gaze_path_load_csv(path, &p, &err), FV_OK);
    fv_gaze_path_eval(p, 0.5, &l, &r);
    assert_float_equal(r.x, 0.3f, 1e-6f);
    fv_gaze_path_destroy(p);

    struct { const char *text; const char *needle; } bad[] = {
        {"time,x,y\n0,0.5,0.5\n1,0.5\n", ":3:"},
        {"0,0.5,0.5\n1,1.5,0.5\n", ":2:"},
        {"0,0.5,0.5\n0,0.5,0.5\n", "does not increase"},
        {"0,0.5,0.5\n1,0.5,0.5,0.5,0.5\n", "columns"},
        {"0,0.5,abc\n", ":1:"},
        {"# only a comment\n", "no samples"},
        {"0,nan,0.5\n", "every sample of the left eye is missing"},
        {"0,,\n1,nan,nan\n", "every sample"},
        {"0,0.5,0.5\n1,0.5,abc\n", ":2:"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        path = write_tmp(bad[i].text);
        p = NULL;
        assert_int_equal(fv_gaze_path_load_csv(path, &p, &err), FV_ERR_INVALID);
        assert_null(p);
        if (!strstr(err.msg, bad[i].needle)) fail_msg("case %zu: '%s' lacks '%s'", i, err.msg, bad[i].needle);
    }
    /* Missing samples: an empty field or nan, per eye. Left: known at 0 and 3, missing at 1 and
     * 2 (held at key 0's gaze, not interpolated towards key 3); right eye known throughout. */
    path = write_tmp("time,xl,yl,xr,yr\n0,0.2,0.2,0.4,0.4\n1,,,0.5,0.5\n2,nan,NaN,0.6,0.6\n3,0.8,0.8,0.7,0.7\n");
    assert_int_equal(fv_gaze_path_load_csv(path, &p, &err), FV_OK);
    assert_true(fv_gaze_path_eval(p, 0.5, &l, &r)); /* key 0 known, key 1 missing: hold, known */
    assert_float_equal(l.x, 0.2f, 0.0f);
    assert_float_equal(r.x, 0.45f, 1e-6f);
    assert_false(fv_gaze_path_eval(p, 2.5, &l, &r)); /* in the gap */
    assert_float_equal(l.x, 0.2f, 0.0f);
    assert_float_equal(r.x, 0.65f, 1e-6f);
    assert_true(fv_gaze_path_eval(p, 3.5, &l, NULL));
    assert_float_equal(l.x, 0.8f, 0.0f);
    assert_int_equal(fv_gaze_path_missing(p), FV_GAZE_MISSING_HOLD);
    fv_gaze_path_destroy(p);
    /* A trace that starts in a blink holds its first known gaze. */
    path = write_tmp("0,,\n1,0.3,0.6\n");
    assert_int_equal(fv_gaze_path_load_csv(path, &p, &err), FV_OK);
    assert_false(fv_gaze_path_eval(p, 0.5, &l, NULL));
    assert_float_equal(l.y, 0.6f, 0.0f);
    fv_gaze_path_destroy(p);
    fv_gaze_missing pol;
    assert_true(fv_gaze_missing_from_name("widen", &pol));
    assert_int_equal(pol, FV_GAZE_MISSING_WIDEN);
    assert_false(fv_gaze_missing_from_name("blink", &pol));
    unlink(path);
    assert_int_equal(fv_gaze_path_load_csv("/nonexistent/trace.csv", &p, &err), FV_ERR_IO);
    assert_non_null(strstr(err.msg, "/nonexistent/trace.csv"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eq7_radii),    cmocka_unit_test(test_eccentricity), cmocka_unit_test(test_regions_and_blend),
        cmocka_unit_test(test_validate),     cmocka_unit_test(test_acuity_v),     cmocka_unit_test(test_acuity_cdf),
        cmocka_unit_test(test_acuity_falloffs), cmocka_unit_test(test_gaze_keys), cmocka_unit_test(test_gaze_csv),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
