/* Helpers shared by the cmocka tests (tests/unit and tests/conformance): a warning sink that
 * records what it was told, a check of a refusal (status, a needle in its one-line message), a
 * parameter bag from a list of "key=value" strings, and rendering a few frames of a technique by
 * hand. Header-only (static inline): include it after <cmocka.h>'s prerequisites, or on its own.
 */
#ifndef FV_TESTKIT_H
#define FV_TESTKIT_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"

/* ---- warnings ---- */

/* What an fv_log sink was told: how many warnings, the last one, and all of them, each followed
 * by '|' (truncated when long). Start from {0}. */
typedef struct fv_test_warnings {
    int count;
    char last[512];
    char all[2048];
} fv_test_warnings;

/* The sink: fv_log log = {fv_test_warn, &warnings}. */
static inline void fv_test_warn(void *user, const char *msg)
{
    fv_test_warnings *w = user;
    w->count++;
    snprintf(w->last, sizeof w->last, "%s", msg);
    size_t n = strlen(w->all);
    snprintf(w->all + n, sizeof w->all - n, "%s|", msg);
}

/* ---- refusals ---- */

/* A refusal's message: it names `needle` and is one line. `what` (the input at fault) heads the
 * failure report. */
static inline void fv_test_expect_msg(const fv_error *err, const char *needle, const char *what)
{
    if (!strstr(err->msg, needle)) fail_msg("%s: message '%s' lacks '%s'", what, err->msg, needle);
    if (strchr(err->msg, '\n')) fail_msg("%s: message '%s' is more than one line", what, err->msg);
}

/* A call that had to fail: it returned `want` and its message names `needle` in one line. */
static inline void fv_test_expect_fail(fv_status got, const fv_error *err, fv_status want, const char *needle, const char *what)
{
    if (got != want) fail_msg("%s: status %d, expected %d (%s)", what, (int)got, (int)want, got == FV_OK ? "" : err->msg);
    fv_test_expect_msg(err, needle, what);
}

/* ---- parameters ---- */

/* A new bag from a NULL-terminated list of "key=value" strings (kv may be NULL: an empty bag);
 * fails the test on a malformed entry. Release with fv_params_destroy. */
static inline fv_params *fv_test_params(const char *const *kv)
{
    fv_params *p = NULL;
    fv_error err;
    if (fv_params_create(&p, &err) != FV_OK) fail_msg("%s", err.msg);
    for (int i = 0; kv && kv[i]; i++)
        if (fv_params_parse(p, kv[i], &err) != FV_OK) fail_msg("'%s': %s", kv[i], err.msg);
    return p;
}

/* The same from one string of entries separated by spaces or commas ("spp=4 max_depth=2"; ""
 * or NULL: an empty bag), as a technique class's test_params. */
static inline fv_params *fv_test_params_str(const char *list)
{
    fv_params *p = fv_test_params(NULL);
    fv_error err;
    for (const char *c = list ? list : ""; *c;) {
        size_t n = strcspn(c, " ,");
        if (n > 0) {
            char kv[256];
            if (n >= sizeof kv) fail_msg("parameter '%.40s...' too long", c);
            memcpy(kv, c, n);
            kv[n] = '\0';
            if (fv_params_parse(p, kv, &err) != FV_OK) fail_msg("'%s': %s", kv, err.msg);
        }
        c += n + (c[n] != '\0');
    }
    return p;
}

/* ---- scenes ---- */

/* Loads a built-in scene or file with its view (the camera a built-in comes with), for a group
 * setup: 0 on success, -1 (and the message on stderr) otherwise. */
static inline int fv_test_load(const char *name, fv_scene **scene, fv_view **view)
{
    fv_error err;
    if (fv_scene_load(name, NULL, scene, view, &err) == FV_OK) return 0;
    fprintf(stderr, "%s: %s\n", name, err.msg);
    return -1;
}

/* rel under the folder the environment variable `var` names when set (a test binary carried to
 * another machine, scripts/gpu-check), else under `built` (the folder compiled in; NULL: none),
 * else under `fallback`. */
static inline const char *fv_test_path_in(const char *var, const char *built, const char *fallback, const char *rel, char *buf, size_t n)
{
    const char *dir = getenv(var);
    if (!dir) dir = built ? built : fallback;
    snprintf(buf, n, "%s/%s", dir, rel);
    return buf;
}

#ifndef FOVEA_TEST_DATA
#define FV_TEST_DATA_BUILT NULL
#else
#define FV_TEST_DATA_BUILT FOVEA_TEST_DATA
#endif
#ifndef FOVEA_SOURCE_DIR
#define FV_TEST_SOURCE_BUILT NULL
#else
#define FV_TEST_SOURCE_BUILT FOVEA_SOURCE_DIR
#endif

