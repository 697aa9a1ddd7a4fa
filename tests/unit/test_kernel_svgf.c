/* SVGF as kernels (filter/ksvgf.h, run by filter/svgf_kernels.c a pixel at a time) against the CPU
 * filter adding one tap at a time (fv_svgf, FV_SVGF_ISA_PLAIN): the same bits, frame after frame
 * with a moving history (bilinear taps between pixels, some outside the grid, some inconsistent),
 * on a screen grid, on the Visual-Polar grid of a 160x90 screen (technique/vpolar/space.c: short
 * columns in the fovea, wrap-around rows, clamped columns) with its off-screen cells inactive and
 * fewer passes in the periphery, and on a log-polar grid; with holes, with sigma_normal 128
 * (squarings) and 100 (powf), with 0, 1 and 5 passes, each pass's prefilter inside its launch and
 * as a launch of its own; the counters (history_fraction, mean_history) equal too. Plus a case small enough to work out by hand. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/svgf.h"
#include "filter/svgf_kernels.h"
#include "technique/vpolar/space.h"

typedef struct frame_buf {
    size_t n;
    float *color, *albedo, *normal, *depth, *position, *prev;
    uint32_t *id;
    uint8_t *sampled;
} frame_buf;

static float hash01(uint32_t a, uint32_t b)
{
    uint32_t s = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u;
    s ^= s >> 15, s *= 0x2C1B3C6Du, s ^= s >> 12, s *= 0x297A2D39u, s ^= s >> 15;
    return (float)(s >> 8) / 16777216.0f;
}

/* A noisy scene on g for frame k: two objects (left and right of column w/2: depth slopes, normals,
 * ids differ), 3% background, 10% holes (with_holes), a NaN colour now and then; the history
 * coordinates move with k: each pixel's centre shifted by a fraction of a column and of a row (the
 * bilinear taps straddle pixels, some fall off a screen grid, the polar rows wrap), 2% NaN. The
 * positions move with the coordinates, so most history is consistent. */
static frame_buf make_frame(const fv_grid *g, uint32_t k, bool with_holes)
{
    frame_buf b;
    b.n = (size_t)g->w * g->h;
    b.color = calloc(b.n * 3, sizeof(float));
    b.albedo = calloc(b.n * 3, sizeof(float));
    b.normal = calloc(b.n * 3, sizeof(float));
    b.position = calloc(b.n * 3, sizeof(float));
    b.depth = calloc(b.n, sizeof(float));
    b.prev = calloc(b.n * 2, sizeof(float));
    b.id = calloc(b.n, sizeof(uint32_t));
    b.sampled = calloc(b.n, 1);
    const float sx = 0.37f + 0.11f * (float)k, sv = 0.004f * (float)(k + 1);
    for (int y = 0; y < g->h; y++)
        for (int x = 0; x < g->w; x++) {
            size_t i = (size_t)y * g->w + x;
            b.prev[2 * i] = b.prev[2 * i + 1] = NAN;
            if (!fv_grid_valid(g, x, y)) continue;
            b.sampled[i] = !with_holes || hash01((uint32_t)i, 900 + k) > 0.1f;
            if (hash01((uint32_t)i, 700 + k) > 0.02f) {
                fv_grid_centre(g, x, y, &b.prev[2 * i], &b.prev[2 * i + 1]);
                b.prev[2 * i] -= sx;
                b.prev[2 * i + 1] += sv;
            }
            if (hash01((uint32_t)i, 31) < 0.03f) continue; /* background */
            const int obj = x < g->w / 2;
            for (int c = 0; c < 3; c++) {
                b.color[3 * i + c] = (0.3f + 0.4f * (float)obj + 0.2f * (float)c) * 2.0f * hash01((uint32_t)i, 100 + 3 * k + (uint32_t)c);
                b.albedo[3 * i + c] = c == 2 && x % 5 == 0 ? 0.0f : 0.5f + 0.1f * (float)c;
            }
            if (hash01((uint32_t)i, 500 + k) < 0.002f) b.color[3 * i] = NAN;
            float tx = obj ? 0.3f : -0.2f, ty = 0.05f * (hash01((uint32_t)i, 41) - 0.5f), len = sqrtf(tx * tx + ty * ty + 1.0f);
            b.normal[3 * i] = tx / len, b.normal[3 * i + 1] = ty / len, b.normal[3 * i + 2] = 1.0f / len;
            b.depth[i] = (obj ? 3.0f : 2.0f) + 0.01f * (float)y + 0.003f * (float)x;
            b.position[3 * i] = 0.01f * ((float)x + sx * (float)k), b.position[3 * i + 1] = 0.01f * (float)y;
            b.position[3 * i + 2] = b.depth[i];
            b.id[i] = 1u + (uint32_t)obj;
        }
    return b;
}

