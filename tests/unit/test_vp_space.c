/* Sample spaces of Visual-Polar path tracing and its baselines: the acuity area of Eq. 2 worked
 * by hand, the grid's sample count against the reduction, forward/inverse round trips, a grid that
 * reaches the farthest corner from any gaze with the same samples, a fovea of at least one sample
 * per pixel with a constant density, a periphery whose density follows the acuity, the φ wrap, the
 * fit error, log-polar and Cartesian maps worked by hand, refused options, an off-screen mask
 * that no screen pixel's trilinear φ-mip lookup ever reads past, and a radial table within 1e-3
 * columns of the exact map. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/phi_mips.h"
#include "technique/vpolar/space.h"

#define W 1280
#define H 1440

static double ppd_for(int w, int h)
{
    fv_eye_model m;
    fv_eye_model_default(w, h, &m);
    return fv_eye_px_per_deg(&m);
}

static fv_space *make(fv_space_kind kind, double reduction)
{
    fv_space_opts o;
    fv_space_opts_default(kind, &o);
    if (kind != FV_SPACE_LOGPOLAR) o.reduction = reduction;
    fv_space *s = NULL;
    fv_error err;
    fv_status st = fv_space_create(&o, W, H, ppd_for(W, H), &s, &err);
    if (st != FV_OK) fail_msg("%s", err.msg);
    return s;
}

/* pi e^2 inside 5.79 degrees; beyond, Eq. 2 shifted to meet it:
 * A(10) = Eq2(10) - Eq2(5.79) + pi 5.79^2 = 243.0915 - 105.0462 + 105.3191 = 243.3644. */
static void test_acuity_area(void **st)
{
    (void)st;
    assert_float_equal(fv_space_acuity_area(2.0), 12.566371, 1e-5);
    assert_float_equal(fv_space_acuity_area(5.79), 105.319066, 1e-5);
    assert_float_equal(fv_space_acuity_area(5.79 + 1e-9), 105.319066, 1e-4);
    assert_float_equal(fv_space_acuity_area(10.0), 243.363729, 1e-4);
    assert_float_equal(fv_acuity_cdf(5.79), 105.046243, 1e-6); /* the shift space.c uses */
    assert_float_equal(fv_space_acuity_area(30.0), 643.950652, 1e-4);
    /* Its slope is 2 pi e V(e) / 60: the density the samples follow is proportional to V. */
    double e = 20.0, h = 1e-4;
    double slope = (fv_space_acuity_area(e + h) - fv_space_acuity_area(e - h)) / (2 * h);
    /* (Eq. 2's 166.4 pi rounds 2 pi 449.4 / (60 0.09) = 166.44 pi, hence the 3e-4 relative.) */
    assert_float_equal(slope, 2 * FV_PI_D * e * fv_acuity_v(e) / 60.0, 3e-4 * slope);
}

static long count_of(const fv_space *s)
{
    const fv_grid *g = fv_space_grid(s);
    long n = 0;
    for (int x = 0; x < g->w; x++) n += fv_grid_col_h(g, x);
    return n;
}

/* The grid holds (1 - reduction) of the screen's pixels (within rounding), for the three
 * reductions of the paper's Sec. 4.2; the columns grow in the fovea and are full beyond. */
static void test_sample_count(void **st)
{
    (void)st;
    const double red[3] = {0.61, 0.71, 0.88};
    for (int i = 0; i < 3; i++) {
        fv_space *s = make(FV_SPACE_VPOLAR, red[i]);
        long n = fv_space_sample_count(s);
        assert_int_equal(n, count_of(s));
        double target = (1.0 - red[i]) * W * H;
        assert_true(fabs(n - target) < 0.005 * target);
        const fv_grid *g = fv_space_grid(s);
        assert_true(g->wrap);
        fv_space_info info;
        fv_space_get_info(s, &info);
        for (int x = 1; x < g->w; x++) assert_true(g->col_h[x] >= g->col_h[x - 1]);
        assert_int_equal(g->col_h[g->w - 1], g->h);
        assert_true(g->col_h[0] < g->h / 10);
        assert_true(info.fovea_columns > 1.0 && info.fovea_columns < g->w / 2.0);
        /* The clipped triangle holds as many cells as the fovea has samples (Sec. 3.2). */
        long clipped = (long)g->w * g->h - n;
        assert_true(fabs(clipped - info.fovea_share * n) < 0.01 * n);
        fv_space_destroy(s);
    }
}

