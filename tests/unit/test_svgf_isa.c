/* The SVGF denoiser's two builds of its hot sweeps (filter/svgf.h, fv_svgf_set_isa): forced to the
 * baseline x86-64 build and to the AVX2 build, they give the same bits over several frames with a
 * history, on a polar grid with a triangle of column heights (vector runs, per-pixel fallbacks,
 * wrap-around rows and clamped columns), a full polar grid and a screen grid, with holes and
 * inactive cells, for sigma_normal 128 (squarings) and 100 (powf). The polar wrap has no seam:
 * rotating a full polar grid's rows rotates the result, bit for bit, in either build. Inactive
 * cells (fv_svgf_frame.active) never leak: whatever they hold (NaN, huge values, other normals)
 * the active cells' results are the same bits, equal to those with the cells as background, and
 * the inactive cells' colours are left as they were. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "filter/svgf.h"

typedef struct frame_buf {
    fv_grid g;
    size_t n;
    float *color, *albedo, *normal, *depth, *position, *prev;
    uint32_t *id;
    uint8_t *sampled, *active;
} frame_buf;

static float hash01(uint32_t a, uint32_t b)
{
    uint32_t s = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u;
    s ^= s >> 15, s *= 0x2C1B3C6Du, s ^= s >> 12, s *= 0x297A2D39u, s ^= s >> 15;
    return (float)(s >> 8) / 16777216.0f;
}

/* A noisy scene on grid g for frame k: two objects (left and right of column w/2, different depth
 * slopes and normals), 3% background, 10% holes, every 7th column's lower half inactive (when
 * with_active); the history coordinates are each pixel's own centre (a still camera). */
static frame_buf make_frame(const fv_grid *g, uint32_t k, bool with_active)
{
    frame_buf b;
    b.g = *g;
    b.n = (size_t)g->w * g->h;
    b.color = calloc(b.n * 3, sizeof(float));
    b.albedo = calloc(b.n * 3, sizeof(float));
    b.normal = calloc(b.n * 3, sizeof(float));
    b.position = calloc(b.n * 3, sizeof(float));
    b.depth = calloc(b.n, sizeof(float));
    b.prev = calloc(b.n * 2, sizeof(float));
    b.id = calloc(b.n, sizeof(uint32_t));
    b.sampled = calloc(b.n, 1);
    b.active = with_active ? calloc(b.n, 1) : NULL;
    for (int y = 0; y < g->h; y++)
        for (int x = 0; x < g->w; x++) {
            size_t i = (size_t)y * g->w + x;
            b.prev[2 * i] = b.prev[2 * i + 1] = NAN;
            if (!fv_grid_valid(g, x, y)) continue;
            if (b.active) b.active[i] = !(x % 7 == 3 && y >= fv_grid_col_h(g, x) / 2);
            b.sampled[i] = hash01((uint32_t)i, 900 + k) > 0.1f;
            fv_grid_centre(g, x, y, &b.prev[2 * i], &b.prev[2 * i + 1]);
            if (hash01((uint32_t)i, 31) < 0.03f) continue; /* background */
            const int obj = x < g->w / 2;
            for (int c = 0; c < 3; c++) {
                b.color[3 * i + c] = (0.3f + 0.4f * (float)obj + 0.2f * (float)c) * 2.0f * hash01((uint32_t)i, 100 + 3 * k + (uint32_t)c);
                b.albedo[3 * i + c] = 0.5f + 0.1f * (float)c;
            }
            float tx = obj ? 0.3f : -0.2f, ty = 0.05f * (hash01((uint32_t)i, 41) - 0.5f), len = sqrtf(tx * tx + ty * ty + 1.0f);
            b.normal[3 * i] = tx / len, b.normal[3 * i + 1] = ty / len, b.normal[3 * i + 2] = 1.0f / len;
            b.depth[i] = (obj ? 3.0f : 2.0f) + 0.01f * (float)y + 0.003f * (float)x;
            b.position[3 * i] = 0.01f * (float)x, b.position[3 * i + 1] = 0.01f * (float)y, b.position[3 * i + 2] = b.depth[i];
            b.id[i] = 1u + (uint32_t)obj;
        }
    return b;
}

