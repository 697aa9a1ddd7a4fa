/* The CUDA simulator's own checks (tests/cuda_sim, docs/gpu.md "The CUDA simulator"), so that
 * sim_test_gpu_* can trust it: kernels written as for nvcc and launched with FV_CUDA_LAUNCH.
 *
 *   cuda_sim_selftest          every thread of every block runs once with its own indices, on the
 *                              pool and in a barrier-free launch (one thread after another); a block
 *                              reduction in shared memory with several __syncthreads per thread
 *                              gives the hand-computed sums; a kernel's launches alternate the
 *                              order of their blocks; an impossible launch shape is an error
 *                              for cudaGetLastError and runs nothing, a failed call's error is
 *                              kept there too (out of memory); host waits are counted as CUDA
 *                              makes the host wait (a synchronize after queued work, every copy
 *                              with pageable memory; pinned memory's copies are queued), and the
 *                              backends' own count agrees; SIMT efficiency of a kernel worked by
 *                              hand; events time; everything freed.
 *   cuda_sim_selftest CASE     one misuse the simulator must abort on with its message (ctest
 *                              matches the message: tests/CMakeLists.txt).
 */
#include <stdio.h>
#include <string.h>
#include "cuda_runtime.h"
#include "device/cuda/common.h"
#include "device/cuda/launch.h"
#include "kernel/ksimt.h"
#include "fv_cuda_sim.h"

#define CHECK(cond)                                                                  \
    do {                                                                             \
        if (!(cond)) {                                                               \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
            return 1;                                                                \
        }                                                                            \
    } while (0)

/* Each thread writes its global linear index into its own cell and counts itself. */
__global__ void whoami(unsigned *cell, unsigned *hits, unsigned n)
{
    const unsigned bx = blockIdx.x + gridDim.x * (blockIdx.y + gridDim.y * blockIdx.z);
    const unsigned tx = threadIdx.x + blockDim.x * (threadIdx.y + blockDim.y * threadIdx.z);
    const unsigned i = bx * (blockDim.x * blockDim.y * blockDim.z) + tx;
    if (i < n) {
        cell[i] = i;
        atomicAdd(hits, 1u);
    }
}

/* A tree reduction of 256 values a block: wrong without a real barrier between the steps. */
__global__ void block_sum(const unsigned *in, unsigned long long *out)
{
    __shared__ unsigned long long part[256];
    const unsigned t = threadIdx.x;
    part[t] = in[blockIdx.x * 256 + t];
    __syncthreads();
    for (unsigned half = 128; half > 0; half /= 2) {
        if (t < half) part[t] += part[t + half];
        __syncthreads();
    }
    if (t == 0) out[blockIdx.x] = part[0];
}

/* The order the blocks ran in: block b's turn, from a counter thread 0 of each block takes. */
__global__ void turn(unsigned *next, unsigned *order)
{
    if (threadIdx.x == 0) order[blockIdx.x] = atomicAdd(next, 1u);
}

/* Misuse: threads of one block reach __syncthreads unequally. */
__global__ void divergent_barrier(int *x)
{
    if (threadIdx.x == 3) return;
    __syncthreads();
    x[threadIdx.x] = 1;
}

/* Lane t of a block counts t % 32 sphere-tracing steps in its first warp and 4 in the others. */
__global__ void simt_steps(void)
{
    const unsigned t = threadIdx.x;
    const unsigned n = t < 32 ? t : 4;
    for (unsigned i = 0; i < n; i++) FV_SIMT_STEP(FV_SIMT_MARCH);
}

