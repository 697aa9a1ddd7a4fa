/* fovea — what tests/gpu check beyond their images when they run on the CUDA simulator (their
 * sim_test_* build, FOVEA_CUDA_SIM; docs/gpu.md "The CUDA simulator"), where nothing else can
 * count them: the host's synchronizes and the kernels launched over a stretch of work, that the
 * backend's own count of its runtime calls is what the simulator saw, that
 * destroying the techniques freed every device allocation, stream and event, and that every
 * allocation's failure is handled (a GPU that is full). On a real GPU (or without CUDA) the checks
 * compile to nothing. Include after <cmocka.h> and fovea/fovea.h.
 */
#ifndef FV_TESTS_GPU_SIM_CHECKS_H
#define FV_TESTS_GPU_SIM_CHECKS_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#ifdef FOVEA_CUDA_SIM
#include "fv_cuda_sim.h"

/* An image side of a CUDA-against-portable comparison. On a GPU the tests' sizes are the ones their
 * bounds were chosen for (the share of pixels a last-bit difference of the GPU's powf or sinf may
 * move). The simulator runs the kernels on the CPU with the C library's functions, so its images
 * equal the portable ones exactly at any size, and every launch, copy, counter and host wait is
 * the same at half the side: a quarter of the pixels, at a quarter of the cost of the suite's
 * slowest tests under the sanitizers. Halving also leaves partial 8x8 blocks at the edges of the
 * sizes that are multiples of 8, which the full sizes never had. */
#define FV_SIM_SIDE(n) ((n) / 2)

/* The simulator always has its device: a test that finds none fails rather than skips. */
#define FV_GPU_TEST_NO_DEVICE 1

typedef fv_cuda_sim_counts fv_sim_mark;

static inline fv_sim_mark fv_sim_now(void)
{
    fv_sim_mark m;
    fv_cuda_sim_counts_get(&m);
    return m;
}

/* Since `since`: exactly `syncs` synchronize calls (the frame's designed waits: one a frame or a
 * pair), `launches` kernel launches (< 0: any number, > 0), and no upload from pageable memory
 * queued behind a kernel of its stream. The other waits CUDA makes (every copy between the device
 * and pageable memory) are checked against what the backend reports (fv_sim_expect_reported) and
 * per family in test_gpu_counts. */
static inline void fv_sim_expect(fv_sim_mark since, uint64_t syncs, long launches, const char *what)
{
    fv_sim_mark now = fv_sim_now();
    uint64_t c = now.syncs - since.syncs, l = now.launches - since.launches;
    printf("%s: CUDA simulator: %llu synchronizes, %llu host waits, %llu launches, %llu blocks\n", what, (unsigned long long)c,
           (unsigned long long)(now.host_waits - since.host_waits), (unsigned long long)l, (unsigned long long)(now.blocks - since.blocks));
    if (c != syncs) fail_msg("%s: the host synchronized %llu times, expected %llu", what, (unsigned long long)c, (unsigned long long)syncs);
    const uint64_t u = now.uploads_behind_kernels - since.uploads_behind_kernels;
    if (u) fail_msg("%s: %llu host-to-device copies queued behind a kernel of their stream (a hidden host wait mid-frame)", what, (unsigned long long)u);
    if (launches >= 0 ? l != (uint64_t)launches : l == 0)
        fail_msg("%s: %llu kernel launches, expected %ld", what, (unsigned long long)l, launches);
}

/* Pinned host ranges not yet freed (cudaHostAlloc's): what a frame's read-back slots hold. */
static inline uint64_t fv_sim_live_pinned(void) { return fv_sim_now().live_pinned; }

/* Since `since`, what the simulator counted equals what the backend reported in `stats` (its own
 * count of its calls, fv_cuda_calls: the figures --stats-json shows on a GPU): launches, host waits,
 * pageable copies, bytes each way, device allocations and frees. So no runtime call escapes the
 * backend's count, and its count follows CUDA's rules as the simulator does. */
static inline void fv_sim_expect_reported(fv_sim_mark since, const fv_stats *stats, const char *what)
{
    const fv_sim_mark now = fv_sim_now();
    const struct {
        const char *key;
        uint64_t sim;
    } c[] = {{"launches", now.launches - since.launches},
             {"host_waits", now.host_waits - since.host_waits},
             {"pageable_copies", now.pageable_copies - since.pageable_copies},
             {"h2d_bytes", now.bytes_h2d - since.bytes_h2d},
             {"d2h_bytes", now.bytes_d2h - since.bytes_d2h},
             {"device_allocs", now.allocations - since.allocations},
             {"device_frees", now.frees - since.frees}};
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++)
        if (fv_stats_get_count(stats, c[i].key) != (double)c[i].sim)
            fail_msg("%s: the backend reports %s %g, the simulator counted %llu", what, c[i].key, fv_stats_get_count(stats, c[i].key),
                     (unsigned long long)c[i].sim);
}

/* Since `since`: exactly `calls` synchronize calls (stream, event or device). The host waits above
 * are counted with one flag for the whole device, so two synchronizes back to back (a stream each)
 * read as one wait; this counts each. */
