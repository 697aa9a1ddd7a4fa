/* fovea — the sphere-tracing family's kernels, their CUDA side (technique/sdf/sdf_kernels.h): a
 * thread a cell or pixel, the functions the portable backend runs on the CPU, so the GPU's image is
 * the portable one up to the last bits of powf and cosf (docs/gpu.md). */
#include "device/cuda/kernel_cuda.h"
#include "technique/sdf/sdf_kernels.h"

FV_SDF_KERNELS(FV_KERNEL_CUDA)
