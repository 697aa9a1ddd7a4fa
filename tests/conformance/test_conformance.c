/* Conformance of every registered technique: each check below runs once per class in the registry
 * (src/technique/registry.c), with the class's own test_params, so a new method gets all of them
 * by registering. Per technique:
 *   furnace     inside the built-in furnace (with the class's furnace_params added) the image's
 *               mean radiance is the class's declared furnace_radiance within its relative
 *               furnace_tolerance; every pixel written and
 *               finite; "nan_samples" reported (zero here);
 *   params      an unknown key is refused naming the key and the method; create leaves the
 *               caller's bag as it was, whether it succeeds or not;
 *   threads     1 and 2 threads give bit-identical colour over two frames (cornell);
 *   stereo      eye 0 then eye 1 of two stereo frames: both films finite and lit, the eyes differ;
 *   refusals    a film of another size than the camera, an eye out of range, no camera: each
 *               refused with FV_ERR_INVALID, and a correct render afterwards still works;
 *   overflow    a light whose radiance overflows float: no pixel non-finite, "nan_samples" > 0
 *               in every frame;
 *   progress    the callback sees fractions in (0, 1) and last 1, never decreasing, never from two
 *               threads at once; a callback returning false (at its first call, or half-way)
 *               cancels with FV_ERR_CANCELLED and hears nothing more, and the cancelled frame,
 *               asked again, comes out bit-identical to an uninterrupted sequence's.
 *   widen       a whole-screen fovea (fv_eye_model_whole_screen, `--gaze-missing widen`) changes
 *               a foveated method's image (class.h, foveated) and leaves it independent of the
 *               gaze; any other method's image is unchanged by the eye model and the gaze.
 *   history     a method without warm-up frames renders a frame alone as it does in sequence.
 *   table       the class's description (class.h) holds: every key create reads is in its
 *               parameter table and every key of the table is read, by a reader of the declared
 *               type with the declared default and choices (fv_params_watch tells what each
 *               reader was called with); each entry's default lies in
 *               its declared range or choices; the main parameter is declared, its steps are
 *               valid values and its default one of them; a family; a baseline that is another
 *               registered method, whose chain of baselines ends at the reference (no cycle),
 *               and one for every foveated method;
 *   defaults    every declared default set explicitly gives bit-identical frames to leaving it
 *               out, and every declared choice and main-parameter step is accepted;
 *   ranges      a value just outside a declared numeric range (the bound itself at an open end),
 *               an int off its declared values, a choice not declared and a malformed bool are
 *               refused with FV_ERR_INVALID naming the key.
 * Once, for all: films of no size cannot be created, and the overflow scene overflows.
 * Renders are 40x32 and a few frames: about 3 s in all, small enough under sanitizers too.
 */
#include <math.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "testkit.h"
#include "scene/light.h"
#include "core/params_read.h"
#include "scene/scene_impl.h"
#include "technique/class.h"

#define W 40
#define H 32
#define NPIX ((size_t)W * H)
#define FURNACE_FRAMES 3

/* ---- scenes, shared by every test ---- */

/* Each check's scenes: the mesh ones, or for a method that only sphere-traces signed distance
 * fields (class.h, sdf_only) their SDF twins: sdf-furnace, sdf-primitives, and the overflowing
 * spot over an SDF floor. */
typedef struct suite {
    fv_scene *furnace, *cornell, *overflow;
    fv_camera furnace_cam, cornell_cam, overflow_cam;
    float stereo_sep; /* a clear disparity at the scene's scale */
} suite;

static suite g_mesh, g_sdf;

static const suite *suite_of(const fv_technique_class *c) { return c->sdf_only ? &g_sdf : &g_mesh; }

/* A built-in scene and its camera at W x H (the one place that knows how a scene's view is read). */
static fv_scene *load_builtin(const char *name, fv_camera *cam)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    fv_error err;
    if (fv_scene_load(name, NULL, &s, &v, &err) != FV_OK) fail_msg("%s: %s", name, err.msg);
    fv_view_camera(v, s, 0.0, W, H, cam);
    fv_view_destroy(v);
    return s;
}

/* A diffuse floor (albedo 0.5, 4 x 4 at y = 0) lit by a 1 x 1 lamp (emission 5) at y = 2, and a
 * spot light at (0, 0.5, 0) pointing down with intensity 3e38 and a hard 10-degree cone (inner =
 * outer). The library refuses such an intensity since issue 14 (fovea/limits.h: at most 1e20), so
 * the light is added at 1 and raised behind the validation (scene_impl.h) before the commit: the
 * techniques' NaN/Inf guard must still hold for whatever overflows. The spot's numbers overflow
 * float:
 *  - a floor point in its cone is at d <= 0.5 / cos 10deg = 0.508, so the light it receives is
 *    I / d^2 >= 3e38 / 0.258 = 1.16e39 > FLT_MAX = 3.40e38: +inf (next-event estimation);
 *  - a photon leaving it inside the cone carries I 4 pi / pmf >= 3.77e39: +inf (photon mapping).
 * The spot's power, 2 pi (1 - cos 10deg) I = 2 pi 0.0152 3e38 = 2.9e37, stays finite, so the light
 * table is sound and the lamp's light still reaches the floor (by BSDF sampling: next to the spot
 * its pick probability rounds to 0). The cone's footprint, radius 0.5 tan 10deg = 0.088, is at the
 * image centre, where every technique samples. */
