/* A frame allocates nothing once warmed up (issue 29, docs/threads.md "No allocation in a frame"):
 * fpm-guided's frames, with its lattice filter, its A-Trous workspace and its kept photon paths,
 * counted call by call. This executable is linked with `-Wl,--wrap` for malloc, calloc, realloc
 * and aligned_alloc (tests/CMakeLists.txt), so every call fovea's own code makes goes through the
 * counters below first; the libraries it calls (Embree, the OpenMP runtime) are not counted. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"

/* The test's own count (this executable's, not the library's): calls by any thread. */
static uint64_t g_allocs;

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t n);
void *__real_aligned_alloc(size_t align, size_t n);
void *__wrap_malloc(size_t n)
{
    __atomic_add_fetch(&g_allocs, 1, __ATOMIC_RELAXED);
    return __real_malloc(n);
}
void *__wrap_calloc(size_t n, size_t size)
{
    __atomic_add_fetch(&g_allocs, 1, __ATOMIC_RELAXED);
    return __real_calloc(n, size);
}
void *__wrap_realloc(void *p, size_t n)
{
    __atomic_add_fetch(&g_allocs, 1, __ATOMIC_RELAXED);
    return __real_realloc(p, n);
}
void *__wrap_aligned_alloc(size_t align, size_t n)
{
    __atomic_add_fetch(&g_allocs, 1, __ATOMIC_RELAXED);
    return __real_aligned_alloc(align, n);
}

static uint64_t allocs(void) { return __atomic_load_n(&g_allocs, __ATOMIC_RELAXED); }

/* Renders `frames` frames of method on scene at a still camera, gaze and time (the scene's dynamic
 * objects are still there, so kept photon paths are refreshed near them every frame); returns the
 * allocations of the frames after the first `warm`. */
static uint64_t frame_allocs(const char *scene, const char *method, const char *const *kv, int threads, int warm, int frames)
{
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load(scene, NULL, &s, &v, &err), FV_OK);
    fv_params *p = fv_test_params(kv);
    fv_technique *t = NULL;
    if (fv_technique_create(method, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_params_destroy(p);
    fv_film *f;
    assert_int_equal(fv_film_create(40, 30, 0, &f, &err), FV_OK);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 40, 30, &cam);
    fv_stats stats;
    uint64_t before = 0;
    for (int i = 0; i < frames; i++) {
        if (i == warm) before = allocs();
        fv_frame fr;
        fv_frame_init(&fr, NULL);
        fr.camera = &cam;
        fr.prev_camera = i ? &cam : NULL;
        fr.index = i;
        fr.seed = 5;
        fr.threads = threads;
        fr.gaze = (fv_gaze){0.4f, 0.6f};
        fv_stats_clear(&stats);
        if (fv_technique_render(t, &fr, f, &stats, &err) != FV_OK) fail_msg("%s", err.msg);
    }
    const uint64_t n = allocs() - before;
    fv_technique_destroy(t);
    fv_film_destroy(f);
    fv_view_destroy(v);
    fv_scene_destroy(s);
    return n;
}

/* The wrap is in place: a film fovea makes is counted (its struct and its buffers). */
static void test_counter_counts(void **st)
{
    (void)st;
    const uint64_t a = allocs();
    fv_film *f;
    fv_error err;
    assert_int_equal(fv_film_create(8, 8, 0, &f, &err), FV_OK);
    assert_true(allocs() - a >= 1);
    fv_film_destroy(f);
}

/* fpm-guided at 1 and 2 threads, its periphery on a lattice (filtered and filled) and its focus
 * region filtered: after warm-up frames (the paths traced, buffers grown), none of four frames
 * allocates. */
static void test_fpm_guided_steady(void **st)
{
    (void)st;
    const char *kv[] = {"photons=4000", NULL};
    for (int threads = 1; threads <= 2; threads++) assert_int_equal(frame_allocs("cornell-fpm", "fpm-guided", kv, threads, 4, 8), 0);
    const char *coarse[] = {"photons=4000", "periphery_step=3", "acuity_levels=2", "focus_passes=2", NULL};
    assert_int_equal(frame_allocs("cornell-fpm", "fpm-guided", coarse, 2, 4, 8), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counter_counts),
        cmocka_unit_test(test_fpm_guided_steady),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
