/* fpm-guided's parts (technique/photon/guided.c): the focus cell set, photon guiding that stays
 * unbiased while it concentrates photons, eye paths split at the first dielectric (hand-worked
 * Fresnel weights), kept photon paths refreshed near a moving object equal to a full retrace, the sparse periphery fill (exact on a constant plane, never across an edge),
 * memory flat over 500 moving frames, and parameter checking. */
#include <malloc.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "filter/lattice.h"
#include "technique/photon/pm_gather.h"
#include "technique/photon/guide.h"
#include "technique/photon/path_store.h"
#include "testkit.h"

/* ---- the focus cells ---- */

/* Cells of edge 10. A disc at (5, 5, 5) of radius 3 stays inside cell (0,0,0); one at (9, 5, 5)
 * of radius 3 reaches x = 12, so it adds cell (1,0,0) too: two cells. */
static void test_focus_cells(void **st)
{
    (void)st;
    fv_focus_cells *a, *b;
    fv_error err;
    assert_int_equal(fv_focus_cells_create(&a, &err), FV_OK);
    assert_int_equal(fv_focus_cells_create(&b, &err), FV_OK);
    fv_focus_cells_reset(a, 10.0f);
    fv_focus_cells_reset(b, 10.0f);
    assert_int_equal(fv_focus_cells_add(a, fv_v3(5, 5, 5), 3.0f, &err), FV_OK);
    assert_int_equal(fv_focus_cells_count(a), 1);
    assert_int_equal(fv_focus_cells_add(a, fv_v3(9, 5, 5), 3.0f, &err), FV_OK);
    assert_int_equal(fv_focus_cells_count(a), 2);
    assert_true(fv_focus_cells_contains(a, fv_v3(15, 1, 9)));
    assert_false(fv_focus_cells_contains(a, fv_v3(-1, 1, 9)));
    assert_false(fv_focus_cells_contains(a, fv_v3(NAN, 1, 9)));
    /* b holds one of a's two cells and one of its own: overlap(a, b) = 1/2. */
    assert_int_equal(fv_focus_cells_add(b, fv_v3(5, 5, 5), 1.0f, &err), FV_OK);
    assert_int_equal(fv_focus_cells_add(b, fv_v3(-5, 5, 5), 1.0f, &err), FV_OK);
    assert_float_equal(fv_focus_cells_overlap(a, b), 0.5, 1e-12);
    /* Thousands of cells (the set grows) all found again. */
    for (int i = 0; i < 3000; i++) assert_int_equal(fv_focus_cells_add(b, fv_v3(10.0f * i + 5, -95, 5), 1.0f, &err), FV_OK);
    assert_int_equal(fv_focus_cells_count(b), 3002);
    for (int i = 0; i < 3000; i++) assert_true(fv_focus_cells_contains(b, fv_v3(10.0f * i + 1, -99, 1)));
    fv_focus_cells_destroy(a);
    fv_focus_cells_destroy(b);
}

/* ---- photon guiding is unbiased ---- */

static void add_quad(fv_scene *s, const char *name, fv_vec3 a, fv_vec3 b, fv_vec3 c, fv_vec3 d, int mat)
{
    fv_error err;
    const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
    const fv_vec3 v[4] = {a, b, c, d};
    fv_mesh_desc m = {name, v, 4, NULL, quad, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &m, NULL, NULL, &err), FV_OK);
}

/* A closed diffuse room, 200 on a side (albedo 0.5: light bounces), lit by a 40 x 40 area light
 * under its ceiling. */
static fv_scene *diffuse_room(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE), e = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.5f);
    e.albedo = fv_v3s(0.0f);
    e.emission = fv_v3s(10.0f);
    int mm, em;
    assert_int_equal(fv_scene_add_material(s, &m, &mm, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &e, &em, &err), FV_OK);
    const float L = 100.0f;
    fv_vec3 p[8];
    for (int k = 0; k < 8; k++) p[k] = fv_v3(k & 1 ? L : -L, k & 2 ? 2 * L : 0.0f, k & 4 ? L : -L);
    add_quad(s, "floor", p[0], p[1], p[5], p[4], mm);
    add_quad(s, "ceiling", p[2], p[6], p[7], p[3], mm);
    add_quad(s, "w0", p[0], p[4], p[6], p[2], mm);
    add_quad(s, "w1", p[1], p[3], p[7], p[5], mm);
    add_quad(s, "w2", p[0], p[2], p[3], p[1], mm);
    add_quad(s, "w3", p[4], p[5], p[7], p[6], mm);
    add_quad(s, "light", fv_v3(-20, 199, -20), fv_v3(20, 199, -20), fv_v3(20, 199, 20), fv_v3(-20, 199, 20), em);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

