/* The tables of the Visual-Polar device frame that follow the gaze (technique/vpolar/gaze_tables.h:
 * the on-screen mask, the radial table) computed on the portable backend by the family's kernels,
 * against the CPU's own (fv_space_onscreen_mask, fv_space_radial_table and the blur profile
 * fv_blur_sigma_at, as the CPU pipeline tabulates it): equal bit for bit, for Visual-Polar and
 * log-polar grids (the clipped fovea's columns, full-height ones) and a Cartesian one (its radial
 * table only), gazes at the centre, corners, an edge, inside and off the screen. And what the frame
 * launches: the mask and a radial table when the gaze moves, nothing when it stays, only the mask
 * when it comes back to the gaze before last (that radial table is still in the other buffer), and
 * no allocation after the first frame. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "device/backend.h"
#include "filter/blur.h"
#include "technique/vpolar/gaze_tables.h"
#include "technique/vpolar/space.h"

#define W 320
#define H 360
#define STEP 0.5f
#define REACH 6.0f

static const fv_gaze k_gazes[] = {{0.5f, 0.5f}, {0.0f, 0.0f}, {1.0f, 1.0f}, {0.5f, 0.0f}, {0.3f, 0.8f}, {-0.25f, 0.5f}, {1.2f, 1.3f}, {0.97f, 0.02f}};
#define NGAZES (sizeof k_gazes / sizeof k_gazes[0])

static fv_space *make(fv_space_kind kind)
{
    fv_space_opts o;
    fv_space_opts_default(kind, &o);
    if (kind == FV_SPACE_CARTESIAN) o.reduction = 0.3;
    fv_eye_model m;
    fv_eye_model_default(W, H, &m);
    fv_space *s = NULL;
    fv_error err;
    if (fv_space_create(&o, W, H, fv_eye_px_per_deg(&m), &s, &err) != FV_OK) fail_msg("%s", err.msg);
    return s;
}

/* The radial table's description at view v, with the blur's profile stretched by scale. */
static fv_kvp_radial radial_at(const fv_space *s, const fv_space_view *v, int n, double ppd, double scale)
{
    fv_kvp_radial r;
    memset(&r, 0, sizeof r);
    r.space = *fv_space_kernel(s);
    r.view = fv_space_kview(v);
    r.step = STEP, r.n = n;
    r.blur = 1;
    r.px_per_deg = ppd, r.scale = scale;
    r.fovea_deg = 5.0, r.ramp_deg = 30.0, r.sigma_px = 6.8 * W / 1280.0;
    return r;
}

static void calls_since(fv_backend *b, const fv_backend_calls *before, fv_backend_calls *d)
{
    fv_backend_calls now;
    fv_backend_calls_get(b, &now);
    fv_backend_calls_diff(&now, before, d);
}