static fv_scene *overflow_scene(bool sdf_floor, fv_camera *cam)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material floor = fv_material_default(FV_MAT_DIFFUSE), lamp = fv_material_default(FV_MAT_DIFFUSE);
    floor.albedo = fv_v3s(0.5f);
    lamp.albedo = fv_v3s(0.0f);
    lamp.emission = fv_v3s(5.0f);
    int fm, lm;
    assert_int_equal(fv_scene_add_material(s, &floor, &fm, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &lamp, &lm, &err), FV_OK);
    const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
    const fv_vec3 fv[4] = {{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}};
    const fv_vec3 lv[4] = {{-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0.5f, 2, 0.5f}, {-0.5f, 2, 0.5f}}; /* faces down */
    fv_mesh_desc fd = {"floor", fv, 4, NULL, quad, 2, NULL, fm, NULL}, ld = {"lamp", lv, 4, NULL, quad, 2, NULL, lm, NULL};
    if (sdf_floor) {
        /* the same floor as a field: a 4 x 4 slab whose top is y = 0 */
        fv_sdf_node n[2];
        memset(n, 0, sizeof n);
        n[0].kind = FV_SDF_BOX;
        n[0].v[0] = fv_v3(2.0f, 0.1f, 2.0f);
        n[0].material = fm;
        n[0].q = (fv_quat){0, 0, 0, 1};
        n[1].kind = FV_SDF_TRANSFORM;
        n[1].a = 0;
        n[1].v[0] = fv_v3(0, -0.1f, 0);
        n[1].q = (fv_quat){0, 0, 0, 1};
        n[1].p[0] = 1.0f;
        assert_int_equal(fv_scene_add_sdf(s, "floor", n, 2, 1, NULL, NULL, &err), FV_OK);
    } else {
        assert_int_equal(fv_scene_add_mesh(s, &fd, NULL, NULL, &err), FV_OK);
    }
    assert_int_equal(fv_scene_add_mesh(s, &ld, NULL, NULL, &err), FV_OK);
    fv_light_desc spot = {FV_LIGHT_SPOT, {0, 0.5f, 0}, {0, -1, 0}, {1, 1, 1}, 10.0f, 10.0f};
    assert_int_equal(fv_scene_add_light(s, &spot, &err), FV_OK);
    s->delta[s->ndelta - 1].desc.intensity = fv_v3s(3e38f);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    /* Below the lamp, looking down at the footprint from 1.7 away: the view is 2 tan 15deg 1.7 =
     * 0.91 high, so the footprint spans about 6 of the 32 rows. */
    *cam = (fv_camera){{0, 1.2f, 1.2f}, {0, 0, 0}, {0, 1, 0}, 30.0f, W, H};
    return s;
}

static int group_setup(void **st)
{
    (void)st;
    g_mesh.furnace = load_builtin("furnace", &g_mesh.furnace_cam);
    g_mesh.cornell = load_builtin("cornell", &g_mesh.cornell_cam);
    g_mesh.overflow = overflow_scene(false, &g_mesh.overflow_cam);
    g_mesh.stereo_sep = 60.0f; /* the box is 556 wide */
    g_sdf.furnace = load_builtin("sdf-furnace", &g_sdf.furnace_cam);
    g_sdf.cornell = load_builtin("sdf-primitives", &g_sdf.cornell_cam);
    g_sdf.overflow = overflow_scene(true, &g_sdf.overflow_cam);
    g_sdf.stereo_sep = 0.5f; /* the shapes stand about 1 apart */
    return 0;
}

static int group_teardown(void **st)
{
    (void)st;
    const suite *all[2] = {&g_mesh, &g_sdf};
    for (int i = 0; i < 2; i++) {
        fv_scene_destroy(all[i]->furnace);
        fv_scene_destroy(all[i]->cornell);
        fv_scene_destroy(all[i]->overflow);
    }
    return 0;
}

/* ---- helpers ---- */

static const fv_technique_class *cls_of(void **st) { return *st; }

/* The class's test_params plus the NULL-terminated extra entries. */
static fv_params *params_of(const fv_technique_class *c, const char *const *extra)
{
    fv_params *p = fv_test_params_str(c->test_params);
    fv_error err;
    for (int i = 0; extra && extra[i]; i++)
        if (fv_params_parse(p, extra[i], &err) != FV_OK) fail_msg("%s", err.msg);
    return p;
}

static fv_technique *create_with(const fv_technique_class *c, const fv_scene *s, const char *more)
{
    fv_params *p = params_of(c, NULL);
    fv_params *q = fv_test_params_str(more);
    fv_error err0;
    for (int i = 0; i < fv_params_count(q); i++)
        if (fv_params_set(p, fv_params_key(q, i), fv_params_value(q, i), &err0) != FV_OK) fail_msg("%s", err0.msg);
    fv_params_destroy(q);
    fv_technique *t = NULL;
    fv_error err;
    if (fv_technique_create(c->name, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s: %s", c->name, err.msg);
    fv_params_destroy(p);
    return t;
}

static fv_technique *create(const fv_technique_class *c, const fv_scene *s) { return create_with(c, s, NULL); }

static fv_film *film_new(int w, int h)
{
    fv_film *f = NULL;
    fv_error err;
    if (fv_film_create(w, h, 0, &f, &err) != FV_OK) fail_msg("%s", err.msg);
    return f;
}

/* Fails unless every colour value is finite; returns the mean over pixels and channels. */
static double finite_mean(const fv_film *f, const char *what)
{
    const float *c = fv_film_color_const(f);
    size_t n = (size_t)3 * fv_film_width(f) * fv_film_height(f);
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(c[i])) fail_msg("%s: pixel %zu channel %zu is %g", what, i / 3, i % 3, c[i]);
        sum += c[i];
    }
    return sum / (double)n;
}

static bool has_counter(const fv_stats *s, const char *name)
{
    for (int i = 0; i < s->n_counters; i++)
        if (strcmp(s->counter[i].name, name) == 0) return true;
    return false;
}

static fv_frame frame_at(const fv_camera *cam, int index, int threads)
{
    fv_frame f;
    fv_frame_init(&f, cam);
    f.index = index;
    f.threads = threads;
    f.prev_camera = index > 0 ? cam : NULL;
    return f;
}

/* ---- 1. the furnace ---- */

static void test_furnace(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_technique *t = create_with(c, suite_of(c)->furnace, c->furnace_params);
    fv_film *f = film_new(W, H);
    fv_frame fr = frame_at(&suite_of(c)->furnace_cam, 0, 0);
    fv_stats s;
    fv_test_render_frames(t, &fr, FURNACE_FRAMES, f, &s);
    double mean = finite_mean(f, c->name);
    print_message("%-15s furnace mean %.5f (declared %.5f +- %.0f%%)\n", c->name, mean, c->furnace_radiance, 100.0 * c->furnace_tolerance);
    if (!(fabs(mean / c->furnace_radiance - 1.0) <= c->furnace_tolerance))
        fail_msg("%s: furnace mean %.5f, declared %.5f within %g", c->name, mean, c->furnace_radiance, c->furnace_tolerance);
    if (!has_counter(&s, "nan_samples")) fail_msg("%s: no \"nan_samples\" counter in its stats", c->name);
    assert_float_equal(fv_stats_get_count(&s, "nan_samples"), 0.0, 0.0);
    fv_film_destroy(f);
    fv_technique_destroy(t);
}

