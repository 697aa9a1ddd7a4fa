/* Tests of the VPL depth cube maps (src/technique/vpl/cubemap.c; Foveated Instant Radiosity
 * Sec. 3.4's VPL shadow maps, rasterised or built with rays):
 *  - the face mapping: direction -> (face, u, v) -> direction round-trips, the six axes land on
 *    the face centres, every texel centre maps back to its own texel;
 *  - refusals: cube_size 7, 0 and 2049 and vpls 0 name their key; cube_size 8 works;
 *  - against Embree's own shadow rays (fv_scene_visible): in `cornell`, VPLs on the walls and
 *    blocks, thousands of camera-visible points in each VPL's hemisphere, agreement > 97% (nearest
 *    and 2x2 filtered, printed with the build speed), for both builds;
 *  - rasterised against traced: texel by texel the same depths in cornell-fir with its cube moved,
 *    with and without a normal; in an open scene with one floating occluder,
 *    100% agreement with the analytic shadow for points away from its silhouette;
 *  - a point straight behind the occluder is hidden, and seen once the occluder is gone;
 *  - determinism: the same map built twice, or many maps on 1 or 2 threads, is bit-identical.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>
#include "core/rng.h"
#include "scene/query.h"
#include "technique/vpl/cubemap.h"
#include "testkit.h"

static double now_s(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static fv_vec3 random_dir(fv_rng *r)
{
    const float z = 2.0f * fv_rng_next(r) - 1.0f, phi = 2.0f * FV_PI * fv_rng_next(r);
    const float s = sqrtf(fv_maxf(0.0f, 1.0f - z * z));
    return fv_v3(s * cosf(phi), s * sinf(phi), z);
}

/* ---- the mapping ---- */

static void test_mapping(void **st)
{
    (void)st;
    fv_rng r = fv_rng_make(7, 0, 0, 0);
    for (int k = 0; k < 100000; k++) {
        fv_vec3 d = random_dir(&r);
        float u, v;
        int f = fv_cube_face_of(d, &u, &v);
        assert_true(f >= 0 && f < 6 && u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f);
        fv_vec3 back = fv_normalize(fv_cube_dir(f, u, v));
        if (fv_length(fv_sub(back, d)) > 1e-5f)
            fail_msg("(%g %g %g) -> face %d (%g, %g) -> (%g %g %g)", d.x, d.y, d.z, f, u, v, back.x, back.y, back.z);
    }
    /* The axes: +X -X +Y -Y +Z -Z hit faces 0..5 at their centres. */
    const fv_vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; f++) {
        float u, v;
        assert_int_equal(fv_cube_face_of(fv_scale(axes[f], 3.0f), &u, &v), f);
        assert_true(u == 0.5f && v == 0.5f);
        fv_vec3 c = fv_cube_dir(f, 0.5f, 0.5f);
        assert_true(c.x == axes[f].x && c.y == axes[f].y && c.z == axes[f].z);
    }
    /* The written orientation: +X's u grows along +Y, -Z's u along -X, every v along the next axis. */
    fv_vec3 d = fv_cube_dir(0, 1.0f, 0.5f);
    assert_true(d.x == 1.0f && d.y == 1.0f && d.z == 0.0f);
    d = fv_cube_dir(5, 1.0f, 0.5f);
    assert_true(d.x == -1.0f && d.y == 0.0f && d.z == -1.0f);
    d = fv_cube_dir(2, 0.5f, 1.0f);
    assert_true(d.x == 1.0f && d.y == 1.0f && d.z == 0.0f);
    /* Every texel centre of an 8 x 8 cube maps back to its own texel. */
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 8; x++) {
                float u, v;
                int g = fv_cube_face_of(fv_cube_dir(f, (x + 0.5f) / 8.0f, (y + 0.5f) / 8.0f), &u, &v);
                assert_int_equal(g, f);
                assert_int_equal((int)(u * 8.0f), x);
                assert_int_equal((int)(v * 8.0f), y);
            }
}

/* ---- refusals ---- */

