/* fovea — `pt`'s kernels, their CUDA side (technique/pt/pt_kernels.h).
 *
 * Design (docs/gpu.md): a megakernel. Each thread runs its pixel's whole paths, the same function
 * the portable backend runs on the CPU, so the GPU's image equals the portable one up to float
 * rounding. A wavefront design (a queue of rays per bounce) would trade this sameness for
 * coherence; it is measured against this one before it replaces it. */
#include "device/cuda/kernel_cuda.h"
#include "technique/pt/pt_kernels.h"

FV_PT_KERNELS(FV_KERNEL_CUDA)
