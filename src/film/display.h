/* fovea — what a display shows of a linear colour, written once: exposure, clamp to [0, 1], the
 * sRGB transfer function, 8 bits. The PNG writer (film/image_io.c) converts a film's float colour
 * on the host with it, and the display kernel (device/display_kernels.h) converts on a device
 * before the pixels cross the bus, so both give the same bytes (on the host and the portable
 * backend bit for bit; a GPU's powf may differ from the C library's in its last bit).
 */
#ifndef FV_FILM_DISPLAY_H
#define FV_FILM_DISPLAY_H

#include <math.h>
#include <stdint.h>
#include "fovea/math.h"

/* The sRGB encoding of one linear channel, clamped to [0, 1] (NaN: 0). */
FV_HD static inline float fv_display_encode(float x)
{
    if (!(x > 0.0f)) return 0.0f;
    if (x >= 1.0f) return 1.0f;
    return x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
}

/* One linear channel times exposure as the byte a display gets. */
FV_HD static inline uint8_t fv_display_byte(float linear, float exposure)
{
    return (uint8_t)lrintf(255.0f * fv_display_encode(linear * exposure));
}

/* Pixel i of an RGB float image as RGBA8 (alpha 255) into out[4 i ..]. */
FV_HD static inline void fv_display_rgba8(const float *rgb, size_t i, float exposure, uint8_t *out)
{
    out[4 * i] = fv_display_byte(rgb[3 * i], exposure);
    out[4 * i + 1] = fv_display_byte(rgb[3 * i + 1], exposure);
    out[4 * i + 2] = fv_display_byte(rgb[3 * i + 2], exposure);
    out[4 * i + 3] = 255;
}

#endif