static void test_refusals(void **st)
{
    (void)st;
    fv_cubemaps *m = (fv_cubemaps *)1;
    fv_error err;
    fv_test_expect_fail(fv_cubemaps_create(1, 7, &m, &err), &err, FV_ERR_INVALID, "cube_size", "cube_size 7");
    assert_null(m);
    fv_test_expect_fail(fv_cubemaps_create(1, 0, &m, &err), &err, FV_ERR_INVALID, "cube_size", "cube_size 0");
    fv_test_expect_fail(fv_cubemaps_create(1, 2049, &m, &err), &err, FV_ERR_INVALID, "cube_size", "cube_size 2049");
    fv_test_expect_fail(fv_cubemaps_create(0, 128, &m, &err), &err, FV_ERR_INVALID, "vpls", "vpls 0");
    fv_test_expect_fail(fv_cubemaps_create(-3, 128, &m, &err), &err, FV_ERR_INVALID, "vpls", "vpls -3");

    /* The smallest size builds and answers: from the middle of the Cornell box, a point above the
     * blocks and one on the floor are seen, a point behind the back wall is not. */
    fv_scene *s;
    fv_view *view;
    assert_int_equal(fv_test_load("cornell", &s, &view), 0);
    assert_int_equal(fv_cubemaps_create(2, 8, &m, &err), FV_OK);
    assert_int_equal(fv_cubemaps_face_size(m), 8);
    assert_int_equal(fv_cubemaps_count(m), 2);
    fv_vec3 c = fv_v3(278, 274, 280);
    assert_int_equal(fv_cubemaps_build(m, s, 0, c, NULL, &err), FV_OK);
    assert_true(fv_cubemaps_visible(m, 0, fv_v3(278, 450, 200)));
    assert_true(fv_cubemaps_visible(m, 0, fv_v3(450, 0, 100)));
    assert_false(fv_cubemaps_visible(m, 0, fv_v3(278, 274, 700)));
    /* An unbuilt map sees everything; bad indices and positions are refused. */
    assert_true(fv_cubemaps_visible(m, 1, fv_v3(278, 274, 700)));
    fv_test_expect_fail(fv_cubemaps_build(m, s, 2, c, NULL, &err), &err, FV_ERR_INVALID, "vpls", "index 2");
    fv_test_expect_fail(fv_cubemaps_build(m, s, 0, fv_v3(NAN, 0, 0), NULL, &err), &err, FV_ERR_INVALID, "finite",
                        "NaN position");
    int bad = -1;
    fv_test_expect_fail(fv_cubemaps_build_many(m, s, &bad, &c, NULL, 1, 0, &err), &err, FV_ERR_INVALID, "vpls",
                        "index -1");
    fv_cubemaps_destroy(m);
    fv_view_destroy(view);
    fv_scene_destroy(s);
}

/* ---- against Embree in the Cornell box ---- */

#define NVPL 8
#define NQ 3000

