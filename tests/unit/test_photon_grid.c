/* The photon grid (technique/photon/photon_map.c) against brute force on random photon maps: a
 * query returns exactly the photons within r, in the order sums are taken in (cells z, then y,
 * then x, then the order the photons were stored); the gather's surface tests made by the query
 * keep exactly the photons the scalar tests keep; the nearest photon is the brute-force one; the
 * gather's sums (f_r * flux and Eq. 4's u) equal, to the bit, the sums of the straightforward
 * gather (every photon within r, the normal and side tests, fv_bsdf_eval) taken in that order, on
 * a diffuse and a glossy surface; the grid is the same whatever the thread count; and all this
 * with a dense grid, with wrapped axes (a radius far below the photons' spread) and with maps of
 * one to three photons. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "kernel/kbsdf.h"
#include "technique/photon/pm_gather.h"
#include "technique/photon/photon_map.h"

static uint64_t rng_state;

static float rnd(void) /* uniform in [0, 1) */
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (float)(rng_state >> 40) / 16777216.0f;
}

static fv_vec3 rnd_unit(void)
{
    for (;;) {
        fv_vec3 v = fv_v3(2 * rnd() - 1, 2 * rnd() - 1, 2 * rnd() - 1);
        float l = fv_length(v);
        if (l > 0.1f && l < 1.0f) return fv_scale(v, 1.0f / l);
    }
}

/* n photons over [0, ext)^3: three quarters on three planes (a floor, a wall, a slanted plane:
 * photons lie on surfaces), a quarter anywhere; normals mostly the plane's; signed fluxes. */
static fv_photon *random_photons(int n, float ext)
{
    fv_photon *p = calloc((size_t)n, sizeof *p);
    const fv_vec3 slant = fv_normalize(fv_v3(1, 1, 0));
    for (int i = 0; i < n; i++) {
        int kind = (int)(rnd() * 4);
        fv_vec3 q = fv_v3(rnd() * ext, rnd() * ext, rnd() * ext), nrm = rnd_unit();
        if (kind == 0) q.y = 0.25f * ext, nrm = fv_v3(0, 1, 0);
        if (kind == 1) q.x = 0.5f * ext, nrm = fv_v3(-1, 0, 0);
        if (kind == 2) q.y = ext - q.x, nrm = slant; /* x + y = ext */
        if (rnd() < 0.2f) nrm = rnd_unit();
        p[i].pos = q;
        p[i].n = nrm;
        p[i].dir = rnd_unit();
        p[i].flux = fv_v3(rnd() - 0.2f, rnd() - 0.2f, rnd() - 0.2f);
    }
    return p;
}

static int coord(float v, float inv) { return (int)floorf(v * inv); }

/* The order a query must list photon j: its cell (z, y, x), then its place in the input. */
typedef struct ref_item {
    int cz, cy, cx, j;
} ref_item;

static int ref_cmp(const void *a, const void *b)
{
    const ref_item *u = a, *v = b;
    if (u->cz != v->cz) return u->cz < v->cz ? -1 : 1;
    if (u->cy != v->cy) return u->cy < v->cy ? -1 : 1;
    if (u->cx != v->cx) return u->cx < v->cx ? -1 : 1;
    return u->j < v->j ? -1 : u->j > v->j;
}

static float dist2(fv_vec3 p, fv_vec3 x)
{
    fv_vec3 d = fv_sub(p, x);
    return fv_dot(d, d);
}

/* Brute force: the input photons within r of x, in the query's order; with facing, only those
 * the gather's scalar test keeps (!(n . N <= 0.5)). Photons within r lie in the
 * cells of [x - r, x + r] (the box a query visits) unless rounding puts one just outside; those
 * are listed separately (*outside) and must be rare. */
static int reference(const fv_photon *p, int n, float cell, fv_vec3 x, float r, const fv_vec3 *facing, ref_item *out, int *outside)
{
    const float inv = 1.0f / cell, r2 = r * r;
    const int lo[3] = {coord(x.x - r, inv), coord(x.y - r, inv), coord(x.z - r, inv)};
    const int hi[3] = {coord(x.x + r, inv), coord(x.y + r, inv), coord(x.z + r, inv)};
    int k = 0;
    *outside = 0;
    for (int j = 0; j < n; j++) {
        if (!(dist2(p[j].pos, x) <= r2)) continue;
        if (facing && fv_dot(p[j].n, *facing) <= 0.5f) continue;
        ref_item it = {coord(p[j].pos.z, inv), coord(p[j].pos.y, inv), coord(p[j].pos.x, inv), j};
        if (it.cx < lo[0] || it.cx > hi[0] || it.cy < lo[1] || it.cy > hi[1] || it.cz < lo[2] || it.cz > hi[2]) {
            (*outside)++;
            continue;
        }
        out[k++] = it;
    }
    qsort(out, (size_t)k, sizeof *out, ref_cmp);
    return k;
}

