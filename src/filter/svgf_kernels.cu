/* fovea — SVGF's kernels, their CUDA side (filter/svgf_kernels.h). */
#include "device/cuda/kernel_cuda.h"
#include "filter/svgf_kernels.h"

FV_SVGF_KERNELS(FV_KERNEL_CUDA)
