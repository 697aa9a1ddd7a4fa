/* Tests of the sphere-tracing family (src/technique/sdf: sdf-gt, sdf-relaxed, ipr, fipr), after
 * Polychronakis et al. 2023. The generic checks every method gets (furnace, threads, stereo,
 * progress, refusals) are in tests/conformance; these are the family's own:
 *  - the pyramid's image operations worked by hand: level sizes and block centres on odd grids,
 *    the 3x3 minimum start with borders and misses, Sobel edges (a step, a receding plane, a
 *    silhouette against the sky), the mask probability of Eq. 1;
 *  - the tracer on an analytic sphere (hit distance, misses, steps, max_steps, a start inside the
 *    solid), plain and over-relaxed marches never passing the first surface, the 8-lane and
 *    scalar tracers bit-identical;
 *  - images: simd on and off bit-identical for every method, super-sampling changing only edges,
 *    the min filter keeping thin objects, ipr matching sdf-gt for fewer steps and never stopping
 *    inside a solid, the image independent of the hit distance, fipr's mask, its counters, its
 *    refresh phases and its fovea (ipr's, pixel for pixel), the whole image ipr's under a
 *    whole-screen fovea (`--gaze-missing widen`), and the shading against sdf-furnace's exact 1
 *    and pt's direct light.
 * Renders are small (at most 160x128): a few seconds in Release.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "core/rng.h"
#include "technique/sdf/march.h"
#include "technique/sdf/pyramid.h"
#include "technique/sdf/world.h"
#include "testkit.h"

/* ---- scenes built by hand ---- */

static fv_sdf_node leaf(fv_sdf_kind k, int mat)
{
    fv_sdf_node n;
    memset(&n, 0, sizeof n);
    n.kind = k;
    n.q = (fv_quat){0, 0, 0, 1};
    n.a = n.b = -1;
    n.material = mat;
    return n;
}

static fv_sdf_node moved_to(int child, fv_vec3 t)
{
    fv_sdf_node n = leaf(FV_SDF_TRANSFORM, 0);
    n.a = child;
    n.v[0] = t;
    n.p[0] = 1.0f;
    return n;
}

static fv_scene *new_scene(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    return s;
}

static int diffuse(fv_scene *s, const char *name, fv_vec3 albedo)
{
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    snprintf(m.name, sizeof m.name, "%s", name);
    m.albedo = albedo;
    int id = -1;
    fv_error err;
    assert_int_equal(fv_scene_add_material(s, &m, &id, &err), FV_OK);
    return id;
}

/* One field object: node n placed at `at`. */
static void add_placed(fv_scene *s, const char *name, fv_sdf_node n, fv_vec3 at)
{
    fv_sdf_node t[2] = {n, moved_to(0, at)};
    fv_error err;
    fv_status st = fv_scene_add_sdf(s, name, t, 2, 1, NULL, NULL, &err);
    if (st != FV_OK) fail_msg("%s: %s", name, err.msg);
}

static void add_sphere(fv_scene *s, const char *name, fv_vec3 c, float r, int mat)
{
    fv_sdf_node n = leaf(FV_SDF_SPHERE, mat);
    n.p[0] = r;
    add_placed(s, name, n, c);
}

/* A slab whose top is y = 0, half x half wide. */
static void add_ground(fv_scene *s, float half, int mat)
{
    fv_sdf_node n = leaf(FV_SDF_BOX, mat);
    n.v[0] = fv_v3(half, 0.5f, half);
    add_placed(s, "ground", n, fv_v3(0, -0.5f, 0));
}

static void add_point_light(fv_scene *s, fv_vec3 pos, float intensity)
{
    fv_light_desc l = {FV_LIGHT_POINT, pos, {0, -1, 0}, {intensity, intensity, intensity}, 0, 0};
    fv_error err;
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
}

static void commit(fv_scene *s)
{
    fv_error err;
    fv_status st = fv_scene_commit(s, NULL, &err);
    if (st != FV_OK) fail_msg("commit: %s", err.msg);
}

static fv_scene *load(const char *name, int w, int h, fv_camera *cam)
{
    fv_scene *s;
    fv_view *v;
    if (fv_test_load(name, &s, &v) != 0) fail_msg("cannot load %s", name);
    fv_view_camera(v, s, 0.0, w, h, cam);
    fv_view_destroy(v);
    return s;
}

/* ---- rendering ---- */

typedef struct shot {
    fv_film *film;
    fv_stats stats;
} shot;

/* Frames 0 .. frames-1 of `method` with the parameters in `params` ("k=v k=v"), gaze at the
 * centre, seed 7, two threads: the last frame's film (colour, depth, albedo, position) and stats. */