/* ---- 2. parameters ---- */

typedef struct bag_copy {
    int n;
    char kv[32][2][128];
} bag_copy;

static void bag_snapshot(const fv_params *p, bag_copy *b)
{
    b->n = fv_params_count(p);
    assert_true(b->n <= 32);
    for (int i = 0; i < b->n; i++) {
        snprintf(b->kv[i][0], sizeof b->kv[i][0], "%s", fv_params_key(p, i));
        snprintf(b->kv[i][1], sizeof b->kv[i][1], "%s", fv_params_value(p, i));
    }
}

static void bag_unchanged(const fv_params *p, const bag_copy *b, const char *what)
{
    if (fv_params_count(p) != b->n) fail_msg("%s: the bag had %d entries, now %d", what, b->n, fv_params_count(p));
    for (int i = 0; i < b->n; i++)
        if (strcmp(fv_params_key(p, i), b->kv[i][0]) || strcmp(fv_params_value(p, i), b->kv[i][1]))
            fail_msg("%s: entry %d was %s=%s, now %s=%s", what, i, b->kv[i][0], b->kv[i][1], fv_params_key(p, i), fv_params_value(p, i));
}

static void test_params(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_error err;
    bag_copy before;
    /* Its own test parameters are accepted and left as they were. */
    fv_params *p = params_of(c, NULL);
    bag_snapshot(p, &before);
    fv_technique *t = NULL;
    if (fv_technique_create(c->name, suite_of(c)->cornell, p, NULL, &t, &err) != FV_OK) fail_msg("%s: %s", c->name, err.msg);
    bag_unchanged(p, &before, c->name);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    /* One unknown key more: refused, naming the key and the method; nothing returned. */
    const char *extra[] = {"no_such_key=1", NULL};
    p = params_of(c, extra);
    bag_snapshot(p, &before);
    t = NULL;
    fv_status rc = fv_technique_create(c->name, suite_of(c)->cornell, p, NULL, &t, &err);
    fv_test_expect_fail(rc, &err, FV_ERR_INVALID, "no_such_key", c->name);
    fv_test_expect_msg(&err, c->name, c->name);
    assert_null(t);
    bag_unchanged(p, &before, c->name);
    fv_params_destroy(p);
    /* --spp: a method with a samples-per-pixel key accepts 4 through it (1, 4 and 16 are valid
     * everywhere); one without refuses in one line that names what to use instead. */
    p = params_of(c, NULL);
    rc = fv_technique_set_spp(c->name, p, 4, &err);
    if (c->spp_param) {
        assert_int_equal(rc, FV_OK);
        assert_string_equal(fv_technique_spp_param(fv_technique_index(c->name)), c->spp_param);
        t = NULL;
        if (fv_technique_create(c->name, suite_of(c)->cornell, p, NULL, &t, &err) != FV_OK) fail_msg("%s spp=4: %s", c->name, err.msg);
        fv_technique_destroy(t);
    } else {
        fv_test_expect_fail(rc, &err, FV_ERR_INVALID, "--param", c->name);
        assert_non_null(c->spp_instead);
        assert_null(strchr(err.msg, '\n'));
    }
    fv_params_destroy(p);
}

/* ---- 3. threads ---- */

static void test_threads(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_technique *t1 = create(c, suite_of(c)->cornell), *t2 = create(c, suite_of(c)->cornell);
    fv_film *a = film_new(W, H), *b = film_new(W, H);
    for (int i = 0; i < 2; i++) {
        fv_frame f1 = frame_at(&suite_of(c)->cornell_cam, i, 1), f2 = frame_at(&suite_of(c)->cornell_cam, i, 2);
        fv_test_render_frames(t1, &f1, 1, a, NULL);
        fv_test_render_frames(t2, &f2, 1, b, NULL);
        finite_mean(a, c->name);
        if (memcmp(fv_film_color_const(a), fv_film_color_const(b), NPIX * 3 * sizeof(float)) != 0)
            fail_msg("%s: frame %d differs between 1 and 2 threads", c->name, i);
    }
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_technique_destroy(t1);
    fv_technique_destroy(t2);
}

/* ---- 4. stereo ---- */

static void test_stereo(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_technique *t = create(c, suite_of(c)->cornell);
    fv_film *fl = film_new(W, H), *fr = film_new(W, H);
    fv_camera l, r;
    fv_camera_stereo(&suite_of(c)->cornell_cam, suite_of(c)->stereo_sep, &l, &r);
    for (int i = 0; i < 2; i++) {
        fv_frame e0 = frame_at(&l, i, 0);
        e0.eye_count = 2;
        fv_frame e1 = frame_at(&r, i, 0);
        e1.eye = 1;
        e1.eye_count = 2;
        e1.left_camera = &l;
        fv_test_render_frames(t, &e0, 1, fl, NULL);
        fv_test_render_frames(t, &e1, 1, fr, NULL);
        assert_int_equal(fv_film_width(fl), l.width);
        assert_int_equal(fv_film_height(fr), r.height);
        double ml = finite_mean(fl, c->name), mr = finite_mean(fr, c->name);
        if (!(ml > 0.0 && mr > 0.0)) fail_msg("%s: frame %d: left mean %g, right mean %g", c->name, i, ml, mr);
        if (memcmp(fv_film_color_const(fl), fv_film_color_const(fr), NPIX * 3 * sizeof(float)) == 0)
            fail_msg("%s: frame %d: both eyes got the same image", c->name, i);
    }
    fv_film_destroy(fl);
    fv_film_destroy(fr);
    fv_technique_destroy(t);
}

/* ---- 5. refusals ---- */