static frame_buf copy_frame(const frame_buf *a)
{
    frame_buf b = *a;
    b.color = malloc(a->n * 3 * sizeof(float));
    memcpy(b.color, a->color, a->n * 3 * sizeof(float));
    return b;
}

static void free_frame(frame_buf *b, bool inputs)
{
    free(b->color);
    if (!inputs) return;
    free(b->albedo), free(b->normal), free(b->position), free(b->depth), free(b->prev), free(b->id), free(b->sampled);
}

typedef struct run_case {
    const char *name;
    fv_grid g;
    const uint8_t *active;
    float sigma_normal;
    int iterations;
    int periph_x, periph_passes; /* periph_x < 0: none */
    bool holes;
    bool separate;  /* the prefilter as its own launch (fv_svgf_kernels_set_fused false) */
} run_case;

/* Frames through the plain CPU filter and through the kernels: the same bits, the same counters;
 * returns the last frame's history_fraction (for the callers' checks that there was history). */
static double same_bits(const run_case *rc, int frames)
{
    fv_svgf_opts o;
    fv_svgf_opts_default(&o);
    o.sigma_normal = rc->sigma_normal;
    o.iterations = rc->iterations;
    fv_svgf *cpu = NULL;
    fv_svgf_kernels *ker = NULL;
    fv_error err;
    if (fv_svgf_create(&rc->g, &o, &cpu, &err) != FV_OK) fail_msg("%s", err.msg);
    if (fv_svgf_kernels_create(&rc->g, &o, &ker, &err) != FV_OK) fail_msg("%s", err.msg);
    assert_true(fv_svgf_set_isa(cpu, FV_SVGF_ISA_PLAIN));
    if (rc->separate) fv_svgf_kernels_set_fused(ker, false);
    if (rc->periph_x >= 0) {
        fv_svgf_set_periphery(cpu, rc->periph_x, rc->periph_passes);
        fv_svgf_kernels_set_periphery(ker, rc->periph_x, rc->periph_passes);
    }
    double frac = 0.0;
    for (int k = 0; k < frames; k++) {
        frame_buf a = make_frame(&rc->g, (uint32_t)k, rc->holes), b = copy_frame(&a);
        fv_svgf_frame fa = {a.color, a.albedo, a.normal, a.depth, a.position, a.id, k ? a.prev : NULL, rc->holes ? a.sampled : NULL, rc->active};
        fv_svgf_frame fb = fa;
        fb.color = b.color;
        fv_svgf_info ia, ib;
        if (fv_svgf_filter(cpu, &fa, 1, &ia, &err) != FV_OK) fail_msg("%s", err.msg);
        if (fv_svgf_kernels_filter(ker, &fb, 1, &ib, &err) != FV_OK) fail_msg("%s", err.msg);
        for (size_t i = 0; i < a.n * 3; i++)
            if (memcmp(&a.color[i], &b.color[i], sizeof(float)))
                fail_msg("%s, frame %d: pixel %zu channel %zu: cpu %.9g, kernels %.9g", rc->name, k, i / 3, i % 3, (double)a.color[i],
                         (double)b.color[i]);
        assert_true(ia.history_fraction == ib.history_fraction);
        assert_true(ia.mean_history == ib.mean_history);
        frac = ia.history_fraction;
        free_frame(&b, false), free_frame(&a, true);
    }
    fv_svgf_destroy(cpu);
    fv_svgf_kernels_destroy(ker);
    return frac;
}

static void test_screen(void **st)
{
    (void)st;
    const run_case cases[4] = {
        {"screen", {61, 37, NULL, false}, NULL, 128.0f, 5, -1, 0, false, false},
        {"screen, holes, powf, separate prefilter", {61, 37, NULL, false}, NULL, 100.0f, 5, -1, 0, true, true},
        {"screen, one pass", {40, 23, NULL, false}, NULL, 128.0f, 1, -1, 0, true, false},
        {"screen, no pass", {40, 23, NULL, false}, NULL, 64.0f, 0, -1, 0, true, false},
    };
    for (int i = 0; i < 4; i++) assert_true(same_bits(&cases[i], 5) > 0.5);
}

/* The real spaces' grids for a 160x90 screen at 1.6 px/degree (a headset-wide view), the gaze near a corner (cells off
 * the screen, inactive). */