static int selftest(void)
{
    fv_cuda_tally tally = {};
    fv_cuda_sim_counts c0;
    fv_cuda_sim_counts_get(&c0);

    /* indices: a 3-D grid of 3-D blocks, 5 x 3 x 2 blocks of 4 x 3 x 2 threads = 720, n = 700 */
    const unsigned n = 700;
    unsigned *cell = nullptr, *hits = nullptr;
    CHECK(cudaMalloc((void **)&cell, n * sizeof(unsigned)) == cudaSuccess);
    CHECK(cudaMalloc((void **)&hits, sizeof(unsigned)) == cudaSuccess);
    CHECK(cudaMemset(hits, 0, sizeof(unsigned)) == cudaSuccess);
    FV_CUDA_LAUNCH(&tally, whoami, dim3(5, 3, 2), dim3(4, 3, 2), 0)(cell, hits, n);
    CHECK(cudaGetLastError() == cudaSuccess);
    static unsigned host[700];
    unsigned h = 0;
    CHECK(cudaMemcpy(host, cell, sizeof host, cudaMemcpyDeviceToHost) == cudaSuccess);
    CHECK(cudaMemcpy(&h, hits, sizeof h, cudaMemcpyDeviceToHost) == cudaSuccess);
    CHECK(h == n);
    for (unsigned i = 0; i < n; i++) CHECK(host[i] == i);
    /* the same launch barrier-free: the threads in turn on this thread, each once, with its indices */
    CHECK(cudaMemset(hits, 0, sizeof(unsigned)) == cudaSuccess && cudaMemset(cell, 0, n * sizeof(unsigned)) == cudaSuccess);
    FV_CUDA_LAUNCH_NO_BARRIER(whoami, dim3(5, 3, 2), dim3(4, 3, 2), 0)(cell, hits, n);
    CHECK(cudaGetLastError() == cudaSuccess);
    CHECK(cudaMemcpy(host, cell, sizeof host, cudaMemcpyDeviceToHost) == cudaSuccess);
    CHECK(cudaMemcpy(&h, hits, sizeof h, cudaMemcpyDeviceToHost) == cudaSuccess);
    CHECK(h == n);
    for (unsigned i = 0; i < n; i++) CHECK(host[i] == i);

    /* the reduction: block b sums b * 256 + t for t < 256 = 65536 b + 32640 */
    const unsigned blocks = 6;
    static unsigned in[6 * 256];
    for (unsigned i = 0; i < blocks * 256; i++) in[i] = i;
    unsigned *din = nullptr;
    unsigned long long *dout = nullptr;
    CHECK(cudaMalloc((void **)&din, sizeof in) == cudaSuccess);
    CHECK(cudaMalloc((void **)&dout, blocks * sizeof(unsigned long long)) == cudaSuccess);
    cudaStream_t st;
    CHECK(cudaStreamCreate(&st) == cudaSuccess);
    CHECK(cudaMemcpyAsync(din, in, sizeof in, cudaMemcpyHostToDevice, st) == cudaSuccess);
    FV_CUDA_LAUNCH(&tally, block_sum, blocks, 256, st)(din, dout);
    /* into pinned memory the copy is queued: the synchronize is the wait */
    unsigned long long *sums = nullptr;
    CHECK(cudaHostAlloc((void **)&sums, 6 * sizeof *sums, cudaHostAllocDefault) == cudaSuccess);
    cudaPointerAttributes pa;
    CHECK(cudaPointerGetAttributes(&pa, sums + 1) == cudaSuccess && pa.type == cudaMemoryTypeHost);
    CHECK(cudaPointerGetAttributes(&pa, in) == cudaSuccess && pa.type == cudaMemoryTypeUnregistered);
    CHECK(cudaPointerGetAttributes(&pa, dout) == cudaSuccess && pa.type == cudaMemoryTypeDevice);
    CHECK(cudaMemcpyAsync(sums, dout, 6 * sizeof *sums, cudaMemcpyDeviceToHost, st) == cudaSuccess);
    fv_cuda_sim_counts c1;
    fv_cuda_sim_counts_get(&c1);
    /* whoami's two read-backs twice and the upload of in, all pageable: five waits */
    CHECK(c1.host_waits == c0.host_waits + 5 && c1.pageable_copies == c0.pageable_copies + 5);
    CHECK(c1.bytes_h2d == c0.bytes_h2d + sizeof in && c1.bytes_d2h == c0.bytes_d2h + 2 * (n * sizeof(unsigned) + sizeof h) + 6 * sizeof *sums);
    CHECK(cudaStreamSynchronize(st) == cudaSuccess);
    fv_cuda_sim_counts c2;
    fv_cuda_sim_counts_get(&c2);
    CHECK(c2.host_waits == c1.host_waits + 1); /* the work queued since the last wait */
    CHECK(cudaStreamSynchronize(st) == cudaSuccess);
    fv_cuda_sim_counts c3;
    fv_cuda_sim_counts_get(&c3);
    CHECK(c3.host_waits == c2.host_waits && c3.syncs == c2.syncs + 1); /* nothing queued: no wait */
    /* into pageable memory the copy itself is a wait, queued work or not, and leaves none queued */
    unsigned long long pageable[6];
    FV_CUDA_LAUNCH(&tally, block_sum, blocks, 256, st)(din, dout);
    CHECK(cudaMemcpyAsync(pageable, dout, sizeof pageable, cudaMemcpyDeviceToHost, st) == cudaSuccess);
    CHECK(cudaMemcpyAsync(pageable, dout, sizeof pageable, cudaMemcpyDeviceToHost, st) == cudaSuccess);
    CHECK(cudaStreamSynchronize(st) == cudaSuccess);
    fv_cuda_sim_counts c4;
    fv_cuda_sim_counts_get(&c4);
    CHECK(c4.host_waits == c3.host_waits + 2 && c4.pageable_copies == c3.pageable_copies + 2 && c4.syncs == c3.syncs + 1);
    CHECK(memcmp(pageable, sums, sizeof pageable) == 0);
    /* the backends' own count (device/cuda/common.h) follows the same rules */
    const fv_cuda_calls t0 = tally.n;
    FV_CUDA_LAUNCH(&tally, block_sum, blocks, 256, st)(din, dout);
    CHECK(fv_cuda_copy(&tally, pageable, dout, sizeof pageable, cudaMemcpyDeviceToHost, st) == cudaSuccess);
    CHECK(fv_cuda_copy(&tally, sums, dout, 6 * sizeof *sums, cudaMemcpyDeviceToHost, st) == cudaSuccess);
    CHECK(fv_cuda_wait(&tally, st) == cudaSuccess);
    fv_cuda_sim_counts c5;
    fv_cuda_sim_counts_get(&c5);
    CHECK(tally.n.launches == t0.launches + 1 && tally.n.pageable_copies == t0.pageable_copies + 1 && tally.n.syncs == t0.syncs + 1);
    CHECK(tally.n.host_waits - t0.host_waits == c5.host_waits - c4.host_waits && tally.n.host_waits == t0.host_waits + 2);
    CHECK(tally.n.bytes_d2h - t0.bytes_d2h == c5.bytes_d2h - c4.bytes_d2h);
    for (unsigned b = 0; b < blocks; b++) CHECK(sums[b] == 65536ull * b + 32640ull);
    CHECK(cudaFreeHost(sums) == cudaSuccess);
    /* registered memory is pinned until unregistered */
    CHECK(cudaHostRegister(pageable, sizeof pageable, cudaHostRegisterDefault) == cudaSuccess);
    CHECK(cudaPointerGetAttributes(&pa, pageable + 5) == cudaSuccess && pa.type == cudaMemoryTypeHost);
    CHECK(cudaHostUnregister(pageable) == cudaSuccess);
    CHECK(cudaPointerGetAttributes(&pa, pageable) == cudaSuccess && pa.type == cudaMemoryTypeUnregistered);

    /* SIMT efficiency, worked by hand: a block of 40 threads is a full warp whose lanes count 0..31
     * steps (496 useful, 32 x 31 = 992 paid) and a warp of 8 lanes counting 4 each (32 useful, the
     * warp's 32 lanes x 4 = 128 paid): 528 / 1120 in all */
    fv_cuda_sim_simt_reset();
    FV_CUDA_LAUNCH(&tally, simt_steps, 1, 40, 0)();
    FV_CUDA_LAUNCH(&tally, simt_steps, 2, 40, 0)();
    fv_cuda_sim_simt sr[4];
    CHECK(fv_cuda_sim_simt_get(sr, 4) == 1 && !strcmp(sr[0].kernel, "simt_steps") && sr[0].launches == 2 && sr[0].threads_per_block == 40);
    CHECK(sr[0].warps == 6 && sr[0].lane_total == 3 * 528 && sr[0].warp_total == 3 * 1120);
    CHECK(sr[0].lane_steps[FV_SIMT_MARCH] == 3 * 528 && sr[0].warp_steps[FV_SIMT_MARCH] == 3 * 1120 && sr[0].warp_steps[FV_SIMT_TRAVERSE] == 0);
    /* barrier-free, the threads run in turn but each counts apart: the same figures */
    fv_cuda_sim_simt_reset();
    FV_CUDA_LAUNCH_NO_BARRIER(simt_steps, 1, 40, 0)();
    FV_CUDA_LAUNCH_NO_BARRIER(simt_steps, 2, 40, 0)();
    CHECK(fv_cuda_sim_simt_get(sr, 4) == 1 && sr[0].launches == 2 && sr[0].threads_per_block == 40);
    CHECK(sr[0].warps == 6 && sr[0].lane_total == 3 * 528 && sr[0].warp_total == 3 * 1120);
    CHECK(sr[0].lane_steps[FV_SIMT_MARCH] == 3 * 528 && sr[0].warp_steps[FV_SIMT_MARCH] == 3 * 1120 && sr[0].warp_steps[FV_SIMT_TRAVERSE] == 0);
    fv_cuda_sim_simt_reset();
    CHECK(fv_cuda_sim_simt_get(sr, 4) == 0);

    /* an impossible shape: an error for cudaGetLastError (then cleared), and nothing runs */
    CHECK(cudaMemset(hits, 0, sizeof(unsigned)) == cudaSuccess);
    FV_CUDA_LAUNCH(&tally, whoami, 1, 2048, 0)(cell, hits, n);
    CHECK(cudaGetLastError() == cudaErrorInvalidConfiguration);
    CHECK(cudaGetLastError() == cudaSuccess);
    FV_CUDA_LAUNCH(&tally, whoami, 0, 64, 0)(cell, hits, n);
    CHECK(cudaPeekAtLastError() == cudaErrorInvalidConfiguration);
    CHECK(cudaGetLastError() == cudaErrorInvalidConfiguration);
    CHECK(cudaMemcpy(&h, hits, sizeof h, cudaMemcpyDeviceToHost) == cudaSuccess);
    CHECK(h == 0);

    /* a kernel's launches run their blocks first to last, then last to first, and so on (CUDA
     * promises no order: a block that reads what another of its launch writes is caught) */
    unsigned order[4], *dorder = nullptr;
    CHECK(cudaMalloc((void **)&dorder, sizeof order) == cudaSuccess);
    for (unsigned run = 0; run < 2; run++) {
        CHECK(cudaMemset(hits, 0, sizeof(unsigned)) == cudaSuccess);
        FV_CUDA_LAUNCH(&tally, turn, 4, 32, 0)(hits, dorder);
        CHECK(cudaMemcpy(order, dorder, sizeof order, cudaMemcpyDeviceToHost) == cudaSuccess);
        for (unsigned b = 0; b < 4; b++) CHECK(order[b] == (run == 0 ? b : 3 - b));
    }
    /* barrier-free launches alternate too (the kernel's count of launches is shared: the third) */
    for (unsigned run = 0; run < 2; run++) {
        CHECK(cudaMemset(hits, 0, sizeof(unsigned)) == cudaSuccess);
        FV_CUDA_LAUNCH_NO_BARRIER(turn, 4, 32, 0)(hits, dorder);
        CHECK(cudaMemcpy(order, dorder, sizeof order, cudaMemcpyDeviceToHost) == cudaSuccess);
        for (unsigned b = 0; b < 4; b++) CHECK(order[b] == (run == 0 ? b : 3 - b));
    }
    CHECK(cudaFree(dorder) == cudaSuccess);

    /* any call that fails leaves its error for cudaGetLastError, as CUDA does: an allocation out of
     * memory too (so a backend clears it before the launches it checks, device/cuda/common.h) */
    void *none = &h;
    fv_cuda_sim_fail_allocation(0);
    CHECK(cudaMalloc(&none, 16) == cudaErrorMemoryAllocation && none == nullptr);
    CHECK(cudaPeekAtLastError() == cudaErrorMemoryAllocation);
    CHECK(cudaGetLastError() == cudaErrorMemoryAllocation);
    CHECK(cudaGetLastError() == cudaSuccess);

    /* events: unrecorded is an error, recorded ones time */
    cudaEvent_t a, b;
    CHECK(cudaEventCreate(&a) == cudaSuccess && cudaEventCreate(&b) == cudaSuccess);
    float ms = -1.0f;
    CHECK(cudaEventElapsedTime(&ms, a, b) == cudaErrorInvalidResourceHandle);
    CHECK(cudaGetLastError() == cudaErrorInvalidResourceHandle);
    CHECK(cudaEventRecord(a, st) == cudaSuccess && cudaEventRecord(b, st) == cudaSuccess);
    CHECK(cudaEventSynchronize(b) == cudaSuccess);
    CHECK(cudaEventElapsedTime(&ms, a, b) == cudaSuccess && ms >= 0.0f);

    int count = 0;
    cudaDeviceProp p;
    CHECK(cudaGetDeviceCount(&count) == cudaSuccess && count == 1);
    CHECK(cudaGetDeviceProperties(&p, 0) == cudaSuccess && p.major == 9 && strstr(p.name, "simulator"));
    CHECK(cudaGetDeviceProperties(&p, 1) == cudaErrorInvalidDevice);
    CHECK(cudaGetLastError() == cudaErrorInvalidDevice);

    CHECK(cudaEventDestroy(a) == cudaSuccess && cudaEventDestroy(b) == cudaSuccess);
    CHECK(cudaStreamDestroy(st) == cudaSuccess);
    CHECK(cudaFree(cell) == cudaSuccess && cudaFree(hits) == cudaSuccess && cudaFree(din) == cudaSuccess && cudaFree(dout) == cudaSuccess);
    CHECK(cudaFree(nullptr) == cudaSuccess);
    fv_cuda_sim_counts e;
    fv_cuda_sim_counts_get(&e);
    CHECK(e.live_allocations == 0 && e.live_bytes == 0 && e.live_streams == 0 && e.live_events == 0 && e.live_pinned == 0);
    CHECK(e.launches == c0.launches + 8 + 5);  /* the two impossible ones are not launches */
    CHECK(e.blocks == c0.blocks + 2 * 30 + 3 * 6 + 2 * (1 + 2) + 4 * 4);
    CHECK(e.allocations == c0.allocations + 5 && e.frees == c0.frees + 5); /* cell, hits, din, dout, dorder */
    printf("CUDA simulator self-test: passed\n");
    return 0;
}