static const fv_gaze k_gazes[] = {{0.5f, 0.5f}, {0.0f, 0.0f}, {1.0f, 1.0f}, {0.1f, 0.8f}, {0.93f, 0.31f}, {0.5f, 0.02f}};
#define NGAZE ((int)(sizeof k_gazes / sizeof k_gazes[0]))

/* From any gaze the farthest screen corner maps to the grid's last column and every other screen
 * point inside it: one grid, the same number of samples, always covering the screen. */
static void test_reaches_farthest_corner(void **st)
{
    (void)st;
    fv_space *s = make(FV_SPACE_VPOLAR, 0.61);
    const fv_grid *g = fv_space_grid(s);
    for (int i = 0; i < NGAZE; i++) {
        fv_space_view v = fv_space_view_at(s, k_gazes[i]);
        const float cx[4] = {0, W, 0, W}, cy[4] = {0, 0, H, H};
        float xmax = 0.0f;
        for (int c = 0; c < 4; c++) {
            float X, V;
            fv_space_from_screen(&v, cx[c], cy[c], &X, &V, NULL);
            assert_true(X <= (float)g->w + 1e-3f);
            xmax = X > xmax ? X : xmax;
        }
        assert_float_equal(xmax, (float)g->w, 1e-3f);
        /* and the grid's outermost column reaches out to that corner */
        assert_float_equal(fv_space_radius(&v, (float)g->w), v.rho_max, 0.05f);
    }
    fv_space_destroy(s);
}

/* Screen -> grid -> screen and grid -> screen -> grid, for several gazes, within the reported error
 * of the fitted inverse. */
static void test_round_trip(void **st)
{
    (void)st;
    fv_space *s = make(FV_SPACE_VPOLAR, 0.61);
    fv_space_info info;
    fv_space_get_info(s, &info);
    assert_true(info.fit_error_px < 0.05);
    const fv_grid *g = fv_space_grid(s);
    unsigned r = 7;
    for (int i = 0; i < NGAZE; i++) {
        fv_space_view v = fv_space_view_at(s, k_gazes[i]);
        /* The profile stretches by rho_max / rho_ref, and the fit error with it. */
        float tol = (float)(info.fit_error_px * v.rho_max / (0.5 * hypot(W, H))) + 2e-3f * v.rho_max / 500.0f + 1e-3f;
        for (int k = 0; k < 2000; k++) {
            r = r * 1664525u + 1013904223u;
            float px = (float)(r >> 8) / 16777216.0f * W;
            r = r * 1664525u + 1013904223u;
            float py = (float)(r >> 8) / 16777216.0f * H;
            float X, V, qx, qy;
            fv_space_from_screen(&v, px, py, &X, &V, NULL);
            assert_true(X >= 0.0f && X <= (float)g->w + 1e-3f && V >= 0.0f && V < 1.0f);
            fv_space_to_screen(&v, X, V, &qx, &qy);
            assert_true(hypotf(qx - px, qy - py) <= tol);
        }
        for (int x = 0; x < g->w; x += 7)
            for (int y = 0; y < fv_grid_col_h(g, x); y += 5) {
                float X, V, px, py, X2, V2;
                fv_grid_centre(g, x, y, &X, &V);
                fv_space_to_screen(&v, X, V, &px, &py);
                fv_space_from_screen(&v, px, py, &X2, &V2, NULL);
                float dv = fabsf(V2 - V);
                dv = dv > 0.5f ? 1.0f - dv : dv; /* φ wraps */
                /* The fit's few hundredths of a pixel are up to 2.5 columns per pixel at the
                 * fovea's edge, where the columns are densest. */
                assert_true(fabsf(X2 - X) < 0.06f);
                assert_true(dv < 1e-4f);
            }
    }
    fv_space_destroy(s);
}