static shot render_n(const char *method, const fv_scene *s, const fv_camera *cam, const char *params, int frames)
{
    shot r;
    fv_error err;
    fv_params *p = fv_test_params_str(params);
    fv_technique *t = NULL;
    fv_status st = fv_technique_create(method, s, p, NULL, &t, &err);
    if (st != FV_OK) fail_msg("%s %s: %s", method, params, err.msg);
    assert_int_equal(fv_film_create(cam->width, cam->height, FV_AUX_DEPTH | FV_AUX_ALBEDO | FV_AUX_POSITION, &r.film, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, cam);
    fr.seed = 7;
    fr.threads = 2;
    fv_test_render_frames(t, &fr, frames, r.film, &r.stats);
    assert_true(fv_stats_get_count(&r.stats, "nan_samples") == 0);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return r;
}

static shot render1(const char *method, const fv_scene *s, const fv_camera *cam, const char *params)
{
    return render_n(method, s, cam, params, 1);
}

static size_t npix(const shot *a) { return (size_t)fv_film_width(a->film) * fv_film_height(a->film); }

static const float *col(const shot *a) { return fv_film_color_const(a->film); }

/* The largest channel difference of pixel i between two shots. */
static float pix_diff(const shot *a, const shot *b, size_t i)
{
    const float *ca = col(a) + 3 * i, *cb = col(b) + 3 * i;
    return fmaxf(fabsf(ca[0] - cb[0]), fmaxf(fabsf(ca[1] - cb[1]), fabsf(ca[2] - cb[2])));
}

static double mean_abs_diff(const shot *a, const shot *b)
{
    double sum = 0.0;
    for (size_t i = 0; i < 3 * npix(a); i++) sum += fabs((double)col(a)[i] - col(b)[i]);
    return sum / (3.0 * (double)npix(a));
}

static double mean_colour(const shot *a)
{
    double sum = 0.0;
    for (size_t i = 0; i < 3 * npix(a); i++) sum += col(a)[i];
    return sum / (3.0 * (double)npix(a));
}

static void drop(shot *a) { fv_film_destroy(a->film); }

/* ======================================================================================== */
/* 1. Level sizes and block centres                                                          */
/* ======================================================================================== */

/* 37 x 23 samples, 3 levels: f = 4, 2, 1 and ceil(37/4) x ceil(23/4) = 10 x 6,
 * ceil(37/2) x ceil(23/2) = 19 x 12, 37 x 23. */
static void test_levels_odd(void **st)
{
    (void)st;
    fv_pyramid_level lv[3];
    fv_pyramid_levels(37, 23, 3, lv);
    assert_int_equal(lv[0].f, 4);
    assert_int_equal(lv[0].w, 10);
    assert_int_equal(lv[0].h, 6);
    assert_int_equal(lv[1].f, 2);
    assert_int_equal(lv[1].w, 19);
    assert_int_equal(lv[1].h, 12);
    assert_int_equal(lv[2].f, 1);
    assert_int_equal(lv[2].w, 37);
    assert_int_equal(lv[2].h, 23);
    /* one level: the target itself; 6 levels on 100 x 1: f = 32, ceil(100/32) = 4 x 1 */
    fv_pyramid_levels(37, 23, 1, lv);
    assert_int_equal(lv[0].f, 1);
    assert_int_equal(lv[0].w, 37);
    fv_pyramid_level six[FV_PYRAMID_MAX_LEVELS];
    fv_pyramid_levels(100, 1, 6, six);
    assert_int_equal(six[0].f, 32);
    assert_int_equal(six[0].w, 4);
    assert_int_equal(six[0].h, 1);

    fv_pyramid_levels(37, 23, 3, lv);
    float x, y;
    /* a whole block of the tip: (2, 1) covers samples [8, 12) x [4, 8), centre (10, 6) */
    fv_pyramid_centre(&lv[0], 37, 23, 2, 1, &x, &y);
    assert_float_equal(x, 10.0f, 0);
    assert_float_equal(y, 6.0f, 0);
    /* the tip's last block (9, 5) covers [36, 40) x [20, 24), clipped to [36, 37) x [20, 23):
     * centre (36.5, 21.5), not the unclipped (38, 22) */
    fv_pyramid_centre(&lv[0], 37, 23, 9, 5, &x, &y);
    assert_float_equal(x, 36.5f, 0);
    assert_float_equal(y, 21.5f, 0);
    /* the middle level's last block (18, 11): [36, 38) x [22, 24) clipped to [36, 37) x [22, 23) */
    fv_pyramid_centre(&lv[1], 37, 23, 18, 11, &x, &y);
    assert_float_equal(x, 36.5f, 0);
    assert_float_equal(y, 22.5f, 0);
    /* last column but a whole row: (18, 3) covers [36, 37) x [6, 8): (36.5, 7) */
    fv_pyramid_centre(&lv[1], 37, 23, 18, 3, &x, &y);
    assert_float_equal(x, 36.5f, 0);
    assert_float_equal(y, 7.0f, 0);
    /* the target: sample centres */
    fv_pyramid_centre(&lv[2], 37, 23, 36, 22, &x, &y);
    assert_float_equal(x, 36.5f, 0);
    assert_float_equal(y, 22.5f, 0);
}

/* ======================================================================================== */
/* 2. The start of a ray: the 3x3 minimum one level down                                      */
/* ======================================================================================== */

/* A 4 x 3 parent level:
 *      x=0  1    2    3
 *   y=0  5  6    9    2
 *   y=1  7  8    4    inf
 *   y=2  1  inf  3    10
 * (0, 0) sees {5, 6, 7, 8}: 5 (the 1 at (0, 2) and the 2 at (3, 0) are out of its reach);
 * (1, 1) sees the whole left 3 x 3: 1; (3, 1) sees {9, 2, 4, inf, 3, 10}: 2;
 * (3, 2) sees {4, inf, 3, 10}: 3; (1, 0) sees {5, 6, 9, 7, 8, 4}: 4. */
static void test_start_min_filter(void **st)
{
    (void)st;
    const float I = INFINITY;
    const float d[12] = {5, 6, 9, 2, 7, 8, 4, I, 1, I, 3, 10};
    fv_pyramid_level p = {4, 3, 2};
    assert_float_equal(fv_pyramid_start(d, &p, 0, 0, true), 5.0f, 0);
    assert_float_equal(fv_pyramid_start(d, &p, 1, 1, true), 1.0f, 0);
    assert_float_equal(fv_pyramid_start(d, &p, 3, 1, true), 2.0f, 0);
    assert_float_equal(fv_pyramid_start(d, &p, 3, 2, true), 3.0f, 0);
    assert_float_equal(fv_pyramid_start(d, &p, 1, 0, true), 4.0f, 0);
    /* without the filter: the parent's own depth, a miss included */
    assert_float_equal(fv_pyramid_start(d, &p, 0, 0, false), 5.0f, 0);
    assert_float_equal(fv_pyramid_start(d, &p, 1, 1, false), 8.0f, 0);
    assert_true(isinf(fv_pyramid_start(d, &p, 3, 1, false)));
    assert_true(isinf(fv_pyramid_start(d, &p, 1, 2, false)));
    /* a hit anywhere in the neighbourhood wins over misses; all misses give +inf */
    assert_float_equal(fv_pyramid_start(d, &p, 1, 2, true), 1.0f, 0);
    const float none[4] = {I, I, I, I};
    fv_pyramid_level q = {2, 2, 2};
    float s = fv_pyramid_start(none, &q, 1, 1, true);
    assert_true(isinf(s) && s > 0.0f);
    /* one row: (0, 0) of {3, 1, 2} sees {3, 1} */
    const float row[3] = {3, 1, 2};
    fv_pyramid_level r = {3, 1, 2};
    assert_float_equal(fv_pyramid_start(row, &r, 0, 0, true), 1.0f, 0);
    assert_float_equal(fv_pyramid_start(row, &r, 2, 0, true), 1.0f, 0);
}

/* ======================================================================================== */
/* 3. Sobel edges on the tip's depth                                                          */
/* ======================================================================================== */

static int count_edges(const uint8_t *e, size_t n)
{
    int c = 0;
    for (size_t i = 0; i < n; i++) c += e[i];
    return c;
}

static void test_sobel(void **st)
{
    (void)st;
    enum { W = 8, H = 6 };
    float d[W * H];
    uint8_t e[W * H];

    /* A step: depth 1 for x < 4, 3 from x = 4. At x = 3 and x = 4 the horizontal kernel spans
     * the step: gx = (3 + 2*3 + 3) - (1 + 2*1 + 1) = 8, gy = 0, above 0.25 x 1 and 0.25 x 3: both
     * sides are edges. Elsewhere (borders clamped) every difference is 0: no edge. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) d[y * W + x] = x < 4 ? 1.0f : 3.0f;
    fv_pyramid_sobel(d, W, H, 0.25f, e);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int want = x == 3 || x == 4;
            if (e[y * W + x] != want) fail_msg("step: edge(%d, %d) = %d, expected %d", x, y, e[y * W + x], want);
        }
    /* The threshold is relative: 8 > t x 3 needs t < 8/3; at t = 2.7 only the near side (1)
     * remains an edge, at t = 8.1 neither. */
    fv_pyramid_sobel(d, W, H, 2.7f, e);
    for (int y = 0; y < H; y++) {
        assert_int_equal(e[y * W + 3], 1);
        assert_int_equal(e[y * W + 4], 0);
    }
    fv_pyramid_sobel(d, W, H, 8.1f, e);
    assert_int_equal(count_edges(e, W * H), 0);

    /* A receding plane, depth 100 + 2y: gy = 4 (D(y+1) - D(y-1)) = 16 inside (8 on the clamped
     * borders), under 0.25 x 100 = 25: no edge, though an absolute threshold of 0.25 would
     * flag every pixel. A steeper one, 100 + 4y, reaches 32 > 0.25 x 112 = 28 in rows 1 .. 4. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) d[y * W + x] = 100.0f + 2.0f * (float)y;
    fv_pyramid_sobel(d, W, H, 0.25f, e);
    assert_int_equal(count_edges(e, W * H), 0);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) d[y * W + x] = 100.0f + 4.0f * (float)y;
    fv_pyramid_sobel(d, W, H, 0.25f, e);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) assert_int_equal(e[y * W + x], y >= 1 && y <= 4);

    /* A miss (+inf) next to a hit: the sky counts as twice the farthest depth, 2 x 5 = 10.
     * Depth 5 for y < 3, a miss from y = 3: gy = 4 x (10 - 5) = 20 at rows 2 and 3, above
     * 0.25 x 5 and 0.25 x 10: both are edges; the rows beyond are flat. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) d[y * W + x] = y < 3 ? 5.0f : INFINITY;
    fv_pyramid_sobel(d, W, H, 0.25f, e);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) assert_int_equal(e[y * W + x], y == 2 || y == 3);
    /* All misses: no edge (and no NaN from inf - inf). */
    for (int i = 0; i < W * H; i++) d[i] = INFINITY;
    fv_pyramid_sobel(d, W, H, 0.25f, e);
    assert_int_equal(count_edges(e, W * H), 0);
    /* One hit alone in the sky at (2, 2): it and its eight neighbours are edges, nothing else. */
    d[2 * W + 2] = 4.0f;
    fv_pyramid_sobel(d, W, H, 0.25f, e);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int want = abs(x - 2) <= 1 && abs(y - 2) <= 1;
            /* the centre: gx = gy = 0 by symmetry, so not an edge after all */
            if (x == 2 && y == 2) want = 0;
            if (e[y * W + x] != want) fail_msg("single hit: edge(%d, %d) = %d, expected %d", x, y, e[y * W + x], want);
        }
}