static void cornell_agreement(fv_cube_build how)
{
    fv_scene *s;
    fv_view *view;
    assert_int_equal(fv_test_load("cornell", &s, &view), 0);
    /* VPLs: first hits of rays from the box's middle (walls, floor, ceiling, both blocks), facing
     * back toward it. */
    const fv_vec3 mid = fv_v3(278, 300, 280);
    const fv_vec3 aims[NVPL] = {{0, -1, 0.1f}, {0.2f, -1, -0.3f}, {-0.3f, -1, 0.4f}, {0, 0.05f, 1},
                                {1, -0.2f, 0.1f}, {-1, 0.3f, -0.2f}, {0.1f, 1, 0.3f}, {-0.2f, -0.6f, 0.2f}};
    fv_vec3 pos[NVPL], nrm[NVPL];
    int idx[NVPL];
    for (int k = 0; k < NVPL; k++) {
        fv_hit h;
        assert_true(fv_scene_intersect(s, FV_TRACE_ALL, mid, fv_normalize(aims[k]), INFINITY, &h));
        pos[k] = h.p;
        nrm[k] = fv_dot(h.ng, aims[k]) < 0.0f ? h.ng : fv_neg(h.ng);
        idx[k] = k;
    }
    fv_cubemaps *m;
    fv_error err;
    assert_int_equal(fv_cubemaps_create(NVPL, 128, &m, &err), FV_OK);
    fv_cubemaps_set_build(m, how);
    /* The first build also pays for first touches of the pool's pages: time the second. */
    assert_int_equal(fv_cubemaps_build_many(m, s, idx, pos, nrm, NVPL, 0, &err), FV_OK);
    enum { REPEAT = 6 };
    double t0 = now_s();
    for (int k = 0; k < REPEAT; k++) assert_int_equal(fv_cubemaps_build_many(m, s, idx, pos, nrm, NVPL, 0, &err), FV_OK);
    double dt = (now_s() - t0) / REPEAT;
    printf("cube maps 128^2 by %s: %.1f maps/s (%d VPLs on all threads)\n", fv_cube_build_names[how], NVPL / dt, NVPL);

    /* Receivers: first hits of camera rays through random points of the image. */
    fv_camera cam;
    fv_view_camera(view, s, 0.0, 256, 256, &cam);
    fv_camera_basis b;
    assert_int_equal(fv_camera_basis_make(&cam, &b, &err), FV_OK);
    fv_rng r = fv_rng_make(11, 0, 0, 0);
    int pairs = 0, agree = 0, agree_pcf = 0, lit = 0, lit_map = 0;
    for (int k = 0; k < NQ; k++) {
        const float sx = (2.0f * fv_rng_next(&r) - 1.0f) * b.tan_half_x, sy = (2.0f * fv_rng_next(&r) - 1.0f) * b.tan_half_y;
        fv_vec3 d = fv_normalize(fv_add(b.forward, fv_add(fv_scale(b.right, sx), fv_scale(b.up, sy))));
        fv_hit h;
        if (!fv_scene_intersect(s, FV_TRACE_ALL, b.pos, d, INFINITY, &h)) continue;
        for (int i = 0; i < NVPL; i++) {
            /* Only points the VPL can light (its cosine is zero behind and vanishing along its plane). */
            fv_vec3 w = fv_sub(h.p, pos[i]);
            if (fv_dot(nrm[i], w) <= 0.02f * fv_length(w)) continue;
            const bool ref = fv_scene_visible(s, FV_TRACE_ALL, pos[i], nrm[i], h.p);
            const bool got = fv_cubemaps_visible(m, i, h.p);
            const float pcf = fv_cubemaps_visibility(m, i, h.p, FV_CUBE_PCF2X2);
            assert_true(pcf >= 0.0f && pcf <= 1.0f);
            assert_true(fv_cubemaps_visibility(m, i, h.p, FV_CUBE_NEAREST) == (got ? 1.0f : 0.0f));
            pairs++;
            agree += got == ref;
            agree_pcf += (pcf >= 0.5f) == ref;
            lit += ref;
            lit_map += got;
        }
    }
    const double rate = (double)agree / pairs, rate_pcf = (double)agree_pcf / pairs;
    printf("cornell: %d (VPL, point) pairs, %d lit by Embree, %d by the maps; agreement %.2f%% nearest, %.2f%% 2x2\n",
           pairs, lit, lit_map, 100.0 * rate, 100.0 * rate_pcf);
    assert_true(pairs > 5000);
    assert_true(lit > pairs / 4 && lit < pairs); /* the blocks do cast shadows */
    assert_true(rate > 0.97);
    assert_true(rate_pcf > 0.97);
    fv_cubemaps_destroy(m);
    fv_view_destroy(view);
    fv_scene_destroy(s);
}

static void test_cornell_agreement(void **st)
{
    (void)st;
    cornell_agreement(FV_CUBE_BUILD_RAYS);
    cornell_agreement(FV_CUBE_BUILD_RASTER);
}

/* ---- rasterised against traced ---- */

/* Both builds store the depth along each texel's centre ray (cube_raster.h): in cornell-fir with
 * its cube moved (a dynamic object at t = 1.3 s), VPLs on random camera-visible points, texel by
 * texel the two maps agree to 1e-4 relative except where a texel centre's ray passes within
 * rounding of a triangle edge, which may resolve differently; those are a few per face, far below
 * 0.5% of the texels. Without normals (a point light's six faces) as well. */
