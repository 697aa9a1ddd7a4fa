/* fovea — how the .cu files of device/cuda launch a kernel: FV_CUDA_LAUNCH(tally, kernel, grid, block, stream)(args...)
 * instead of CUDA's kernel<<<grid, block, 0, stream>>>(args...). Under nvcc it is exactly that
 * triple-chevron launch; in the CUDA simulator build (FOVEA_CUDA_SIM, docs/gpu.md "The CUDA
 * simulator") it runs the kernel on the host through sim/cuda_runtime.h. The chevrons are not C++, so every launch goes through this macro:
 * then the host compiler compiles the same .cu files and the tests execute their host code.
 *
 * stream: a cudaStream_t, or 0 for the default stream. The launches take no dynamic shared memory
 * (kernels declare __shared__ arrays of a fixed size); a kernel that needs it adds a macro here.
 */
#ifndef FV_DEVICE_CUDA_LAUNCH_H
#define FV_DEVICE_CUDA_LAUNCH_H

#include <cuda_runtime.h>

/* FV_CUDA_LAUNCH_NO_BARRIER counts nothing: for the launchers of declared kernels (device/cuda/
 * kernel_cuda.h), whose backend (device/cuda/backend.cu) counts the launch itself. It also promises
 * that the kernel never reaches __syncthreads: nvcc has no use for that, but the simulator then runs
 * a block's threads one after another on one OS thread instead of a thread each with a barrier among
 * them (far cheaper), and aborts if the kernel calls __syncthreads after all.
 * tally: the backend's fv_cuda_tally (device/cuda/common.h), which counts the launch. The count is
 * taken in a for statement's first clause that runs its body once, so the macro stays one
 * statement (safe under an if without braces) and nvcc still sees a plain launch. */
#if defined(__CUDACC__)
#define FV_CUDA_LAUNCH_NO_BARRIER(kernel, grid, block, stream) kernel<<<(grid), (block), 0, (stream)>>>
#define FV_CUDA_LAUNCH(tally, kernel, grid, block, stream) \
    for (int fv_launch_once_ = fv_cuda_launching(tally); fv_launch_once_; fv_launch_once_ = 0) kernel<<<(grid), (block), 0, (stream)>>>
#elif defined(FV_CUDA_SIM)
/* sim/cuda_runtime.h defines FV_CUDA_SIM and the launcher; the name and call site go into its
 * messages. */
#define FV_CUDA_LAUNCH_NO_BARRIER(kernel, grid, block, stream) \
    fv_cuda_sim::launch(kernel, #kernel, (grid), (block), (stream), __FILE__, __LINE__, true)
#define FV_CUDA_LAUNCH(tally, kernel, grid, block, stream)                                             \
    for (int fv_launch_once_ = fv_cuda_launching(tally); fv_launch_once_; fv_launch_once_ = 0) \
    fv_cuda_sim::launch(kernel, #kernel, (grid), (block), (stream), __FILE__, __LINE__)
#else
#error "device/cuda/*.cu are compiled by nvcc or, in the simulator build, with tests/cuda_sim first on the include path"
#endif

#endif
