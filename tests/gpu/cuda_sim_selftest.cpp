/* The CUDA simulator's own checks (src/device/cuda/sim, docs/gpu.md "The CUDA simulator"), so that
 * sim_test_gpu_* can trust it: kernels written as for nvcc and launched with FV_CUDA_LAUNCH.
 *
 *   cuda_sim_selftest          every thread of every block runs once with its own indices; a block
 *                              reduction in shared memory with several __syncthreads per thread
 *                              gives the hand-computed sums; a kernel's launches alternate the
 *                              order of their blocks; an impossible launch shape is an error
 *                              for cudaGetLastError and runs nothing, a failed call's error is
 *                              kept there too (out of memory); host waits are counted only
 *                              when work was queued; events time; everything freed.
 *   cuda_sim_selftest CASE     one misuse the simulator must abort on with its message (ctest
 *                              matches the message: tests/CMakeLists.txt).
 */
#include <stdio.h>
#include <string.h>
#include "cuda_runtime.h"
#include "device/cuda/launch.h"
#include "device/cuda/sim/fv_cuda_sim.h"

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

static int selftest(void)
{
    fv_cuda_sim_counts c0;
    fv_cuda_sim_counts_get(&c0);

    /* indices: a 3-D grid of 3-D blocks, 5 x 3 x 2 blocks of 4 x 3 x 2 threads = 720, n = 700 */
    const unsigned n = 700;
    unsigned *cell = nullptr, *hits = nullptr;
    CHECK(cudaMalloc((void **)&cell, n * sizeof(unsigned)) == cudaSuccess);
    CHECK(cudaMalloc((void **)&hits, sizeof(unsigned)) == cudaSuccess);
    CHECK(cudaMemset(hits, 0, sizeof(unsigned)) == cudaSuccess);
    FV_CUDA_LAUNCH(whoami, dim3(5, 3, 2), dim3(4, 3, 2), 0)(cell, hits, n);
    CHECK(cudaGetLastError() == cudaSuccess);
    static unsigned host[700];
    unsigned h = 0;
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
    FV_CUDA_LAUNCH(block_sum, blocks, 256, st)(din, dout);
    unsigned long long sums[6];
    CHECK(cudaMemcpyAsync(sums, dout, sizeof sums, cudaMemcpyDeviceToHost, st) == cudaSuccess);
    fv_cuda_sim_counts c1;
    fv_cuda_sim_counts_get(&c1);
    CHECK(cudaStreamSynchronize(st) == cudaSuccess);
    fv_cuda_sim_counts c2;
    fv_cuda_sim_counts_get(&c2);
    CHECK(c2.host_waits == c1.host_waits + 1); /* the work queued since the last wait */
    CHECK(cudaStreamSynchronize(st) == cudaSuccess);
    fv_cuda_sim_counts c3;
    fv_cuda_sim_counts_get(&c3);
    CHECK(c3.host_waits == c2.host_waits && c3.syncs == c2.syncs + 1); /* nothing queued: no wait */
    for (unsigned b = 0; b < blocks; b++) CHECK(sums[b] == 65536ull * b + 32640ull);

    /* an impossible shape: an error for cudaGetLastError (then cleared), and nothing runs */
    CHECK(cudaMemset(hits, 0, sizeof(unsigned)) == cudaSuccess);
    FV_CUDA_LAUNCH(whoami, 1, 2048, 0)(cell, hits, n);
    CHECK(cudaGetLastError() == cudaErrorInvalidConfiguration);
    CHECK(cudaGetLastError() == cudaSuccess);
    FV_CUDA_LAUNCH(whoami, 0, 64, 0)(cell, hits, n);
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
        FV_CUDA_LAUNCH(turn, 4, 32, 0)(hits, dorder);
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
    CHECK(e.live_allocations == 0 && e.live_bytes == 0 && e.live_streams == 0 && e.live_events == 0);
    CHECK(e.launches == c0.launches + 4);  /* the two impossible ones are not launches */
    CHECK(e.blocks == c0.blocks + 30 + 6 + 2 * 4);
    printf("CUDA simulator self-test: passed\n");
    return 0;
}

/* Each misuse case; the simulator aborts in it (returning is a failure). */
static int misuse(const char *what)
{
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
    else if (!strcmp(what, "divergent-barrier")) FV_CUDA_LAUNCH(divergent_barrier, 1, 16, 0)((int *)p);
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