static void test_raster_matches_rays(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *view;
    fv_error err;
    assert_int_equal(fv_test_load("cornell-fir", &s, &view), 0);
    assert_int_equal(fv_scene_set_time(s, 1.3, &err), FV_OK);
    enum { N = 12, SIZE = 64 };
    fv_vec3 pos[N], nrm[N];
    int idx[N];
    fv_camera cam;
    fv_view_camera(view, s, 1.3, 128, 128, &cam);
    fv_camera_basis b;
    assert_int_equal(fv_camera_basis_make(&cam, &b, &err), FV_OK);
    fv_rng r = fv_rng_make(5, 0, 0, 0);
    for (int k = 0; k < N;) {
        const float sx = (2.0f * fv_rng_next(&r) - 1.0f) * b.tan_half_x, sy = (2.0f * fv_rng_next(&r) - 1.0f) * b.tan_half_y;
        fv_vec3 d = fv_normalize(fv_add(b.forward, fv_add(fv_scale(b.right, sx), fv_scale(b.up, sy))));
        fv_hit h;
        if (!fv_scene_intersect(s, FV_TRACE_ALL, b.pos, d, INFINITY, &h)) continue;
        pos[k] = h.p;
        nrm[k] = fv_dot(h.ng, d) < 0.0f ? h.ng : fv_neg(h.ng);
        idx[k] = k;
        k++;
    }
    for (int with_normals = 1; with_normals >= 0; with_normals--) {
        fv_cubemaps *ray, *ras;
        assert_int_equal(fv_cubemaps_create(N, SIZE, &ray, &err), FV_OK);
        assert_int_equal(fv_cubemaps_create(N, SIZE, &ras, &err), FV_OK);
        fv_cubemaps_set_build(ray, FV_CUBE_BUILD_RAYS);
        fv_cubemaps_set_build(ras, FV_CUBE_BUILD_RASTER);
        assert_true(fv_cube_build_rasterises(FV_CUBE_BUILD_RASTER, s) && !fv_cube_build_rasterises(FV_CUBE_BUILD_RAYS, s));
        /* without a normal the map starts at the point itself: lift it off its surface, where a
         * ray would graze the surface it starts on (a point light is not on a surface) */
        const fv_vec3 *nn = with_normals ? nrm : NULL;
        fv_vec3 at[N];
        for (int k = 0; k < N; k++) at[k] = with_normals ? pos[k] : fv_madd(pos[k], nrm[k], 5.0f);
        assert_int_equal(fv_cubemaps_build_many(ray, s, idx, at, nn, N, 0, &err), FV_OK);
        assert_int_equal(fv_cubemaps_build_many(ras, s, idx, at, nn, N, 0, &err), FV_OK);
        const size_t texels = (size_t)6 * SIZE * SIZE;
        size_t differ = 0, zeros = 0, finite = 0;
        for (int i = 0; i < N; i++) {
            const float *a = fv_cubemaps_depths(ray, i), *c = fv_cubemaps_depths(ras, i);
            for (size_t t = 0; t < texels; t++) {
                zeros += a[t] == 0.0f;
                finite += isfinite(a[t]) && a[t] > 0.0f;
                /* the hemisphere rule is shared: exactly the same texels are 0 */
                assert_true((a[t] == 0.0f) == (c[t] == 0.0f));
                const bool same = (isinf(a[t]) && isinf(c[t])) || fabsf(a[t] - c[t]) <= 1e-4f * fabsf(a[t]);
                differ += !same;
            }
        }
        printf("raster vs rays (%s normals): %zu of %zu texels differ (%zu behind, %zu with a depth)\n",
               with_normals ? "with" : "without", differ, (size_t)N * texels, zeros, finite);
        assert_true(finite > (size_t)N * texels / 4);
        assert_true(with_normals ? zeros > (size_t)N * texels / 4 : zeros == 0);
        assert_true(differ * 200 < (size_t)N * texels);
        fv_cubemaps_destroy(ray);
        fv_cubemaps_destroy(ras);
    }
    fv_view_destroy(view);
    fv_scene_destroy(s);
}

/* ---- an open scene with one occluder ---- */

