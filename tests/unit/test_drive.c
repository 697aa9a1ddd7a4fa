/* The sequence driver (fovea/drive.h): every tool builds frames through it, so its policy is
 * checked here field by field with hand-worked values:
 *  - time of frame i is time0 + i / fps;
 *  - camera: the view's, then the options' path, then the overrides;
 *  - stereo: two cameras eye_separation apart;
 *  - gaze: fixed > options' path > view's path > centre;
 *  - eye model: options' > view's display rescaled to the width (615 ppi at 1080 px -> 307.5 at
 *    540 px) > default;
 *  - rendering: both eyes, progress over the whole frame, cancel, bad options refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"

static fv_scene *g_scene;
static fv_view *g_view; /* cornell's camera: the framing camera looks at the box from behind */

static int setup(void **st)
{
    (void)st;
    return fv_test_load("cornell", &g_scene, &g_view);
}

static int teardown(void **st)
{
    (void)st;
    fv_view_destroy(g_view);
    fv_scene_destroy(g_scene);
    return 0;
}

static fv_driver *make(const fv_view *v, const fv_drive_opts *o)
{
    fv_error err;
    fv_driver *d = NULL;
    if (fv_driver_create(g_scene, v, o, &d, &err) != FV_OK) fail_msg("%s", err.msg);
    return d;
}

static fv_gaze_path *fixed_path(float x, float y)
{
    fv_error err;
    fv_gaze_path *p = NULL;
    assert_int_equal(fv_gaze_path_create_fixed((fv_gaze){x, y}, &p, &err), FV_OK);
    return p;
}

