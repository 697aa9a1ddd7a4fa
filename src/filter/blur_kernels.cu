/* fovea — the blur's kernels, their CUDA side (filter/blur_kernels.h). */
#include "device/cuda/kernel_cuda.h"
#include "filter/blur_kernels.h"

FV_BLUR_KERNELS(FV_KERNEL_CUDA)