/* ======================================================================================== */
/* 4. The mask probability (Sec. 3.2.3, Eq. 1)                                               */
/* ======================================================================================== */

static void test_probability(void **st)
{
    (void)st;
    /* inside the fovea (7.5), its border included, edge or not */
    assert_float_equal(fv_pyramid_probability(0.0, 7.5, 30.0, false), 1.0, 0);
    assert_float_equal(fv_pyramid_probability(7.5, 7.5, 30.0, false), 1.0, 0);
    assert_float_equal(fv_pyramid_probability(3.0, 7.5, 30.0, true), 1.0, 0);
    /* beyond outer_deg: 0, even on an edge */
    assert_float_equal(fv_pyramid_probability(30.5, 7.5, 30.0, false), 0.0, 0);
    assert_float_equal(fv_pyramid_probability(45.0, 7.5, 30.0, true), 0.0, 0);
    /* an edge between the two: 1 */
    assert_float_equal(fv_pyramid_probability(20.0, 7.5, 30.0, true), 1.0, 0);
    /* Eq. 1: p(10) = 0.90964 e^(-10 / 2.9661) + 0.00792 = 0.90964 e^-3.3714305 + 0.00792
     *             = 0.90964 x 0.0343405 + 0.00792 = 0.0312375 + 0.00792 = 0.0391575;
     * p(20) = 0.90964 e^-6.742861 + 0.00792 = 0.90964 x 0.00117927 + 0.00792 = 0.0089927;
     * p(30) (still inside outer_deg) = 0.90964 x 4.04966e-5 + 0.00792 = 0.0079568. */
    assert_float_equal(fv_pyramid_probability(10.0, 7.5, 30.0, false), 0.0391575, 1e-6);
    assert_float_equal(fv_pyramid_probability(20.0, 7.5, 30.0, false), 0.0089927, 1e-6);
    assert_float_equal(fv_pyramid_probability(30.0, 7.5, 30.0, false), 0.0079568, 1e-6);
    /* falling with eccentricity, never below the floor 0.00792 */
    double prev = 1.0;
    for (double w = 7.6; w <= 30.0; w += 0.1) {
        double p = fv_pyramid_probability(w, 7.5, 30.0, false);
        assert_true(p < prev && p > 0.00792);
        prev = p;
    }
    /* a small fovea: just past 1 deg, 0.90964 e^(-1.01 / 2.9661) + 0.00792 = 0.90964 e^-0.3405145
     * + 0.00792 = 0.90964 x 0.7114042 + 0.00792 = 0.6471217 + 0.00792 = 0.6550417 */
    assert_float_equal(fv_pyramid_probability(1.01, 1.0, 30.0, false), 0.6550417, 1e-6);
}

/* ======================================================================================== */
/* 5. The tracer                                                                             */
/* ======================================================================================== */

/* A unit sphere at c = (1, 2, -3) alone, with a light so the scene commits. */
static fv_scene *sphere_world(fv_sdf_world *w)
{
    fv_scene *s = new_scene();
    int red = diffuse(s, "red", fv_v3(0.8f, 0.2f, 0.2f));
    add_sphere(s, "ball", fv_v3(1, 2, -3), 1.0f, red);
    add_point_light(s, fv_v3(0, 10, 0), 10.0f);
    commit(s);
    fv_error err;
    assert_int_equal(fv_sdf_world_build(w, s, &err), FV_OK);
    return s;
}

static fv_march_ray ray_at(const fv_sdf_world *w, fv_vec3 o, fv_vec3 d, float eps_k)
{
    fv_march_ray r;
    r.o = o;
    r.d = fv_normalize(d);
    if (!fv_sdf_world_clip(w, r.o, r.d, &r.t0, &r.t1)) r.t0 = 1.0f, r.t1 = 0.0f;
    r.eps = w->eps_abs;
    r.eps_k = eps_k;
    return r;
}

