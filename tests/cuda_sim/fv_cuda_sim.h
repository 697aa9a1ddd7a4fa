/* fovea — what the CUDA simulator (tests/cuda_sim/cuda_runtime.h) counted, for the tests that run
 * the CUDA backend on it (tests/gpu, built a second time as sim_test_gpu_*): C, so that the C tests
 * can read it. Exists only in the test-only library fovea_sim.
 */
#ifndef FV_CUDA_SIM_COUNTS_H
#define FV_CUDA_SIM_COUNTS_H

#include <stddef.h>
#include <stdint.h>
#include "kernel/ksimt.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_cuda_sim_counts {
    uint64_t launches;   /* kernels launched (with a valid shape) */
    uint64_t blocks;     /* blocks run */
    uint64_t syncs;      /* cudaStreamSynchronize, cudaEventSynchronize, cudaDeviceSynchronize calls */
    uint64_t host_waits; /* calls that made the host wait for the device (see cuda_runtime.h): a
                          * synchronize or a cudaFree after queued work, a synchronous copy, and
                          * every copy between the device and pageable host memory */
    uint64_t pageable_copies; /* copies between the device and pageable (not pinned) host memory */
    uint64_t bytes_h2d, bytes_d2h; /* copied host to device, device to host */
    uint64_t allocations, frees;   /* cudaMalloc and cudaFree calls that took or gave back memory */
    uint64_t live_allocations; /* device allocations not yet freed */
    uint64_t live_bytes;
    uint64_t live_streams, live_events;
    uint64_t live_pinned;      /* pinned or registered host ranges not yet freed or unregistered */
    uint64_t injected_failures; /* device or pinned allocations failed by fv_cuda_sim_fail_allocation */
    uint64_t uploads_behind_kernels; /* cudaMemcpyAsync host to device from pageable memory queued
                                      * behind a kernel launched on its stream since the host last
                                      * waited: the host waits for that kernel first, mid-frame */
} fv_cuda_sim_counts;

/* The counts since the process started (the live ones: now). */
void fv_cuda_sim_counts_get(fv_cuda_sim_counts *out);

/* Makes the n-th cudaMalloc or cudaHostAlloc from now (0: the next) fail with
 * cudaErrorMemoryAllocation, as a full GPU (or pinned memory run out) would; n < 0 cancels. So a test can walk every allocation's failure path in turn. */
void fv_cuda_sim_fail_allocation(int64_t n);

/* SIMT efficiency of one kernel over its launches since the last reset (kernel/ksimt.h): the
 * iterations the lanes counted, and what the warps paid for them (32 x each warp's busiest lane),
 * per kind and in all (a lane's kinds summed). A kernel whose loops count nothing has zeros. */
typedef struct fv_cuda_sim_simt {
    char kernel[64];
    uint64_t launches, warps;
    unsigned threads_per_block; /* of its last launch */
    uint64_t lane_steps[FV_SIMT_KINDS], warp_steps[FV_SIMT_KINDS];
    uint64_t lane_total, warp_total;
} fv_cuda_sim_simt;

/* Copies the records of up to n kernels, by name, into out; returns how many kernels have one. */
size_t fv_cuda_sim_simt_get(fv_cuda_sim_simt *out, size_t n);
void fv_cuda_sim_simt_reset(void);

#ifdef __cplusplus
}
#endif
#endif
