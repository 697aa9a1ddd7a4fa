/* fovea — spatiotemporal variance-guided filtering (SVGF: Schied, Kaplanyan, Wyman et al., HPG
 * 2017), the real-time denoiser of 1-sample-per-pixel path tracing, on any fv_grid: screen space
 * for the Cartesian baselines, Visual-Polar or log-polar space for the foveated techniques
 * (Visual-Polar Sec. 3.3: wrap-around on φ, clamp on ρ, columns of different heights).
 *
 * One call per frame:
 *  1. demodulate: illumination = colour / albedo (albedo below 1e-3 counts as 1), so texture and
 *     material colour are not blurred;
 *  2. temporal accumulation: each pixel fetches its history at prev_coord (continuous coordinates in
 *     the previous frame's grid, computed by the caller through its own reprojection and
 *     screen-to-grid map) with a bilinear lookup; a tap counts only if it is consistent (same object
 *     id, normals within ~25 degrees, world positions within a depth-relative distance) and the
 *     weights of the consistent taps are renormalised (below 0.01 in all: no history). Colour and
 *     the first two luminance moments are blended with weight max(alpha, 1 / (history length + 1));
 *     on a screen grid a coordinate outside [0, w] x [0, 1] has no history, on a polar grid X clamps
 *     and V wraps;
 *  3. variance: from the temporal moments when the history is at least 4 frames long (counting this
 *     one), otherwise from a 7x7 spatial bilateral estimate of the moments (depth and normal weights);
 *  4. edge-avoiding À-Trous: `iterations` passes of the 5x5 B3 kernel with taps 2^i apart, weights
 *     w_z = exp(-|z_p - z_q| / (sigma_depth |grad z . (p - q)| + eps)), with |grad z . (p - q)|
 *     approximated as max(|dz/dx|, |dz/dy|) |p - q|, as common implementations do (the gradient
 *     from one-sided differences, see svgf.c),
 *     w_n = max(0, n_p . n_q)^sigma_normal,
 *     w_l = exp(-|l_p - l_q| / (sigma_lum sqrt(gauss3x3(var_p)) + eps)),
 *     and the variance filtered alongside with the squared weights. The output of the first pass is
 *     what the next frame reprojects (the paper's choice);
 *  5. remodulate by the albedo.
 *
 * Pixels without a surface (zero normal, e.g. the background), rows beyond a column's height and
 * pixels marked 0 in `active` are left as they are and never used as taps. Pixels marked 0 in `sampled` (no path this frame: linear
 * fall-off's killed rays) have no colour and no features and keep no history: after the last pass
 * each takes the B3-kernel-weighted average (no edge-stopping: its own features are unknown) of the
 * filtered sampled surface pixels among its 5x5 taps 1 apart, or if there are none 2 apart, then
 * 4, ... up to 2^(iterations-1) (at least 1); beyond that it stays black. A sampled surface pixel
 * whose colour, albedo, normal, depth or position is not finite is treated as not sampled.
 *
 * Limits: one colour buffer (direct and indirect light are not separated as in the paper); no
 * adaptive temporal weights (A-SVGF); results independent of the thread count.
 */
#ifndef FV_FILTER_SVGF_H
#define FV_FILTER_SVGF_H

#include <stdbool.h>
#include <stdint.h>
#include "filter/grid.h"
#include "fovea/status.h"

typedef struct fv_svgf_opts {
    float alpha_color;    /* 0.2: lowest weight of the new sample in the colour average */
    float alpha_moments;  /* 0.2: the same for the moments */
    int iterations;       /* 5 À-Trous passes (taps 1, 2, 4, 8, 16 apart) */
    float sigma_depth;    /* 1 */
    float sigma_normal;   /* 128: exponent on the normals' cosine */
    float sigma_lum;      /* 4: luminance edge-stopping, in standard deviations */
} fv_svgf_opts;

void fv_svgf_opts_default(fv_svgf_opts *o);
/* Every field finite and in range (alphas in (0, 1], iterations 0..10, sigmas > 0): FV_ERR_INVALID
 * naming the field otherwise. */
fv_status fv_svgf_opts_validate(const fv_svgf_opts *o, fv_error *err);

/* A grid SVGF can filter: at least 1x1, every column height in [1, h], at most 2^31 - 1 pixels;
 * FV_ERR_INVALID naming what is wrong otherwise (fv_svgf_create's check). */