static void free_frame(frame_buf *b)
{
    free(b->color), free(b->albedo), free(b->normal), free(b->position), free(b->depth), free(b->prev);
    free(b->id), free(b->sampled), free(b->active);
}

static void filter(fv_svgf *f, frame_buf *b, bool history)
{
    fv_svgf_frame fr = {b->color, b->albedo, b->normal, b->depth, b->position, b->id, history ? b->prev : NULL,
                        b->sampled, b->active};
    fv_error err;
    if (fv_svgf_filter(f, &fr, 2, NULL, &err) != FV_OK) fail_msg("%s", err.msg);
}

static fv_svgf *make_filter(const fv_grid *g, float sigma_normal, fv_svgf_isa isa)
{
    fv_svgf_opts o;
    fv_svgf_opts_default(&o);
    o.sigma_normal = sigma_normal;
    fv_svgf *f = NULL;
    fv_error err;
    if (fv_svgf_create(g, &o, &f, &err) != FV_OK) fail_msg("%s", err.msg);
    assert_true(fv_svgf_set_isa(f, isa));
    return f;
}

static bool have_avx2(void)
{
    fv_svgf *f = NULL;
    const fv_grid g = {2, 2, NULL, false};
    assert_int_equal(fv_svgf_create(&g, NULL, &f, NULL), FV_OK);
    bool ok = fv_svgf_set_isa(f, FV_SVGF_ISA_AVX2);
    fv_svgf_destroy(f);
    return ok;
}

static int *triangle(int w, int h)
{
    int *c = malloc(sizeof(int) * w);
    for (int x = 0; x < w; x++) c[x] = 1 + 3 * x < h ? 1 + 3 * x : h;
    return c;
}

/* Four frames through a baseline filter and an AVX2 filter: the same bits each frame. */
static void test_same_bits(void **st)
{
    (void)st;
    if (!have_avx2()) {
        print_message("no AVX2 on this CPU: only the baseline build runs\n");
        skip();
    }
    int *tri = triangle(150, 72);
    const fv_grid grids[3] = {{150, 72, tri, true}, {150, 72, NULL, true}, {150, 72, NULL, false}};
    const float sigmas[2] = {128.0f, 100.0f};
    for (int gi = 0; gi < 3; gi++)
        for (int si = 0; si < 2; si++) {
            fv_svgf *fb = make_filter(&grids[gi], sigmas[si], FV_SVGF_ISA_BASELINE);
            fv_svgf *fa = make_filter(&grids[gi], sigmas[si], FV_SVGF_ISA_AVX2);
            for (uint32_t k = 0; k < 4; k++) {
                frame_buf b = make_frame(&grids[gi], k, gi == 0), a = make_frame(&grids[gi], k, gi == 0);
                filter(fb, &b, k > 0);
                filter(fa, &a, k > 0);
                assert_memory_equal(b.color, a.color, b.n * 3 * sizeof(float));
                double sum = 0.0;
                for (size_t i = 0; i < b.n * 3; i++) sum += b.color[i];
                assert_true(sum > 0.0 && isfinite(sum));
                free_frame(&b), free_frame(&a);
            }
            fv_svgf_destroy(fb), fv_svgf_destroy(fa);
        }
    free(tri);
}

/* The vectorised paths against one tap at a time (FV_SVGF_ISA_PLAIN): the register-blocked pixels,
 * and on the triangle the short columns, the columns beside them and the clamped edge, whose taps
 * are gathered 4 or 8 pixels at a time, give the same bits as adding each tap to each pixel in
 * turn; in the baseline build and, where the CPU has it, in the AVX2 build. */