/* Samples (grid cell centres) that land within radius r of the gaze. */
static long samples_within(const fv_space *s, const fv_space_view *v, double r0, double r1)
{
    const fv_grid *g = fv_space_grid(s);
    long n = 0;
    for (int x = 0; x < g->w; x++)
        for (int y = 0; y < fv_grid_col_h(g, x); y++) {
            float X, V, px, py;
            fv_grid_centre(g, x, y, &X, &V);
            fv_space_to_screen(v, X, V, &px, &py);
            double d = hypot(px - v->gx, py - v->gy);
            n += d >= r0 && d < r1;
        }
    return n;
}

/* The fovea (5.79 degrees, 52.2 px at the centre gaze) is sampled at the reported constant density,
 * at least one sample per pixel, at the centre and at a corner gaze (where it is twice as wide). */
static void test_fovea_density(void **st)
{
    (void)st;
    const double red[3] = {0.61, 0.71, 0.88};
    for (int i = 0; i < 3; i++) {
        fv_space *s = make(FV_SPACE_VPOLAR, red[i]);
        fv_space_info info;
        fv_space_get_info(s, &info);
        double rf = 5.79 * ppd_for(W, H);
        assert_float_equal(rf, 52.2, 0.1);
        fv_space_view v = fv_space_view_at(s, (fv_gaze){0.5f, 0.5f});
        /* an inner disc and a ring: same density, so ρ is linear and the clipping right */
        double d_in = samples_within(s, &v, 0, 0.5 * rf) / (FV_PI_D * 0.25 * rf * rf);
        double d_ring = samples_within(s, &v, 0.5 * rf, 0.95 * rf) / (FV_PI_D * (0.9025 - 0.25) * rf * rf);
        assert_true(fabs(d_in / info.fovea_density_centre - 1.0) < 0.04);
        assert_true(fabs(d_ring / info.fovea_density_centre - 1.0) < 0.04);
        assert_true(info.fovea_density_corner >= 0.999);
        fv_space_view c = fv_space_view_at(s, (fv_gaze){0.0f, 1.0f});
        double rfc = 2.0 * rf;
        double d_c = samples_within(s, &c, 0, 0.9 * rfc) / (FV_PI_D * 0.81 * rfc * rfc);
        assert_true(fabs(d_c / info.fovea_density_corner - 1.0) < 0.04);
        assert_true(d_c >= 0.96);
        fv_space_destroy(s);
    }
}

/* Beyond the fovea the density follows V(e) (Eq. 1-2): the ratio of the mean densities of two
 * annuli equals the ratio of their acuity areas per unit area. */
static void test_periphery_follows_acuity(void **st)
{
    (void)st;
    fv_space *s = make(FV_SPACE_VPOLAR, 0.61);
    fv_space_view v = fv_space_view_at(s, (fv_gaze){0.5f, 0.5f});
    double ppd = ppd_for(W, H);
    const double e[3][2] = {{10, 14}, {25, 32}, {45, 55}};
    double dens[3], expect[3];
    for (int i = 0; i < 3; i++) {
        double r0 = e[i][0] * ppd, r1 = e[i][1] * ppd;
        dens[i] = samples_within(s, &v, r0, r1) / (FV_PI_D * (r1 * r1 - r0 * r0));
        expect[i] = (fv_space_acuity_area(e[i][1]) - fv_space_acuity_area(e[i][0])) / (FV_PI_D * (e[i][1] * e[i][1] - e[i][0] * e[i][0]));
    }
    for (int i = 1; i < 3; i++) assert_true(fabs((dens[i] / dens[0]) / (expect[i] / expect[0]) - 1.0) < 0.05);
    /* and it falls: 45-55 degrees gets well under a tenth of the 10-14 degree density */
    assert_true(dens[2] < 0.1 * dens[0]);
    fv_space_destroy(s);
}