static void test_polar(void **st)
{
    (void)st;
    const fv_space_kind kinds[2] = {FV_SPACE_VPOLAR, FV_SPACE_LOGPOLAR};
    for (int ki = 0; ki < 2; ki++) {
        fv_space_opts so;
        fv_space_opts_default(kinds[ki], &so);
        fv_space *sp = NULL;
        fv_error err;
        if (fv_space_create(&so, 160, 90, 1.6, &sp, &err) != FV_OK) fail_msg("%s", err.msg);
        const fv_grid *g = fv_space_grid(sp);
        assert_true(g->wrap);
        if (kinds[ki] == FV_SPACE_VPOLAR) {
            assert_non_null(g->col_h);
            assert_true(g->col_h[0] < g->h / 4); /* short columns in the fovea */
        }
        fv_gaze gz = {0.8f, 0.25f};
        fv_space_view v = fv_space_view_at(sp, gz);
        uint8_t *act = calloc((size_t)g->w * g->h, 1);
        const long on = fv_space_onscreen_mask(&v, 6.0f, act);
        assert_true(on > 0 && on < fv_space_sample_count(sp)); /* some cells off the screen */
        const run_case cases[4] = {
            {"polar", *g, act, 128.0f, 5, -1, 0, true, false},
            {"polar, periphery, separate prefilter", *g, act, 128.0f, 5, g->w / 3, 2, true, true},
            {"polar, powf, periphery in the fovea", *g, NULL, 100.0f, 4, 3, 1, true, false},
            {"polar, all active, no holes", *g, NULL, 128.0f, 5, -1, 0, false, false},
        };
        for (int i = 0; i < 4; i++) assert_true(same_bits(&cases[i], 4) > 0.3);
        free(act);
        fv_space_destroy(sp);
    }
}

/* By hand: a 6x1 screen grid, surfaces of colour 1 and albedo 0.5 (illumination 2, an exact power
 * of two: every weighted mean of 2s is 2 exactly), a hole, a background pixel of colour 7 and an
 * inactive one of colour 9. The surfaces come out 1, the hole the mean of its surface neighbours,
 * 1; background and inactive pixels keep their colours. With a still history on the second frame
 * every surface finds one of length 2. */
static void test_by_hand(void **st)
{
    (void)st;
    const fv_grid g = {6, 1, NULL, false};
    fv_svgf_kernels *ker = NULL;
    assert_int_equal(fv_svgf_kernels_create(&g, NULL, &ker, NULL), FV_OK);
    for (int k = 0; k < 2; k++) {
        float color[18], albedo[18], normal[18], depth[6], pos[18], prev[12];
        uint32_t id[6];
        const uint8_t sampled[6] = {1, 1, 0, 1, 1, 1}, active[6] = {1, 1, 1, 1, 1, 0};
        for (int x = 0; x < 6; x++) {
            const bool bg = x == 4;
            for (int c = 0; c < 3; c++) {
                color[3 * x + c] = bg ? 7.0f : x == 5 ? 9.0f : 1.0f;
                albedo[3 * x + c] = 0.5f;
                normal[3 * x + c] = bg ? 0.0f : c == 2 ? 1.0f : 0.0f;
                pos[3 * x + c] = c == 0 ? 0.01f * (float)x : c == 2 ? 2.0f : 0.0f;
            }
            depth[x] = 2.0f, id[x] = 1;
            prev[2 * x] = (float)x + 0.5f, prev[2 * x + 1] = 0.5f;
        }
        fv_svgf_frame fr = {color, albedo, normal, depth, pos, id, k ? prev : NULL, sampled, active};
        fv_svgf_info info;
        assert_int_equal(fv_svgf_kernels_filter(ker, &fr, 1, &info, NULL), FV_OK);
        const float want[6] = {1.0f, 1.0f, 1.0f, 1.0f, 7.0f, 9.0f};
        for (int x = 0; x < 6; x++)
            for (int c = 0; c < 3; c++) assert_true(color[3 * x + c] == want[x]);
        assert_true(info.history_fraction == (k ? 1.0 : 0.0));
        assert_true(info.mean_history == (k ? 2.0 : 0.0));
    }
    fv_svgf_kernels_destroy(ker);
}

/* The kernels refuse what fv_svgf refuses. */
static void test_refusals(void **st)
{
    (void)st;
    fv_svgf_kernels *ker = NULL;
    fv_error err;
    const int bad_h[2] = {3, 0};
    const fv_grid bad = {2, 3, bad_h, true}, good = {2, 2, NULL, false};
    assert_int_equal(fv_svgf_kernels_create(&bad, NULL, &ker, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "column 1 has 0 rows"));
    assert_null(ker);
    fv_svgf_opts o;
    fv_svgf_opts_default(&o);
    o.sigma_lum = -1.0f;
    assert_int_equal(fv_svgf_kernels_create(&good, &o, &ker, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "sigma_lum"));
    assert_int_equal(fv_svgf_kernels_create(&good, NULL, &ker, &err), FV_OK);
    fv_svgf_frame fr = {0};
    assert_int_equal(fv_svgf_kernels_filter(ker, &fr, 1, NULL, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "no color buffer"));
    fv_svgf_kernels_destroy(ker);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_screen),
        cmocka_unit_test(test_polar),
        cmocka_unit_test(test_by_hand),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
