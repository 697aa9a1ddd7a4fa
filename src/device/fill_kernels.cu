/* fovea — the fill kernels' CUDA side (device/fill_kernels.h). */
#include "device/cuda/kernel_cuda.h"
#include "device/fill_kernels.h"

FV_FILL_KERNELS(FV_KERNEL_CUDA)
