/* fovea — the display kernel's portable side and descriptor (device/display_kernels.h). */
#include "device/display_kernels.h"

FV_DISPLAY_KERNELS(FV_KERNEL_DEFINE)
