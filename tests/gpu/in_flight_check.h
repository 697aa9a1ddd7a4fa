/* fovea — a short sequence rendered frame by frame (fv_technique_render / _render_pair) and again
 * pipelined (fv_technique_submit of frame i+1 before fv_technique_collect of frame i, two sets of
 * films and stats, docs/gpu.md "Frames in flight"): every frame's colour must be byte-identical and
 * its counters the same. Shared by tests/unit/test_in_flight.c (portable, cpu) and
 * tests/gpu/test_gpu_counts.c (cuda; on the CUDA simulator also: no synchronize within a submit,
 * one within a collect, and the backend's counts of submit plus collect are the simulator's).
 * Include after <cmocka.h>, fovea/fovea.h, ../unit/testkit.h and sim_checks.h.
 */
#ifndef FV_TESTS_GPU_IN_FLIGHT_CHECK_H
#define FV_TESTS_GPU_IN_FLIGHT_CHECK_H

#define FV_IN_FLIGHT_MAX_FRAMES 6

/* Counters compared between the two ways (those a frame reports on every device; the timings
 * differ). */
static const char *const k_in_flight_keys[] = {"rays",      "samples",    "nan_samples",     "launches",  "host_waits",
                                               "h2d_bytes", "d2h_bytes",  "pageable_copies", "device_allocs", "device_frees"};

typedef struct fv_in_flight_case {
    const char *method, *scene, *params; /* params: e.g. "spp=1 device=portable" */
    float sep;                           /* > 0: stereo pairs with the eyes this far apart */
    int w, h, frames;
} fv_in_flight_case;

/* The frames of case c at index i: a still view, gaze moving. */
static inline void fv_in_flight_frames(const fv_in_flight_case *c, const fv_camera cam[2], int i, fv_frame f[2])
{
    fv_test_stereo_frames(cam, 0.0, i, 7, i > 0, f);
    for (int e = 0; e < 2; e++) f[e].gaze = (fv_gaze){0.4f + 0.05f * (float)i, 0.5f};
    if (c->sep <= 0.0f) f[0].eye_count = 1;
}

static inline void fv_in_flight_check(const fv_in_flight_case *c)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(c->scene, &s, &v) != 0) fail_msg("cannot load %s", c->scene);
    fv_camera centre, cam[2];
    fv_view_camera(v, s, 0.0, c->w, c->h, &centre);
    cam[0] = cam[1] = centre;
    if (c->sep > 0.0f) fv_camera_stereo(&centre, c->sep, &cam[0], &cam[1]);
    const int eyes = c->sep > 0.0f ? 2 : 1;
    const size_t n = (size_t)3 * c->w * c->h;
    float *want = malloc((size_t)FV_IN_FLIGHT_MAX_FRAMES * 2 * n * sizeof(float));
    if (!want || c->frames > FV_IN_FLIGHT_MAX_FRAMES) fail_msg("in-flight check: %d frames", c->frames);
    fv_stats want_stats[FV_IN_FLIGHT_MAX_FRAMES];
    fv_film *film[2][2] = {{NULL, NULL}, {NULL, NULL}};
    fv_error err;
    for (int k = 0; k < 2; k++)
        for (int e = 0; e < eyes; e++)
            if (fv_film_create(c->w, c->h, 0, &film[k][e], &err) != FV_OK) fail_msg("%s", err.msg);
    char what[200];
    snprintf(what, sizeof what, "%s %s [%s] %s", c->method, c->scene, c->params, eyes == 2 ? "stereo" : "mono");

    /* frame by frame */
    fv_technique *t = fv_test_technique(c->method, c->params, s);
    for (int i = 0; i < c->frames; i++) {
        fv_frame f[2];
        fv_in_flight_frames(c, cam, i, f);
        fv_stats_clear(&want_stats[i]);
        const fv_status rs = eyes == 2 ? fv_technique_render_pair(t, f, film[0], &want_stats[i], &err)
                                       : fv_technique_render(t, &f[0], film[0][0], &want_stats[i], &err);
        if (rs != FV_OK) fail_msg("%s: frame %d: %s", what, i, err.msg);
        for (int e = 0; e < eyes; e++) memcpy(want + ((size_t)i * 2 + e) * n, fv_film_color_const(film[0][e]), n * sizeof(float));
    }
    fv_technique_destroy(t);

    /* pipelined: frame i+1 submitted before frame i is collected */
    t = fv_test_technique(c->method, c->params, s);
    fv_stats got[2];
    fv_frame f[2][2];
    for (int i = 0; i <= c->frames; i++) {
        const int k = i % 2;
        if (i < c->frames) {
            fv_in_flight_frames(c, cam, i, f[k]);
            fv_stats_clear(&got[k]);
            const fv_sim_mark m = fv_sim_now();
            if (fv_technique_submit(t, eyes, f[k], film[k], &got[k], &err) != FV_OK) fail_msg("%s: submit %d: %s", what, i, err.msg);
            fv_sim_expect_sync_calls(m, 0, what); /* nothing waited for in a submit */
            if (fv_technique_in_flight(t) != (i == 0 ? 1 : 2)) fail_msg("%s: %d frames in flight after submit %d", what, fv_technique_in_flight(t), i);
        }
        if (i == 0) continue;
        const int j = i - 1, kj = j % 2;
        const fv_sim_mark m = fv_sim_now();
        if (fv_technique_collect(t, &err) != FV_OK) fail_msg("%s: collect %d: %s", what, j, err.msg);
        fv_sim_expect_sync_calls(m, 1, what); /* one wait, for frame j only */
        for (int e = 0; e < eyes; e++)
            if (memcmp(want + ((size_t)j * 2 + e) * n, fv_film_color_const(film[kj][e]), n * sizeof(float)) != 0)
                fail_msg("%s: frame %d eye %d differs from the frame rendered alone", what, j, e);
        for (size_t q = 0; q < sizeof k_in_flight_keys / sizeof k_in_flight_keys[0]; q++)
            if (fv_stats_get_count(&got[kj], k_in_flight_keys[q]) != fv_stats_get_count(&want_stats[j], k_in_flight_keys[q]))
                fail_msg("%s: frame %d: %s %g, rendered alone %g", what, j, k_in_flight_keys[q], fv_stats_get_count(&got[kj], k_in_flight_keys[q]),
                         fv_stats_get_count(&want_stats[j], k_in_flight_keys[q]));
    }
    if (fv_technique_in_flight(t) != 0) fail_msg("%s: frames left in flight", what);
    printf("%s: %d frames pipelined, byte-identical to frame by frame\n", what, c->frames);
    fv_technique_destroy(t);
    for (int k = 0; k < 2; k++)
        for (int e = 0; e < 2; e++) fv_film_destroy(film[k][e]);
    free(want);
    fv_view_destroy(v);
    fv_scene_destroy(s);
    fv_sim_expect_freed(what);
}

#endif