static void test_time_and_camera(void **st)
{
    (void)st;
    fv_error err;
    fv_view *v;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    fv_camera c = {{1, 2, 3}, {1, 2, 0}, {0, 1, 0}, 40.0f, 10, 10};
    fv_view_set_camera(v, &c);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = 64, o.height = 32, o.time0 = 2.0, o.fps = 4.0;
    fv_driver *d = make(v, &o);
    fv_frame_views fv;
    fv_driver_views(d, 3, &fv);
    assert_float_equal(fv.time, 2.75, 1e-12); /* 2 + 3 / 4 */
    assert_int_equal(fv.eye_count, 1);
    assert_float_equal(fv.camera[0].pos.z, 3.0f, 0.0f);
    assert_int_equal(fv.camera[0].width, 64);
    assert_int_equal(fv.camera[0].height, 32);
    fv_driver_destroy(d);

    /* an options path moves the camera; then the overrides replace single fields */
    fv_camera_key keys[2] = {{0.0, {0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 40.0f}, {1.0, {0, 0, 20}, {0, 0, 0}, {0, 1, 0}, 60.0f}};
    fv_camera_path path = {keys, 2};
    o.time0 = 0.0, o.fps = 2.0;
    o.camera_path = &path;
    d = make(v, &o);
    fv_driver_views(d, 1, &fv); /* t = 0.5: halfway */
    assert_float_equal(fv.camera[0].pos.z, 15.0f, 1e-5f);
    assert_float_equal(fv.camera[0].fov_y, 50.0f, 1e-4f);
    fv_driver_destroy(d);
    o.camera_set = FV_DRIVE_POS | FV_DRIVE_FOV;
    o.pos = fv_v3(7, 8, 9);
    o.fov_y = 30.0f;
    d = make(v, &o);
    fv_driver_views(d, 1, &fv);
    assert_float_equal(fv.camera[0].pos.x, 7.0f, 0.0f);
    assert_float_equal(fv.camera[0].pos.z, 9.0f, 0.0f);
    assert_float_equal(fv.camera[0].fov_y, 30.0f, 0.0f);
    assert_float_equal(fv.camera[0].look.z, 0.0f, 0.0f); /* not overridden: from the path */
    fv_driver_destroy(d);
    fv_view_destroy(v);
}

static void test_stereo(void **st)
{
    (void)st;
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = o.height = 16;
    o.eye_separation = 0.5f;
    fv_driver *d = make(NULL, &o);
    assert_int_equal(fv_driver_eye_count(d), 2);
    fv_frame_views fv;
    fv_driver_views(d, 0, &fv);
    assert_int_equal(fv.eye_count, 2);
    assert_float_equal(fv_length(fv_sub(fv.camera[0].pos, fv.camera[1].pos)), 0.5f, 1e-4f); /* off-axis framing: float rounding */
    fv_driver_destroy(d);
}

static void test_gaze_precedence(void **st)
{
    (void)st;
    fv_error err;
    fv_view *v;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = o.height = 16;
    fv_frame_views fv;
    /* nothing: the centre */
    fv_driver *d = make(v, &o);
    fv_driver_views(d, 0, &fv);
    assert_float_equal(fv.gaze[0].x, 0.5f, 0.0f);
    fv_driver_destroy(d);
    /* the view's path */
    fv_view_set_gaze_path(v, fixed_path(0.1f, 0.2f));
    d = make(v, &o);
    fv_driver_views(d, 0, &fv);
    assert_float_equal(fv.gaze[0].x, 0.1f, 1e-6f);
    assert_float_equal(fv.gaze[1].y, 0.2f, 1e-6f);
    fv_driver_destroy(d);
    /* the options' path beats the view's */
    fv_gaze_path *mine = fixed_path(0.3f, 0.4f);
    o.gaze_path = mine;
    d = make(v, &o);
    fv_driver_views(d, 0, &fv);
    assert_float_equal(fv.gaze[0].x, 0.3f, 1e-6f);
    fv_driver_destroy(d);
    /* a fixed gaze beats both, and the viewer's live gaze beats that */
    o.fixed_gaze = true;
    o.gaze = (fv_gaze){0.9f, 0.8f};
    d = make(v, &o);
    fv_driver_views(d, 0, &fv);
    assert_float_equal(fv.gaze[0].x, 0.9f, 0.0f);
    fv_driver_set_gaze(d, (fv_gaze){0.6f, 0.7f});
    fv_driver_views(d, 5, &fv);
    assert_float_equal(fv.gaze[0].y, 0.7f, 0.0f);
    fv_driver_destroy(d);
    fv_gaze_path_destroy(mine);
    fv_view_destroy(v);
}

static void test_eye_model(void **st)
{
    (void)st;
    fv_error err;
    fv_view *v;
    assert_int_equal(fv_view_create(&v, &err), FV_OK);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = 540, o.height = 600;
    /* no display anywhere: the default for the size */
    fv_driver *d = make(v, &o);
    fv_eye_model def;
    fv_eye_model_default(540, 600, &def);
    assert_float_equal(fv_driver_eye_model(d)->ppi, def.ppi, 0.0f);
    fv_driver_destroy(d);
    /* the view's display, its density rescaled from 1080 to 540 pixels wide */
    fv_eye_model disp;
    fv_eye_model_default(1080, 1200, &disp);
    disp.ppi = 615.0f;
    disp.fovea_deg = 5.0f;
    fv_view_set_display(v, &disp);
    d = make(v, &o);
    const fv_eye_model *e = fv_driver_eye_model(d);
    assert_float_equal(e->ppi, 307.5f, 1e-4f);
    assert_int_equal(e->width, 540);
    assert_int_equal(e->height, 600);
    assert_float_equal(e->fovea_deg, 5.0f, 0.0f);
    fv_driver_destroy(d);
    /* the options' model is taken as given */
    fv_eye_model mine = disp;
    mine.ppi = 100.0f;
    o.eye_model = &mine;
    d = make(v, &o);
    assert_float_equal(fv_driver_eye_model(d)->ppi, 100.0f, 0.0f);
    fv_driver_destroy(d);
    fv_view_destroy(v);
}

static void test_bad_options(void **st)
{
    (void)st;
    fv_error err;
    fv_driver *d = NULL;
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.fps = 0.0;
    assert_int_equal(fv_driver_create(g_scene, NULL, &o, &d, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "fps"));
    fv_drive_opts_init(&o);
    o.width = 0;
    assert_int_equal(fv_driver_create(g_scene, NULL, &o, &d, &err), FV_ERR_INVALID);
    fv_drive_opts_init(&o);
    o.eye_separation = NAN;
    assert_int_equal(fv_driver_create(g_scene, NULL, &o, &d, &err), FV_ERR_INVALID);
    assert_null(d);
    /* Beyond the ray kernels' range (fovea/limits.h): Embree would abort the process. */
    fv_drive_opts_init(&o);
    o.eye_separation = 1e20f;
    assert_int_equal(fv_driver_create(g_scene, NULL, &o, &d, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "eye separation: coordinate 1e+20 is beyond"));
    fv_drive_opts_init(&o);
    o.camera_set = FV_DRIVE_POS;
    o.pos = fv_v3(1e19f, 273, -800);
    assert_int_equal(fv_driver_create(g_scene, NULL, &o, &d, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "camera position: coordinate 1e+19 is beyond"));
    assert_null(d);
}

/* A trace with a blink: key 1 is missing. Hold keeps the gaze of key 0 until key 2 and the
 * frame's eye model is the driver's; widen puts the gaze at the centre with a fovea covering the
 * whole image, for exactly the frames in the gap. */
static void test_missing_gaze(void **st)
{
    (void)st;
    fv_error err;
    fv_gaze_key k[3] = {{0.0, {0.2f, 0.3f}, {0.2f, 0.3f}}, {1.0, {NAN, NAN}, {NAN, NAN}}, {2.0, {0.8f, 0.7f}, {0.8f, 0.7f}}};
    fv_gaze_path *p = NULL;
    assert_int_equal(fv_gaze_path_create_keys(k, 3, &p, &err), FV_OK);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = 32;
    o.height = 16;
    o.fps = 2.0; /* frames at t = 0, 0.5, 1, 1.5, 2 */
    o.gaze_path = p;
    fv_frame_views fv;
    fv_driver *d = make(NULL, &o);
    const fv_eye_model *eye = fv_driver_eye_model(d);
    fv_driver_views(d, 1, &fv); /* t = 0.5: key 0 known, key 1 missing: held, known */
    assert_true(fv.gaze_known);
    assert_float_equal(fv.gaze[0].x, 0.2f, 0.0f);
    fv_driver_views(d, 3, &fv); /* t = 1.5: in the gap: held, unknown, the driver's model */
    assert_false(fv.gaze_known);
    assert_float_equal(fv.gaze[0].x, 0.2f, 0.0f);
    assert_float_equal(fv.gaze[0].y, 0.3f, 0.0f);
    assert_ptr_equal(fv.eye_model, eye);
    fv_driver_views(d, 4, &fv);
    assert_true(fv.gaze_known);
    assert_float_equal(fv.gaze[0].x, 0.8f, 0.0f);
    fv_driver_destroy(d);

    o.gaze_missing = FV_GAZE_MISSING_WIDEN;
    d = make(NULL, &o);
    fv_driver_views(d, 3, &fv);
    assert_false(fv.gaze_known);
    assert_float_equal(fv.gaze[0].x, 0.5f, 0.0f);
    assert_float_equal(fv.gaze[1].y, 0.5f, 0.0f);
    assert_ptr_not_equal(fv.eye_model, fv_driver_eye_model(d));
    /* Every pixel, the corners included, is in the fovea; the model is still a valid one. */
    assert_int_equal(fv_eye_model_validate(fv.eye_model, &err), FV_OK);
    assert_int_equal(fv_eye_region(fv.eye_model, fv.gaze[0], 0, 0), FV_REGION_FOVEA);
    assert_int_equal(fv_eye_region(fv.eye_model, fv.gaze[0], 31, 15), FV_REGION_FOVEA);
    /* r_f = (hypot(32, 16) / 2 + 1) px = 18.89 px */
    assert_float_equal(fv_eye_fovea_radius_px(fv.eye_model), 0.5 * hypot(32.0, 16.0) + 1.0, 1e-4);
    fv_driver_views(d, 1, &fv); /* outside the gap nothing changes */
    assert_true(fv.gaze_known);
    assert_float_equal(fv.gaze[0].x, 0.2f, 0.0f);
    assert_ptr_equal(fv.eye_model, fv_driver_eye_model(d));
    fv_driver_destroy(d);

    /* The path's own policy applies when the driver leaves it to the path. */
    o.gaze_missing = FV_GAZE_MISSING_PATH;
    fv_gaze_path_set_missing(p, FV_GAZE_MISSING_WIDEN);
    d = make(NULL, &o);
    fv_driver_views(d, 3, &fv);
    assert_float_equal(fv.gaze[0].x, 0.5f, 0.0f);
    /* ... and a render of a frame in the gap works with the widened model. */
    fv_technique *t = NULL;
    fv_film *film = NULL;
    fv_stats stats;
    fv_stats_clear(&stats);
    assert_int_equal(fv_technique_create("pt", g_scene, NULL, NULL, &t, &err), FV_OK);
    assert_int_equal(fv_film_create(32, 16, 0, &film, &err), FV_OK);
    assert_int_equal(fv_driver_render(d, t, 3, false, &film, &stats, NULL, NULL, &err), FV_OK);
    fv_film_destroy(film);
    fv_technique_destroy(t);
    fv_driver_destroy(d);
    fv_gaze_path_destroy(p);
}

typedef struct progress_log {
    double f[4096];
    int n;
    int cancel_after; /* calls; < 0: never */
} progress_log;

static bool on_progress(void *user, double f)
{
    progress_log *p = user;
    if (p->n < 4096) p->f[p->n++] = f;
    return p->cancel_after < 0 || p->n < p->cancel_after;
}

static void test_render_progress_and_cancel(void **st)
{
    (void)st;
    fv_error err;
    fv_params *p;
    assert_int_equal(fv_params_create(&p, &err), FV_OK);
    assert_int_equal(fv_params_set(p, "spp", "2", &err), FV_OK);
    fv_technique *t;
    assert_int_equal(fv_technique_create("pt", g_scene, p, NULL, &t, &err), FV_OK);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = 64, o.height = 64, o.eye_separation = 50.0f, o.threads = 1;
    fv_driver *d = make(g_view, &o);
    fv_film *films[2];
    assert_int_equal(fv_film_create(64, 64, 0, &films[0], &err), FV_OK);
    assert_int_equal(fv_film_create(64, 64, 0, &films[1], &err), FV_OK);
    fv_stats stats;
    fv_stats_clear(&stats);
    progress_log log = {{0}, 0, -1};
    assert_int_equal(fv_driver_render(d, t, 0, false, films, &stats, on_progress, &log, &err), FV_OK);
    /* both eyes: the first half of the reports from the left eye, ending at 1 */
    assert_true(log.n >= 4);
    bool left = false, right = false;
    for (int i = 0; i < log.n; i++) {
        if (i) assert_true(log.f[i] >= log.f[i - 1]);
        left |= log.f[i] > 0.0 && log.f[i] < 0.5;
        right |= log.f[i] > 0.5 && log.f[i] < 1.0;
    }
    assert_true(left && right);
    assert_float_equal(log.f[log.n - 1], 1.0, 1e-12);
    double sum0 = 0, sum1 = 0;
    for (int i = 0; i < 3 * 64 * 64; i++) sum0 += fv_film_color(films[0])[i], sum1 += fv_film_color(films[1])[i];
    assert_true(sum0 > 0.0 && sum1 > 0.0 && sum0 != sum1);
    /* no film for the right eye: the left eye alone, the same pixels, half the samples, and its
     * progress runs to 1 over that one eye */
    fv_film *left_film[2] = {NULL, NULL};
    assert_int_equal(fv_film_create(64, 64, 0, &left_film[0], &err), FV_OK);
    fv_stats pair_stats, left_stats;
    fv_stats_clear(&pair_stats);
    fv_stats_clear(&left_stats);
    assert_int_equal(fv_driver_render(d, t, 0, false, films, &pair_stats, NULL, NULL, &err), FV_OK);
    progress_log one = {{0}, 0, -1};
    assert_int_equal(fv_driver_render(d, t, 0, false, left_film, &left_stats, on_progress, &one, &err), FV_OK);
    assert_memory_equal(fv_film_color(left_film[0]), fv_film_color(films[0]), 3 * 64 * 64 * sizeof(float));
    assert_float_equal(fv_stats_get_count(&left_stats, "samples"), 64.0 * 64.0 * 2.0, 0.0);
    assert_float_equal(fv_stats_get_count(&pair_stats, "samples"), 2.0 * 64.0 * 64.0 * 2.0, 0.0);
    assert_true(one.n >= 2 && one.f[0] > 0.0 && one.f[0] < 0.5);
    assert_float_equal(one.f[one.n - 1], 1.0, 1e-12);
    fv_film_destroy(left_film[0]);
    /* cancel in the left eye: the frame stops with FV_ERR_CANCELLED; the next frame renders */
    progress_log stop = {{0}, 0, 2};
    assert_int_equal(fv_driver_render(d, t, 1, true, films, &stats, on_progress, &stop, &err), FV_ERR_CANCELLED);
    assert_true(stop.n <= 3);
    assert_int_equal(fv_driver_render(d, t, 2, false, films, &stats, NULL, NULL, &err), FV_OK);
    fv_film_destroy(films[0]);
    fv_film_destroy(films[1]);
    fv_driver_destroy(d);
    fv_technique_destroy(t);
    fv_params_destroy(p);
}

/* The viewer flies the camera with fv_driver_set_camera between frames: the previous frame's
 * camera a technique reprojects from must be the one that frame was rendered with, not the new
 * one (which would make every reprojection an identity while the camera moves). */
static void test_set_camera_keeps_the_past(void **st)
{
    (void)st;
    fv_error err;
    fv_params *p;
    assert_int_equal(fv_params_create(&p, &err), FV_OK);
    assert_int_equal(fv_params_set(p, "spp", "1", &err), FV_OK);
    fv_technique *t;
    assert_int_equal(fv_technique_create("pt", g_scene, p, NULL, &t, &err), FV_OK);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = o.height = 16, o.threads = 1;
    fv_driver *d = make(g_view, &o);
    fv_film *film;
    assert_int_equal(fv_film_create(16, 16, 0, &film, &err), FV_OK);
    fv_stats stats;
    fv_stats_clear(&stats);
    fv_frame_views v0, pv;
    fv_driver_views(d, 0, &v0);
    assert_int_equal(fv_driver_render(d, t, 0, false, &film, &stats, NULL, NULL, &err), FV_OK);
    fv_camera c = v0.camera[0];
    c.pos.x += 100.0f;
    c.look.x += 100.0f;
    fv_driver_set_camera(d, &c);
    fv_driver_prev_views(d, 1, &pv);
    assert_float_equal(pv.camera[0].pos.x, v0.camera[0].pos.x, 0.0f);
    assert_float_equal(pv.camera[0].look.x, v0.camera[0].look.x, 0.0f);
    fv_frame_views v1;
    fv_driver_views(d, 1, &v1);
    assert_float_equal(v1.camera[0].pos.x, c.pos.x, 0.0f);
    assert_int_equal(fv_driver_render(d, t, 1, true, &film, &stats, NULL, NULL, &err), FV_OK);
    /* after frame 1, frame 2's past is frame 1 as rendered, the moved camera */
    fv_driver_prev_views(d, 2, &pv);
    assert_float_equal(pv.camera[0].pos.x, c.pos.x, 0.0f);
    /* a frame that was not the last rendered is derived from today's settings */
    fv_driver_prev_views(d, 5, &pv);
    assert_float_equal(pv.camera[0].pos.x, c.pos.x, 0.0f);
    fv_film_destroy(film);
    fv_driver_destroy(d);
    fv_technique_destroy(t);
    fv_params_destroy(p);
}

/* Warm-up frames come first, at frame 0's views, and shift the index the technique sees: with 3 of
 * them frame 0 is what frame 3 of a driver without warm-up is (pt keeps no state, cornell does not
 * move), and the warm-up's progress rises to 1. */
static void test_warm_up(void **st)
{
    (void)st;
    fv_error err;
    fv_params *p;
    assert_int_equal(fv_params_create(&p, &err), FV_OK);
    assert_int_equal(fv_params_set(p, "spp", "1", &err), FV_OK);
    fv_technique *t;
    assert_int_equal(fv_technique_create("pt", g_scene, p, NULL, &t, &err), FV_OK);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = 32, o.height = 32, o.threads = 1;
    fv_film *a, *b;
    assert_int_equal(fv_film_create(32, 32, 0, &a, &err), FV_OK);
    assert_int_equal(fv_film_create(32, 32, 0, &b, &err), FV_OK);
    fv_stats stats;
    fv_stats_clear(&stats);
    fv_driver *plain = make(g_view, &o);
    assert_int_equal(fv_driver_render(plain, t, 3, false, &b, &stats, NULL, NULL, &err), FV_OK);
    o.warmup = 3;
    fv_driver *warm = make(g_view, &o);
    progress_log log = {{0}, 0, -1};
    assert_int_equal(fv_driver_warm_up(warm, t, &a, &stats, on_progress, &log, &err), FV_OK);
    assert_true(log.n >= 3);
    for (int i = 1; i < log.n; i++) assert_true(log.f[i] >= log.f[i - 1]);
    assert_float_equal(log.f[log.n - 1], 1.0, 1e-9);
    /* frame 0 goes on from the last warm-up frame, which had its views */
    fv_frame_views v0, pv;
    fv_driver_views(warm, 0, &v0);
    fv_driver_prev_views(warm, 0, &pv);
    assert_memory_equal(&pv.camera[0], &v0.camera[0], sizeof v0.camera[0]);
    assert_int_equal(fv_driver_render(warm, t, 0, true, &a, &stats, NULL, NULL, &err), FV_OK);
    assert_memory_equal(fv_film_color(a), fv_film_color(b), 32 * 32 * 3 * sizeof(float));
    fv_driver_destroy(warm);
    fv_driver_destroy(plain);
    /* a count out of range is refused */
    fv_driver *bad = NULL;
    o.warmup = -1;
    assert_int_equal(fv_driver_create(g_scene, g_view, &o, &bad, &err), FV_ERR_INVALID);
    o.warmup = FV_DRIVE_MAX_WARMUP + 1;
    assert_int_equal(fv_driver_create(g_scene, g_view, &o, &bad, &err), FV_ERR_INVALID);
    assert_null(bad);
    fv_film_destroy(a);
    fv_film_destroy(b);
    fv_technique_destroy(t);
    fv_params_destroy(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_time_and_camera), cmocka_unit_test(test_stereo),
        cmocka_unit_test(test_gaze_precedence), cmocka_unit_test(test_eye_model),
        cmocka_unit_test(test_bad_options),     cmocka_unit_test(test_render_progress_and_cancel),
        cmocka_unit_test(test_set_camera_keeps_the_past),
        cmocka_unit_test(test_missing_gaze),     cmocka_unit_test(test_warm_up),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
