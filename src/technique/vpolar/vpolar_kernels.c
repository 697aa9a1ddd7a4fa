/* fovea — the Visual-Polar family's kernels, their portable side and descriptors
 * (technique/vpolar/vpolar_kernels.h). */
#include "technique/vpolar/vpolar_kernels.h"

FV_VP_KERNELS(FV_KERNEL_DEFINE)