static void test_march_sphere(void **st)
{
    (void)st;
    fv_sdf_world w;
    fv_scene *s = sphere_world(&w);
    const fv_vec3 c = fv_v3(1, 2, -3);
    const float eps_k = 1e-3f;
    fv_march_opts plain = {256, 1.0f, false};
    for (int wide = 0; wide < 2; wide++) {
        plain.wide = wide;
        /* Straight at the centre from D = 7 along a skew direction: the surface is at t = D - 1 = 6;
         * the hit lies within the hit distance max(eps, eps_k t) = 6e-3 in front of it. */
        fv_vec3 dir = fv_normalize(fv_v3(2, -3, 6));
        fv_vec3 o = fv_madd(c, dir, -7.0f);
        fv_march_ray r = ray_at(&w, o, dir, eps_k);
        assert_true(r.t0 > 0.0f && r.t0 < 6.0f); /* the box around the sphere starts before it */
        fv_march_hit h;
        fv_march(&w, &plain, &r, &h, 1, false);
        assert_int_equal(h.hit, 1);
        assert_int_equal(h.exhausted, 0);
        assert_true(h.t <= 6.0f + 1e-5f && h.t >= 6.0f - 6e-3f);
        assert_true(h.steps >= 1 && h.steps <= 2); /* the box's entry, then the surface */
        /* From t0 = 0 (no box): the first distance is D - 1 = 6, one step lands on the surface,
         * whose distance (0, to rounding) ends the march: two evaluations. */
        r.t0 = 0.0f;
        fv_march(&w, &plain, &r, &h, 1, false);
        assert_int_equal(h.hit, 1);
        assert_true(h.t <= 6.0f + 1e-5f && h.t >= 6.0f - 6e-3f);
        assert_int_equal(h.steps, 2);
        /* A ray passing 0.2 beside the sphere (its closest approach 1.2 from the centre) misses,
         * as does one starting past its end. */
        fv_vec3 side = fv_normalize(fv_cross(dir, fv_v3(0, 1, 0)));
        r = ray_at(&w, fv_madd(o, side, 1.2f), dir, eps_k);
        fv_march(&w, &plain, &r, &h, 1, false);
        assert_int_equal(h.hit, 0);
        assert_true(isinf(h.t));
        /* ... while 0.9 beside the axis hits where (0.9^2 + z^2 = 1): t = 7 - sqrt(0.19) = 6.56411 */
        r = ray_at(&w, fv_madd(o, side, 0.9f), dir, eps_k);
        fv_march(&w, &plain, &r, &h, 1, false);
        assert_int_equal(h.hit, 1);
        assert_true(h.t <= 6.56411f + 1e-4f && h.t >= 6.56411f - 2e-2f);
        r.t0 = 2.0f, r.t1 = 1.0f;
        fv_march(&w, &plain, &r, &h, 1, false);
        assert_int_equal(h.hit, 0);
        assert_int_equal(h.steps, 0);
        /* max_steps = 1 from t0 = 0: still marching after one evaluation. A camera ray counts it
         * as a hit where it stands (t = 6 after one step), a shadow ray as not blocked. */
        fv_march_opts one = plain;
        one.max_steps = 1;
        r = ray_at(&w, o, dir, eps_k);
        r.t0 = 0.0f;
        fv_march(&w, &one, &r, &h, 1, false);
        assert_int_equal(h.hit, 1);
        assert_int_equal(h.exhausted, 1);
        assert_int_equal(h.steps, 1);
        assert_float_equal(h.t, 6.0f, 1e-5);
        fv_march(&w, &one, &r, &h, 1, true);
        assert_int_equal(h.hit, 0);
        assert_int_equal(h.exhausted, 1);
        /* Over-relaxed from t0 = 0: the step 1.6 x 6 = 9.6 would leave the box around the sphere
         * (t1 = 8 and a little), where no later point checks it, so the tracer takes the plain
         * step instead: two evaluations. Without the box (t1 = inf) it lands 2.6 past the centre,
         * 1.6 outside the far side; the unbounding spheres (radii 6 and 1.6) do not cover a step
         * of 9.6, so the ray returns to the plain step, t = 6, and hits there: three. */
        fv_march_opts relaxed = plain;
        relaxed.relax = 1.6f;
        fv_march(&w, &relaxed, &r, &h, 1, false);
        assert_int_equal(h.hit, 1);
        assert_true(h.t <= 6.0f + 1e-5f && h.t >= 6.0f - 6e-3f);
        assert_int_equal(h.steps, 2);
        r.t1 = INFINITY;
        fv_march(&w, &relaxed, &r, &h, 1, false);
        assert_int_equal(h.hit, 1);
        assert_true(h.t <= 6.0f + 1e-5f && h.t >= 6.0f - 6e-3f);
        assert_int_equal(h.steps, 3);
        /* A start inside the sphere (t0 = 6.5, as a pyramid start behind a surface can be): the
         * field there is -0.5, and stepping back by it reaches the surface at t = 6, where the
         * ray hits, instead of taking the point inside for a hit. A shadow ray starting inside
         * is blocked at once. */
        for (int k = 0; k < 2; k++) {
            r = ray_at(&w, o, dir, eps_k);
            r.t0 = 6.5f;
            fv_march(&w, k ? &relaxed : &plain, &r, &h, 1, false);
            assert_int_equal(h.hit, 1);
            assert_true(h.t <= 6.0f + 1e-5f && h.t >= 6.0f - 6e-3f);
            assert_true(h.steps == 2);
            fv_march(&w, k ? &relaxed : &plain, &r, &h, 1, true);
            assert_int_equal(h.hit, 1);
            assert_int_equal(h.steps, 1);
            assert_float_equal(h.t, 6.5f, 0);
        }
    }
    fv_sdf_world_free(&w);
    fv_scene_destroy(s);
}

/* Camera rays of sdf-columns through random film positions, as the pipeline builds them. */
static int columns_rays(fv_sdf_world *w, fv_scene **s, fv_march_ray *rays, int n)
{
    fv_camera cam;
    *s = load("sdf-columns", 64, 48, &cam);
    fv_error err;
    assert_int_equal(fv_sdf_world_build(w, *s, &err), FV_OK);
    fv_camera_basis b;
    assert_int_equal(fv_camera_basis_make(&cam, &b, &err), FV_OK);
    fv_rng rng = fv_rng_stream(11, FV_STREAM_CAMERA, 0, 0, 0);
    const float eps_k = 0.25f * 2.0f * b.tan_half_x / 64.0f;
    for (int i = 0; i < n; i++) rays[i] = ray_at(w, b.pos, fv_camera_dir(&b, 64.0f * fv_rng_next(&rng), 48.0f * fv_rng_next(&rng)), eps_k);
    return n;
}

static bool same_hit(const fv_march_hit *a, const fv_march_hit *b)
{
    return memcmp(&a->t, &b->t, sizeof a->t) == 0 && a->steps == b->steps && a->hit == b->hit && a->exhausted == b->exhausted &&
           (!a->hit || a->mat == b->mat);
}

/* Over a few thousand camera rays of sdf-columns: the 8-lane and the scalar tracer agree bit for
 * bit, plain, relaxed, and as shadow rays (any_hit); and neither the plain nor the relaxed (1.6)
 * march ever goes through a surface: where a fine march (hit distance 1e-5 of the scene, no
 * footprint term) finds the first surface at t*, both stop at most a hit distance behind it
 * (t <= t* + their hit distance there), and a ray with a surface never leaves as a miss. (Both
 * may stop well before t*, where a grazing ray runs within the footprint-sized hit distance of a
 * surface, and then not at the same point: only the far side is a tracer's fault.) */
static void test_march_relaxed_and_wide(void **st)
{
    (void)st;
    enum { N = 3001 }; /* not a multiple of 8: the last batch runs part-empty */
    fv_march_ray *rays = malloc(N * sizeof *rays), *fine = malloc(N * sizeof *fine);
    fv_march_hit *a = malloc(N * sizeof *a), *b = malloc(N * sizeof *b), *c = malloc(N * sizeof *c), *t = malloc(N * sizeof *t);
    assert_non_null(rays);
    assert_non_null(fine);
    assert_non_null(a);
    assert_non_null(b);
    assert_non_null(c);
    assert_non_null(t);
    fv_sdf_world w;
    fv_scene *s;
    columns_rays(&w, &s, rays, N);
    fv_march_opts plain = {256, 1.0f, true}, relaxed = {256, 1.6f, true}, exact = {65535, 1.0f, true};
    for (int i = 0; i < N; i++) {
        fine[i] = rays[i];
        fine[i].eps_k = 0.0f;
    }
    fv_march(&w, &exact, fine, t, N, false);
    fv_march(&w, &plain, rays, a, N, false);
    fv_march(&w, &relaxed, rays, b, N, false);
    int hits = 0;
    uint64_t sp = 0, sr = 0;
    for (int i = 0; i < N; i++) {
        sp += a[i].steps;
        sr += b[i].steps;
        if (!t[i].hit) continue;
        assert_int_equal(t[i].exhausted, 0);
        hits++;
        const fv_march_hit *m[2] = {&a[i], &b[i]};
        for (int k = 0; k < 2; k++) {
            float eps = fmaxf(rays[i].eps, rays[i].eps_k * t[i].t);
            if (!m[k]->hit || m[k]->t > t[i].t + eps)
                fail_msg("ray %d: the first surface is at t = %g, the %s march %s at t = %g after %d steps", i, t[i].t,
                         k ? "relaxed" : "plain", m[k]->hit ? "stops" : "leaves", m[k]->t, m[k]->steps);
        }
    }
    print_message("sdf-columns, %d rays: %d meet a surface; steps plain %llu, relaxed %llu\n", N, hits, (unsigned long long)sp,
                  (unsigned long long)sr);
    assert_true(hits > N / 2); /* an enclosed room: most rays hit */
    assert_true(sr < sp);      /* relaxing pays, a little, at this footprint */

    const fv_march_opts *opts[2] = {&plain, &relaxed};
    for (int k = 0; k < 2; k++) {
        fv_march_opts o = *opts[k];
        for (int any = 0; any < 2; any++) {
            o.wide = true;
            fv_march(&w, &o, rays, b, N, any);
            o.wide = false;
            fv_march(&w, &o, rays, c, N, any);
            for (int i = 0; i < N; i++)
                if (!same_hit(&b[i], &c[i]))
                    fail_msg("relax %g any_hit %d ray %d: wide t=%a steps=%d hit=%d mat=%d, scalar t=%a steps=%d hit=%d mat=%d", o.relax,
                             any, i, b[i].t, b[i].steps, b[i].hit, b[i].mat, c[i].t, c[i].steps, c[i].hit, c[i].mat);
        }
    }
    /* the result of a ray does not depend on its batch: the rays one by one */
    for (int i = 0; i < N; i += 97) {
        fv_march_hit one;
        fv_march(&w, &plain, &rays[i], &one, 1, false);
        assert_true(same_hit(&one, &a[i]));
    }
    fv_sdf_world_free(&w);
    fv_scene_destroy(s);
    free(rays);
    free(fine);
    free(a);
    free(b);
    free(c);
    free(t);
}

