/* fovea — the foveated blur's two passes as device kernels, declared once (device/kernel_decl.h)
 * for every family that blurs on a device: the Visual-Polar family's stage 5 (Sec. 3.5 of the
 * Visual-Polar paper) and fipr's pass 5. Each pixel runs filter/kblur.h's functions, which the
 * CPU's blur (filter/blur.c) runs too; the kernels' table is filter/blur.h's, copied to the device.
 */
#ifndef FV_FILTER_BLUR_KERNELS_H
#define FV_FILTER_BLUR_KERNELS_H

#include <math.h>
#include <stdbool.h>
#include "device/kernel_decl.h"
#include "filter/kblur.h"

/* src -> dst, one pass; every pointer device memory (the table's too). */
typedef struct fv_blur_args {
    fv_kblur_table t;
    const float *sigma;
    const float *src;
    float *dst;
} fv_blur_args;

/* A sigma whose kernel is not in the table: the pixel becomes NaN (visible to every check) rather
 * than a read past the table. The frames size the table to a bound of every sigma, so this does not
 * happen. */
FV_HD static inline bool fv_blur_outside(const fv_blur_args *a, int x, int y)
{
    const size_t pix = (size_t)y * (size_t)a->t.w + (size_t)x;
    const int q = fv_kblur_quantise(a->sigma[pix]);
    if (q >= 0 && q < a->t.nq) return false;
    for (int ch = 0; ch < 3; ch++) a->dst[3 * pix + ch] = NAN;
    return true;
}

FV_HD static inline void fv_blur_h_item(const fv_blur_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    if (!fv_blur_outside(a, x, y)) fv_kblur_h_pixel(&a->t, a->sigma, a->src, a->dst, x, y);
}

FV_HD static inline void fv_blur_v_item(const fv_blur_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    if (!fv_blur_outside(a, x, y)) fv_kblur_v_pixel(&a->t, a->sigma, a->src, a->dst, x, y);
}

#define FV_BLUR_KERNELS(K)                                                  \
    K(fv_blur_h_kernel, fv_blur_args, fv_blur_h_item, 2, 0)                 \
    K(fv_blur_v_kernel, fv_blur_args, fv_blur_v_item, 2, 0)

FV_BLUR_KERNELS(FV_KERNEL_EXTERN)

#endif