/* φ runs once around the gaze: just below and just above the +x axis map to the two ends of a
 * column, and a lookup there blends the first and last rows (wrap-around, Sec. 3.3). */
static void test_phi_wrap(void **st)
{
    (void)st;
    fv_space *s = make(FV_SPACE_VPOLAR, 0.61);
    fv_space_view v = fv_space_view_at(s, (fv_gaze){0.5f, 0.5f});
    float X, V1, V2, rows;
    fv_space_from_screen(&v, v.gx + 300.0f, v.gy + 0.5f, &X, &V1, &rows);
    fv_space_from_screen(&v, v.gx + 300.0f, v.gy - 0.5f, &X, &V2, NULL);
    assert_true(V1 < 0.001f && V1 > 0.0f);
    assert_true(V2 > 0.999f && V2 < 1.0f);
    /* y grows downwards: a quarter turn is straight below the gaze */
    fv_space_from_screen(&v, v.gx, v.gy + 300.0f, &X, &V1, NULL);
    assert_float_equal(V1, 0.25f, 1e-6f);
    const fv_grid *g = fv_space_grid(s);
    long idx[4];
    float wt[4];
    fv_grid_bilinear(g, X, 0.0f, idx, wt);
    int n = fv_grid_col_h(g, (int)(X - 0.5f));
    assert_int_equal(idx[0] / g->w, n - 1);
    assert_int_equal(idx[1] / g->w, 0);
    /* Rows per screen pixel along φ: H_v / (2 pi r) beyond the fovea. */
    assert_float_equal(rows, (float)g->h / (2.0f * FV_PI * 300.0f), 1e-3f);
    fv_space_destroy(s);
}

/* The paper fits a quartic (Eq. 3); ours is refitted per screen: a quartic leaves sub-pixel to pixel
 * error, the default sextic a few hundredths of a pixel. */
static void test_fit_error(void **st)
{
    (void)st;
    fv_space_opts o;
    fv_space_opts_default(FV_SPACE_VPOLAR, &o);
    double prev = 1e9;
    for (int d = 3; d <= 8; d++) {
        o.fit_degree = d;
        fv_space *s;
        fv_error err;
        assert_int_equal(fv_space_create(&o, W, H, ppd_for(W, H), &s, &err), FV_OK);
        fv_space_info info;
        fv_space_get_info(s, &info);
        const double *c;
        assert_int_equal(fv_space_fit_coeffs(s, &c), d + 1);
        assert_true(info.fit_error_px < prev * 1.01);
        if (d == 6) assert_true(info.fit_error_px < 0.05);
        if (d == 3) assert_true(info.fit_error_px > 1.0);
        prev = info.fit_error_px;
        fv_space_destroy(s);
    }
}

/* Kernel log-polar (Meng et al.): r = exp(L u^alpha), L = log rho_max. Centre gaze of 1280x1440:
 * rho_max = 963.3276, at u = 0.5 and alpha 4: exp(6.8703 / 16) = 1.53633. */
static void test_logpolar(void **st)
{
    (void)st;
    fv_space *s = make(FV_SPACE_LOGPOLAR, 0);
    const fv_grid *g = fv_space_grid(s);
    assert_int_equal(g->w, 711);
    assert_int_equal(g->h, 800);
    assert_null(g->col_h);
    fv_space_view v = fv_space_view_at(s, (fv_gaze){0.5f, 0.5f});
    assert_float_equal(v.rho_max, 963.3276f, 1e-3f);
    assert_float_equal(fv_space_radius(&v, 0.5f * g->w), 1.536335f, 1e-4f);
    assert_float_equal(fv_space_radius(&v, 0.0f), 1.0f, 1e-6f);
    assert_float_equal(fv_space_radius(&v, (float)g->w), 963.3276f, 0.01f);
    float X, V, px, py;
    fv_space_from_screen(&v, v.gx - 100.0f, v.gy, &X, &V, NULL);
    assert_float_equal(V, 0.5f, 1e-6f);
    fv_space_to_screen(&v, X, V, &px, &py);
    assert_float_equal(px, v.gx - 100.0f, 1e-2f);
    assert_float_equal(py, v.gy, 1e-2f);
    fv_space_destroy(s);
}