static void expect_refused(fv_technique *t, const fv_frame *f, fv_film *film, const char *needle, const char *what)
{
    fv_stats s;
    fv_stats_clear(&s);
    fv_error err;
    fv_test_expect_fail(fv_technique_render(t, f, film, &s, &err), &err, FV_ERR_INVALID, needle, what);
}

static void test_refusals(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_technique *t = create(c, suite_of(c)->cornell);
    fv_film *good = film_new(W, H), *half = film_new(W / 2, H / 2);
    fv_frame f = frame_at(&suite_of(c)->cornell_cam, 0, 0);
    /* registry.c: "camera size 40x32 differs from the film's 20x16" */
    expect_refused(t, &f, half, "20x16", "film of half the camera's size");
    const struct {
        int eye, count;
    } eyes[] = {{1, 1}, {2, 2}, {-1, 1}, {0, 0}, {0, 3}};
    for (size_t i = 0; i < sizeof eyes / sizeof eyes[0]; i++) {
        fv_frame e = f;
        e.eye = eyes[i].eye;
        e.eye_count = eyes[i].count;
        e.left_camera = &suite_of(c)->cornell_cam;
        char what[64];
        snprintf(what, sizeof what, "eye %d of %d", e.eye, e.eye_count);
        expect_refused(t, &e, good, what, what);
    }
    fv_frame none = f;
    none.camera = NULL;
    expect_refused(t, &none, good, "camera", "no camera");
    /* Nothing of that reached the method: a correct frame renders. */
    fv_test_render_frames(t, &f, 2, good, NULL);
    assert_true(finite_mean(good, c->name) > 0.0);
    fv_film_destroy(good);
    fv_film_destroy(half);
    fv_technique_destroy(t);
}

/* Films of no size cannot exist (technique-independent, run once). */
static void test_film_sizes(void **st)
{
    (void)st;
    const int sizes[][2] = {{0, 10}, {10, 0}, {-4, 10}, {FV_FILM_MAX_DIM + 1, 1}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        fv_film *f = NULL;
        fv_error err;
        char what[64];
        snprintf(what, sizeof what, "%dx%d", sizes[i][0], sizes[i][1]);
        fv_test_expect_fail(fv_film_create(sizes[i][0], sizes[i][1], 0, &f, &err), &err, FV_ERR_INVALID, what, what);
        assert_null(f);
    }
}

/* ---- 6. overflow ---- */

/* The scene does what its comment says: the spot's light at the footprint's centre and a photon
 * straight down are +inf (u = {0, 0.5, 0.75, ..} picks the spot, whose pick probability rounds to
 * 1, and the uniform sphere direction z = 1 - 2 u1 = 0, phi = 2 pi u2 = 3 pi / 2: (0, -1, 0)). */
static void test_overflow_scene(void **st)
{
    (void)st;
    fv_light_sample ls;
    assert_true(fv_light_sample_li(g_mesh.overflow, fv_v3(0, 0, 0), 0.0f, 0.5f, 0.5f, &ls));
    assert_true(ls.delta);
    assert_false(isfinite(ls.li.y));
    const float u[5] = {0.0f, 0.5f, 0.75f, 0.5f, 0.5f};
    fv_vec3 o, d, power, n;
    assert_true(fv_light_sample_emission(g_mesh.overflow, u, &o, &d, &power, &n));
    assert_float_equal(d.y, -1.0f, 1e-6f);
    assert_false(isfinite(power.y));
}

static void test_overflow(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_technique *t = create(c, suite_of(c)->overflow);
    fv_film *f = film_new(W, H);
    for (int i = 0; i < 2; i++) {
        fv_frame fr = frame_at(&suite_of(c)->overflow_cam, i, 0);
        fv_stats s;
        fv_test_render_frames(t, &fr, 1, f, &s);
        finite_mean(f, c->name);
        double dropped = fv_stats_get_count(&s, "nan_samples");
        print_message("%-15s overflow frame %d: nan_samples %g\n", c->name, i, dropped);
        if (!(dropped > 0.0)) fail_msg("%s: frame %d: non-finite radiance was not counted in \"nan_samples\"", c->name, i);
    }
    fv_film_destroy(f);
    fv_technique_destroy(t);
}

/* ---- 7. progress and cancel ---- */

#define MAX_CALLS 4096

typedef struct progress_log {
    int calls, cancel_at; /* cancel_at: return false on that call (1-based), 0 never */
    int after_cancel;     /* calls after returning false */
    double f[MAX_CALLS];
    atomic_int inside, overlap;
} progress_log;

static bool on_progress(void *user, double fraction)
{
    progress_log *p = user;
    if (atomic_fetch_add(&p->inside, 1) != 0) atomic_store(&p->overlap, 1);
    int call = ++p->calls;
    if (call <= MAX_CALLS) p->f[call - 1] = fraction;
    bool go = !(p->cancel_at && call >= p->cancel_at);
    if (p->cancel_at && call > p->cancel_at) p->after_cancel++;
    atomic_fetch_sub(&p->inside, 1);
    return go;
}

static void progress_init(progress_log *p, int cancel_at)
{
    memset(p, 0, sizeof *p);
    atomic_init(&p->inside, 0);
    atomic_init(&p->overlap, 0);
    p->cancel_at = cancel_at;
}

/* Renders frame `index` of cornell (or its SDF twin) with progress into f; returns the status. */
static fv_status render_progress(fv_technique *t, int index, int threads, progress_log *p, fv_film *f)
{
    const fv_technique_class *c = fv_technique_class_find(fv_technique_name_of(t));
    fv_frame fr = frame_at(&suite_of(c)->cornell_cam, index, threads);
    fr.progress = on_progress;
    fr.progress_user = p;
    fv_stats s;
    fv_stats_clear(&s);
    fv_error err;
    fv_status rc = fv_technique_render(t, &fr, f, &s, &err);
    if (rc != FV_OK && rc != FV_ERR_CANCELLED) fail_msg("%s", err.msg);
    return rc;
}