fv_status fv_svgf_grid_validate(const fv_grid *grid, fv_error *err);

/* The filter and its history for one grid. The grid is copied; its col_h array is not and must
 * outlive the filter. o NULL: the defaults. Bad options, a column height outside [1, h] or more
 * than 2^31 - 1 pixels -> FV_ERR_INVALID; FV_ERR_NOMEM (nothing leaked). Every buffer is allocated
 * here (about 140 bytes per pixel; a polar grid with short columns also keeps column-major copies
 * of its first columns, docs/filters.md), none per frame. FOVEA_SVGF_LINES=off in the environment
 * leaves those copies out (the same bits, slower: for measurements). */
typedef struct fv_svgf fv_svgf;

fv_status fv_svgf_create(const fv_grid *grid, const fv_svgf_opts *o, fv_svgf **out, fv_error *err);
void fv_svgf_destroy(fv_svgf *f);
/* Which build of the hot sweeps runs: AUTO (the default) picks AVX2 when the CPU has it, else the
 * baseline x86-64 (SSE2) build; both give the same bits, so this only matters for speed and for
 * the tests that compare them. False (nothing changes) when AVX2 is asked for and the CPU lacks it.
 * The environment variable FOVEA_SVGF_ISA=baseline, read by fv_svgf_create, forces the baseline. */
/* PLAIN is the baseline build with every pixel's taps added one tap at a time (no register-blocked
 * pixels, no gathered vectors): the order the vectorised paths must reproduce, for the tests. */
typedef enum fv_svgf_isa { FV_SVGF_ISA_AUTO = 0, FV_SVGF_ISA_BASELINE, FV_SVGF_ISA_AVX2, FV_SVGF_ISA_PLAIN } fv_svgf_isa;
bool fv_svgf_set_isa(fv_svgf *f, fv_svgf_isa isa);

/* Fewer À-Trous passes in the periphery (Visual-Polar Sec. 3.5: where the foveated blur will
 * average over the same scales anyway): the columns from x_from on take part only in the first
 * `passes` passes; in the later ones their values go through unchanged (and still serve as taps
 * for the columns that are filtered). passes >= iterations or x_from >= w: every column gets every
 * pass (the default). Takes effect from the next frame; may change every frame. */
void fv_svgf_set_periphery(fv_svgf *f, int x_from, int passes);

/* Forgets the history (the next frame starts a new sequence). */
void fv_svgf_reset(fv_svgf *f);

/* One frame's buffers, all on the filter's grid (storage w * h pixels). */
typedef struct fv_svgf_frame {
    float *color;              /* 3 per pixel: in the noisy radiance, out the filtered radiance */
    const float *albedo;       /* 3 per pixel */
    const float *normal;       /* 3 per pixel, unit; zero vector: no surface */
    const float *depth;        /* 1 per pixel: distance along the camera ray */
    const float *position;     /* 3 per pixel: world position of the first hit */
    const uint32_t *id;        /* 1 per pixel: object id + 1, 0 for none */
    const float *prev_coord;   /* 2 per pixel: (X, V) in the previous frame's grid, NaN when the
                                  point was not seen then; NULL: no history for this frame */
    const uint8_t *sampled;    /* NULL: every pixel was sampled; else 0 where no path was traced */
    const uint8_t *active;     /* NULL: every pixel; else 0 where the pixel is out of the picture
                                  (a polar grid's cells off the screen): treated like rows beyond
                                  a column's height, never filtered, never a tap, no history, its
                                  colour left as it is; its buffers are not read */
} fv_svgf_frame;

/* Statistics of the last frame, for the technique's counters. */
typedef struct fv_svgf_info {
    double history_fraction;   /* sampled surface pixels that found a consistent history */
    double mean_history;       /* their mean history length, in frames counting this one (0: none) */
} fv_svgf_info;

/* Every buffer fv_svgf_filter needs is there: FV_ERR_INVALID naming the first missing one. */
fv_status fv_svgf_frame_validate(const fv_svgf_frame *fr, fv_error *err);

/* Filters fr->color in place. threads 0 = all. FV_ERR_INVALID for missing buffers (nothing
 * changes, the history included). info may be NULL. */
fv_status fv_svgf_filter(fv_svgf *f, const fv_svgf_frame *fr, int threads, fv_svgf_info *info, fv_error *err);

#endif
