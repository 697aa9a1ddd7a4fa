/* fovea — the sphere-tracing family's kernels, their portable side and descriptors (technique/sdf/sdf_kernels.h). */
#include "technique/sdf/sdf_kernels.h"

FV_SDF_KERNELS(FV_KERNEL_DEFINE)