static void test_plain_same_bits(void **st)
{
    (void)st;
    int *tri = triangle(150, 72);
    const fv_grid grids[3] = {{150, 72, tri, true}, {150, 72, NULL, true}, {150, 72, NULL, false}};
    const fv_svgf_isa isas[2] = {FV_SVGF_ISA_BASELINE, FV_SVGF_ISA_AVX2};
    for (int gi = 0; gi < 3; gi++)
        for (int ii = 0; ii < (have_avx2() ? 2 : 1); ii++) {
            fv_svgf *fp = make_filter(&grids[gi], 128.0f, FV_SVGF_ISA_PLAIN);
            fv_svgf *fv = make_filter(&grids[gi], 128.0f, isas[ii]);
            for (uint32_t k = 0; k < 4; k++) {
                frame_buf p = make_frame(&grids[gi], k, gi == 0), v = make_frame(&grids[gi], k, gi == 0);
                filter(fp, &p, k > 0);
                filter(fv, &v, k > 0);
                assert_memory_equal(p.color, v.color, p.n * 3 * sizeof(float));
                free_frame(&p), free_frame(&v);
            }
            fv_svgf_destroy(fp), fv_svgf_destroy(fv);
        }
    free(tri);
}

/* Fewer passes beyond a column (fv_svgf_set_periphery), the cut inside the short columns, beside
 * them and far from them: every build gives the bits of one tap at a time (the fovea's lines stop
 * at the cut), and the cut changes the image (its columns really skip passes). */
static void test_periphery_same_bits(void **st)
{
    (void)st;
    int *tri = triangle(150, 72);
    const fv_grid g = {150, 72, tri, true};
    const fv_svgf_isa isas[2] = {FV_SVGF_ISA_BASELINE, FV_SVGF_ISA_AVX2};
    const int cuts[3] = {10, 30, 90};
    for (int ci = 0; ci < 3; ci++)
        for (int ii = 0; ii < (have_avx2() ? 2 : 1); ii++) {
            fv_svgf *fp = make_filter(&g, 128.0f, FV_SVGF_ISA_PLAIN);
            fv_svgf *fv = make_filter(&g, 128.0f, isas[ii]);
            fv_svgf *fall = make_filter(&g, 128.0f, isas[ii]);
            fv_svgf_set_periphery(fp, cuts[ci], 2);
            fv_svgf_set_periphery(fv, cuts[ci], 2);
            for (uint32_t k = 0; k < 3; k++) {
                frame_buf p = make_frame(&g, k, true), v = make_frame(&g, k, true), a = make_frame(&g, k, true);
                filter(fp, &p, k > 0);
                filter(fv, &v, k > 0);
                filter(fall, &a, k > 0);
                assert_memory_equal(p.color, v.color, p.n * 3 * sizeof(float));
                size_t differ = 0;
                for (int y = 0; y < g.h; y++)
                    for (int x = cuts[ci]; x < g.w; x++) {
                        const size_t i = 3 * ((size_t)y * g.w + x);
                        differ += memcmp(&v.color[i], &a.color[i], 3 * sizeof(float)) != 0;
                    }
                assert_true(differ > 0);
                free_frame(&p), free_frame(&v), free_frame(&a);
            }
            fv_svgf_destroy(fp), fv_svgf_destroy(fv), fv_svgf_destroy(fall);
        }
    free(tri);
}

/* Rows wrap without a seam: rotating a full polar grid's rows by r rotates the filtered image by r
 * (the first frame and one with a history whose coordinates rotate too). */
