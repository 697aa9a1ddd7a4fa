/* fovea — the blur's kernels, their portable side and descriptors (filter/blur_kernels.h). */
#include "filter/blur_kernels.h"

FV_BLUR_KERNELS(FV_KERNEL_DEFINE)