/* The path of test data file `rel` (under tests/data): $FOVEA_TEST_DATA when set, else the source
 * tree's folder the test was built with. */
static inline const char *fv_test_data(const char *rel, char *buf, size_t n)
{
    return fv_test_path_in("FOVEA_TEST_DATA", FV_TEST_DATA_BUILT, "tests/data", rel, buf, n);
}

/* The path of `rel` under the source tree (scenes/..., bench/...): $FOVEA_SOURCE_DIR when set (the
 * bundle scripts/gpu-check unpacks mirrors those folders), else the tree the test was built from. */
static inline const char *fv_test_source(const char *rel, char *buf, size_t n)
{
    return fv_test_path_in("FOVEA_SOURCE_DIR", FV_TEST_SOURCE_BUILT, ".", rel, buf, n);
}

/* ---- rendering by hand ---- */

/* Renders frames 0 .. n-1 of t into film from the template `first` (camera, seed, threads, gaze,
 * eye, ...): frame i gets index i and, from frame 1 on, prev_camera = camera (a still view). Before
 * each frame the film is cleared and its colour set to NaN, so a pixel the technique leaves
 * unwritten cannot pass for a result. stats (may be NULL) receives the last frame's stats.
 * Fails the test when a render fails. */
static inline void fv_test_render_frames(fv_technique *t, const fv_frame *first, int n, fv_film *film, fv_stats *stats)
{
    fv_stats s;
    fv_stats_clear(&s);
    for (int i = 0; i < n; i++) {
        fv_frame fr = *first;
        fr.index = first->index + i;
        if (i > 0) fr.prev_camera = first->camera;
        fv_film_clear(film);
        float *col = fv_film_color(film);
        for (size_t k = 0, m = (size_t)3 * fv_film_width(film) * fv_film_height(film); k < m; k++) col[k] = NAN;
        fv_error err;
        fv_stats_clear(&s);
        if (fv_technique_render(t, &fr, film, &s, &err) != FV_OK)
            fail_msg("%s: frame %d of %d: %s", fv_technique_name_of(t), i, n, err.msg);
    }
    if (stats) *stats = s;
}

/* A technique of `method` with the parameters `list` (as fv_test_params_str) in scene s; fails the
 * test when it cannot be made. */