static inline void fv_sim_expect_sync_calls(fv_sim_mark since, uint64_t calls, const char *what)
{
    const uint64_t c = fv_sim_now().syncs - since.syncs;
    if (c != calls) fail_msg("%s: %llu synchronize calls, expected %llu", what, (unsigned long long)c, (unsigned long long)calls);
}

static inline void fv_sim_expect_freed(const char *what)
{
    fv_sim_mark m = fv_sim_now();
    if (m.live_allocations || m.live_streams || m.live_events)
        fail_msg("%s: after destroy, %llu device allocations (%llu bytes), %llu streams and %llu events are left", what,
                 (unsigned long long)m.live_allocations, (unsigned long long)m.live_bytes, (unsigned long long)m.live_streams,
                 (unsigned long long)m.live_events);
}
/* Fills every device allocation in turn: runs run(ctx) with the n-th cudaMalloc failing, for
 * n = 0, 1, ... until a run makes fewer allocations. Each run that met its failure must fail
 * cleanly: a status of FV_ERR_NOMEM or FV_ERR_INTERNAL, a message that names CUDA, and nothing
 * left allocated once run has destroyed what it created; the last run must succeed. run returns
 * the first status that was not FV_OK (with err set). Returns the allocations walked. */
typedef fv_status (*fv_sim_run_fn)(void *ctx, fv_error *err);

static inline int fv_sim_walk_allocation_failures(fv_sim_run_fn run, void *ctx, const char *what)
{
    for (int64_t n = 0; n < 1000; n++) {
        const fv_sim_mark m = fv_sim_now();
        fv_error err;
        memset(&err, 0, sizeof err);
        fv_cuda_sim_fail_allocation(n);
        const fv_status s = run(ctx, &err);
        fv_cuda_sim_fail_allocation(-1);
        const bool met = fv_sim_now().injected_failures != m.injected_failures;
        fv_sim_expect_freed(what);
        if (!met) {
            if (s != FV_OK) fail_msg("%s: failed with no allocation failing: %s", what, err.msg);
            printf("%s: each of %lld device allocations failed in turn, cleanly\n", what, (long long)n);
            return (int)n;
        }
        if (s == FV_OK) fail_msg("%s: device allocation %lld failed, yet the run succeeded", what, (long long)n);
        if ((s != FV_ERR_NOMEM && s != FV_ERR_INTERNAL) || !strstr(err.msg, "CUDA"))
            fail_msg("%s: device allocation %lld failed: status %d, \"%s\"", what, (long long)n, (int)s, err.msg);
    }
    fail_msg("%s: more than 1000 device allocations", what);
    return -1;
}
/* A run for fv_sim_walk_allocation_failures: `method` with `params` created on s, then `frames`
 * frames of cam (at `time`) rendered into a film with auxiliary buffers, then all destroyed. */
typedef struct fv_sim_frames {
    const fv_scene *scene;
    const fv_camera *cam;
    const char *method, *params;
    int frames;
    double time;
} fv_sim_frames;

static inline fv_status fv_sim_run_frames(void *ctx, fv_error *err)
{
    const fv_sim_frames *r = (const fv_sim_frames *)ctx;
    fv_params *p = fv_test_params_str(r->params);
    fv_technique *t = NULL;
    fv_film *film = NULL;
    fv_status s = fv_technique_create(r->method, r->scene, p, NULL, &t, err);
    if (s == FV_OK) s = fv_film_create(r->cam->width, r->cam->height, FV_AUX_DEPTH | FV_AUX_NORMAL | FV_AUX_ID, &film, err);
    for (int i = 0; s == FV_OK && i < r->frames; i++) {
        fv_frame f;
        fv_frame_init(&f, r->cam);
        f.seed = 3;
        f.index = i;
        f.time = r->time;
        f.prev_camera = i > 0 ? r->cam : NULL;
        fv_stats stats;
        fv_stats_clear(&stats);
        s = fv_technique_render(t, &f, film, &stats, err);
    }
    if (film) fv_film_destroy(film);
    if (t) fv_technique_destroy(t);
    fv_params_destroy(p);
    return s;
}
#else
#define FV_GPU_TEST_NO_DEVICE 77 /* ctest: skipped */
#define FV_SIM_SIDE(n) (n)
typedef int fv_sim_mark;
static inline fv_sim_mark fv_sim_now(void) { return 0; }
static inline uint64_t fv_sim_live_pinned(void) { return 0; }
static inline void fv_sim_expect(fv_sim_mark since, uint64_t syncs, long launches, const char *what)
{
    (void)since, (void)syncs, (void)launches, (void)what;
}
static inline void fv_sim_expect_reported(fv_sim_mark since, const fv_stats *stats, const char *what)
{
    (void)since, (void)stats, (void)what;
}
static inline void fv_sim_expect_sync_calls(fv_sim_mark since, uint64_t calls, const char *what)
{
    (void)since, (void)calls, (void)what;
}
static inline void fv_sim_expect_freed(const char *what) { (void)what; }
#endif

#endif
