/* fovea — kernels every family may use, declared once (device/kernel_decl.h): a float array set to
 * one value (a byte clear cannot write +inf, say, for "no surface yet" depths). */
#ifndef FV_DEVICE_FILL_KERNELS_H
#define FV_DEVICE_FILL_KERNELS_H

#include "device/kernel_decl.h"
#include "fovea/math.h"

typedef struct fv_fill_f32_args {
    float *p; /* device memory, the launch's w floats */
    float value;
} fv_fill_f32_args;

FV_HD static inline void fv_fill_f32_item(const fv_fill_f32_args *a, int x, int y, uint64_t *c)
{
    (void)y, (void)c;
    a->p[x] = a->value;
}

#define FV_FILL_KERNELS(K) K(fv_fill_f32_kernel, fv_fill_f32_args, fv_fill_f32_item, 1, 0)

FV_FILL_KERNELS(FV_KERNEL_EXTERN)

#endif