static void test_cartesian(void **st)
{
    (void)st;
    fv_space *s = make(FV_SPACE_CARTESIAN, 0.75);
    const fv_grid *g = fv_space_grid(s);
    assert_int_equal(g->w, 640);
    assert_int_equal(g->h, 720);
    assert_false(g->wrap);
    fv_space_view v = fv_space_view_at(s, (fv_gaze){0.2f, 0.7f});
    float X, V, px, py, rows;
    fv_space_from_screen(&v, 100.0f, 360.0f, &X, &V, &rows);
    assert_float_equal(X, 50.0f, 1e-5f);
    assert_float_equal(V, 0.25f, 1e-6f);
    assert_float_equal(rows, 0.0f, 0.0f);
    fv_space_to_screen(&v, 320.0f, 0.5f, &px, &py);
    assert_float_equal(px, 640.0f, 1e-4f);
    assert_float_equal(py, 720.0f, 1e-4f);
    fv_space_destroy(s);
    s = make(FV_SPACE_CARTESIAN, 0.0);
    assert_int_equal(fv_space_sample_count(s), (long)W * H);
    fv_space_destroy(s);
}

static void expect_invalid(fv_space_opts o, int w, int h, const char *needle)
{
    fv_space *s = NULL;
    fv_error err;
    fv_status st = fv_space_create(&o, w, h, ppd_for(w > 0 ? w : 1, h > 0 ? h : 1), &s, &err);
    if (st != FV_ERR_INVALID) fail_msg("expected an error mentioning '%s', got status %d", needle, (int)st);
    assert_null(s);
    if (!strstr(err.msg, needle)) fail_msg("'%s' does not mention '%s'", err.msg, needle);
}

static void test_bad_options(void **st)
{
    (void)st;
    fv_space_opts o;
    fv_space_opts_default(FV_SPACE_VPOLAR, &o);
    const double bad_red[] = {0.0, 1.0, -0.2, 1.5, NAN};
    for (int i = 0; i < 5; i++) {
        fv_space_opts b = o;
        b.reduction = bad_red[i];
        expect_invalid(b, W, H, "reduction");
    }
    fv_space_opts b = o;
    b.reduction = 0.995; /* the fovea alone needs more than half the samples */
    expect_invalid(b, W, H, "fovea");
    b = o;
    b.fit_degree = 1;
    expect_invalid(b, W, H, "fit_degree");
    b.fit_degree = 11;
    expect_invalid(b, W, H, "fit_degree");
    b = o;
    b.fovea_deg = 80.0;
    expect_invalid(b, W, H, "fovea");
    b.fovea_deg = -1.0;
    expect_invalid(b, W, H, "fovea_deg");
    expect_invalid(o, 0, 10, "size");
    expect_invalid(o, 1, 2, "small");
    fv_space_opts_default(FV_SPACE_LOGPOLAR, &b);
    b.lp_sigma = 1.0;
    expect_invalid(b, W, H, "sigma");
    fv_space_opts_default(FV_SPACE_LOGPOLAR, &b);
    b.lp_alpha = 0.0;
    expect_invalid(b, W, H, "alpha");
    fv_space_opts_default(FV_SPACE_CARTESIAN, &b);
    b.reduction = 1.0;
    expect_invalid(b, W, H, "reduction");
}

/* fv_space_turns against the exact angle: within 3e-7 turns all round (a million directions, the
 * axes, the diagonals and the octant fold at tan(pi/8) included), in [0, 1), and atan2's
 * conventions at the axes (0 for +x, 1/4 for +y, 1/2 for -x, 3/4 for -y). */