/* Each misuse case; the simulator aborts in it (returning is a failure). */
static int misuse(const char *what)
{
    fv_cuda_tally tally = {};
    void *p = nullptr;
    char host[128];
    if (cudaMalloc(&p, 64) != cudaSuccess) return 1;
    if (!strcmp(what, "copy-past-end")) cudaMemcpy(p, host, 65, cudaMemcpyHostToDevice);
    else if (!strcmp(what, "copy-offset-past-end")) cudaMemcpy(host, (char *)p + 32, 40, cudaMemcpyDeviceToHost);
    else if (!strcmp(what, "copy-wrong-kind")) cudaMemcpy(p, host, 16, cudaMemcpyDeviceToHost);
    else if (!strcmp(what, "memset-host")) cudaMemset(host, 0, 16);
    else if (!strcmp(what, "free-unknown")) cudaFree(host);
    else if (!strcmp(what, "free-twice")) {
        cudaFree(p);
        cudaFree(p);
    } else if (!strcmp(what, "free-offset")) cudaFree((char *)p + 8);
    else if (!strcmp(what, "leak")) return 0; /* p is never freed: the check at exit aborts */
    else if (!strcmp(what, "divergent-barrier")) FV_CUDA_LAUNCH(&tally, divergent_barrier, 1, 16, 0)((int *)p);
    else if (!strcmp(what, "barrier-in-no-barrier-launch")) FV_CUDA_LAUNCH_NO_BARRIER(divergent_barrier, 2, dim3(4, 2), 0)((int *)p);
    else if (!strcmp(what, "destroyed-stream")) {
        cudaStream_t s;
        cudaStreamCreate(&s);
        cudaStreamDestroy(s);
        cudaMemsetAsync(p, 0, 16, s);
    } else {
        fprintf(stderr, "unknown case %s\n", what);
        return 1;
    }
    fprintf(stderr, "the simulator let %s pass\n", what);
    return 1;
}

int main(int argc, char **argv) { return argc > 1 ? misuse(argv[1]) : selftest(); }
