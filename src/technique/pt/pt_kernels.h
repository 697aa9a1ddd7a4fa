/* fovea — `pt`'s device kernels, declared once (device/kernel_decl.h): the pixel kernel of
 * kernel/kpt.h, one item a pixel, counting rays and non-finite estimates. pt_kernels.c makes the
 * portable side, pt_kernels.cu the CUDA side; pt.c's device frame launches them. */
#ifndef FV_TECHNIQUE_PT_KERNELS_H
#define FV_TECHNIQUE_PT_KERNELS_H

#include "device/kernel_decl.h"
#include "kernel/kpt.h"

enum { FV_PT_COUNT_RAYS, FV_PT_COUNT_NAN, FV_PT_COUNTS };

typedef struct fv_pt_pixel_args {
    fv_kscene scene; /* device pointers */
    fv_kpt_frame f;
    fv_film_views out; /* device buffers */
} fv_pt_pixel_args;

FV_HD static inline void fv_pt_pixel_item(const fv_pt_pixel_args *a, int x, int y, uint64_t *c)
{
    fv_kpt_pixel(&a->scene, &a->f, x, y, &a->out, &c[FV_PT_COUNT_RAYS], &c[FV_PT_COUNT_NAN]);
}

#define FV_PT_KERNELS(K) K(fv_pt_pixel_kernel, fv_pt_pixel_args, fv_pt_pixel_item, 2, FV_PT_COUNTS)

FV_PT_KERNELS(FV_KERNEL_EXTERN)

#endif
