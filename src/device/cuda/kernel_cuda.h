/* fovea — the CUDA side of a kernel declared once (device/kernel_decl.h): FV_KERNEL_CUDA expands a
 * family's table entry into its __global__ kernel and launcher; device/cuda/backend.cu calls the
 * launcher. Included by the families' .cu files only (nvcc, or the CUDA simulator's C++ build).
 */
#ifndef FV_DEVICE_CUDA_KERNEL_CUDA_H
#define FV_DEVICE_CUDA_KERNEL_CUDA_H

#include <cuda_runtime.h>
#include <stdint.h>
#include "device/cuda/launch.h"
#include "device/kernel_decl.h"

/* A kernel's launcher: items w x h, args its argument struct (copied into the launch), counts
 * device memory for its counters (NULL: none). */
struct fv_kernel_cuda {
    void (*launch)(const void *args, int w, int h, unsigned long long *counts, cudaStream_t st);
};

#define FV_KERNEL_CUDA_BLOCK_2D 8   /* 8 x 8 items: neighbouring pixels, whose rays start coherent */
#define FV_KERNEL_CUDA_BLOCK_1D 256

/* The block's sum of every thread's n counters, added once into counts. Every thread of the block
 * reaches both barriers (no thread returns early in FV_KERNEL_CUDA). */
template <int N> __device__ __forceinline__ void fv_cuda_kernel_sum(const uint64_t *c, unsigned long long *counts)
{
    if (N == 0 || !counts) return; /* the same for every thread of the launch */
    __shared__ unsigned long long sum[N > 0 ? N : 1];
    const int tid = (int)(threadIdx.y * blockDim.x + threadIdx.x);
    if (tid < N) sum[tid] = 0;
    __syncthreads();
    for (int i = 0; i < N; i++)
        if (c[i]) atomicAdd(&sum[i], (unsigned long long)c[i]);
    __syncthreads();
    if (tid < N && sum[tid]) atomicAdd(&counts[tid], sum[tid]);
}

#define FV_KERNEL_CUDA(name, args_t, fn, dims_, ncounts_)                                                          \
    __global__ void name##_global(args_t a_, int w_, int h_, unsigned long long *counts_)                         \
    {                                                                                                              \
        const int x_ = (int)(blockIdx.x * blockDim.x + threadIdx.x), y_ = (int)(blockIdx.y * blockDim.y + threadIdx.y); \
        uint64_t c_[(ncounts_) > 0 ? (ncounts_) : 1] = {0}; /* its own counters only: no stack for the others */ \
        if (x_ < w_ && y_ < h_) fn(&a_, x_, y_, c_);                                                               \
        fv_cuda_kernel_sum<(ncounts_)>(c_, counts_);                                                               \
    }                                                                                                              \
    static void name##_launch(const void *args_, int w_, int h_, unsigned long long *counts_, cudaStream_t st_)  \
    {                                                                                                              \
        const unsigned b_ = (dims_) == 1 ? FV_KERNEL_CUDA_BLOCK_1D : FV_KERNEL_CUDA_BLOCK_2D;                       \
        const dim3 block_(b_, (dims_) == 1 ? 1u : b_);                                                                                                    \
        const dim3 grid_((unsigned)(((unsigned)w_ + block_.x - 1) / block_.x), (unsigned)(((unsigned)h_ + block_.y - 1) / block_.y)); \
        FV_CUDA_LAUNCH_PLAIN(name##_global, grid_, block_, st_)(*(const args_t *)args_, w_, h_, counts_);          \
    }                                                                                                              \
    extern "C" const fv_kernel_cuda name##_cuda = {name##_launch};

#endif
