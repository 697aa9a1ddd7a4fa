/* fovea — the Visual-Polar family's kernels, their CUDA side (technique/vpolar/vpolar_kernels.h):
 * the functions the portable backend runs on the CPU, a thread a cell or a pixel (8 x 8 blocks,
 * whose camera rays start coherent), so the GPU's image equals the portable one up to float
 * rounding and the traversal's last bits. */
#include "device/cuda/kernel_cuda.h"
#include "technique/vpolar/vpolar_kernels.h"

FV_VP_KERNELS(FV_KERNEL_CUDA)