/* A floor y = 0 over [-1, 1]^2 (x, z) and, when `occluder`, a square [-0.2, 0.2]^2 at y = 0.5. */
static fv_scene *open_scene(bool occluder)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material mt = fv_material_default(FV_MAT_DIFFUSE);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &mt, &mat, &err), FV_OK);
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    const fv_vec3 floor_v[4] = {{-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}};
    fv_mesh_desc fl = {"floor", floor_v, 4, NULL, idx, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &fl, NULL, NULL, &err), FV_OK);
    if (occluder) {
        const fv_vec3 occ_v[4] = {{-0.2f, 0.5f, -0.2f}, {-0.2f, 0.5f, 0.2f}, {0.2f, 0.5f, 0.2f}, {0.2f, 0.5f, -0.2f}};
        fv_mesh_desc oc = {"occluder", occ_v, 4, NULL, idx, 2, NULL, mat, NULL};
        assert_int_equal(fv_scene_add_mesh(s, &oc, NULL, NULL, &err), FV_OK);
    }
    const fv_light_desc light = {FV_LIGHT_POINT, {0, 2, 0}, {0, -1, 0}, {1, 1, 1}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &light, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

/* Signed distance, in the occluder's plane, from where the segment p -> q crosses y = 0.5 to the
 * occluder's edge: > 0 inside its shadow, < 0 outside. p at y = 1, q at y = 0. */
static float shadow_depth(fv_vec3 p, fv_vec3 q)
{
    const float mx = fabsf(0.5f * (p.x + q.x)), mz = fabsf(0.5f * (p.z + q.z));
    if (mx <= 0.2f && mz <= 0.2f) return fv_minf(0.2f - mx, 0.2f - mz);
    const float ox = fv_maxf(mx - 0.2f, 0.0f), oz = fv_maxf(mz - 0.2f, 0.0f);
    return -sqrtf(ox * ox + oz * oz);
}

static void test_open_box(void **st)
{
    (void)st;
    fv_scene *with = open_scene(true), *without = open_scene(false);
    const fv_vec3 p = fv_v3(0.1f, 1.0f, 0.05f), n = fv_v3(0, -1, 0);
    fv_cubemaps *m;
    fv_error err;
    assert_int_equal(fv_cubemaps_create(2, 128, &m, &err), FV_OK);
    assert_int_equal(fv_cubemaps_build(m, with, 0, p, &n, &err), FV_OK);
    assert_int_equal(fv_cubemaps_build(m, without, 1, p, &n, &err), FV_OK);

    /* Only the VPL's hemisphere is traced: facing down, its +Y face holds zeros; on its -Y face the
     * centre texel (under the occluder) and a corner texel (out at the floor) see real depths. */
    const float *dep = fv_cubemaps_depths(m, 1);
    for (int k = 0; k < 128 * 128; k++) assert_true(dep[2 * 128 * 128 + k] == 0.0f);
    const float centre_depth = dep[(3 * 128 + 64) * 128 + 64];
    assert_true(fabsf(centre_depth - 1.0f) < 0.01f);
    const float off_depth = dep[(3 * 128 + 32) * 128 + 32]; /* towards (-0.5, -1, 0.5): the floor at 1.22 */
    assert_true(off_depth > 1.15f && off_depth < 1.3f);
    assert_true(fabsf(fv_cubemaps_depths(m, 0)[(3 * 128 + 64) * 128 + 64] - 0.5f) < 0.01f);

    /* Straight behind the occluder's centre (0, 0.5, 0): hidden, and seen without the occluder. */
    const fv_vec3 behind = fv_add(p, fv_scale(fv_sub(fv_v3(0, 0.5f, 0), p), 2.0f));
    assert_false(fv_scene_visible(with, FV_TRACE_ALL, p, n, behind));
    assert_false(fv_cubemaps_visible(m, 0, behind));
    assert_true(fv_cubemaps_visibility(m, 0, behind, FV_CUBE_PCF2X2) == 0.0f);
    assert_true(fv_cubemaps_visible(m, 1, behind));
    assert_true(fv_cubemaps_visibility(m, 1, behind, FV_CUBE_PCF2X2) == 1.0f);

    /* A grid over the floor: away from the shadow's edge (2 texels at the occluder, ~0.016), the
     * maps, Embree and the analytic shadow all agree, point for point. */
    int far = 0, near = 0, near_agree = 0, shadowed = 0;
    for (int zi = 0; zi < 80; zi++)
        for (int xi = 0; xi < 80; xi++) {
            const fv_vec3 q = fv_v3(-0.99f + 1.98f * xi / 79.0f, 0.0f, -0.99f + 1.98f * zi / 79.0f);
            const float sd = shadow_depth(p, q);
            const bool ref = fv_scene_visible(with, FV_TRACE_ALL, p, n, q);
            const bool got = fv_cubemaps_visible(m, 0, q);
            assert_true(fv_cubemaps_visible(m, 1, q)); /* nothing blocks the floor without it */
            if (fabsf(sd) < 0.02f) {
                near++;
                near_agree += got == ref;
                continue;
            }
            far++;
            shadowed += sd > 0.0f;
            if (ref != (sd < 0.0f)) fail_msg("Embree disagrees with the analytic shadow at (%g, %g)", q.x, q.z);
            if (got != ref) fail_msg("map says %d, Embree %d at (%g, %g), %g from the edge", got, ref, q.x, q.z, sd);
            if ((fv_cubemaps_visibility(m, 0, q, FV_CUBE_PCF2X2) >= 0.5f) != ref)
                fail_msg("2x2 filter disagrees at (%g, %g)", q.x, q.z);
        }
    printf("open box: %d points away from the silhouette all agree (%d shadowed); %d of %d near it agree\n", far,
           shadowed, near_agree, near);
    assert_true(shadowed > 100 && far > 5000);
    fv_cubemaps_destroy(m);
    fv_scene_destroy(with);
    fv_scene_destroy(without);
}

/* ---- determinism ---- */

static void test_determinism(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *view;
    assert_int_equal(fv_test_load("cornell", &s, &view), 0);
    enum { N = 6, SIZE = 64 };
    fv_vec3 pos[N], nrm[N];
    int idx[N];
    fv_rng r = fv_rng_make(3, 0, 0, 0);
    for (int k = 0; k < N; k++) {
        fv_hit h;
        fv_vec3 d;
        do d = random_dir(&r); /* the box is open towards -z */
        while (!fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(278, 274, 280), d, INFINITY, &h));
        pos[k] = h.p;
        nrm[k] = fv_dot(h.ng, d) < 0.0f ? h.ng : fv_neg(h.ng);
        idx[k] = N - 1 - k; /* any order of maps */
    }
    fv_cubemaps *a, *b;
    fv_error err;
    assert_int_equal(fv_cubemaps_create(N, SIZE, &a, &err), FV_OK);
    assert_int_equal(fv_cubemaps_create(N, SIZE, &b, &err), FV_OK);
    const size_t bytes = (size_t)6 * SIZE * SIZE * sizeof(float);
    /* The same map twice, into the same slot and into another one. */
    assert_int_equal(fv_cubemaps_build(a, s, 0, pos[0], &nrm[0], &err), FV_OK);
    assert_int_equal(fv_cubemaps_build(b, s, 3, pos[0], &nrm[0], &err), FV_OK);
    assert_memory_equal(fv_cubemaps_depths(a, 0), fv_cubemaps_depths(b, 3), bytes);
    assert_int_equal(fv_cubemaps_build(a, s, 0, pos[0], &nrm[0], &err), FV_OK);
    assert_memory_equal(fv_cubemaps_depths(a, 0), fv_cubemaps_depths(b, 3), bytes);
    /* Many at once on 1 and 2 threads. */
    assert_int_equal(fv_cubemaps_build_many(a, s, idx, pos, nrm, N, 1, &err), FV_OK);
    assert_int_equal(fv_cubemaps_build_many(b, s, idx, pos, nrm, N, 2, &err), FV_OK);
    for (int i = 0; i < N; i++) {
        assert_memory_equal(fv_cubemaps_depths(a, i), fv_cubemaps_depths(b, i), bytes);
        fv_vec3 ca = fv_cubemaps_centre(a, i), cb = fv_cubemaps_centre(b, i);
        assert_memory_equal(&ca, &cb, sizeof ca);
    }
    fv_cubemaps_destroy(a);
    fv_cubemaps_destroy(b);
    fv_view_destroy(view);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mapping),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_cornell_agreement),
        cmocka_unit_test(test_raster_matches_rays),
        cmocka_unit_test(test_open_box),
        cmocka_unit_test(test_determinism),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