/* ======================================================================================== */
/* 6. Images: simd, super-sampling                                                           */
/* ======================================================================================== */

static const char *const k_methods[4] = {"sdf-gt", "sdf-relaxed", "ipr", "fipr"};

/* Every method, simd=true and simd=false: the same colour bit for bit on sdf-temple. */
static void test_simd_identical(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-temple", 96, 80, &cam);
    for (int m = 0; m < 4; m++) {
        shot a = render1(k_methods[m], s, &cam, "simd=true"), b = render1(k_methods[m], s, &cam, "simd=false");
        if (memcmp(col(&a), col(&b), 3 * npix(&a) * sizeof(float)) != 0) fail_msg("%s: simd=true and simd=false differ", k_methods[m]);
        assert_true(mean_colour(&a) > 0.01);
        assert_true(fv_stats_get_count(&a.stats, "steps") == fv_stats_get_count(&b.stats, "steps"));
        drop(&a);
        drop(&b);
    }
    fv_scene_destroy(s);
}

/* The largest channel difference of pixel (x, y) from its eight neighbours in one image: 0 in a
 * flat region, large across an edge (silhouette, shadow, material). */
static float local_contrast(const shot *a, int x, int y)
{
    const int w = fv_film_width(a->film), h = fv_film_height(a->film);
    float m = 0.0f;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            int u = x + dx, v = y + dy;
            if (u < 0 || v < 0 || u >= w || v >= h) continue;
            const float *p = col(a) + 3 * ((size_t)y * w + x), *q = col(a) + 3 * ((size_t)v * w + u);
            m = fmaxf(m, fmaxf(fabsf(p[0] - q[0]), fmaxf(fabsf(p[1] - q[1]), fabsf(p[2] - q[2]))));
        }
    return m;
}

/* spp 4 and 16 (2x2 and 4x4 sub-pixel grids) against spp 1 (the pixel centre): they differ, but
 * only where the image has an edge. In flat regions (every neighbour of the 1-spp pixel within
 * 0.02) the super-sampled value stays within 0.02 too, but for 1% of them (measured: at most 15
 * of 4150, none beyond 0.03), and the mean difference is small but not zero. */
static void test_spp_edges(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-temple", 96, 80, &cam);
    const char *meth[2] = {"sdf-gt", "ipr"};
    for (int m = 0; m < 2; m++) {
        shot one = render1(meth[m], s, &cam, "spp=1");
        const char *spp[2] = {"spp=4", "spp=16"};
        for (int k = 0; k < 2; k++) {
            shot ss = render1(meth[m], s, &cam, spp[k]);
            assert_true(fv_stats_get_count(&ss.stats, "samples") == (k == 0 ? 4.0 : 16.0) * 96 * 80);
            double mad = mean_abs_diff(&one, &ss);
            int flat = 0, flat_bad = 0, changed = 0;
            double flat_max = 0.0;
            for (int y = 0; y < 80; y++)
                for (int x = 0; x < 96; x++) {
                    size_t i = (size_t)y * 96 + x;
                    float d = pix_diff(&one, &ss, i);
                    changed += d > 0.02f;
                    if (local_contrast(&one, x, y) > 0.02f) continue;
                    flat++;
                    flat_max = fmax(flat_max, d);
                    flat_bad += d > 0.02f;
                }
            print_message("%s %s vs spp=1: mean abs diff %.5f; %d pixels changed > 0.02; %d flat pixels, max diff %.4f, %d over 0.02\n",
                          meth[m], spp[k], mad, changed, flat, flat_max, flat_bad);
            assert_true(mad > 1e-4 && mad < 0.02);
            assert_true(changed > 0);
            assert_true(flat > 96 * 80 / 4);
            assert_true(flat_bad <= flat / 100 && flat_max < 0.06);
            drop(&ss);
        }
        drop(&one);
    }
    fv_scene_destroy(s);
}

/* ======================================================================================== */
/* 7. Thin objects and the min filter                                                         */
/* ======================================================================================== */

#define THIN_W 128
#define THIN_H 96

/* A grey ground under a fence of red capsules of radius 0.02, about a third of a pixel's
 * footprint where they stand (2 tan 20deg x 8 / 96 = 0.061 per pixel at distance 8): some tilted,
 * some lying, so they cross the tip's rays at every phase. */
static fv_scene *thin_scene(fv_camera *cam)
{
    fv_scene *s = new_scene();
    int grey = diffuse(s, "grey", fv_v3s(0.5f));
    int red = diffuse(s, "thin", fv_v3(0.9f, 0.05f, 0.05f));
    add_ground(s, 20.0f, grey);
    char name[32];
    for (int i = 0; i < 9; i++) {
        fv_sdf_node n = leaf(FV_SDF_CAPSULE, red);
        float x = -3.0f + 0.75f * (float)i, z = -0.5f * (float)(i % 3);
        n.v[0] = fv_v3(0, 0, 0);
        n.v[1] = i % 3 == 2 ? fv_v3(1.5f, 0.3f, 0.0f) : fv_v3(0.4f * (float)(i % 3) - 0.2f, 2.0f, 0.0f);
        n.p[0] = 0.02f;
        snprintf(name, sizeof name, "thin%d", i);
        add_placed(s, name, n, fv_v3(x, 0.02f, z));
    }
    add_point_light(s, fv_v3(2, 6, 5), 60.0f);
    commit(s);
    *cam = (fv_camera){{0, 1.5f, 8}, {0, 0.8f, 0}, {0, 1, 0}, 40.0f, THIN_W, THIN_H};
    return s;
}

static bool is_thin(const shot *a, size_t i)
{
    const float *al = fv_film_aux_const(a->film, FV_AUX_ALBEDO);
    return al[3 * i] > 0.85f && al[3 * i + 1] < 0.1f;
}

/* Pixels where sdf-gt sees a thin capsule: the share of them ipr loses (it sees the ground or
 * another capsule farther back: not the same red surface at the same depth), with and without
 * the min filter. The filter must lose fewer, and without it some must be lost, else the scene
 * would not test the filter. */
