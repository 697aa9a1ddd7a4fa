/* fovea — the foveated Gaussian blur of Visual-Polar path tracing (Sec. 3.5; filter/blur.h) as
 * kernel code: the rounding of a pixel's sigma to the kernel grid, its radius, and one output pixel
 * of each of the two separable passes. filter/blur.c runs the same arithmetic over runs of pixels
 * with vectors (every output float gets these IEEE operations in this order there too), and rounds
 * and sizes its kernels with these functions; the portable backend and CUDA run the passes a pixel
 * at a time, the horizontal one into a scratch image, the vertical one from it into the film.
 */
#ifndef FV_FILTER_KBLUR_H
#define FV_FILTER_KBLUR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "fovea/math.h"

#define FV_KBLUR_Q_BITS 5 /* sigma grid: 2^Q_BITS values per octave */
#define FV_KBLUR_Q_STEPS (1 << FV_KBLUR_Q_BITS)

/* The sigma profile of Sec. 3.5 (fv_blur_sigma_at, filter/blur.h): 0 up to fovea_deg, rising
 * linearly to sigma_max at ramp_deg, held beyond. Negated comparisons, so that a NaN eccentricity
 * gets no blur and a ramp that ends at (or before) the fovea's edge becomes a step instead of a
 * division by zero. */
FV_HD static inline double fv_kblur_sigma_at(double e_deg, double fovea_deg, double ramp_deg, double sigma_max)
{
    if (!(e_deg > fovea_deg)) return 0.0;
    if (!(e_deg < ramp_deg)) return sigma_max;
    return sigma_max * (e_deg - fovea_deg) / (ramp_deg - fovea_deg);
}

/* Sigma rounded to its grid index q: multiples of 1/32 pixel below 2 pixels, then 32 values per
 * octave (filter/blur.c says why). Integer arithmetic on the float's bits keeps it exact. */
FV_HD static inline int fv_kblur_quantise(float s)
{
    if (s < 1.0f) return (int)(s * (float)FV_KBLUR_Q_STEPS + 0.5f);
    union { float f; uint32_t u; } b = {s};
    const int octave = (int)(b.u >> 23) - 127;                                                                  /* s >= 1: normal */
    const int step = (int)(((b.u & 0x7FFFFFu) + (1u << (22 - FV_KBLUR_Q_BITS))) >> (23 - FV_KBLUR_Q_BITS)); /* 0..Q_STEPS */
    return FV_KBLUR_Q_STEPS * (1 + octave) + step;
}

/* The radius of grid sigma q: 3 sigma (floor), at most rcap (beyond the image no tap has weight). */
FV_HD static inline int fv_kblur_radius(int q, int rcap)
{
    long long r;
    if (q < 2 * FV_KBLUR_Q_STEPS) {
        r = 3LL * q / FV_KBLUR_Q_STEPS;
    } else {
        const int octave = q / FV_KBLUR_Q_STEPS - 1;
        if (octave > 40) return rcap;
        r = (3LL * (FV_KBLUR_Q_STEPS + q % FV_KBLUR_Q_STEPS) << octave) >> FV_KBLUR_Q_BITS;
    }
    return r < rcap ? (int)r : rcap;
}

/* The weight of the taps of a radius-r kernel centred at pos that fall inside [0, n). */
FV_HD static inline float fv_kblur_inside_weight(const float *k, int r, int pos, int n)
{
    float wsum = k[0];
    for (int d = 1; d <= r; d++) wsum += k[d] * (float)((pos - d >= 0) + (pos + d < n));
    return wsum;
}

/* The kernels of one image: kernel q (k[0..r], k[0] + 2 sum k[d] = 1) at k + off[q] for every q up
 * to the image's largest (filter/blur.h, fv_blur_kernels). */
typedef struct fv_kblur_table {
    int w, h;
    int rcap;          /* max(w, h) - 1 */
    int nq;
    const int *off;
    const float *k;
} fv_kblur_table;

/* Pixel (x, y) of the horizontal pass: src (the mapped image) to tmp, with the pixel's own sigma. A
 * pixel whose kernel is its centre alone is copied. */
FV_HD static inline void fv_kblur_h_pixel(const fv_kblur_table *t, const float *sigma, const float *src, float *tmp, int x, int y)
{
    const size_t pix = (size_t)y * (size_t)t->w + (size_t)x;
    const int q = fv_kblur_quantise(sigma[pix]);
    const int r = fv_kblur_radius(q, t->rcap);
    const float *row = src + 3 * (size_t)y * (size_t)t->w;
    if (r == 0) {
        for (int c = 0; c < 3; c++) tmp[3 * pix + c] = src[3 * pix + c];
        return;
    }
    const float *k = t->k + t->off[q];
    const bool edge = x < r || x >= t->w - r;
    const float wsum = edge ? fv_kblur_inside_weight(k, r, x, t->w) : 1.0f;
    for (int c = 0; c < 3; c++) {
        float a = k[0] * row[3 * x + c];
        for (int d = 1; d <= r; d++) {
            const float lo = x - d >= 0 ? row[3 * (x - d) + c] : 0.0f, hi = x + d < t->w ? row[3 * (x + d) + c] : 0.0f;
            a += k[d] * (lo + hi);
        }
        tmp[3 * pix + c] = edge ? a / wsum : a;
    }
}

/* Pixel (x, y) of the vertical pass: tmp (the horizontal pass) to out. */
FV_HD static inline void fv_kblur_v_pixel(const fv_kblur_table *t, const float *sigma, const float *tmp, float *out, int x, int y)
{
    const size_t pix = (size_t)y * (size_t)t->w + (size_t)x, w3 = 3 * (size_t)t->w;
    const int q = fv_kblur_quantise(sigma[pix]);
    const int r = fv_kblur_radius(q, t->rcap);
    if (r == 0) {
        for (int c = 0; c < 3; c++) out[3 * pix + c] = tmp[3 * pix + c];
        return;
    }
    const float *k = t->k + t->off[q];
    const bool edge = y < r || y + r >= t->h;
    const float wsum = edge ? fv_kblur_inside_weight(k, r, y, t->h) : 1.0f;
    for (int c = 0; c < 3; c++) {
        const float *col = tmp + 3 * (size_t)x + c;
        float a = k[0] * col[(size_t)y * w3];
        for (int d = 1; d <= r; d++) {
            const float lo = y - d >= 0 ? col[(size_t)(y - d) * w3] : 0.0f, hi = y + d < t->h ? col[(size_t)(y + d) * w3] : 0.0f;
            a += k[d] * (lo + hi);
        }
        out[3 * pix + c] = edge ? a / wsum : a;
    }
}

#endif
