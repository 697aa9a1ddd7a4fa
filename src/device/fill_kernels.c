/* fovea — the fill kernels' portable side and descriptors (device/fill_kernels.h). */
#include "device/fill_kernels.h"

FV_FILL_KERNELS(FV_KERNEL_DEFINE)