static void test_turns(void **st)
{
    (void)st;
    double worst = 0.0;
    for (int i = 0; i < 1000000; i++) {
        double a = 2.0 * M_PI * (i + 0.37) / 1000000.0, r = 1.0 + 700.0 * fmod(i * 0.618034, 1.0);
        float dx = (float)(r * cos(a)), dy = (float)(r * sin(a));
        double exact = atan2((double)dy, (double)dx) / (2.0 * M_PI);
        exact = exact < 0.0 ? exact + 1.0 : exact;
        float v = fv_space_turns(dx, dy);
        assert_true(v >= 0.0f && v < 1.0f);
        double d = fabs(v - exact);
        d = d > 0.5 ? 1.0 - d : d;
        worst = d > worst ? d : worst;
    }
    assert_true(worst < 3e-7);
    assert_float_equal(fv_space_turns(3.0f, 0.0f), 0.0f, 0.0);
    assert_float_equal(fv_space_turns(0.0f, 2.0f), 0.25f, 1e-7);
    assert_float_equal(fv_space_turns(-5.0f, 0.0f), 0.5f, 1e-7);
    assert_float_equal(fv_space_turns(0.0f, -1.0f), 0.75f, 1e-7);
    assert_float_equal(fv_space_turns(1.0f, 1.0f), 0.125f, 1e-7);
    assert_float_equal(fv_space_turns(1.0f, 0.41421356f), 0.0625f, 1e-7);
    assert_float_equal(fv_space_turns(0.0f, 0.0f), 0.0f, 0.0);
}

/* The radial table the map stage and the denoiser's reprojection read (fv_space_radial_table,
 * fv_space_table_x, every 0.5 px as the pipeline builds it): the column it gives at any distance
 * from the gaze is within 1e-3 columns of fv_space_from_screen, for gazes at the centre, a corner
 * and an edge (the profile stretches with the gaze), in every direction; its mip level is
 * fv_space_from_screen's at the entries. */
static void test_radial_table(void **st)
{
    (void)st;
    fv_space *s = make(FV_SPACE_VPOLAR, 0.61);
    const fv_gaze gazes[3] = {{0.5f, 0.5f}, {0.02f, 0.97f}, {0.5f, 0.0f}};
    const float step = 0.5f;
    const int n = (int)(sqrt((double)W * W + (double)H * H) / step) + 3;
    float *table = malloc(sizeof(float) * 3 * (size_t)n);
    for (int gi = 0; gi < 3; gi++) {
        const fv_space_view v = fv_space_view_at(s, gazes[gi]);
        fv_space_radial_table(&v, step, n, 3, table);
        for (int i = 0; i < n; i += 97) {
            float X, V, rows;
            fv_space_from_screen(&v, v.gx + (float)i * step, v.gy, &X, &V, &rows);
            assert_float_equal(table[3 * i], X, 0.0);
            assert_float_equal(table[3 * i + 1], rows > 1.0f ? log2f(rows) : 0.0f, 0.0);
        }
        double worst = 0.0;
        for (int k = 0; k < 200000; k++) {
            const float px = (float)W * (float)fmod(k * 0.618034, 1.0), py = (float)H * (float)fmod(k * 0.414214 + 0.1, 1.0);
            const float dx = px - v.gx, dy = py - v.gy;
            float X, V;
            fv_space_from_screen(&v, px, py, &X, &V, NULL);
            const double d = fabs(fv_space_table_x(table, 3, n, 1.0f / step, sqrtf(dx * dx + dy * dy)) - X);
            worst = d > worst ? d : worst;
        }
        print_message("gaze (%.2f, %.2f): table column within %.2g of the exact\n", gazes[gi].x, gazes[gi].y, worst);
        assert_true(worst < 1e-3);
    }
    free(table);
    fv_space_destroy(s);
}

/* The level-0 rows [*lo, *hi] (unwrapped: may run below 0 or past the column's height) that feed
 * row j of level k of column x: each level's row averages the rows of the level below that overlap
 * its angles (phi_mips.h). */