static void test_thin_min_filter(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = thin_scene(&cam);
    shot gt = render1("sdf-gt", s, &cam, "");
    shot with = render1("ipr", s, &cam, "min_filter=true"), without = render1("ipr", s, &cam, "min_filter=false");
    const float *dg = fv_film_aux_const(gt.film, FV_AUX_DEPTH), *dw = fv_film_aux_const(with.film, FV_AUX_DEPTH),
                *dn = fv_film_aux_const(without.film, FV_AUX_DEPTH);
    int thin = 0, lost_with = 0, lost_without = 0;
    for (size_t i = 0; i < npix(&gt); i++) {
        if (!is_thin(&gt, i)) continue;
        thin++;
        lost_with += !is_thin(&with, i) || !(fabsf(dw[i] - dg[i]) < 0.01f * dg[i]);
        lost_without += !is_thin(&without, i) || !(fabsf(dn[i] - dg[i]) < 0.01f * dg[i]);
    }
    double share_with = (double)lost_with / thin, share_without = (double)lost_without / thin;
    print_message("thin capsules: %d pixels in sdf-gt; ipr loses %d (%.1f%%) with the min filter, %d (%.1f%%) without\n", thin, lost_with,
                  100.0 * share_with, lost_without, 100.0 * share_without);
    assert_true(thin > 100);
    assert_true(lost_without > 0);
    assert_true(share_with < share_without);
    drop(&gt);
    drop(&with);
    drop(&without);
    fv_scene_destroy(s);
}

/* ======================================================================================== */
/* 8. ipr against sdf-gt                                                                     */
/* ======================================================================================== */

/* Pixels of ipr whose first hit lies inside a solid (the field there below minus the hit
 * distance 0.25 x footprint x depth): a ray started behind a surface and took the inside for a hit. */
static int hits_inside(const fv_scene *s, const fv_camera *cam, const shot *a)
{
    fv_sdf_world w;
    fv_error err;
    assert_int_equal(fv_sdf_world_build(&w, s, &err), FV_OK);
    fv_camera_basis b;
    assert_int_equal(fv_camera_basis_make(cam, &b, &err), FV_OK);
    const float foot = 2.0f * b.tan_half_x / (float)cam->width;
    const float *d = fv_film_aux_const(a->film, FV_AUX_DEPTH), *p = fv_film_aux_const(a->film, FV_AUX_POSITION);
    int inside = 0;
    for (size_t i = 0; i < npix(a); i++)
        if (isfinite(d[i])) inside += fv_sdf_world_eval1(&w, p[3 * i], p[3 * i + 1], p[3 * i + 2], NULL) < -0.25f * foot * d[i];
    fv_sdf_world_free(&w);
    return inside;
}

/* ipr against sdf-gt on sdf-primitives at 160x128. Both stop anywhere in the hit shell (up to
 * hit x footprint x t in front of the surface), from different starts, and the normal's
 * tetrahedron and the shadow ray's origin move with the stop: curved surfaces differ by about
 * 1e-3 at the default hit = 0.25, far less at hit = 0.05. So: at hit = 0.05 more than 99% of the
 * pixels within 1e-3; at the default more than 99% within 1e-2 and a mean difference under 1e-3;
 * no ipr hit inside a solid. Steps: the open scene's grazing checkerboard keeps the target rays
 * busy (measured 0.79 of sdf-gt's camera-ray steps), sdf-temple's terrain pays more (0.42). */
static void test_ipr_vs_gt(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-primitives", 160, 128, &cam);
    shot gt = render1("sdf-gt", s, &cam, ""), ip = render1("ipr", s, &cam, "");
    shot gt5 = render1("sdf-gt", s, &cam, "hit=0.05"), ip5 = render1("ipr", s, &cam, "hit=0.05");
    int close2 = 0, close3 = 0;
    for (size_t i = 0; i < npix(&gt); i++) {
        close2 += pix_diff(&gt, &ip, i) <= 1e-2f;
        close3 += pix_diff(&gt5, &ip5, i) <= 1e-3f;
    }
    double sg = fv_stats_get_count(&gt.stats, "steps"), si = fv_stats_get_count(&ip.stats, "steps");
    double mad = mean_abs_diff(&gt, &ip), mad5 = mean_abs_diff(&gt5, &ip5);
    int inside = hits_inside(s, &cam, &ip);
    print_message("sdf-primitives 160x128: ipr within 1e-2 of sdf-gt at %.2f%% of pixels (mean abs diff %.2e); at hit=0.05 within "
                  "1e-3 at %.2f%% (%.2e); %d hits inside a solid; steps %.0f vs %.0f (%.3f)\n",
                  100.0 * close2 / (double)npix(&gt), mad, 100.0 * close3 / (double)npix(&gt), mad5, inside, si, sg, si / sg);
    assert_true(close2 > 0.99 * (double)npix(&gt));
    assert_true(close3 > 0.99 * (double)npix(&gt));
    assert_true(mad < 1e-3 && mad5 < 2e-4);
    assert_int_equal(inside, 0);
    assert_true(si < 0.85 * sg);
    /* The hit distance moves hits by a fraction of a pixel, never the image: sdf-gt's mean at
     * hit = 0.25 and 0.05 within 3% (a field whose bound collapses away from the surface, as the
     * repeated checkerboard's did along its cells' borders, stops rays on phantom walls at the
     * larger hit distance and darkens the image by half). */
    print_message("sdf-gt mean %.5f at hit=0.25, %.5f at hit=0.05\n", mean_colour(&gt), mean_colour(&gt5));
    assert_true(fabs(mean_colour(&gt) - mean_colour(&gt5)) < 0.03 * mean_colour(&gt5));
    /* the counters add up: steps over the levels, rays 1/16 + 1/4 + 1 of the samples */
    assert_true(fv_stats_get_count(&ip.stats, "steps_level0") + fv_stats_get_count(&ip.stats, "steps_level1") +
                    fv_stats_get_count(&ip.stats, "steps_level2") == si);
    assert_true(fv_stats_get_count(&ip.stats, "rays_level0") == 40 * 32);
    assert_true(fv_stats_get_count(&ip.stats, "rays_level1") == 80 * 64);
    assert_true(fv_stats_get_count(&ip.stats, "rays_level2") == 160 * 128);
    assert_true(fv_stats_get_count(&gt.stats, "rays_level0") == 160 * 128);
    /* levels=1 is sdf-gt */
    shot one = render1("ipr", s, &cam, "levels=1");
    assert_memory_equal(col(&one), col(&gt), 3 * npix(&gt) * sizeof(float));
    drop(&one);
    drop(&gt);
    drop(&ip);
    drop(&gt5);
    drop(&ip5);
    fv_scene_destroy(s);

    s = load("sdf-temple", 160, 128, &cam);
    gt = render1("sdf-gt", s, &cam, "");
    ip = render1("ipr", s, &cam, "");
    sg = fv_stats_get_count(&gt.stats, "steps");
    si = fv_stats_get_count(&ip.stats, "steps");
    inside = hits_inside(s, &cam, &ip);
    print_message("sdf-temple 160x128: steps %.0f vs %.0f (%.3f), mean abs diff %.2e, %d hits inside a solid\n", si, sg, si / sg,
                  mean_abs_diff(&gt, &ip), inside);
    assert_true(si < 0.6 * sg);
    assert_true(mean_abs_diff(&gt, &ip) < 1e-3);
    assert_int_equal(inside, 0);
    drop(&gt);
    drop(&ip);
    fv_scene_destroy(s);
}

/* ======================================================================================== */
/* 9. fipr: mask, counters, refresh, fovea                                                   */
/* ======================================================================================== */

#define FW 90
#define FH 70