static inline fv_technique *fv_test_technique(const char *method, const char *list, const fv_scene *s)
{
    fv_params *p = fv_test_params_str(list);
    fv_technique *t = NULL;
    fv_error err;
    if (fv_technique_create(method, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s %s: %s", method, list, err.msg);
    fv_params_destroy(p);
    return t;
}

/* Creating `method` in scene s with the parameters `list` must be refused: FV_ERR_INVALID, a
 * one-line message naming `needle`, and no technique. */
static inline void fv_test_expect_refusal(const char *method, const char *list, const fv_scene *s, const char *needle)
{
    fv_params *p = fv_test_params_str(list);
    fv_technique *t = NULL;
    fv_error err;
    char what[256];
    snprintf(what, sizeof what, "%s %s", method, list);
    fv_test_expect_fail(fv_technique_create(method, s, p, NULL, &t, &err), &err, FV_ERR_INVALID, needle, what);
    if (t) fail_msg("%s: refused, yet a technique was made", what);
    fv_params_destroy(p);
}

/* One frame of t into film, its colour set to NaN first so that a pixel the technique does not
 * write cannot pass a comparison; *stats (cleared first) receives the frame's costs. */
static inline void fv_test_render_fresh(fv_technique *t, const fv_frame *f, fv_film *film, fv_stats *stats)
{
    fv_film_clear(film);
    float *col = fv_film_color(film);
    for (size_t k = 0, m = (size_t)3 * fv_film_width(film) * fv_film_height(film); k < m; k++) col[k] = NAN;
    fv_error err;
    fv_stats_clear(stats);
    if (fv_technique_render(t, f, film, stats, &err) != FV_OK) fail_msg("%s: frame %d: %s", fv_technique_name_of(t), f->index, err.msg);
}

/* Frame `index` of a stereo pair through cam[0] (left) and cam[1] (right) at `time` with `seed`;
 * `continues`: each eye's previous frame was through the same camera (a still pair's history). */
static inline void fv_test_stereo_frames(const fv_camera cam[2], double time, int index, uint64_t seed, bool continues, fv_frame f[2])
{
    for (int e = 0; e < 2; e++) {
        fv_frame_init(&f[e], &cam[e]);
        f[e].time = time;
        f[e].index = index;
        f[e].seed = seed;
        f[e].eye = e;
        f[e].eye_count = 2;
        f[e].prev_camera = continues ? &cam[e] : NULL;
    }
}

/* One frame (index 0, `seed`) of `method` with the parameters `list` (as fv_test_params_str) in
 * scene s through cam, into a new film the caller destroys. Fails the test on any error. */
static inline fv_film *fv_test_render_once(const char *method, const char *list, const fv_scene *s, const fv_camera *cam, uint64_t seed)
{
    fv_params *p = fv_test_params_str(list);
    fv_technique *t = NULL;
    fv_error err;
    if (fv_technique_create(method, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s: %s", method, err.msg);
    fv_film *film = NULL;
    if (fv_film_create(cam->width, cam->height, 0, &film, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_frame f;
    fv_frame_init(&f, cam);
    f.seed = seed;
    fv_test_render_frames(t, &f, 1, film, NULL);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return film;
}

/* One frame of `pt` (parameters as fv_test_params_str: spp, device, ...) in scene s through cam
 * at `time` after `frames` frames, with the first hit's depth, normal, albedo and id, into a new
 * film the caller destroys. Fails the test on any error, when no ray was counted, or on a
 * non-finite sample. */
static inline fv_film *fv_test_render_pt(const fv_scene *s, const fv_camera *cam, const char *params, double time, int frames, uint64_t seed)
{
    fv_params *p = fv_test_params_str(params);
    fv_technique *t = NULL;
    fv_error err;
    if (fv_technique_create("pt", s, p, NULL, &t, &err) != FV_OK) fail_msg("pt %s: %s", params, err.msg);
    fv_film *film = NULL;
    if (fv_film_create(cam->width, cam->height, FV_AUX_DEPTH | FV_AUX_NORMAL | FV_AUX_ALBEDO | FV_AUX_ID, &film, &err) != FV_OK)
        fail_msg("%s", err.msg);
    fv_frame f;
    fv_frame_init(&f, cam);
    f.seed = seed;
    f.time = time;
    fv_stats stats;
    fv_test_render_frames(t, &f, frames, film, &stats);
    if (fv_stats_get_count(&stats, "rays") <= 0.0) fail_msg("pt %s counted no rays", params);
    if (fv_stats_get_count(&stats, "nan_samples") != 0.0) fail_msg("pt %s: %g non-finite samples", params, fv_stats_get_count(&stats, "nan_samples"));
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return film;
}

/* ---- two renders of the same estimator ----
 *
 * How two films that drew the same random numbers differ (pt on the CPU, the portable backend and
 * CUDA): each channel's mean, the share of pixels equal within `tol` relative (or absolute below
 * 1e-6), and the RMS of the per-pixel difference relative to the image's mean. */
typedef struct fv_test_agreement {
    double mean_a[3], mean_b[3];
    double max_mean_rel; /* the largest |mean_b - mean_a| / mean_a over the channels */
    double equal_share;  /* pixels whose three channels agree within tol */
    double rms_rel;      /* sqrt(mean((b - a)^2)) / mean(a) over all channels */
} fv_test_agreement;

static inline fv_test_agreement fv_test_agree(const fv_film *a, const fv_film *b, double tol)
{
    fv_test_agreement r;
    memset(&r, 0, sizeof r);
    const float *ca = fv_film_color_const(a), *cb = fv_film_color_const(b);
    size_t n = (size_t)fv_film_width(a) * fv_film_height(a);
    double sq = 0.0, all = 0.0;
    size_t equal = 0;
    for (size_t i = 0; i < n; i++) {
        bool same = true;
        for (int c = 0; c < 3; c++) {
            double x = ca[3 * i + c], y = cb[3 * i + c];
            r.mean_a[c] += x;
            r.mean_b[c] += y;
            sq += (y - x) * (y - x);
            all += x;
            if (fabs(y - x) > tol * fabs(x) && fabs(y - x) > 1e-6) same = false;
        }
        equal += same;
    }
    for (int c = 0; c < 3; c++) {
        r.mean_a[c] /= (double)n;
        r.mean_b[c] /= (double)n;
        double rel = r.mean_a[c] > 0.0 ? fabs(r.mean_b[c] - r.mean_a[c]) / r.mean_a[c] : fabs(r.mean_b[c]);
        if (rel > r.max_mean_rel) r.max_mean_rel = rel;
    }
    r.equal_share = (double)equal / (double)n;
    double mean = all / (3.0 * (double)n);
    r.rms_rel = mean > 0.0 ? sqrt(sq / (3.0 * (double)n)) / mean : sqrt(sq / (3.0 * (double)n));
    return r;
}

#endif
