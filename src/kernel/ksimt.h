/* fovea — SIMT probes: where a kernel's main loops count their iterations, so that the CUDA
 * simulator can say how much of each warp does useful work (docs/gpu.md, "SIMT efficiency").
 *
 * A GPU runs 32 threads of a block as one warp in lock step: a warp takes as many iterations of a
 * loop as its busiest lane, and the other lanes idle meanwhile. Counting, per lane, the iterations
 * of the loops where a kernel spends its time (traversal steps, sphere-tracing steps, samples,
 * bounces) gives the warp's useful share without a GPU: lane iterations / (32 x the warp's
 * largest), summed over warps. The simulator groups each block's threads into warps as the
 * hardware does (linear thread index, x fastest) and keeps the sums per kernel.
 *
 * FV_SIMT_STEP(kind) counts one iteration of the calling lane. It is code only in the simulator's
 * build (FV_CUDA_SIM, the .cu files compiled as C++): under nvcc and in the CPU's C build it is
 * nothing, so the kernels and their registers are exactly what they were.
 */
#ifndef FV_KERNEL_KSIMT_H
#define FV_KERNEL_KSIMT_H

/* What a count is an iteration of. */
enum fv_simt_kind {
    FV_SIMT_TRAVERSE = 0, /* a BVH node visited (kernel/ktraverse.h, top and bottom level) */
    FV_SIMT_MARCH,        /* a sphere-tracing step: one field evaluation along a ray (technique/sdf/kmarch.h) */
    FV_SIMT_SAMPLE,       /* a pixel's or cell's sample (a camera ray and its path) */
    FV_SIMT_BOUNCE,       /* a path's segment (kernel/kpath_impl.h) */
    FV_SIMT_KINDS
};

#if defined(FV_CUDA_SIM)
/* tests/cuda_sim/runtime.cpp: adds one to the calling simulated thread's count; nothing outside a
 * kernel. */
void fv_cuda_sim_simt_step(int kind);
#define FV_SIMT_STEP(kind) fv_cuda_sim_simt_step(kind)
#else
#define FV_SIMT_STEP(kind) ((void)0)
#endif

#endif
