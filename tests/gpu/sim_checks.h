/* fovea — what tests/gpu check beyond their images when they run on the CUDA simulator (their
 * sim_test_* build, FOVEA_CUDA_SIM; docs/gpu.md "The CUDA simulator"), where nothing else can
 * count them: the host's waits for the device and the kernels launched over a stretch of work, and
 * that destroying the techniques freed every device allocation, stream and event. On a real GPU
 * (or without CUDA) the checks compile to nothing. Include after <cmocka.h>.
 */
#ifndef FV_TESTS_GPU_SIM_CHECKS_H
#define FV_TESTS_GPU_SIM_CHECKS_H

#include <stdint.h>

#ifdef FOVEA_CUDA_SIM
#include "device/cuda/sim/fv_cuda_sim.h"

/* The simulator always has its device: a test that finds none fails rather than skips. */
#define FV_GPU_TEST_NO_DEVICE 1

typedef fv_cuda_sim_counts fv_sim_mark;

static inline fv_sim_mark fv_sim_now(void)
{
    fv_sim_mark m;
    fv_cuda_sim_counts_get(&m);
    return m;
}

/* Since `since`: exactly `waits` host waits, and `launches` kernel launches (< 0: any number, > 0). */
static inline void fv_sim_expect(fv_sim_mark since, uint64_t waits, long launches, const char *what)
{
    fv_sim_mark now = fv_sim_now();
    uint64_t w = now.host_waits - since.host_waits, l = now.launches - since.launches;
    printf("%s: CUDA simulator: %llu host waits, %llu launches, %llu blocks\n", what, (unsigned long long)w, (unsigned long long)l,
           (unsigned long long)(now.blocks - since.blocks));
    if (w != waits) fail_msg("%s: the host waited for the device %llu times, expected %llu", what, (unsigned long long)w, (unsigned long long)waits);
    if (launches >= 0 ? l != (uint64_t)launches : l == 0)
        fail_msg("%s: %llu kernel launches, expected %ld", what, (unsigned long long)l, launches);
}

static inline void fv_sim_expect_freed(const char *what)
{
    fv_sim_mark m = fv_sim_now();
    if (m.live_allocations || m.live_streams || m.live_events)
        fail_msg("%s: after destroy, %llu device allocations (%llu bytes), %llu streams and %llu events are left", what,
                 (unsigned long long)m.live_allocations, (unsigned long long)m.live_bytes, (unsigned long long)m.live_streams,
                 (unsigned long long)m.live_events);
}
#else
#define FV_GPU_TEST_NO_DEVICE 77 /* ctest: skipped */
typedef int fv_sim_mark;
static inline fv_sim_mark fv_sim_now(void) { return 0; }
static inline void fv_sim_expect(fv_sim_mark since, uint64_t waits, long launches, const char *what)
{
    (void)since, (void)waits, (void)launches, (void)what;
}
static inline void fv_sim_expect_freed(const char *what) { (void)what; }
#endif

#endif