static void test_fipr_mask(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-primitives", FW, FH, &cam);
    shot mask = render1("fipr", s, &cam, "show=mask");
    fv_eye_model eye;
    fv_eye_model_default(FW, FH, &eye);
    const fv_gaze g = {0.5f, 0.5f};
    int white = 0, inner = 0, outer = 0, between = 0, between_white = 0;
    for (int y = 0; y < FH; y++)
        for (int x = 0; x < FW; x++) {
            const float *c = col(&mask) + 3 * ((size_t)y * FW + x);
            assert_true((c[0] == 0.0f || c[0] == 1.0f) && c[1] == c[0] && c[2] == c[0]);
            white += c[0] == 1.0f;
            double e = fv_eye_eccentricity_deg(&eye, g, x, y);
            if (e <= 7.5) {
                inner++;
                if (c[0] != 1.0f) fail_msg("pixel (%d, %d) at %.2f deg, inside the fovea, is not in the mask", x, y, e);
            } else if (e > 30.0) {
                outer++;
                if (c[0] != 0.0f) fail_msg("pixel (%d, %d) at %.2f deg, beyond outer_deg, is in the mask", x, y, e);
            } else {
                between++;
                between_white += c[0] == 1.0f;
            }
        }
    print_message("fipr mask %dx%d: %d white; %d pixels in the fovea, %d between (%d white), %d beyond\n", FW, FH, white, inner,
                  between, between_white, outer);
    assert_true(inner > 20 && outer > 100 && between > 100);
    assert_true(between_white > 0 && between_white < between); /* edges and the random share */
    assert_true(fv_stats_get_count(&mask.stats, "mask_pixels") == white);
    drop(&mask);
    fv_scene_destroy(s);
}

/* refresh=4: frame 0 shades every middle-level ray (there is no history yet), frame f > 0 those
 * of phase f mod 4, a 2x2 interleave (u & 1) + 2 (v & 1). At 90 x 70 the middle level is 45 x 35
 * (u: 23 even, 22 odd; v: 18 even, 17 odd): frame 1 (u odd, v even) 22 x 18 = 396, frame 2
 * (u even, v odd) 23 x 17 = 391, frame 3 (both odd) 22 x 17 = 374, frame 4 (both even)
 * 23 x 18 = 414; the four sum to 45 x 35 = 1575. refresh=2: checkerboards of 788 and 787. */
static void test_fipr_refresh(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-primitives", FW, FH, &cam);
    const double want4[5] = {1575, 396, 391, 374, 414}, want2[3] = {1575, 787, 788};
    for (int f = 0; f < 5; f++) {
        shot a = render_n("fipr", s, &cam, "refresh=4", f + 1);
        double got = fv_stats_get_count(&a.stats, "refreshed_pixels");
        if (got != want4[f]) fail_msg("refresh=4 frame %d: %g middle-level rays refreshed, expected %g", f, got, want4[f]);
        assert_true(fv_stats_get_count(&a.stats, "rays_level1") <= 1575);
        drop(&a);
    }
    for (int f = 0; f < 3; f++) {
        shot a = render_n("fipr", s, &cam, "refresh=2", f + 1);
        double got = fv_stats_get_count(&a.stats, "refreshed_pixels");
        if (got != want2[f]) fail_msg("refresh=2 frame %d: %g refreshed, expected %g", f, got, want2[f]);
        drop(&a);
    }
    /* refresh=1: every frame all of them */
    shot a = render_n("fipr", s, &cam, "refresh=1", 2);
    assert_true(fv_stats_get_count(&a.stats, "refreshed_pixels") == 1575);
    drop(&a);
    fv_scene_destroy(s);
}

/* The mask's pixels are traced as ipr traces them (the same middle-level depths through the min
 * filter, the same target rays): bit-identical to ipr there. In the fovea (half a degree inside
 * fovea_deg), which here holds the glossy torus, they are within 1e-2 of sdf-gt, and within 1e-3
 * at 90% of the pixels (hit = 0.05 for all: the hit shell is what separates them, see
 * test_ipr_vs_gt). The reconstructed pixels cost no target rays. */
static void test_fipr_fovea(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-primitives", FW, FH, &cam);
    shot mask = render1("fipr", s, &cam, "show=mask hit=0.05"), fi = render1("fipr", s, &cam, "hit=0.05");
    shot ip = render1("ipr", s, &cam, "hit=0.05"), gt = render1("sdf-gt", s, &cam, "hit=0.05");
    fv_eye_model eye;
    fv_eye_model_default(FW, FH, &eye);
    int masked = 0, fovea = 0, fovea_close = 0, fovea_near = 0;
    for (int y = 0; y < FH; y++)
        for (int x = 0; x < FW; x++) {
            size_t i = (size_t)y * FW + x;
            if (col(&mask)[3 * i] != 1.0f) continue;
            masked++;
            if (memcmp(col(&fi) + 3 * i, col(&ip) + 3 * i, 3 * sizeof(float)) != 0)
                fail_msg("mask pixel (%d, %d): fipr (%g %g %g) is not ipr's (%g %g %g)", x, y, col(&fi)[3 * i], col(&fi)[3 * i + 1],
                         col(&fi)[3 * i + 2], col(&ip)[3 * i], col(&ip)[3 * i + 1], col(&ip)[3 * i + 2]);
            if (fv_eye_eccentricity_deg(&eye, (fv_gaze){0.5f, 0.5f}, x, y) < 7.5 - 0.5) {
                fovea++;
                fovea_close += pix_diff(&fi, &gt, i) <= 1e-3f;
                fovea_near += pix_diff(&fi, &gt, i) <= 1e-2f;
            }
        }
    print_message("fipr: %d mask pixels equal ipr's; in the fovea %d of %d within 1e-3 of sdf-gt\n", masked, fovea_close, fovea);
    assert_true(fovea > 20);
    assert_int_equal(fovea_near, fovea);
    assert_true(fovea_close >= 0.9 * fovea);
    assert_true(fv_stats_get_count(&fi.stats, "rays_level2") == masked);
    drop(&mask);
    drop(&fi);
    drop(&ip);
    drop(&gt);
    fv_scene_destroy(s);
}

/* A missing gaze under `--gaze-missing widen` (docs/gaze.md): the driver's whole-screen eye model
 * puts every pixel in the mask, whatever fovea_deg, outer_deg, the edges and the blur say, so
 * fipr's image is ipr's bit for bit, every frame, with every pixel traced at the target level. */
static void test_fipr_widened(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-primitives", FW, FH, &cam);
    fv_eye_model normal, whole;
    fv_eye_model_default(FW, FH, &normal);
    fv_eye_model_whole_screen(&normal, &whole);
    fv_error err;
    fv_params *pf = fv_test_params_str("refresh=4 blur=true fovea_deg=2 outer_deg=10"), *pi = fv_test_params_str("");
    fv_technique *tf = NULL, *ti = NULL;
    assert_int_equal(fv_technique_create("fipr", s, pf, NULL, &tf, &err), FV_OK);
    assert_int_equal(fv_technique_create("ipr", s, pi, NULL, &ti, &err), FV_OK);
    fv_film *a = NULL, *b = NULL;
    assert_int_equal(fv_film_create(FW, FH, 0, &a, &err), FV_OK);
    assert_int_equal(fv_film_create(FW, FH, 0, &b, &err), FV_OK);
    for (int i = 0; i < 3; i++) {
        fv_frame fr;
        fv_frame_init(&fr, &cam);
        fr.index = i;
        fr.prev_camera = i > 0 ? &cam : NULL;
        fr.eye_model = &whole;
        fv_stats sf, si;
        fv_test_render_frames(tf, &fr, 1, a, &sf);
        fv_test_render_frames(ti, &fr, 1, b, &si);
        assert_true(fv_stats_get_count(&sf, "mask_pixels") == FW * FH);
        assert_true(fv_stats_get_count(&sf, "rays_level2") == FW * FH);
        if (memcmp(fv_film_color_const(a), fv_film_color_const(b), (size_t)3 * FW * FH * sizeof(float)) != 0)
            fail_msg("frame %d: widened fipr differs from ipr", i);
    }
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_technique_destroy(tf);
    fv_technique_destroy(ti);
    fv_params_destroy(pf);
    fv_params_destroy(pi);
    fv_scene_destroy(s);
}

