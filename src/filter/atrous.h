/* fovea — the edge-avoiding À-Trous wavelet filter (Dammertz, Sewtz, Hanika, Lensch, HPG 2010),
 * shared by every technique that post-filters a noisy estimate (Foveated Photon Mapping, Sec. 4.1,
 * filters pm, pm-t and fpm with it; the Visual-Polar denoiser can reuse it).
 *
 * Iteration i convolves with the 5x5 B3-spline kernel (1/16, 1/4, 3/8, 1/4, 1/16)^2 whose taps are
 * spread 2^i pixels apart ("with holes"), each tap weighted by edge-stopping functions of the colour,
 * normal and position differences; the colour sigma halves at every iteration so that the coarse
 * passes smooth less across colour edges. Pixels without a surface (zero normal) are neither
 * filtered nor used. Defaults and their reasons: atrous.c.
 *
 * Limits: the result is the last smoothed level (the detail coefficients are dropped, as in the
 * paper); the colour sigma is one number per pass, not guided by a per-pixel variance; CPU only.
 */
#ifndef FV_FILTER_ATROUS_H
#define FV_FILTER_ATROUS_H

#include "fovea/status.h"

/* Reusable scratch for the filter (one image of colour and two rows of sums), grown to the largest
 * image filtered and kept, so that a technique filtering every frame allocates nothing once warmed
 * up. Owned by the caller (its state); one filter at a time per workspace. */
typedef struct fv_atrous fv_atrous;
fv_status fv_atrous_create(fv_atrous **out, fv_error *err);
void fv_atrous_destroy(fv_atrous *a);

typedef struct fv_atrous_opts {
    int iterations;        /* 5: taps 1, 2, 4, 8, 16 pixels apart (reach 2*31 = 62 pixels) */
    float sigma_color;     /* relative to the image's mean luminance, so exposure does not matter */
    float sigma_normal;    /* on |n_p - n_q|^2 of unit normals */
    float sigma_position;  /* in scene units; 0 turns the position term off */
    /* Light, not colour (filter/demod.h): what each pixel's first surface reflects (3 floats per
     * pixel); the colour is divided by its demodulation factors before filtering and multiplied
     * back after, inside the filter's one parallel region. NULL (default): colour as it is. */
    const float *demod;
    int threads;           /* OpenMP threads, 0 (default): all (core/parallel.h); the frame's --threads */
    fv_atrous *workspace;  /* reused scratch; NULL (default): allocated for this call and freed */
} fv_atrous_opts;

void fv_atrous_opts_default(fv_atrous_opts *o);

/* Filters rgb (w*h*3 linear floats) in place, in one parallel region (a barrier between passes), guided by normal and position (3 floats per pixel
 * each, either may be NULL: its weight is then 1). o NULL means the defaults; an infinite sigma
 * turns its term off. Deterministic and independent of the thread count. Bad sizes or sigmas ->
 * FV_ERR_INVALID, no scratch memory -> FV_ERR_NOMEM (rgb is then unchanged). The scratch is
 * o->workspace's when given (grown if this image is larger), else allocated for the call. */
fv_status fv_atrous_filter(float *rgb, const float *normal, const float *position, int w, int h, const fv_atrous_opts *o,
                           fv_error *err);

/* The filter as a step of a caller's parallel region (docs/threads.md), for a frame that runs
 * several stages in one: fv_atrous_prepare checks o (fv_atrous_filter's errors) and grows ws to a
 * w x h image, once, before the region; fv_atrous_team is then called by every thread of the
 * region's team with the same arguments and o->workspace = ws (the same passes and barriers as
 * fv_atrous_filter, no region opened, nothing allocated; o->threads is the region's). Same result
 * bit for bit. */
fv_status fv_atrous_prepare(fv_atrous *ws, int w, int h, const fv_atrous_opts *o, fv_error *err);
void fv_atrous_team(float *rgb, const float *normal, const float *position, int w, int h, const fv_atrous_opts *o);

#endif
