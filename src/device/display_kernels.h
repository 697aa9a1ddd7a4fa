/* fovea — the display conversion on a device, declared once (device/kernel_decl.h): a film's float
 * colour to RGBA8 with film/display.h's one per-pixel function, so that a display-only frame reads
 * back 4 bytes a pixel instead of 12 (device/film_device.h, fv_film_set_display). */
#ifndef FV_DEVICE_DISPLAY_KERNELS_H
#define FV_DEVICE_DISPLAY_KERNELS_H

#include "device/kernel_decl.h"
#include "film/display.h"

typedef struct fv_display_args {
    const float *rgb; /* device memory: the launch's w pixels, 3 floats each */
    uint8_t *rgba;    /* device memory: 4 bytes a pixel */
    float exposure;
} fv_display_args;

FV_HD static inline void fv_display_item(const fv_display_args *a, int x, int y, uint64_t *c)
{
    (void)y, (void)c;
    fv_display_rgba8(a->rgb, (size_t)x, a->exposure, a->rgba);
}

#define FV_DISPLAY_KERNELS(K) K(fv_display_kernel, fv_display_args, fv_display_item, 1, 0)

FV_DISPLAY_KERNELS(FV_KERNEL_EXTERN)

#endif