static void check_fractions(const progress_log *p, bool need_inner, const char *what)
{
    int n = p->calls < MAX_CALLS ? p->calls : MAX_CALLS;
    if (n < 1) fail_msg("%s: progress never reported", what);
    bool inner = false;
    for (int i = 0; i < n; i++) {
        if (!(p->f[i] >= 0.0 && p->f[i] <= 1.0)) fail_msg("%s: fraction %g", what, p->f[i]);
        if (i > 0 && p->f[i] < p->f[i - 1]) fail_msg("%s: fraction went back from %g to %g (call %d)", what, p->f[i - 1], p->f[i], i);
        inner |= p->f[i] > 0.0 && p->f[i] < 1.0;
    }
    if (need_inner && !inner) fail_msg("%s: no fraction strictly between 0 and 1 in %d calls", what, n);
    if (!(p->f[n - 1] >= 1.0 - 1e-9)) fail_msg("%s: last fraction %g", what, p->f[n - 1]);
    if (atomic_load(&p->overlap)) fail_msg("%s: the callback ran on two threads at once", what);
}

static void test_progress(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_film *f = film_new(W, H), *ref = film_new(W, H);
    progress_log *p = calloc(1, sizeof *p);
    assert_non_null(p);
    /* One thread reports every step; two threads at least the end, in order. */
    fv_technique *t = create(c, suite_of(c)->cornell);
    progress_init(p, 0);
    assert_int_equal(render_progress(t, 0, 1, p, f), FV_OK);
    check_fractions(p, true, c->name);
    progress_init(p, 0);
    assert_int_equal(render_progress(t, 1, 1, p, f), FV_OK);
    check_fractions(p, true, c->name);
    int calls = p->calls; /* of a second frame, which the cancels below interrupt */
    progress_init(p, 0);
    assert_int_equal(render_progress(t, 2, 2, p, f), FV_OK);
    check_fractions(p, false, c->name);
    fv_technique_destroy(t);
    print_message("%-15s progress: %d calls in frame 1 with one thread\n", c->name, calls);

    /* The reference: frames 0 and 1 uninterrupted. */
    fv_technique *r = create(c, suite_of(c)->cornell);
    fv_frame f0 = frame_at(&suite_of(c)->cornell_cam, 0, 1), f1 = frame_at(&suite_of(c)->cornell_cam, 1, 1);
    fv_test_render_frames(r, &f0, 1, ref, NULL);
    fv_test_render_frames(r, &f1, 1, ref, NULL);
    fv_technique_destroy(r);
    /* Frame 1 cancelled at the first call, then half-way; asked again, it is the reference's. */
    const int at[2] = {1, calls / 2 + 1};
    for (int k = 0; k < 2; k++) {
        t = create(c, suite_of(c)->cornell);
        fv_test_render_frames(t, &f0, 1, f, NULL);
        progress_init(p, at[k]);
        if (render_progress(t, 1, 1, p, f) != FV_ERR_CANCELLED) fail_msg("%s: cancel at call %d was not reported", c->name, at[k]);
        if (p->after_cancel) fail_msg("%s: %d progress calls after the cancel", c->name, p->after_cancel);
        fv_test_render_frames(t, &f1, 1, f, NULL);
        finite_mean(f, c->name);
        if (memcmp(fv_film_color_const(f), fv_film_color_const(ref), NPIX * 3 * sizeof(float)) != 0)
            fail_msg("%s: frame 1 after a cancel at progress call %d of %d differs from an uninterrupted frame 1", c->name, at[k], calls);
        fv_technique_destroy(t);
    }
    free(p);
    fv_film_destroy(f);
    fv_film_destroy(ref);
}

/* ---- 8. a fovea widened to the whole screen ---- */

/* Frames 0 and 1 of cornell (or its SDF twin) with this eye model and gaze, by a new instance. */
static void render_eye(const fv_technique_class *c, const fv_eye_model *eye, fv_gaze g, fv_film *f)
{
    fv_technique *t = create(c, suite_of(c)->cornell);
    fv_frame fr = frame_at(&suite_of(c)->cornell_cam, 0, 0);
    fr.eye_model = eye;
    fr.gaze = g;
    fv_test_render_frames(t, &fr, 2, f, NULL);
    finite_mean(f, c->name);
    fv_technique_destroy(t);
}

static bool same_image(const fv_film *a, const fv_film *b)
{
    return memcmp(fv_film_color_const(a), fv_film_color_const(b), NPIX * 3 * sizeof(float)) == 0;
}

/* What the driver gives a frame whose gaze a trace marks missing under `--gaze-missing widen`: the
 * gaze at the centre and fv_eye_model_whole_screen. A foveated method (class.h) must react: its
 * image differs from the ordinary eye model's at the same gaze. And it must render every pixel as
 * its fovea: a fovea covering the screen from any gaze, with the gaze elsewhere, gives the very
 * same image, so nothing anywhere is reduced by its distance from the gaze. (The periphery's error
 * against a pt reference does not say more: at these sizes it is the estimators' bias, the same
 * with either model, and a blurred periphery can be nearer than a sharp one.) Any other method
 * ignores the eye model and the gaze: its image is bit-identical in all three cases. */
static void test_widen(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_eye_model normal, whole, any;
    fv_eye_model_default(W, H, &normal);
    fv_eye_model_whole_screen(&normal, &whole);
    any = whole; /* from any gaze: the diagonal and a pixel */
    any.fovea_frac = any.transition_frac = (float)((hypot(W, H) + 1.0) / W);
    const fv_gaze centre = {0.5f, 0.5f}, off = {0.2f, 0.75f};
    fv_film *a = film_new(W, H), *b = film_new(W, H), *o = film_new(W, H);
    render_eye(c, &normal, centre, a);
    render_eye(c, &whole, centre, b);
    render_eye(c, &any, off, o);
    if (!c->foveated) {
        if (!same_image(a, b)) fail_msg("%s: not foveated, yet its image changes with a whole-screen fovea", c->name);
        if (!same_image(a, o)) fail_msg("%s: not foveated, yet its image changes with the gaze and eye model", c->name);
    } else {
        if (same_image(a, b)) fail_msg("%s: a whole-screen fovea (widen) leaves its image as it was", c->name);
        if (!same_image(b, o))
            fail_msg("%s: with a fovea covering the screen its image still depends on the gaze (something is foveated)", c->name);
    }
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_film_destroy(o);
}