/* The photons a query lists, as records of the map (sorted: compared by content). */
static int run_query(const fv_photon_map *m, fv_vec3 x, float r, const fv_vec3 *facing, const fv_photon **out)
{
    fv_photon_query q;
    uint32_t idx[64];
    int k, total = 0;
    fv_photon_query_begin(&q, m, x, r);
    if (facing) fv_photon_query_facing(&q, *facing);
    while ((k = fv_photon_query_next(&q, idx, 64)) > 0)
        for (int j = 0; j < k; j++) out[total++] = &m->p[idx[j]];
    return total;
}

static int ref_nearest(const fv_photon *p, const ref_item *items, int k, fv_vec3 x, fv_vec3 nrm, float *best)
{
    int index = -1;
    *best = INFINITY;
    for (int i = 0; i < k; i++) {
        float d2 = dist2(p[items[i].j].pos, x);
        if (d2 < *best && fv_dot(p[items[i].j].n, nrm) > 0.5f) *best = d2, index = items[i].j;
    }
    return index;
}

/* A map of n photons over [0, ext)^3 with grid cell `cell`; queries at random points (half near a
 * photon, many on the photons' planes, where a gather happens), radii from a tenth of a cell to
 * three cells. */
static void check_queries(int n, float ext, float cell, int queries, bool expect_wrap)
{
    fv_photon *p = random_photons(n, ext);
    fv_photon_map m, m1;
    fv_error err;
    fv_photon_map_init(&m);
    fv_photon_map_init(&m1);
    assert_int_equal(fv_photon_map_append(&m, p, n, &err), FV_OK);
    assert_int_equal(fv_photon_map_append(&m1, p, n, &err), FV_OK);
    assert_int_equal(fv_photon_map_build_mt(&m, cell, 2, &err), FV_OK);
    assert_int_equal(fv_photon_map_build_mt(&m1, cell, 1, &err), FV_OK);
    /* The same grid on one thread as on two. */
    assert_memory_equal(m.p, m1.p, (size_t)n * sizeof *p);
    assert_memory_equal(m.start, m1.start, ((size_t)m.ncells + 1) * sizeof *m.start);
    assert_true(m.wrap[0] || m.wrap[1] || m.wrap[2] ? expect_wrap : !expect_wrap);
    ref_item *ref = malloc((size_t)n * sizeof *ref);
    const fv_photon **got = malloc((size_t)n * sizeof *got);
    long listed = 0, outside = 0;
    for (int t = 0; t < queries; t++) {
        fv_vec3 x = fv_v3(rnd() * 1.2f * ext - 0.1f * ext, rnd() * 1.2f * ext - 0.1f * ext, rnd() * 1.2f * ext - 0.1f * ext);
        if (t % 4 == 0) x.y = 0.25f * ext;
        if (t % 4 == 1) x.x = 0.5f * ext;
        if (t % 2 == 0) x = fv_add(p[(int)(rnd() * n)].pos, fv_scale(rnd_unit(), cell * rnd())); /* near a photon */
        const float r = cell * (t % 5 == 0 ? 0.1f + 2.9f * rnd() : 1.0f);
        const fv_vec3 nrm = t % 3 == 0 ? rnd_unit() : t % 4 == 1 ? fv_v3(-1, 0, 0) : fv_v3(0, 1, 0);
        for (int f = 0; f < 2; f++) {
            int out;
            int k = reference(p, n, cell, x, r, f ? &nrm : NULL, ref, &out);
            int g = run_query(&m, x, r, f ? &nrm : NULL, got);
            outside += out;
            listed += k;
            if (g != k) fail_msg("query %d (facing %d) at (%g %g %g) r %g: %d photons, brute force %d", t, f, x.x, x.y, x.z, r, g, k);
            for (int i = 0; i < k; i++)
                if (memcmp(got[i], &p[ref[i].j], sizeof *p))
                    fail_msg("query %d (facing %d): photon %d of %d is not brute force's (input photon %d)", t, f, i, k, ref[i].j);
            if (f) continue;
            /* The nearest photon facing nrm, within r: the first closest one in that order. */
            float d_ref, d_got;
            int j = ref_nearest(p, ref, k, x, nrm, &d_ref);
            int gi = fv_photon_map_nearest(&m, x, nrm, r, &d_got);
            assert_true((j < 0) == (gi < 0));
            if (j >= 0) {
                assert_memory_equal(&m.p[gi], &p[j], sizeof *p);
                assert_true(d_got == d_ref);
            }
        }
    }
    /* Most queries find photons; rounding never left one just outside the cells visited. */
    print_message("%d photons, cell %g: %ld photons listed over %d queries, %ld just outside\n", n, cell, listed, 2 * queries, outside);
    assert_true(listed > (n > 100 ? (long)queries : 0));
    assert_int_equal(outside, 0);
    free(ref);
    free(got);
    free(p);
    fv_photon_map_free(&m);
    fv_photon_map_free(&m1);
}

static void test_dense(void **st)
{
    (void)st;
    rng_state = 1;
    check_queries(30000, 10.0f, 0.5f, 3000, false); /* 20^3 cells */
}