static void test_wrap_rotation(void **st)
{
    (void)st;
    const fv_grid g = {60, 48, NULL, true};
    const fv_svgf_isa isas[2] = {FV_SVGF_ISA_BASELINE, FV_SVGF_ISA_AVX2};
    for (int ii = 0; ii < 2; ii++) {
        if (isas[ii] == FV_SVGF_ISA_AVX2 && !have_avx2()) continue;
        const int r = 17;
        fv_svgf *f0 = make_filter(&g, 128.0f, isas[ii]), *f1 = make_filter(&g, 128.0f, isas[ii]);
        for (uint32_t k = 0; k < 2; k++) {
            frame_buf a = make_frame(&g, k, false), b = make_frame(&g, k, false);
            /* b = a with row y moved to row (y + r) mod h; its history coordinates rotate along. */
            for (int y = 0; y < g.h; y++) {
                size_t s = (size_t)y * g.w, d = (size_t)((y + r) % g.h) * g.w;
                memcpy(&b.color[3 * d], &a.color[3 * s], 3 * sizeof(float) * g.w);
                memcpy(&b.albedo[3 * d], &a.albedo[3 * s], 3 * sizeof(float) * g.w);
                memcpy(&b.normal[3 * d], &a.normal[3 * s], 3 * sizeof(float) * g.w);
                memcpy(&b.position[3 * d], &a.position[3 * s], 3 * sizeof(float) * g.w);
                memcpy(&b.depth[d], &a.depth[s], sizeof(float) * g.w);
                memcpy(&b.id[d], &a.id[s], sizeof(uint32_t) * g.w);
                memcpy(&b.sampled[d], &a.sampled[s], (size_t)g.w);
                for (int x = 0; x < g.w; x++) fv_grid_centre(&g, x, (y + r) % g.h, &b.prev[2 * (d + x)], &b.prev[2 * (d + x) + 1]);
            }
            filter(f0, &a, k > 0);
            filter(f1, &b, k > 0);
            for (int y = 0; y < g.h; y++)
                assert_memory_equal(&a.color[3 * (size_t)y * g.w], &b.color[3 * (size_t)((y + r) % g.h) * g.w], 3 * sizeof(float) * g.w);
            free_frame(&a), free_frame(&b);
        }
        fv_svgf_destroy(f0), fv_svgf_destroy(f1);
    }
}

/* Inactive cells filled with garbage, or made background: the active cells come out the same. */
static void test_inactive_never_leak(void **st)
{
    (void)st;
    int *tri = triangle(150, 72);
    const fv_grid g = {150, 72, tri, true};
    const fv_svgf_isa isas[2] = {FV_SVGF_ISA_BASELINE, FV_SVGF_ISA_AVX2};
    for (int ii = 0; ii < 2; ii++) {
        if (isas[ii] == FV_SVGF_ISA_AVX2 && !have_avx2()) continue;
        fv_svgf *f[3];
        for (int v = 0; v < 3; v++) f[v] = make_filter(&g, 128.0f, isas[ii]);
        for (uint32_t k = 0; k < 3; k++) {
            frame_buf b[3];
            for (int v = 0; v < 3; v++) b[v] = make_frame(&g, k, true);
            for (size_t i = 0; i < b[0].n; i++) {
                if (b[0].active[i] || !fv_grid_valid(&g, (int)(i % g.w), (int)(i / g.w))) continue;
                for (int c = 0; c < 3; c++) {
                    b[1].color[3 * i + c] = c == 0 ? NAN : 1e30f;   /* garbage */
                    b[1].normal[3 * i + c] = c == 1 ? 1.0f : 0.0f;  /* another surface */
                    b[2].normal[3 * i + c] = 0.0f;                  /* background */
                }
                b[1].depth[i] = 0.5f;
                b[1].id[i] = 7;
                b[1].sampled[i] = 1;
                b[2].active[i] = 1;
            }
            float *before = malloc(b[1].n * 3 * sizeof(float));
            memcpy(before, b[1].color, b[1].n * 3 * sizeof(float));
            for (int v = 0; v < 3; v++) filter(f[v], &b[v], k > 0);
            for (size_t i = 0; i < b[0].n; i++) {
                if (!fv_grid_valid(&g, (int)(i % g.w), (int)(i / g.w))) continue;
                if (b[0].active[i]) {
                    assert_memory_equal(&b[0].color[3 * i], &b[1].color[3 * i], 3 * sizeof(float));
                    assert_memory_equal(&b[0].color[3 * i], &b[2].color[3 * i], 3 * sizeof(float));
                } else {
                    assert_memory_equal(&b[1].color[3 * i], &before[3 * i], 3 * sizeof(float));
                }
            }
            free(before);
            for (int v = 0; v < 3; v++) free_frame(&b[v]);
        }
        for (int v = 0; v < 3; v++) fv_svgf_destroy(f[v]);
    }
    free(tri);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_bits),
        cmocka_unit_test(test_plain_same_bits),
        cmocka_unit_test(test_periphery_same_bits),
        cmocka_unit_test(test_wrap_rotation),
        cmocka_unit_test(test_inactive_never_leak),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