/* A method that states no temporal state (class.h's warmup_frames 0) renders a frame the same
 * whether it rendered the frames before or starts there: what lets an MPI-split sequence deal its
 * frames to ranks without warm-up (src/dist, docs/distributed.md). The gaze moves every frame so
 * that a foveated method's regions change too. Methods with warm-up frames are the ones this
 * would fail for (tests/cli/test_mpi.sh checks fipr's warm-up gives its exact frames). */
static void test_history(void **st)
{
    const fv_technique_class *c = cls_of(st);
    if (c->warmup_frames > 0) return;
    fv_film *a = film_new(W, H), *b = film_new(W, H);
    fv_technique *seq = create(c, suite_of(c)->cornell), *fresh = create(c, suite_of(c)->cornell);
    fv_eye_model eye;
    fv_eye_model_default(W, H, &eye);
    fv_error err;
    for (int i = 0; i < 3; i++) {
        fv_frame fr = frame_at(&suite_of(c)->cornell_cam, i, 0);
        fr.eye_model = &eye;
        fr.gaze = (fv_gaze){0.2f + 0.3f * (float)i, 0.7f - 0.2f * (float)i};
        fv_stats stats;
        fv_stats_clear(&stats);
        if (fv_technique_render(seq, &fr, a, &stats, &err) != FV_OK) fail_msg("%s: frame %d: %s", c->name, i, err.msg);
        if (i == 2) {
            fr.prev_camera = NULL;
            if (fv_technique_render(fresh, &fr, b, &stats, &err) != FV_OK) fail_msg("%s: frame 2 alone: %s", c->name, err.msg);
        }
    }
    if (!same_image(a, b))
        fail_msg("%s: frame 2 differs after frames 0-1 from frame 2 alone: state it keeps needs warmup_frames (class.h)", c->name);
    fv_technique_destroy(seq);
    fv_technique_destroy(fresh);
    fv_film_destroy(a);
    fv_film_destroy(b);
}

/* ---- 10. the class's description: parameter table, main parameter, baseline ---- */

static const fv_param_info *declared(const fv_technique_class *c, const char *key)
{
    for (int j = 0; j < c->param_count; j++)
        if (strcmp(c->params[j].key, key) == 0) return &c->params[j];
    return NULL;
}

/* Whether `text` is a value parameter p declares valid on its own (its type, range, choices). */
static bool valid_value(const fv_param_info *p, const char *text)
{
    if (p->choices) {
        for (int i = 0; p->choices[i]; i++)
            if (strcmp(p->choices[i], text) == 0) return p->type != FV_PARAM_INT || valid_value(&(fv_param_info){.type = FV_PARAM_INT, .min = p->min, .max = p->max}, text);
        return false;
    }
    char *end;
    double v = strtod(text, &end);
    switch (p->type) {
    case FV_PARAM_INT:
        if (*end || end == text || v != floor(v)) return false;
        /* fall through */
    case FV_PARAM_FLOAT:
        if (*end || end == text || !isfinite(v)) return false;
        return (p->min_open ? v > p->min : v >= p->min) && (p->max_open ? v < p->max : v <= p->max);
    case FV_PARAM_BOOL: return strcmp(text, "true") == 0 || strcmp(text, "false") == 0;
    case FV_PARAM_CHOICE: return false; /* without choices */
    case FV_PARAM_STRING: return true;
    }
    return false;
}

/* The keys a reader asked for, by fv_params_watch, each with what its first reader accepts. */
typedef struct read_keys {
    int n;
    char key[64][32];
    fv_params_read read[64];
} read_keys;

static void on_read(void *user, const fv_params_read *rd)
{
    read_keys *r = user;
    for (int i = 0; i < r->n; i++)
        if (strcmp(r->key[i], rd->key) == 0) return;
    if (r->n == 64) fail_msg("more than 64 keys read");
    r->read[r->n] = *rd;
    snprintf(r->key[r->n++], sizeof r->key[0], "%s", rd->key);
}

/* Whether declaration e says what reader rd reads: its type, its default where it states one, its
 * choices, and a declared range that holds the reader's default when one is declared. (The ranges themselves may differ
 * either way, by design: a reader's bounds may follow other parameters, pt's block_count its spp,
 * and a reader may accept wide bounds and check the declared ones after, as the sphere tracers'
 * relax; the "ranges" check below holds every declared bound to a refusal.) Writes what differs
 * into why. */
static bool agrees(const fv_param_info *e, const fv_params_read *rd, char *why, size_t n)
{
    why[0] = '\0';
    switch (rd->reader) {
    case FV_READ_INT:
    case FV_READ_FLOAT: {
        const bool is_int = rd->reader == FV_READ_INT;
        if (e->type != (is_int ? FV_PARAM_INT : FV_PARAM_FLOAT)) {
            snprintf(why, n, "read as %s, declared %s", is_int ? "int" : "float", fv_param_type_name(e->type));
            return false;
        }
        if (e->def && strtod(e->def, NULL) != rd->def && fabs(strtod(e->def, NULL) - rd->def) > 1e-6 * fabs(rd->def)) {
            snprintf(why, n, "default %g read, %s declared", rd->def, e->def);
            return false;
        }
        if (e->choices) return true; /* an int of listed values: the list is the range */
        /* a derived default (no def) is the reader's sentinel, 0 for pm's Eq. 8 radius */
        if (e->def && (rd->def < e->min || rd->def > e->max || (e->min_open && rd->def == e->min) || (e->max_open && rd->def == e->max))) {
            snprintf(why, n, "the reader's default %g lies outside the declared range", rd->def);
            return false;
        }
        return true;
    }
    case FV_READ_BOOL:
        if (e->type != FV_PARAM_BOOL) {
            snprintf(why, n, "read as bool, declared %s", fv_param_type_name(e->type));
            return false;
        }
        if (e->def && (strcmp(e->def, "true") == 0) != (rd->def != 0.0)) {
            snprintf(why, n, "default %s read, %s declared", rd->def != 0.0 ? "true" : "false", e->def);
            return false;
        }
        return true;
    case FV_READ_CHOICE: {
        if (e->type != FV_PARAM_CHOICE || !e->choices) {
            snprintf(why, n, "read as a choice, declared %s", fv_param_type_name(e->type));
            return false;
        }
        int k = 0;
        for (; rd->choices[k] && e->choices[k]; k++)
            if (strcmp(rd->choices[k], e->choices[k]) != 0) break;
        if (rd->choices[k] || e->choices[k]) {
            snprintf(why, n, "choices differ at '%s'", rd->choices[k] ? rd->choices[k] : e->choices[k]);
            return false;
        }
        if (e->def && strcmp(e->def, rd->choices[(int)rd->def]) != 0) {
            snprintf(why, n, "default %s read, %s declared", rd->choices[(int)rd->def], e->def);
            return false;
        }
        return true;
    }
    case FV_READ_HAS: return true;
    }
    return true;
}

