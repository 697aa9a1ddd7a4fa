/* fovea — the display kernel's CUDA side (device/display_kernels.h). */
#include "device/cuda/kernel_cuda.h"
#include "device/display_kernels.h"

FV_DISPLAY_KERNELS(FV_KERNEL_CUDA)