static void test_wrapped(void **st)
{
    (void)st;
    rng_state = 2;
    check_queries(20000, 40.0f, 0.5f, 3000, true); /* 80^3 cells would be too many: axes wrap */
}

static void test_tiny(void **st)
{
    (void)st;
    for (int n = 1; n <= 3; n++) {
        rng_state = 10 + (uint64_t)n;
        check_queries(n, 2.0f, 0.7f, 500, false);
    }
    /* An empty map answers nothing. */
    fv_photon_map m;
    fv_error err;
    fv_photon_map_init(&m);
    assert_int_equal(fv_photon_map_build(&m, 1.0f, &err), FV_OK);
    const fv_photon *got[1];
    assert_int_equal(run_query(&m, fv_v3(0, 0, 0), 1.0f, NULL, got), 0);
    assert_int_equal(fv_photon_map_nearest(&m, fv_v3(0, 0, 0), fv_v3(0, 1, 0), 1.0f, NULL), -1);
    fv_photon_map_free(&m);
}

/* The gather, on a diffuse and a glossy surface, against the straightforward one: every photon
 * within r in the query order, the normal test, f * flux summed in float and max |flux| in double,
 * f being albedo / pi on the diffuse surface whichever side of its tangent plane the photon came
 * from (the disc's flux density), fv_bsdf_eval of wi in the shading frame on the glossy one.
 * Equal to the bit. */
static void test_gather_sums(void **st)
{
    (void)st;
    rng_state = 3;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material d = fv_material_default(FV_MAT_DIFFUSE), g = fv_material_default(FV_MAT_GLOSSY);
    d.albedo = fv_v3(0.7f, 0.5f, 0.3f);
    int md, mg;
    assert_int_equal(fv_scene_add_material(s, &d, &md, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &g, &mg, &err), FV_OK);
    const int n = 20000;
    const float ext = 10.0f, cell = 0.6f;
    fv_photon *p = random_photons(n, ext);
    fv_photon_map m;
    fv_photon_map_init(&m);
    assert_int_equal(fv_photon_map_append(&m, p, n, &err), FV_OK);
    assert_int_equal(fv_photon_map_build(&m, cell, &err), FV_OK);
    ref_item *ref = malloc((size_t)n * sizeof *ref);
    int nonzero = 0;
    for (int t = 0; t < 2000; t++) {
        fv_pm_hit h;
        memset(&h, 0, sizeof h);
        h.hit = true;
        h.p = fv_v3(rnd() * ext, 0.25f * ext, rnd() * ext);
        h.n = h.ng = fv_v3(0, 1, 0);
        if (t % 3 == 2) { /* on the slanted plane, tilted shading normal */
            h.p = fv_v3(rnd() * ext, 0, rnd() * ext);
            h.p.y = ext - h.p.x;
            h.ng = fv_normalize(fv_v3(1, 1, 0));
            h.n = fv_normalize(fv_v3(1, 1.2f, 0.1f));
        }
        h.wo = fv_normalize(fv_add(h.n, fv_scale(rnd_unit(), 0.7f)));
        h.mat = t % 2 ? mg : md;
        const fv_material *mat = fv_scene_material(s, h.mat);
        fv_shading sh;
        fv_shading_make(mat, h.ng, h.n, h.wo, &sh);
        int out;
        int k = reference(p, n, cell, h.p, cell, NULL, ref, &out);
        assert_int_equal(out, 0);
        fv_vec3 sum = fv_v3s(0.0f);
        double u = 0.0;
        for (int i = 0; i < k; i++) {
            const fv_photon *ph = &p[ref[i].j];
            if (fv_dot(ph->n, sh.n) <= 0.5f) continue;
            fv_vec3 wi = fv_shading_to_local(&sh, fv_neg(ph->dir));
            float pdf;
            fv_vec3 f = mat->type == FV_MAT_DIFFUSE ? fv_scale(mat->albedo, FV_INV_PI) : fv_bsdf_eval(mat, sh.wo, wi, &pdf);
            sum = fv_add(sum, fv_mul(f, ph->flux));
            u += fmax(fabs(ph->flux.x), fmax(fabs(ph->flux.y), fabs(ph->flux.z)));
        }
        double u_got = 0.0;
        fv_vec3 got = fv_pm_gather(s, &m, &h, cell, &u_got);
        fv_vec3 got_nou = fv_pm_gather(s, &m, &h, cell, NULL);
        if (memcmp(&got, &sum, sizeof sum) || memcmp(&u_got, &u, sizeof u) || memcmp(&got_nou, &sum, sizeof sum))
            fail_msg("gather %d (%s): (%.9g %.9g %.9g) u %.17g, straightforward (%.9g %.9g %.9g) u %.17g", t, t % 2 ? "glossy" : "diffuse",
                     got.x, got.y, got.z, u_got, sum.x, sum.y, sum.z, u);
        nonzero += u > 0.0;
    }
    assert_true(nonzero > 1000);
    free(ref);
    free(p);
    fv_photon_map_free(&m);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dense),
        cmocka_unit_test(test_wrapped),
        cmocka_unit_test(test_tiny),
        cmocka_unit_test(test_gather_sums),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