static void test_table(void **st)
{
    const fv_technique_class *c = cls_of(st);
    const int me = fv_technique_index(c->name);
    /* (a) The keys create reads, with the class's test parameters, called directly (the registry
     * reads `device` for every method: not the class's). */
    read_keys r = {0};
    fv_params *p = params_of(c, NULL);
    fv_params_watch(p, on_read, &r);
    void *state = NULL;
    fv_error err;
    fv_status rc = c->create_on ? c->create_on(suite_of(c)->cornell, p, FV_DEVICE_CPU, NULL, &state, &err)
                                : c->create(suite_of(c)->cornell, p, NULL, &state, &err);
    if (rc != FV_OK) fail_msg("%s: %s", c->name, err.msg);
    c->destroy(state);
    fv_params_destroy(p);
    for (int i = 0; i < r.n; i++)
        if (!declared(c, r.key[i])) fail_msg("%s: create reads '%s', which its parameter table does not declare", c->name, r.key[i]);
    /* ... and reads them as declared: the table is what the readers accept, both ways. */
    int bad = 0;
    for (int i = 0; i < r.n; i++) {
        char why[256];
        if (!agrees(declared(c, r.key[i]), &r.read[i], why, sizeof why)) {
            print_error("%s: '%s': %s\n", c->name, r.key[i], why);
            bad++;
        }
    }
    if (bad) fail_msg("%s: %d parameter(s) read otherwise than declared", c->name, bad);
    for (int j = 0; j < c->param_count; j++) {
        bool read = false;
        for (int i = 0; i < r.n && !read; i++) read = strcmp(r.key[i], c->params[j].key) == 0;
        if (!read) fail_msg("%s: its table declares '%s', which create never reads", c->name, c->params[j].key);
    }
    /* Each entry is whole and its default valid; no key twice. */
    for (int j = 0; j < c->param_count; j++) {
        const fv_param_info *e = &c->params[j];
        if (!e->key || !e->help || !e->help[0]) fail_msg("%s: entry %d has no key or help", c->name, j);
        if (declared(c, e->key) != e) fail_msg("%s: '%s' declared twice", c->name, e->key);
        if (!e->def && !e->def_note) fail_msg("%s: '%s' has neither a default nor a note saying how it is derived", c->name, e->key);
        if (e->def && !valid_value(e, e->def)) fail_msg("%s: the default %s=%s is not a valid value of its declaration", c->name, e->key, e->def);
        if (e->type == FV_PARAM_CHOICE && !e->choices) fail_msg("%s: choice '%s' without choices", c->name, e->key);
        if ((e->type == FV_PARAM_INT || e->type == FV_PARAM_FLOAT) && !(e->min <= e->max))
            fail_msg("%s: '%s' has the empty range [%g, %g]", c->name, e->key, e->min, e->max);
        for (int k = 0; e->choices && e->choices[k]; k++)
            if (!valid_value(e, e->choices[k])) fail_msg("%s: the choice %s=%s lies outside its range", c->name, e->key, e->choices[k]);
    }
    /* The main parameter: declared; steps valid and in increasing order of value for numbers; its
     * default one of them (where a viewer steps from). */
    if (c->main.key) {
        const fv_param_info *m = declared(c, c->main.key);
        if (!m) fail_msg("%s: main parameter '%s' is not declared", c->name, c->main.key);
        int n = fv_technique_main_step_count(me);
        if (n < 2) fail_msg("%s: main parameter '%s' with %d steps", c->name, c->main.key, n);
        for (int k = 0; k < n; k++) {
            const char *v = fv_technique_main_step(me, k);
            if (!valid_value(m, v)) fail_msg("%s: step %s=%s is not a valid value", c->name, m->key, v);
            if (k > 0 && !(strtod(v, NULL) > strtod(fv_technique_main_step(me, k - 1), NULL)))
                fail_msg("%s: steps of %s not increasing at %s", c->name, m->key, v);
        }
        int d = fv_technique_main_default_step(me);
        if (d < 0 || strcmp(fv_technique_main_step(me, d), m->def) != 0)
            fail_msg("%s: the default %s=%s is not among its steps", c->name, m->key, m->def ? m->def : "(derived)");
    }
    /* Family and baseline: another registered method, and following baselines ends at the
     * reference without coming back. */
    if (!c->family || !c->family[0]) fail_msg("%s: no family", c->name);
    if (c->foveated && !c->baseline) fail_msg("%s: foveated, yet measured against nothing (no baseline)", c->name);
    int at = me;
    for (int hops = 0; fv_technique_baseline(at); hops++) {
        int next = fv_technique_index(fv_technique_baseline(at));
        if (next < 0) fail_msg("%s: baseline '%s' of %s is not a registered method", c->name, fv_technique_baseline(at), fv_technique_name(at));
        if (next == at) fail_msg("%s: its own baseline", fv_technique_name(at));
        if (hops >= fv_technique_count()) fail_msg("%s: its chain of baselines has a cycle", c->name);
        at = next;
    }
}

/* Two frames of cornell (or its SDF twin) by a new instance made with the class's test
 * parameters plus `extra` (may be NULL). */
