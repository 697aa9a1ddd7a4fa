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

/* A kernel's launcher (its launches are barrier-free: the item functions never reach
 * __syncthreads, and the simulator relies on it, device/cuda/launch.h): items w x h, args its argument struct (copied into the launch), counts
 * device memory for its counters (NULL: none). */
struct fv_kernel_cuda {
    void (*launch)(const void *args, int w, int h, unsigned long long *counts, cudaStream_t st);
};

#define FV_KERNEL_CUDA_BLOCK_2D 8   /* 8 x 8 items: neighbouring pixels, whose rays start coherent */
#define FV_KERNEL_CUDA_BLOCK_1D 256

/* The arguments are __grid_constant__: the item function takes their address, and without it nvcc
 * copies the whole struct (a flat scene's header, a frame) into each thread's local memory; with it
 * the thread reads the launch's constant bank. A thread beyond the items returns at once, and its
 * counters go to the launch's with one atomic each where not zero. Measured with ptxas on pt's kernel
 * (sm_90, nvcc 13): 159 registers and 2,656 B of stack, against 192 / 3,136 with the struct copied
 * and 171 / 2,672 when every thread stays for a block-wide sum in shared memory (the bounds check
 * then wraps the item and more stays live across it): 12 warps an SM against 8. Summing a warp's
 * counters before the atomic is left to the kernels' own tuning (issue "lean kernels"). */
template <int N> __device__ __forceinline__ void fv_cuda_kernel_add(const uint64_t *c, unsigned long long *counts)
{
    for (int i = 0; i < N; i++)
        if (c[i]) atomicAdd(&counts[i], (unsigned long long)c[i]);
}

#define FV_KERNEL_CUDA(name, args_t, fn, dims_, ncounts_)                                                          \
    __global__ void name##_global(const __grid_constant__ args_t a_, int w_, int h_, unsigned long long *counts_) \
    {                                                                                                              \
        const int x_ = (int)(blockIdx.x * blockDim.x + threadIdx.x), y_ = (int)(blockIdx.y * blockDim.y + threadIdx.y); \
        if (x_ >= w_ || y_ >= h_) return;                                                                          \
        uint64_t c_[(ncounts_) > 0 ? (ncounts_) : 1] = {0}; /* its own counters only: no stack for the others */ \
        fn(&a_, x_, y_, c_);                                                                                       \
        if ((ncounts_) > 0) fv_cuda_kernel_add<(ncounts_)>(c_, counts_);                                           \
    }                                                                                                              \
    static void name##_launch(const void *args_, int w_, int h_, unsigned long long *counts_, cudaStream_t st_)  \
    {                                                                                                              \
        const unsigned b_ = (dims_) == 1 ? FV_KERNEL_CUDA_BLOCK_1D : FV_KERNEL_CUDA_BLOCK_2D;                       \
        const dim3 block_(b_, (dims_) == 1 ? 1u : b_);                                                           \
        const dim3 grid_((unsigned)(((unsigned)w_ + block_.x - 1) / block_.x), (unsigned)(((unsigned)h_ + block_.y - 1) / block_.y)); \
        FV_CUDA_LAUNCH_NO_BARRIER(name##_global, grid_, block_, st_)(*(const args_t *)args_, w_, h_, counts_);     \
    }                                                                                                              \
    extern "C" const fv_kernel_cuda name##_cuda = {name##_launch};

#endif
