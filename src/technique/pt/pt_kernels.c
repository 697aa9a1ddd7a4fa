/* fovea — `pt`'s kernels, their portable side and descriptors (technique/pt/pt_kernels.h). */
#include "technique/pt/pt_kernels.h"

FV_PT_KERNELS(FV_KERNEL_DEFINE)