static void mip_rows(const fv_phi_mips *m, int k, int x, int j, long *lo, long *hi)
{
    long a = j, b = j;
    for (; k > 0; k--) {
        long nk = fv_grid_col_h(fv_phi_mips_grid(m, k), x), nb = fv_grid_col_h(fv_phi_mips_grid(m, k - 1), x);
        a = (long)floor((double)a * nb / nk);
        b = (long)ceil((double)(b + 1) * nb / nk) - 1;
    }
    *lo = a, *hi = b;
}

/* Every screen pixel's lookup (the pipeline's map stage: bilinear in the two mip levels around
 * log2 of the rows per pixel, fv_phi_mips_sample) reads only cells the off-screen mask keeps, for
 * gazes at the centre, a corner, an edge and off-centre, in Visual-Polar and log-polar space; and
 * the mask drops a real share of the grid (the farthest circles' arcs off the screen). */
static void test_onscreen_mask(void **st)
{
    (void)st;
    const fv_gaze gazes[4] = {{0.5f, 0.5f}, {0.0f, 0.0f}, {1.0f, 0.4f}, {0.3f, 0.8f}};
    const fv_space_kind kinds[2] = {FV_SPACE_VPOLAR, FV_SPACE_LOGPOLAR};
    for (int ki = 0; ki < 2; ki++) {
        fv_space *s = make(kinds[ki], 0.61);
        const fv_grid *g = fv_space_grid(s);
        fv_phi_mips *m = NULL;
        fv_error err;
        assert_int_equal(fv_phi_mips_create(g, 12, &m, &err), FV_OK);
        const int nlev = fv_phi_mips_levels(m);
        uint8_t *mask = malloc((size_t)g->w * g->h);
        for (int gi = 0; gi < 4; gi++) {
            fv_space_view v = fv_space_view_at(s, gazes[gi]);
            long on = fv_space_onscreen_mask(&v, 6.0f, mask), count = 0;
            for (size_t i = 0; i < (size_t)g->w * g->h; i++) count += mask[i];
            assert_int_equal(on, count);
            assert_true(on < fv_space_sample_count(s));
            if (gi == 0 && ki == 0) assert_true(on < 0.95 * (double)fv_space_sample_count(s));
            long bad = 0;
            for (int y = 0; y < H; y += 1 + (ki == 1))
                for (int x = 0; x < W; x += 1 + (ki == 1)) {
                    float X, V, rows;
                    fv_space_from_screen(&v, (float)x + 0.5f, (float)y + 0.5f, &X, &V, &rows);
                    float level = rows > 1.0f ? log2f(rows) : 0.0f;
                    int k0 = (int)level < nlev - 1 ? (int)level : nlev - 1;
                    int k1 = level > (float)k0 && k0 + 1 < nlev ? k0 + 1 : k0; /* the second level only when blended */
                    for (int k = k0; k <= k1; k++) {
                        long idx[4];
                        float wt[4];
                        const fv_grid *gk = fv_phi_mips_grid(m, k);
                        fv_grid_bilinear(gk, X, V, idx, wt);
                        for (int t = 0; t < 4; t++) {
                            int cx = (int)(idx[t] % gk->w), j = (int)(idx[t] / gk->w);
                            long lo, hi;
                            mip_rows(m, k, cx, j, &lo, &hi);
                            long n0 = fv_grid_col_h(g, cx);
                            for (long r = lo; r <= hi; r++) {
                                long rr = ((r % n0) + n0) % n0;
                                bad += !mask[rr * g->w + cx];
                            }
                        }
                    }
                }
            assert_int_equal(bad, 0);
        }
        free(mask);
        fv_phi_mips_destroy(m);
        fv_space_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_acuity_area),     cmocka_unit_test(test_sample_count),
        cmocka_unit_test(test_reaches_farthest_corner), cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_fovea_density),   cmocka_unit_test(test_periphery_follows_acuity),
        cmocka_unit_test(test_phi_wrap),        cmocka_unit_test(test_fit_error),
        cmocka_unit_test(test_logpolar),        cmocka_unit_test(test_cartesian),
        cmocka_unit_test(test_bad_options),     cmocka_unit_test(test_onscreen_mask),
        cmocka_unit_test(test_turns),           cmocka_unit_test(test_radial_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