static void check_kind(fv_space_kind kind)
{
    fv_space *s = make(kind);
    const fv_grid *g = fv_space_grid(s);
    const bool polar = kind != FV_SPACE_CARTESIAN;
    const size_t cells = (size_t)g->w * (size_t)g->h;
    const int n = (int)(sqrt((double)W * W + (double)H * H) / STEP) + 3;
    fv_eye_model em;
    fv_eye_model_default(W, H, &em);
    const double ppd = fv_eye_px_per_deg(&em);
    fv_backend *b = NULL;
    fv_error err;
    if (fv_backend_create(FV_DEVICE_PORTABLE, &b, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_buffer col_h = {0};
    if (g->col_h && (fv_buffer_ensure(b, &col_h, (size_t)g->w * sizeof(int), "col_h", &err) != FV_OK ||
                     fv_backend_upload(b, col_h.p, g->col_h, (size_t)g->w * sizeof(int), "col_h", &err) != FV_OK))
        fail_msg("%s", err.msg);
    fv_vp_gaze_tables t;
    memset(&t, 0, sizeof t);
    uint8_t *mask = malloc(cells);
    float *lut = malloc((size_t)n * 3 * sizeof(float));
    assert_non_null(mask);
    assert_non_null(lut);
    fv_backend_calls before, d;
    for (size_t gi = 0; gi < NGAZES; gi++) {
        const fv_space_view v = fv_space_view_at(s, k_gazes[gi]);
        const fv_kvp_view kv = fv_space_kview(&v);
        const double scale = 0.5 * sqrt((double)W * W + (double)H * H) / v.rho_max;
        const fv_kvp_radial r = radial_at(s, &v, n, ppd, scale);
        fv_backend_calls_get(b, &before);
        if (fv_vp_gaze_tables_queue(b, &t, fv_space_kernel(s), &kv, col_h.p, polar, REACH, &r, &err) != FV_OK ||
            fv_backend_wait(b, "the tables", &err) != FV_OK)
            fail_msg("%s", err.msg);
        calls_since(b, &before, &d);
        /* a moving gaze: the mask's two steps (and the rows' angles first) and one radial table */
        assert_int_equal(d.launches, (polar ? 2 + (gi == 0) : 0) + 1);
        if (gi > 0) assert_int_equal(d.allocations, 0);
        assert_int_equal(d.bytes_h2d, 0);
        /* portable: device memory is host memory */
        if (polar) {
            const long on = fv_space_onscreen_mask(&v, REACH, mask);
            const uint8_t *dm = fv_vp_gaze_tables_mask(&t);
            assert_non_null(dm);
            long don = 0;
            for (size_t i = 0; i < cells; i++) don += dm[i];
            assert_int_equal(don, on);
            if (memcmp(dm, mask, cells) != 0) fail_msg("space kind %d, gaze %zu: the device's on-screen mask differs from the CPU's", (int)kind, gi);
        } else {
            assert_null(fv_vp_gaze_tables_mask(&t));
        }
        fv_space_radial_table(&v, STEP, n, 3, lut);
        for (int i = 0; i < n; i++)
            lut[3 * i + 2] = (float)fv_blur_sigma_at((double)((float)i * STEP) / ppd * scale, r.fovea_deg, r.ramp_deg, r.sigma_px);
        if (memcmp(fv_vp_gaze_tables_lut(&t), lut, (size_t)n * 3 * sizeof(float)) != 0)
            fail_msg("space kind %d, gaze %zu: the device's radial table differs from the CPU's", (int)kind, gi);
        /* the previous frame's table is kept for the reprojection */
        if (gi > 0) assert_non_null(fv_vp_gaze_tables_prev_lut(&t));
        assert_ptr_not_equal(fv_vp_gaze_tables_prev_lut(&t), fv_vp_gaze_tables_lut(&t));
        fv_vp_gaze_tables_advance(&t);

        /* the same gaze again: nothing launched, one table serves both */
        fv_backend_calls_get(b, &before);
        if (fv_vp_gaze_tables_queue(b, &t, fv_space_kernel(s), &kv, col_h.p, polar, REACH, &r, &err) != FV_OK) fail_msg("%s", err.msg);
        calls_since(b, &before, &d);
        assert_int_equal(d.launches, 0);
        assert_ptr_equal(fv_vp_gaze_tables_prev_lut(&t), fv_vp_gaze_tables_lut(&t));
        fv_vp_gaze_tables_advance(&t);
    }
    /* back to the gaze before last: its radial table is the other buffer's */
    const fv_space_view v1 = fv_space_view_at(s, k_gazes[NGAZES - 2]), v2 = fv_space_view_at(s, k_gazes[NGAZES - 1]);
    const fv_kvp_view kv1 = fv_space_kview(&v1), kv2 = fv_space_kview(&v2);
    const fv_kvp_radial r1 = radial_at(s, &v1, n, ppd, 1.0), r2 = radial_at(s, &v2, n, ppd, 1.0);
    if (fv_vp_gaze_tables_queue(b, &t, fv_space_kernel(s), &kv1, col_h.p, polar, REACH, &r1, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_vp_gaze_tables_advance(&t);
    if (fv_vp_gaze_tables_queue(b, &t, fv_space_kernel(s), &kv2, col_h.p, polar, REACH, &r2, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_vp_gaze_tables_advance(&t);
    fv_backend_calls_get(b, &before);
    if (fv_vp_gaze_tables_queue(b, &t, fv_space_kernel(s), &kv1, col_h.p, polar, REACH, &r1, &err) != FV_OK) fail_msg("%s", err.msg);
    calls_since(b, &before, &d);
    assert_int_equal(d.launches, polar ? 2 : 0);
    /* a new grid computes everything again */
    fv_vp_gaze_tables_forget(&t);
    fv_backend_calls_get(b, &before);
    if (fv_vp_gaze_tables_queue(b, &t, fv_space_kernel(s), &kv1, col_h.p, polar, REACH, &r1, &err) != FV_OK) fail_msg("%s", err.msg);
    calls_since(b, &before, &d);
    assert_int_equal(d.launches, polar ? 4 : 1);

    fv_vp_gaze_tables_release(b, &t);
    fv_buffer_release(b, &col_h);
    fv_backend_destroy(b);
    free(mask), free(lut);
    fv_space_destroy(s);
}

static void test_vpolar(void **st)
{
    (void)st;
    check_kind(FV_SPACE_VPOLAR);
}

static void test_logpolar(void **st)
{
    (void)st;
    check_kind(FV_SPACE_LOGPOLAR);
}

static void test_cartesian(void **st)
{
    (void)st;
    check_kind(FV_SPACE_CARTESIAN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_vpolar), cmocka_unit_test(test_logpolar), cmocka_unit_test(test_cartesian)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
