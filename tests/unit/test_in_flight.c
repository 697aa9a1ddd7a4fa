/* Frames in flight (fovea/technique.h, fv_technique_submit / fv_technique_collect): a short
 * sequence pipelined is byte-identical to the frames rendered one by one, on the portable backend
 * (pt, fipr, vpolar: the device frames with two staging slots) and for methods that render in
 * submit (pt and vpolar on the cpu); misuse is refused; a cancelled submit leaves the frame before it
 * collectable and nothing of its own in flight; a technique destroyed with frames in flight leaks
 * nothing (ASan). The same check runs on the CUDA simulator in tests/gpu/test_gpu_counts.c. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"
#include "../gpu/sim_checks.h"
#include "../gpu/in_flight_check.h"

static void test_sequences(void **st)
{
    (void)st;
    static const fv_in_flight_case cases[] = {
        {"pt", "cornell", "spp=1 device=portable", 64.0f, 24, 16, 4},
        {"pt", "cornell", "spp=1", 0.0f, 24, 16, 3},
        {"fipr", "sdf-temple", "spp=1 device=portable", 0.064f, 24, 16, 4},
        {"vpolar", "cornell", "device=portable", 64.0f, 24, 16, 4},
        {"vpolar", "cornell", "", 0.0f, 24, 16, 3},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) fv_in_flight_check(&cases[i]);
}

static bool stop_at_once(void *user, double fraction)
{
    (void)user, (void)fraction;
    return false;
}

static void test_refusals_and_cancel(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load("cornell", &s, &v) != 0) fail_msg("cannot load cornell");
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 16, 12, &cam);
    fv_film *film[3] = {NULL, NULL, NULL}, *small = NULL;
    fv_error err;
    for (int k = 0; k < 3; k++)
        if (fv_film_create(16, 12, 0, &film[k], &err) != FV_OK) fail_msg("%s", err.msg);
    if (fv_film_create(8, 8, 0, &small, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_technique *t = fv_test_technique("pt", "spp=1 device=portable", s);
    fv_frame f[3];
    for (int i = 0; i < 3; i++) {
        fv_frame_init(&f[i], &cam);
        f[i].index = i;
        f[i].prev_camera = i ? &cam : NULL;
        f[i].seed = 5;
    }
    fv_stats stats[3];
    for (int i = 0; i < 3; i++) fv_stats_clear(&stats[i]);

    fv_test_expect_fail(fv_technique_collect(t, &err), &err, FV_ERR_INVALID, "no submitted frame", "collect with none");
    fv_test_expect_fail(fv_technique_submit(t, 3, f, film, &stats[0], &err), &err, FV_ERR_INVALID, "3 eyes", "three eyes");
    fv_test_expect_fail(fv_technique_submit(t, 1, f, &small, &stats[0], &err), &err, FV_ERR_INVALID, "camera size", "a film of another size");
    if (fv_technique_in_flight(t) != 0) fail_msg("a refused submit left a frame in flight");

    /* frame 0 in flight; frame 1 cancelled at once: frame 0 still collectable, frame 1 not */
    if (fv_technique_submit(t, 1, &f[0], &film[0], &stats[0], &err) != FV_OK) fail_msg("submit 0: %s", err.msg);
    fv_test_expect_fail(fv_technique_render(t, &f[0], film[2], &stats[2], &err), &err, FV_ERR_INVALID, "not collected", "render in flight");
    fv_frame cancelled = f[1];
    cancelled.progress = stop_at_once;
    fv_test_expect_fail(fv_technique_submit(t, 1, &cancelled, &film[1], &stats[1], &err), &err, FV_ERR_CANCELLED, "cancelled", "cancelled submit");
    if (fv_technique_in_flight(t) != 1) fail_msg("%d frames in flight after a cancelled submit, expected 1", fv_technique_in_flight(t));
    if (fv_technique_collect(t, &err) != FV_OK) fail_msg("collect 0 after a cancelled submit: %s", err.msg);
    fv_film *alone = fv_test_render_once("pt", "spp=1 device=portable", s, &cam, 5);
    if (memcmp(fv_film_color_const(alone), fv_film_color_const(film[0]), (size_t)3 * 16 * 12 * sizeof(float)) != 0)
        fail_msg("frame 0, collected after frame 1 was cancelled, differs from frame 0 rendered alone");
    fv_film_destroy(alone);

    /* two in flight, a third refused, then destroyed with both in flight (nothing leaks) */
    for (int i = 0; i < 2; i++)
        if (fv_technique_submit(t, 1, &f[i], &film[i], &stats[i], &err) != FV_OK) fail_msg("submit %d: %s", i, err.msg);
    fv_test_expect_fail(fv_technique_submit(t, 1, &f[2], &film[2], &stats[2], &err), &err, FV_ERR_INVALID, "in flight already", "third submit");
    fv_technique_destroy(t);

    for (int k = 0; k < 3; k++) fv_film_destroy(film[k]);
    fv_film_destroy(small);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_sequences), cmocka_unit_test(test_refusals_and_cancel)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