typedef struct flux_sum {
    double y;
    long n;
} flux_sum;

static void add_flux(void *ctx, const fv_photon *ph, float d2)
{
    (void)d2;
    flux_sum *f = ctx;
    f->y += ph->flux.y;
    f->n++;
}

/* Irradiance (flux per area) within r of x and the photon count there. */
static double irradiance(const fv_photon_map *m, fv_vec3 x, float r, long *count)
{
    flux_sum f = {0.0, 0};
    fv_photon_map_query(m, x, r, add_flux, &f);
    *count = f.n;
    return f.y / (FV_PI * r * r);
}

/* Over 10 seeds each, the irradiance the guided and the unguided maps give at the focus patch on
 * the floor, at a floor patch far from it and on a wall agree within 3.5 standard errors of their
 * difference, while the guided map puts at least 3x the photons in the focus patch. */
static void test_guide_unbiased(void **st)
{
    (void)st;
    fv_scene *s = diffuse_room();
    fv_error err;
    const fv_vec3 pts[3] = {{60, 0, 60}, {-60, 0, -60}, {-100, 100, 0}};
    const float r = 12.0f;
    fv_focus_cells *focus;
    assert_int_equal(fv_focus_cells_create(&focus, &err), FV_OK);
    fv_focus_cells_reset(focus, r);
    for (int i = -1; i <= 1; i++)
        for (int j = -1; j <= 1; j++) assert_int_equal(fv_focus_cells_add(focus, fv_v3(60 + 6.0f * i, 0, 60 + 6.0f * j), r, &err), FV_OK);
    fv_photon_guide *g;
    assert_int_equal(fv_photon_guide_create(0.8, &g, &err), FV_OK);
    enum { SEEDS = 10 };
    const int n = 30000;
    double e[2][3][SEEDS];
    long cnt[2][3] = {{0}};
    for (int seed = 0; seed < SEEDS; seed++)
        for (int guided = 0; guided < 2; guided++) {
            fv_photon_map m;
            fv_photon_map_init(&m);
            fv_photon_job job = {s, n, (uint64_t)(seed + 1), 0, 8, 0, 7, NULL, NULL, NULL, NULL};
            if (guided) {
                fv_photon_job pilot = job;
                pilot.count = n / 8;
                pilot.stream = 8;
                assert_int_equal(fv_photon_guide_learn(g, &pilot, FV_TRACE_STATIC, focus, NULL, &err), FV_OK);
                assert_true(fv_photon_guide_focus_share(g) > 0.0);
                job.warp = fv_photon_guide_warp;
                job.warp_ctx = g;
            }
            assert_int_equal(fv_photon_trace_lights(&job, FV_TRACE_STATIC, &m, NULL, &err), FV_OK);
            assert_int_equal(fv_photon_map_build(&m, r, &err), FV_OK);
            for (int k = 0; k < 3; k++) {
                long c;
                e[guided][k][seed] = irradiance(&m, pts[k], r, &c);
                cnt[guided][k] += c;
            }
            fv_photon_map_free(&m);
        }
    for (int k = 0; k < 3; k++) {
        double mean[2], var[2];
        for (int gi = 0; gi < 2; gi++) {
            double sum = 0, sq = 0;
            for (int i = 0; i < SEEDS; i++) sum += e[gi][k][i];
            mean[gi] = sum / SEEDS;
            for (int i = 0; i < SEEDS; i++) sq += (e[gi][k][i] - mean[gi]) * (e[gi][k][i] - mean[gi]);
            var[gi] = sq / (SEEDS - 1) / SEEDS; /* of the mean */
        }
        double se = sqrt(var[0] + var[1]);
        print_message("point %d: unguided %.5f (%ld photons), guided %.5f (%ld photons), se %.5f\n", k, mean[0], cnt[0][k], mean[1],
                      cnt[1][k], se);
        assert_true(mean[0] > 0.0);
        assert_true(fabs(mean[1] - mean[0]) <= 3.5 * se);
    }
    assert_true(cnt[1][0] >= 3 * cnt[0][0]);
    fv_photon_guide_destroy(g);
    fv_focus_cells_destroy(focus);
    fv_scene_destroy(s);
}

/* ---- kept paths, refreshed near the dynamic objects ---- */

