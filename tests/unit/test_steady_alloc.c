/* A frame allocates nothing once warmed up (issue 29, docs/threads.md "No allocation in a frame"):
 * every registered method's frames (the registry, src/technique/registry.c, with each class's own
 * test_params, at 1 and 2 threads, the gaze moving every frame), and fpm-guided's with its lattice
 * filter, its A-Trous workspace and its kept photon paths, counted call by call; and the scratch
 * arena (core/scratch.h) that per-thread temporaries come from. This executable is linked with
 * `-Wl,--wrap` for malloc, calloc, realloc and aligned_alloc (tests/CMakeLists.txt), so every call
 * fovea's own code makes goes through the counters below first; the libraries it calls (Embree,
 * the OpenMP runtime) are not counted. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"
#include "core/scratch.h"
#include "technique/class.h"

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

/* Renders `frames` frames of a registered class at W x H in its conformance scene (cornell, or
 * sdf-primitives for a method that only sphere-traces fields) with its test_params; the gaze moves
 * every frame (foveation-dependent buffers see a new fovea each time); returns the allocations of
 * the frames after the first `warm`. */
static uint64_t class_frame_allocs(const fv_technique_class *c, int threads, int warm, int frames)
{
    enum { W = 32, H = 24 };
    fv_scene *s;
    fv_view *v;
    fv_error err;
    assert_int_equal(fv_scene_load(c->sdf_only ? "sdf-primitives" : "cornell", NULL, &s, &v, &err), FV_OK);
    fv_params *p = fv_test_params_str(c->test_params);
    fv_technique *t = NULL;
    if (fv_technique_create(c->name, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s: %s", c->name, err.msg);
    fv_params_destroy(p);
    fv_film *f;
    assert_int_equal(fv_film_create(W, H, 0, &f, &err), FV_OK);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, W, H, &cam);
    fv_stats stats;
    uint64_t before = 0;
    for (int i = 0; i < frames; i++) {
        if (i == warm) before = allocs();
        fv_frame fr;
        fv_frame_init(&fr, NULL);
        fr.camera = &cam;
        fr.prev_camera = i ? &cam : NULL;
        fr.index = i;
        fr.seed = 7;
        fr.threads = threads;
        /* a saccade-like path across the screen: no two frames share a gaze */
        fr.gaze = (fv_gaze){0.2f + 0.6f * (float)(i % 5) / 4.0f, 0.75f - 0.5f * (float)(i % 3) / 2.0f};
        fv_stats_clear(&stats);
        if (fv_technique_render(t, &fr, f, &stats, &err) != FV_OK) fail_msg("%s: %s", c->name, err.msg);
    }
    const uint64_t n = allocs() - before;
    fv_technique_destroy(t);
    fv_film_destroy(f);
    fv_view_destroy(v);
    fv_scene_destroy(s);
    return n;
}

/* Methods whose kept structures keep growing beyond four warm-up frames in this test (all of them
 * grown, never shrunk, so they stop once they hold what the frames need), each with the warm-up it
 * takes and why: the test checks four frames after that warm-up instead, and that the longer
 * warm-up is needed (frames 5 to 8 do allocate), so that the list stays true. */
typedef struct slow_warmup {
    const char *method, *why;
    int warm;
} slow_warmup;

static const slow_warmup k_slow[] = {
    /* Alg. 2 keeps the focus pixels' paths from frame to frame: with the gaze moving every frame,
     * the path pool and the foveated photon maps (M_fs, M_fd) fill over the first frames. */
    {"fpm", "the kept foveated paths' pool and maps fill over the first frames", 8},
};

static const slow_warmup *slow(const char *method)
{
    for (size_t i = 0; i < sizeof k_slow / sizeof k_slow[0]; i++)
        if (strcmp(k_slow[i].method, method) == 0) return &k_slow[i];
    return NULL;
}

/* Every registered method, at 1 and 2 threads: frames 5 to 8, after four warm-up frames (or the
 * four after a listed method's longer warm-up), make no allocation. Each method's count is
 * printed, and every method that allocates is named. */
static void test_registry_steady(void **st)
{
    (void)st;
    int bad = 0;
    for (int i = 0; i < fv_technique_count(); i++) {
        const fv_technique_class *c = fv_technique_class_at(i);
        const slow_warmup *k = slow(c->name);
        const int warm = k ? k->warm : 4;
        for (int threads = 1; threads <= 2; threads++) {
            const uint64_t n = class_frame_allocs(c, threads, warm, warm + 4);
            print_message("%-16s threads=%d  allocations in frames %d-%d: %llu\n", c->name, threads, warm + 1, warm + 4, (unsigned long long)n);
            if (n != 0) {
                print_error("%s, %d threads: %llu allocations in 4 warmed-up frames\n", c->name, threads, (unsigned long long)n);
                bad++;
            }
            if (k && class_frame_allocs(c, threads, 4, 8) == 0) {
                print_error("%s, %d threads: no allocation after 4 warm-up frames: take it off the slow list (%s)\n", c->name, threads, k->why);
                bad++;
            }
        }
    }
    for (size_t i = 0; i < sizeof k_slow / sizeof k_slow[0]; i++) assert_non_null(fv_technique_class_find(k_slow[i].method));
    assert_int_equal(bad, 0);
}

/* The arena the per-thread temporaries come from (core/scratch.h): a first piece larger than the
 * block spills (one allocation per take that does not fit), the next begin grows the block to the
 * piece's peak, and the same piece then allocates nothing; takes are 64-aligned and disjoint,
 * take_zero zeroes, and a release returns to the mark. */
static void test_scratch_arena(void **st)
{
    (void)st;
    fv_scratch s = FV_SCRATCH_INIT;
    for (int round = 0; round < 3; round++) {
        fv_scratch_begin(&s);
        const uint64_t a = allocs();
        float *x = fv_scratch_take(&s, 100, sizeof(float)); /* 400 bytes -> 448 */
        const size_t mark = fv_scratch_mark(&s);
        int *y = fv_scratch_take_zero(&s, 10, sizeof(int)); /* 40 -> 64 */
        assert_non_null(x);
        assert_non_null(y);
        assert_int_equal((uintptr_t)x % 64, 0);
        assert_int_equal((uintptr_t)y % 64, 0);
        for (int i = 0; i < 10; i++) assert_int_equal(y[i], 0);
        for (int i = 0; i < 100; i++) x[i] = (float)i;
        y[9] = 7;
        assert_true(x[99] == 99.0f); /* y does not overlap x */
        fv_scratch_release(&s, mark);
        int *z = fv_scratch_take(&s, 10, sizeof(int));
        /* round 0: both takes spilled (no block yet); later: from the block of 448 + 64 bytes,
         * where z reuses y's place */
        assert_int_equal(allocs() - a, round == 0 ? 3 : 0);
        if (round > 0) assert_ptr_equal(z, y);
        assert_true(s.cap >= 512 || round == 0);
    }
    fv_scratch_reserve(&s, 4096);
    assert_true(s.cap >= 4096);
    const uint64_t b = allocs();
    assert_non_null(fv_scratch_take(&s, 1000, sizeof(float)));
    assert_int_equal(allocs() - b, 0);
    assert_int_equal(fv_scratch_bytes(1, 1), 64);
    assert_int_equal(fv_scratch_bytes(65, 1), 128);
    assert_null(fv_scratch_take(&s, SIZE_MAX / 2, 4)); /* overflow: refused, not wrapped */
    fv_scratch_free(&s);
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
        cmocka_unit_test(test_scratch_arena),
        cmocka_unit_test(test_fpm_guided_steady),
        cmocka_unit_test(test_registry_steady),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