static void render_two(const fv_technique_class *c, const fv_params *extra, fv_film *f)
{
    fv_params *p = fv_test_params(NULL);
    fv_error err;
    for (int i = 0; extra && i < fv_params_count(extra); i++)
        if (fv_params_set(p, fv_params_key(extra, i), fv_params_value(extra, i), &err) != FV_OK) fail_msg("%s", err.msg);
    fv_params *tp = params_of(c, NULL); /* the test parameters win: they keep the render cheap */
    for (int i = 0; i < fv_params_count(tp); i++)
        if (fv_params_set(p, fv_params_key(tp, i), fv_params_value(tp, i), &err) != FV_OK) fail_msg("%s", err.msg);
    fv_params_destroy(tp);
    fv_technique *t = NULL;
    if (fv_technique_create(c->name, suite_of(c)->cornell, p, NULL, &t, &err) != FV_OK) fail_msg("%s: %s", c->name, err.msg);
    fv_params_destroy(p);
    fv_frame fr = frame_at(&suite_of(c)->cornell_cam, 0, 0);
    fv_test_render_frames(t, &fr, 2, f, NULL);
    fv_technique_destroy(t);
}

/* Creates the class with its test parameters and key=value: the status, err filled. */
static fv_status create_one(const fv_technique_class *c, const char *key, const char *value, fv_error *err)
{
    fv_params *p = params_of(c, NULL);
    fv_status rc = fv_params_set(p, key, value, err);
    fv_technique *t = NULL;
    if (rc == FV_OK) rc = fv_technique_create(c->name, suite_of(c)->cornell, p, NULL, &t, err);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return rc;
}

static void test_defaults(void **st)
{
    const fv_technique_class *c = cls_of(st);
    fv_params *defaults = fv_test_params(NULL);
    fv_error err;
    for (int j = 0; j < c->param_count; j++)
        if (c->params[j].def && fv_params_set(defaults, c->params[j].key, c->params[j].def, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_film *a = film_new(W, H), *b = film_new(W, H);
    render_two(c, NULL, a);
    render_two(c, defaults, b);
    if (!same_image(a, b)) fail_msg("%s: setting every declared default explicitly changes its frames", c->name);
    fv_params_destroy(defaults);
    fv_film_destroy(a);
    fv_film_destroy(b);
    for (int j = 0; j < c->param_count; j++) {
        const fv_param_info *e = &c->params[j];
        for (int k = 0; e->type == FV_PARAM_CHOICE && e->choices[k]; k++)
            if (create_one(c, e->key, e->choices[k], &err) != FV_OK) fail_msg("%s: declared %s=%s refused: %s", c->name, e->key, e->choices[k], err.msg);
    }
    const int me = fv_technique_index(c->name);
    for (int k = 0; k < fv_technique_main_step_count(me); k++)
        if (create_one(c, c->main.key, fv_technique_main_step(me, k), &err) != FV_OK)
            fail_msg("%s: main step %s=%s refused: %s", c->name, c->main.key, fv_technique_main_step(me, k), err.msg);
}

static void expect_refused_value(const fv_technique_class *c, const char *key, const char *value)
{
    fv_error err;
    char what[160];
    snprintf(what, sizeof what, "%s %s=%s", c->name, key, value);
    fv_test_expect_fail(create_one(c, key, value, &err), &err, FV_ERR_INVALID, key, what);
}

static void test_ranges(void **st)
{
    const fv_technique_class *c = cls_of(st);
    char v[64];
    for (int j = 0; j < c->param_count; j++) {
        const fv_param_info *e = &c->params[j];
        switch (e->type) {
        case FV_PARAM_INT:
            snprintf(v, sizeof v, "%.0f", e->min - 1.0);
            expect_refused_value(c, e->key, v);
            snprintf(v, sizeof v, "%.0f", e->max + 1.0);
            expect_refused_value(c, e->key, v);
            /* the first integer of the range that is not one of the declared values */
            for (double x = e->min; e->choices && x <= e->max; x++) {
                snprintf(v, sizeof v, "%.0f", x);
                if (!valid_value(e, v)) {
                    expect_refused_value(c, e->key, v);
                    break;
                }
            }
            break;
        case FV_PARAM_FLOAT:
            snprintf(v, sizeof v, "%.17g", e->min_open ? e->min : nextafter(e->min, -INFINITY));
            expect_refused_value(c, e->key, v);
            snprintf(v, sizeof v, "%.17g", e->max_open ? e->max : nextafter(e->max, INFINITY));
            expect_refused_value(c, e->key, v);
            break;
        case FV_PARAM_BOOL: expect_refused_value(c, e->key, "maybe"); break;
        case FV_PARAM_CHOICE: expect_refused_value(c, e->key, "no-such-choice"); break;
        case FV_PARAM_STRING: break;
        }
    }
}

/* ---- the table: every check for every registered technique ---- */

typedef struct check {
    const char *name;
    void (*fn)(void **);
} check;

static const check k_checks[] = {
    {"furnace", test_furnace}, {"params", test_params},     {"threads", test_threads},   {"stereo", test_stereo},
    {"refusals", test_refusals}, {"overflow", test_overflow}, {"progress", test_progress}, {"widen", test_widen},
    {"history", test_history}, {"table", test_table},       {"defaults", test_defaults}, {"ranges", test_ranges},
};
#define N_CHECKS (sizeof k_checks / sizeof k_checks[0])

int main(void)
{
    const int n = fv_technique_count();
    struct CMUnitTest *tests = calloc((size_t)n * N_CHECKS + 2, sizeof *tests);
    char(*names)[64] = calloc((size_t)n * N_CHECKS, sizeof *names);
    if (!tests || !names) return 1;
    int k = 0;
    tests[k++] = (struct CMUnitTest)cmocka_unit_test(test_film_sizes);
    tests[k++] = (struct CMUnitTest)cmocka_unit_test(test_overflow_scene);
    for (int i = 0; i < n; i++) {
        const fv_technique_class *c = fv_technique_class_at(i);
        for (size_t j = 0; j < N_CHECKS; j++) {
            char *name = names[(size_t)i * N_CHECKS + j];
            snprintf(name, 64, "%s: %s", c->name, k_checks[j].name);
            tests[k++] = (struct CMUnitTest){name, k_checks[j].fn, NULL, NULL, (void *)c};
        }
    }
    int failed = _cmocka_run_group_tests("conformance", tests, (size_t)k, group_setup, group_teardown);
    free(tests);
    free(names);
    return failed;
}