/* ======================================================================================== */
/* 10. The shading's normalisation                                                           */
/* ======================================================================================== */

/* sdf-furnace: the camera and a light of 2 pi at the centre of a hollow sphere of radius 1, albedo
 * 0.5: albedo / pi x 2 pi / r^2 = 1 at r = 1. The hit stops at most a hit distance eps in front of
 * the wall, so every pixel is in [1, 1 / (1 - eps)^2], eps = 0.25 x footprint (2 tan 30deg / 64). */
static void test_furnace_exact(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-furnace", 64, 64, &cam);
    const double eps = 0.25 * 2.0 * tan(30.0 * FV_PI_D / 180.0) / 64.0, hi = 1.0 / ((1.0 - eps) * (1.0 - eps));
    for (int m = 0; m < 4; m++) {
        shot a = render1(k_methods[m], s, &cam, "");
        double lo_seen = 1e9, hi_seen = -1e9;
        for (size_t i = 0; i < 3 * npix(&a); i++) {
            lo_seen = fmin(lo_seen, col(&a)[i]);
            hi_seen = fmax(hi_seen, col(&a)[i]);
        }
        print_message("%s in sdf-furnace: every channel in [%.7f, %.7f] (bound %.7f)\n", k_methods[m], lo_seen, hi_seen, hi);
        assert_true(lo_seen >= 1.0 - 1e-5 && hi_seen <= hi + 1e-5);
        /* in fact exactly 1 to rounding: the field at the centre is 1, so the first step lands on
         * the wall */
        assert_true(lo_seen > 1.0 - 1e-5 && hi_seen < 1.0 + 1e-5);
        drop(&a);
    }
    fv_scene_destroy(s);
}

/* A diffuse sphere on a diffuse ground, one point light: sdf-gt (16 spp, direct light only)
 * against pt max_depth=1 (64 spp): the image means agree within 2%, as do the means of each
 * quarter (lit ground, sphere, shadow). */
static void test_shading_vs_pt(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    int grey = diffuse(s, "grey", fv_v3s(0.6f)), red = diffuse(s, "red", fv_v3(0.8f, 0.3f, 0.2f));
    add_ground(s, 6.0f, grey);
    add_sphere(s, "ball", fv_v3(0, 1, 0), 1.0f, red);
    add_point_light(s, fv_v3(2, 5, 3), 30.0f);
    commit(s);
    fv_camera cam = {{0, 2.5f, 6}, {0, 0.8f, 0}, {0, 1, 0}, 35.0f, 48, 40};
    shot gt = render1("sdf-gt", s, &cam, "spp=16"), pt = render1("pt", s, &cam, "spp=64 max_depth=1");
    double mg = mean_colour(&gt), mp = mean_colour(&pt);
    print_message("sphere on ground 48x40: sdf-gt mean %.5f, pt max_depth=1 mean %.5f (%.2f%%)\n", mg, mp, 100.0 * (mg - mp) / mp);
    assert_true(mp > 0.02);
    assert_true(fabs(mg - mp) < 0.02 * mp);
    for (int q = 0; q < 4; q++) {
        int x0 = (q & 1) * 24, y0 = (q >> 1) * 20;
        double a = 0.0, b = 0.0;
        for (int y = y0; y < y0 + 20; y++)
            for (int x = x0; x < x0 + 24; x++)
                for (int c = 0; c < 3; c++) {
                    a += col(&gt)[3 * ((size_t)y * 48 + x) + c];
                    b += col(&pt)[3 * ((size_t)y * 48 + x) + c];
                }
        print_message("  quarter %d: sdf-gt %.5f, pt %.5f\n", q, a / 1440.0, b / 1440.0);
        assert_true(fabs(a - b) < 0.03 * b + 1e-3);
    }
    drop(&gt);
    drop(&pt);
    fv_scene_destroy(s);
}

/* ======================================================================================== */
/* shadow_reuse (ours): shadows from the level below where its 3x3 agree                     */
/* ======================================================================================== */

/* On sdf-columns (five lights, shadows of columns on the floor and walls) shadow_reuse traces
 * fewer shadow steps; the pixels it changes are few, near shadow edges; and without shadows it
 * changes nothing (every sample then sees every light facing it). */
static void test_shadow_reuse(void **st)
{
    (void)st;
    fv_camera cam;
    fv_scene *s = load("sdf-columns", 320, 256, &cam);
    shot a = render1("ipr", s, &cam, ""), b = render1("ipr", s, &cam, "shadow_reuse=true");
    double sa = fv_stats_get_count(&a.stats, "shadow_steps"), sb = fv_stats_get_count(&b.stats, "shadow_steps");
    int off = 0;
    for (size_t i = 0; i < npix(&a); i++) off += pix_diff(&a, &b, i) > 1e-3f;
    print_message("sdf-columns 320x256: shadow steps %.0f -> %.0f (%.3f), %d of %zu pixels differ by > 1e-3\n", sa, sb, sb / sa, off,
                  npix(&a));
    assert_true(sb < 0.9 * sa); /* 0.78 here; the share grows with the resolution (0.62 at 360x400) */
    assert_true(off < 0.02 * (double)npix(&a));
    drop(&a);
    drop(&b);
    /* the camera rays are the pyramid's either way */
    a = render1("ipr", s, &cam, "shadows=false");
    b = render1("ipr", s, &cam, "shadows=false shadow_reuse=true");
    assert_memory_equal(col(&a), col(&b), 3 * npix(&a) * sizeof(float));
    drop(&a);
    drop(&b);
    /* fipr takes it too: its mask pixels trace fewer shadow steps for the same mask */
    a = render1("fipr", s, &cam, "");
    b = render1("fipr", s, &cam, "shadow_reuse=true");
    assert_true(fv_stats_get_count(&a.stats, "mask_pixels") == fv_stats_get_count(&b.stats, "mask_pixels"));
    assert_true(fv_stats_get_count(&b.stats, "steps") == fv_stats_get_count(&a.stats, "steps"));
    drop(&a);
    drop(&b);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_levels_odd),       cmocka_unit_test(test_start_min_filter), cmocka_unit_test(test_sobel),
        cmocka_unit_test(test_probability),      cmocka_unit_test(test_march_sphere),     cmocka_unit_test(test_march_relaxed_and_wide),
        cmocka_unit_test(test_simd_identical),   cmocka_unit_test(test_spp_edges),        cmocka_unit_test(test_thin_min_filter),
        cmocka_unit_test(test_ipr_vs_gt),        cmocka_unit_test(test_fipr_mask),        cmocka_unit_test(test_fipr_refresh),
        cmocka_unit_test(test_fipr_fovea),       cmocka_unit_test(test_fipr_widened),     cmocka_unit_test(test_furnace_exact),
        cmocka_unit_test(test_shading_vs_pt),    cmocka_unit_test(test_shadow_reuse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
