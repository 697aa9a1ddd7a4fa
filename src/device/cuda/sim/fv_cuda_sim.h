/* fovea — what the CUDA simulator (device/cuda/sim/cuda_runtime.h) counted, for the tests that run
 * the CUDA backend on it (tests/gpu, built a second time as sim_test_gpu_*): C, so that the C tests
 * can read it. Exists only in the test-only library fovea_sim.
 */
#ifndef FV_CUDA_SIM_COUNTS_H
#define FV_CUDA_SIM_COUNTS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_cuda_sim_counts {
    uint64_t launches;   /* kernels launched (with a valid shape) */
    uint64_t blocks;     /* blocks run */
    uint64_t syncs;      /* cudaStreamSynchronize, cudaEventSynchronize, cudaDeviceSynchronize calls */
    uint64_t host_waits; /* calls that made the host wait for queued device work (see cuda_runtime.h) */
    uint64_t live_allocations; /* device allocations not yet freed */
    uint64_t live_bytes;
    uint64_t live_streams, live_events;
    uint64_t injected_failures; /* allocations failed by fv_cuda_sim_fail_allocation */
    uint64_t uploads_behind_kernels; /* cudaMemcpyAsync host to device queued behind a kernel launched on
                                      * its stream since the host last waited: from pageable memory
                                      * CUDA may make the host wait for that kernel first */
} fv_cuda_sim_counts;

/* The counts since the process started (the live ones: now). */
void fv_cuda_sim_counts_get(fv_cuda_sim_counts *out);

/* Makes the n-th cudaMalloc from now (0: the next) fail with cudaErrorMemoryAllocation, as a full
 * GPU would; n < 0 cancels. So a test can walk every allocation's failure path in turn. */
void fv_cuda_sim_fail_allocation(int64_t n);

#ifdef __cplusplus
}
#endif
#endif