/* The room with a dynamic diffuse box moved between two places: at each time the frame's map made
 * from the kept static paths (those meeting the box's sphere traced again) holds the photons a full
 * trace of the scene at that time gives, photon for photon (positions within rounding: the static
 * objects are instanced in the full scene), and some paths, not all, were traced again. */
static void test_path_store_refresh(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE), e = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.6f);
    e.albedo = fv_v3s(0.0f);
    e.emission = fv_v3s(10.0f);
    int mm, em;
    assert_int_equal(fv_scene_add_material(s, &m, &mm, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &e, &em, &err), FV_OK);
    add_quad(s, "floor", fv_v3(-100, 0, -100), fv_v3(-100, 0, 100), fv_v3(100, 0, 100), fv_v3(100, 0, -100), mm);
    add_quad(s, "wall", fv_v3(-100, 0, -100), fv_v3(100, 0, -100), fv_v3(100, 200, -100), fv_v3(-100, 200, -100), mm);
    add_quad(s, "light", fv_v3(-10, 100, -10), fv_v3(10, 100, -10), fv_v3(10, 100, 10), fv_v3(-10, 100, 10), em);
    fv_vec3 bv[8];
    for (int k = 0; k < 8; k++) bv[k] = fv_v3(k & 1 ? 10.0f : -10.0f, k & 2 ? 10.0f : -10.0f, k & 4 ? 10.0f : -10.0f);
    const uint32_t bi[36] = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
    fv_mesh_desc box = {"box", bv, 8, NULL, bi, 12, NULL, mm, NULL};
    int obj;
    assert_int_equal(fv_scene_add_mesh(s, &box, NULL, &obj, &err), FV_OK);
    fv_anim_key keys[2] = {{0.0, {0, 40, 0}, {0, 0, 0, 1}, {1, 1, 1}}, {1.0, {50, 20, 30}, {0, 0, 0, 1}, {1, 1, 1}}};
    assert_int_equal(fv_scene_animate_object(s, obj, keys, 2, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    fv_path_store *store;
    fv_dyn_dirs *dirs;
    assert_int_equal(fv_path_store_create(&store, &err), FV_OK);
    assert_int_equal(fv_dyn_dirs_create(&dirs, &err), FV_OK);
    fv_photon_job job = {s, 20000, 5, 0, 6, 0, 1, NULL, NULL, NULL, NULL};
    assert_int_equal(fv_path_store_trace(store, &job, NULL, &err), FV_OK);
    for (int t = 0; t < 2; t++) {
        assert_int_equal(fv_scene_set_time(s, (double)t, &err), FV_OK);
        assert_int_equal(fv_dyn_dirs_build(dirs, s, &err), FV_OK);
        fv_photon_map frame, full;
        fv_photon_map_init(&frame);
        fv_photon_map_init(&full);
        int64_t again = 0;
        assert_int_equal(fv_path_store_frame(store, dirs, NULL, NULL, 0, &frame, &again, NULL, &err), FV_OK);
        assert_int_equal(fv_photon_trace_lights(&job, FV_TRACE_ALL, &full, NULL, &err), FV_OK);
        print_message("time %d: %lld of 20000 paths traced again, %d photons (full trace %d)\n", t, (long long)again, frame.n, full.n);
        assert_true(again > 0 && again < 20000);
        assert_int_equal(frame.n, full.n);
        for (int i = 0; i < full.n; i++) {
            assert_true(fv_length(fv_sub(frame.p[i].pos, full.p[i].pos)) < 1e-2f);
            assert_float_equal(frame.p[i].flux.y, full.p[i].flux.y, 1e-4 * fabsf(full.p[i].flux.y) + 1e-9);
        }
        fv_photon_map_free(&frame);
        fv_photon_map_free(&full);
    }
    fv_dyn_dirs_destroy(dirs);
    fv_path_store_destroy(store);
    fv_scene_destroy(s);
}

/* ---- eye paths split at the first dielectric ---- */

/* A glass sheet (ior 1.5) at z = 0 facing a camera ray along -z, a diffuse wall at z = -10
 * behind it. At normal incidence F = ((1.5 - 1) / (1.5 + 1))^2 = 0.04: the reflected branch
 * carries 0.04 and leaves the scene (no surface), the refracted one carries (1 - 0.04) / 1.5^2 =
 * 0.426667 (radiance, Veach 5.2) and reaches the wall. */
static void test_split_weights(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material glass = fv_material_default(FV_MAT_DIELECTRIC), wall = fv_material_default(FV_MAT_DIFFUSE);
    int gm, wm;
    assert_int_equal(fv_scene_add_material(s, &glass, &gm, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &wall, &wm, &err), FV_OK);
    add_quad(s, "glass", fv_v3(-5, -5, 0), fv_v3(5, -5, 0), fv_v3(5, 5, 0), fv_v3(-5, 5, 0), gm);
    add_quad(s, "wall", fv_v3(-5, -5, -10), fv_v3(5, -5, -10), fv_v3(5, 5, -10), fv_v3(-5, 5, -10), wm);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    fv_rng rng = fv_rng_make(1, 2, 3, 4);
    fv_pm_hit h[2];
    int n = fv_pm_eye_path_split(s, fv_v3(0.3f, 0.2f, 5), fv_v3(0, 0, -1), 8, &rng, h);
    assert_int_equal(n, 2);
    assert_false(h[0].hit);
    assert_float_equal(h[0].weight.y, 0.04, 1e-5);
    assert_true(h[1].hit);
    assert_int_equal(h[1].mat, wm);
    assert_float_equal(h[1].weight.y, 0.96 / 2.25, 1e-5);
    assert_float_equal(h[1].p.z, -10.0, 1e-3);
    /* Both branches remember the same first surface: the glass. */
    assert_float_equal(h[0].first_t, 5.0, 1e-4);
    assert_float_equal(h[1].first_t, 5.0, 1e-4);
    /* The unsplit path picks one of the two, at random, with weight 1 / its probability folded in:
     * over many paths the mean weight reaching the wall is the split branch's. */
    double sum = 0.0;
    const int N = 20000;
    for (int i = 0; i < N; i++) {
        fv_pm_hit one;
        fv_pm_eye_path(s, fv_v3(0.3f, 0.2f, 5), fv_v3(0, 0, -1), 8, &rng, &one);
        if (one.hit) sum += one.weight.y;
    }
    assert_float_equal(sum / N, 0.96 / 2.25, 0.01);
    fv_scene_destroy(s);
}

/* ---- the sparse periphery fill ---- */

/* A plane seen face-on, every pixel with normal +z and a position on it: with the lattice holding
 * one constant, every filled pixel equals it, whatever the step (the weights are normalised). */
static void test_fill_constant_plane(void **st)
{
    (void)st;
    enum { W = 37, H = 23 };
    static float rgb[W * H * 3], nrm[W * H * 3], pos[W * H * 3];
    static uint8_t known[W * H], need[W * H];
    for (int step = 1; step <= 5; step++) {
        for (int i = 0; i < W * H; i++) {
            int x = i % W, y = i / W;
            nrm[3 * i] = 0, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 1;
            pos[3 * i] = 0.1f * x, pos[3 * i + 1] = 0.1f * y, pos[3 * i + 2] = 0;
            known[i] = x % step == 0 && y % step == 0;
            rgb[3 * i] = known[i] ? 0.25f : -1.0f;
            rgb[3 * i + 1] = known[i] ? 0.5f : -1.0f;
            rgb[3 * i + 2] = known[i] ? 2.0f : -1.0f;
        }
        fv_lattice_opts o = {step, NULL, 8.0f, 1.0f};
        long missing = fv_lattice_fill(rgb, known, NULL, nrm, pos, W, H, &o, need);
        assert_int_equal(missing, 0);
        for (int i = 0; i < W * H; i++) {
            assert_float_equal(rgb[3 * i], 0.25, 1e-6);
            assert_float_equal(rgb[3 * i + 1], 0.5, 1e-6);
            assert_float_equal(rgb[3 * i + 2], 2.0, 1e-6);
            assert_int_equal(need[i], 0);
        }
    }
}

/* A fold: the left half faces +z and holds 1, the right half faces +x and holds 5. Step 4: no
 * filled pixel mixes the two sides; a pixel whose surface agrees with no lattice corner (a thin
 * object, normal -z) is reported, untouched. */
static void test_fill_edges(void **st)
{
    (void)st;
    enum { W = 24, H = 16, S = 4, EDGE = 10 };
    static float rgb[W * H * 3], nrm[W * H * 3], pos[W * H * 3];
    static uint8_t known[W * H], need[W * H];
    for (int i = 0; i < W * H; i++) {
        int x = i % W, y = i / W;
        bool left = x < EDGE;
        nrm[3 * i] = left ? 0.0f : 1.0f, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = left ? 1.0f : 0.0f;
        pos[3 * i] = 0.1f * x, pos[3 * i + 1] = 0.1f * y, pos[3 * i + 2] = 0;
        known[i] = x % S == 0 && y % S == 0;
        for (int k = 0; k < 3; k++) rgb[3 * i + k] = known[i] ? (left ? 1.0f : 5.0f) : -1.0f;
    }
    const int thin = 5 * W + 6; /* (6, 5) */
    nrm[3 * thin + 2] = -1.0f;
    fv_lattice_opts o = {S, NULL, 8.0f, 0.0f};
    long missing = fv_lattice_fill(rgb, known, NULL, nrm, pos, W, H, &o, need);
    assert_int_equal(missing, 1);
    assert_int_equal(need[thin], 1);
    assert_float_equal(rgb[3 * thin], -1.0, 0.0);
    for (int i = 0; i < W * H; i++) {
        if (i == thin) continue;
        int x = i % W;
        /* Right-side pixels between lattice columns 8 and 12 see only the column at 12 agree. */
        assert_int_equal(need[i], 0);
        assert_float_equal(rgb[3 * i], x < EDGE ? 1.0 : 5.0, 1e-6);
    }
}

/* ---- the technique ---- */

static fv_technique *make(const fv_scene *s, const char *const *kv, fv_status *rc, fv_error *err)
{
    fv_params *p = fv_test_params(kv);
    fv_technique *t = NULL;
    *rc = fv_technique_create("fpm-guided", s, p, NULL, &t, err);
    fv_params_destroy(p);
    return t;
}

static void test_bad_params(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell", NULL, &s, &v, &err), FV_OK);
    const char *bad[][2] = {{"fovea_spp=0", "fovea_spp"},         {"periphery_step=0", "periphery_step"},
                            {"guided_fraction=1", "guided_fraction"}, {"alpha=1", "alpha"},
                            {"pilot_fraction=0", "pilot_fraction"}, {"radius=0", "radius"},
                            {"retrace_overlap=2", "retrace_overlap"}, {"fovea_spp=many", "fovea_spp"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *kv[] = {bad[i][0], NULL};
        fv_status rc;
        fv_technique *t = make(s, kv, &rc, &err);
        assert_null(t);
        fv_test_expect_fail(rc, &err, FV_ERR_INVALID, bad[i][1], bad[i][0]);
    }
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* 500 frames of cornell-fpm with the camera, the mirror cube and the gaze moving: after a warm-up
 * the heap in use does not grow (the maps, the cell sets and the guide are reused). */
static void test_memory_flat(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell-fpm", NULL, &s, &v, &err), FV_OK);
    const char *kv[] = {"photons=4000", "fovea_spp=2", NULL};
    fv_status rc;
    fv_technique *t = make(s, kv, &rc, &err);
    assert_non_null(t);
    fv_film *f;
    assert_int_equal(fv_film_create(24, 24, 0, &f, &err), FV_OK);
    fv_camera cam, prev;
    fv_stats stats;
    size_t early = 0, late = 0;
    double retraced = 0;
    const int frames = 500;
    for (int i = 0; i < frames; i++) {
        double time = 4.0 * i / frames;
        assert_int_equal(fv_scene_set_time(s, time, &err), FV_OK);
        fv_view_camera(v, s, time, 24, 24, &cam);
        fv_frame fr;
        fv_frame_init(&fr, NULL);
        fr.camera = &cam;
        fr.prev_camera = i ? &prev : NULL;
        fr.index = i;
        fr.seed = 3;
        fr.gaze = (fv_gaze){0.5f + 0.3f * sinf(0.05f * i), 0.5f + 0.2f * cosf(0.03f * i)};
        fr.time = time;
        fv_stats_clear(&stats);
        if (fv_technique_render(t, &fr, f, &stats, &err) != FV_OK) fail_msg("%s", err.msg);
        retraced += fv_stats_get_count(&stats, "guided_retraced");
        prev = cam;
        if (i == 100) early = mallinfo2().uordblks;
        late = mallinfo2().uordblks;
    }
    /* The gaze wanders: the guided map is retraced now and then, not every frame. */
    assert_true(retraced > 1 && retraced < frames);
    if (!getenv("FOVEA_SANITIZED")) assert_true(late <= early + 64 * 1024);
    fv_technique_destroy(t);
    fv_film_destroy(f);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_focus_cells),       cmocka_unit_test(test_guide_unbiased), cmocka_unit_test(test_split_weights),
        cmocka_unit_test(test_path_store_refresh),
        cmocka_unit_test(test_fill_constant_plane), cmocka_unit_test(test_fill_edges),   cmocka_unit_test(test_bad_params),
        cmocka_unit_test(test_memory_flat),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
