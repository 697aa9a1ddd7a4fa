/* fovea — the inverted pyramid's per-cell steps as kernel code (Polychronakis et al. 2023, Sec.
 * 3.1-3.2): the levels' sizes, where a level's ray passes, the 3x3 minimum that gives it its start
 * (Sec. 3.2.4), the Sobel edge of a tip cell (pass 2), a pixel of the foveation mask (pass 3, Eq. 1),
 * which middle-level rays pass 4 must trace (the refresh), the reconstruction of a pixel outside the
 * mask, shadow_reuse's agreed visibility and pass 5's transition test. Each is one cell or pixel,
 * reading and writing only its own output, so the CPU pipeline (technique/sdf/sdf_pipeline.c, its
 * batched tracer around them), the portable backend (a cell at a time on the CPU's threads) and
 * CUDA (a thread a cell; both through technique/sdf/sdf_kernels.h) run the same code.
 *
 * Levels are counted from the tip: level 0 is the coarsest, level L-1 the target. They are built on
 * the sample grid (the film's pixels times the samples per pixel along each axis, so at 16 spp the
 * tip has one ray per pixel, which is where the paper's speed-up with super-sampling comes from).
 * Level k has one ray per f = 2^(L-1-k) x f block of target samples: ceil(W / f) x ceil(H / f)
 * rays, the last row and column covering what is left of an odd size; each ray passes through the
 * centre of the part of its block inside the grid.
 */
#ifndef FV_TECHNIQUE_SDF_KPYR_H
#define FV_TECHNIQUE_SDF_KPYR_H

#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include "core/rng.h"
#include "fovea/math.h"
#include "kernel/keye.h"
#include "technique/sdf/ksdf_shade.h"

#define FV_PYRAMID_MAX_LEVELS 6

typedef struct fv_pyramid_level {
    int w, h;  /* rays */
    int f;     /* target samples per ray along each axis */
} fv_pyramid_level;

/* A pyramid's shape and buffers for one frame of one eye (host memory on the CPU and the portable
 * backend, device memory on CUDA). Pointers a method does not use are NULL. */
typedef struct fv_kpyr {
    int L;                /* levels; 1: the one-level baselines (no pyramid) */
    int S;                /* samples per pixel along each axis */
    int sw, sh;           /* target grid: the film's pixels times S */
    int w, h;             /* film pixels */
    int min_filter;       /* Sec. 3.2.4; off only to measure what it buys */
    fv_pyramid_level lv[FV_PYRAMID_MAX_LEVELS];
    float *depth[FV_PYRAMID_MAX_LEVELS];    /* levels 0 .. L-2: where each ray stopped, +inf: missed */
    uint16_t *steps[FV_PYRAMID_MAX_LEVELS]; /* levels 0 .. L-2 */
    uint8_t *need;        /* fipr, middle level: 0 skip, 1 depth only, 2 depth and colour */
    uint8_t *edge;        /* fipr, level 0 */
    uint8_t *mask;        /* fipr, pixels: 1 traced at the target level */
    uint32_t *vis;        /* shadow_reuse: which lights reach each hit of level L-2 */
    float *hist_color;    /* fipr: this eye's middle level, 3 per ray, kept between frames */
    int *hist_stamp;      /* fipr: the frame each was last shaded in, INT_MIN: never */
} fv_kpyr;

/* What fipr's pass 3 and the refresh read of a frame. */
typedef struct fv_kpyr_fovea {
    fv_eye_model eye;
    fv_gaze gaze;
    int whole;            /* the fovea covers the screen: every pixel in the mask */
    uint64_t seed;
    int eye_index;        /* 0 left or mono, 1 right */
    int index;            /* the frame's index in its sequence */
    float fovea_deg, outer_deg;
    int refresh;          /* 1, 2 or 4 */
} fv_kpyr_fovea;

FV_HD static inline void fv_kpyr_levels(int sw, int sh, int levels, fv_pyramid_level *level)
{
    for (int k = 0; k < levels; k++) {
        int f = 1 << (levels - 1 - k);
        level[k].f = f;
        level[k].w = (sw + f - 1) / f;
        level[k].h = (sh + f - 1) / f;
    }
}

/* Target-grid position (in samples) ray (i, j) of a level passes through: the centre of its block
 * clipped to the grid. */
FV_HD static inline void fv_kpyr_centre(const fv_pyramid_level *l, int sw, int sh, int i, int j, float *sx, float *sy)
{
    int x0 = i * l->f, y0 = j * l->f;
    int x1 = x0 + l->f < sw ? x0 + l->f : sw, y1 = y0 + l->f < sh ? y0 + l->f : sh;
    *sx = 0.5f * (float)(x0 + x1);
    *sy = 0.5f * (float)(y0 + y1);
}

/* Start distance of a ray whose parent one level down is (pi, pj): the smallest depth of the
 * parent and its eight neighbours (Sec. 3.2.4), or the parent's own without the filter. */
FV_HD static inline float fv_kpyr_start(const float *depth, const fv_pyramid_level *parent, int pi, int pj, bool min_filter)
{
    if (!min_filter) return depth[(size_t)pj * parent->w + pi];
    float m = INFINITY;
    for (int dy = -1; dy <= 1; dy++) {
        int y = pj + dy;
        if (y < 0 || y >= parent->h) continue;
        for (int dx = -1; dx <= 1; dx++) {
            int x = pi + dx;
            if (x < 0 || x >= parent->w) continue;
            float d = depth[(size_t)y * parent->w + x];
            if (d < m) m = d;
        }
    }
    return m;
}

/* Pass 2 reads a miss as the farthest finite depth of the tip times two (so silhouettes against
 * the sky are edges); far is that maximum, a reduction the caller runs over the tip. */
FV_HD static inline float fv_kpyr_sky(float far) { return far > 0.0f ? 2.0f * far : 1.0f; }

/* Sec. 3.2.2: 1 where the Sobel gradient of the depth (w x h, borders clamped) at (x, y) exceeds
 * threshold x the cell's depth (a relative threshold keeps the ground's smooth recession from
 * counting as an edge), else 0. */
FV_HD static inline uint8_t fv_kpyr_sobel_cell(const float *depth, int w, int h, float sky, float threshold, int x, int y)
{
#define FV_KPYR_D(u, v) (isfinite(depth[(size_t)(v) * w + (u)]) ? depth[(size_t)(v) * w + (u)] : sky)
    int ym = y > 0 ? y - 1 : 0, yp = y + 1 < h ? y + 1 : h - 1;
    int xm = x > 0 ? x - 1 : 0, xp = x + 1 < w ? x + 1 : w - 1;
    float gx = (FV_KPYR_D(xp, ym) + 2.0f * FV_KPYR_D(xp, y) + FV_KPYR_D(xp, yp)) - (FV_KPYR_D(xm, ym) + 2.0f * FV_KPYR_D(xm, y) + FV_KPYR_D(xm, yp));
    float gy = (FV_KPYR_D(xm, yp) + 2.0f * FV_KPYR_D(x, yp) + FV_KPYR_D(xp, yp)) - (FV_KPYR_D(xm, ym) + 2.0f * FV_KPYR_D(x, ym) + FV_KPYR_D(xp, ym));
    float g = sqrtf(gx * gx + gy * gy);
    return g > threshold * FV_KPYR_D(x, y) ? 1 : 0;
#undef FV_KPYR_D
}

/* Sec. 3.2.3 with Eq. 1: the probability a target pixel is traced at the top level: 1 inside the
 * fovea, 0 beyond outer_deg, 1 on an edge, else p(w) = 0.90964 e^(-w / 2.9661) + 0.00792. */
FV_HD static inline double fv_kpyr_probability(double ecc_deg, double fovea_deg, double outer_deg, bool edge)
{
    if (ecc_deg <= fovea_deg) return 1.0;
    if (outer_deg > 0.0 && ecc_deg > outer_deg) return 0.0;
    return edge ? 1.0 : fv_kacuity_hyperbolic(ecc_deg, fovea_deg, outer_deg);
}

/* The tip's edge under pixel (x, y): the tip ray whose block holds the pixel's centre (pass 2's
 * upscaling). */
FV_HD static inline uint8_t fv_kpyr_edge_of_pixel(const fv_kpyr *k, int x, int y)
{
    const fv_pyramid_level *low = &k->lv[0];
    int li = (x * k->S + k->S / 2) / low->f, lj = (y * k->S + k->S / 2) / low->f;
    return k->edge[(size_t)lj * low->w + li];
}

/* Pass 3, pixel (x, y): 1 when it is traced at the target level, drawn against Eq. 1 with the
 * pixel's own random number (seed, pixel and eye, frame), so any order draws the same mask. */
FV_HD static inline uint8_t fv_kpyr_mask_pixel(const fv_kpyr *k, const fv_kpyr_fovea *fv, int x, int y)
{
    const size_t pix = (size_t)y * k->w + x;
    bool e = fv_kpyr_edge_of_pixel(k, x, y) != 0;
    double ecc = fv_keye_eccentricity_deg(&fv->eye, fv->gaze, x, y);
    double prob = fv->whole ? 1.0 : fv_kpyr_probability(ecc, fv->fovea_deg, fv->outer_deg, e);
    fv_rng rng = fv_rng_stream(fv->seed, FV_STREAM_MASK, pix * 2 + (uint64_t)fv->eye_index, 0, (uint64_t)fv->index);
    return prob >= 1.0 || (prob > 0.0 && fv_rng_next(&rng) < prob) ? 1 : 0;
}

/* Floor and ceiling of a / b for b > 0 and any sign of a (C's division truncates towards 0). */
FV_HD static inline int fv_kpyr_floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
FV_HD static inline int fv_kpyr_ceil_div(int a, int b) { return -fv_kpyr_floor_div(-a, b); }

/* Whether middle-level ray (u, v) is due for shading this frame: when its phase comes round (a 2x2
 * interleave for refresh 4, a checkerboard for 2, every frame for 1), so each frame refreshes an
 * even share, and whenever it has never been shaded. */
FV_HD static inline bool fv_kpyr_due(const fv_kpyr *k, const fv_kpyr_fovea *fv, int u, int v)
{
    const int R = fv->refresh, now = fv->index;
    int phase = R == 4 ? (u & 1) + 2 * (v & 1) : R == 2 ? (u + v) & 1 : 0;
    return k->hist_stamp[(size_t)v * k->lv[k->L - 2].w + u] == INT_MIN || ((now % R) + R) % R == phase;
}

/* What pass 4 traces of middle-level ray (u, v): 2 depth and colour (due, above), 1 depth only (a
 * mask pixel starts from it), 0 nothing. Gathered, not scattered, so no two cells write one place:
 * pixel x's samples (x S + a) >> 1, a in [0, S), span the rays [(x S) >> 1, (x S + S - 1) >> 1],
 * and the min filter reads those +-1; so ray u is needed by the pixels x with x S <= 2u + 3 and
 * x S + S - 1 >= 2u - 2 (the same in y), and is needed when any of them is in the mask. */
FV_HD static inline uint8_t fv_kpyr_need_cell(const fv_kpyr *k, const fv_kpyr_fovea *fv, int u, int v)
{
    if (fv_kpyr_due(k, fv, u, v)) return 2;
    const int S = k->S, w = k->w, h = k->h;
    int y0 = fv_kpyr_ceil_div(2 * v - 1 - S, S), y1 = fv_kpyr_floor_div(2 * v + 3, S);
    int x0 = fv_kpyr_ceil_div(2 * u - 1 - S, S), x1 = fv_kpyr_floor_div(2 * u + 3, S);
    y0 = y0 > 0 ? y0 : 0, y1 = y1 < h - 1 ? y1 : h - 1;
    x0 = x0 > 0 ? x0 : 0, x1 = x1 < w - 1 ? x1 : w - 1;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++)
            if (k->mask[(size_t)y * w + x]) return 1;
    return 0;
}

/* A pixel outside fipr's mask: its samples read the middle level's kept colours bilinearly. */
FV_HD static inline fv_vec3 fv_kpyr_reconstruct(const fv_kpyr *k, int x, int y)
{
    const fv_pyramid_level *mid = &k->lv[k->L - 2];
    const int S = k->S;
    const float *col = k->hist_color;
    fv_vec3 sum = fv_v3s(0.0f);
    for (int b = 0; b < S; b++)
        for (int a = 0; a < S; a++) {
            /* the sample's centre in the middle level's ray coordinates (ray i at 2i + 1) */
            float u = ((float)(x * S + a) + 0.5f) / (float)mid->f - 0.5f, v = ((float)(y * S + b) + 0.5f) / (float)mid->f - 0.5f;
            int i0 = (int)floorf(u), j0 = (int)floorf(v);
            float fu = u - (float)i0, fv = v - (float)j0;
            int i1 = i0 + 1, j1 = j0 + 1;
            i0 = i0 < 0 ? 0 : i0 >= mid->w ? mid->w - 1 : i0;
            i1 = i1 < 0 ? 0 : i1 >= mid->w ? mid->w - 1 : i1;
            j0 = j0 < 0 ? 0 : j0 >= mid->h ? mid->h - 1 : j0;
            j1 = j1 < 0 ? 0 : j1 >= mid->h ? mid->h - 1 : j1;
            const float *c00 = &col[3 * ((size_t)j0 * mid->w + i0)], *c10 = &col[3 * ((size_t)j0 * mid->w + i1)];
            const float *c01 = &col[3 * ((size_t)j1 * mid->w + i0)], *c11 = &col[3 * ((size_t)j1 * mid->w + i1)];
            float w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
            sum.x += w00 * c00[0] + w10 * c10[0] + w01 * c01[0] + w11 * c11[0];
            sum.y += w00 * c00[1] + w10 * c10[1] + w01 * c01[1] + w11 * c11[1];
            sum.z += w00 * c00[2] + w10 * c10[2] + w01 * c01[2] + w11 * c11[2];
        }
    return fv_scale(sum, 1.0f / (float)(S * S));
}

/* shadow_reuse (ours): the lights a target sample sees, taken from the level below when its parent
 * (pi, pj) and the parent's eight neighbours all hit and all see the same lights, or unknown (the
 * sample traces its own shadow rays) where they differ: a shadow's edge, a silhouette. */
FV_HD static inline uint32_t fv_kpyr_agreed_vis(const fv_kpyr *k, int pi, int pj)
{
    const fv_pyramid_level *lv = &k->lv[k->L - 2];
    uint32_t v = k->vis[(size_t)pj * lv->w + pi];
    if (v == FV_SDF_VIS_UNKNOWN) return v;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            int x = pi + dx, y = pj + dy;
            if (x < 0 || x >= lv->w || y < 0 || y >= lv->h) continue;
            if (k->vis[(size_t)y * lv->w + x] != v) return FV_SDF_VIS_UNKNOWN;
        }
    return v;
}

/* Pass 5: pixel (x, y) is on a transition when its 5x5 neighbourhood holds both mask and other
 * pixels; the blur's sigma is blur_sigma there and 0 (untouched) elsewhere. */
FV_HD static inline float fv_kpyr_blur_sigma(const uint8_t *mask, int w, int h, int x, int y, float blur_sigma)
{
    int seen[2] = {0, 0};
    for (int dy = -2; dy <= 2; dy++)
        for (int dx = -2; dx <= 2; dx++) {
            int u = x + dx, v = y + dy;
            if (u >= 0 && u < w && v >= 0 && v < h) seen[mask[(size_t)v * w + u] ? 1 : 0] = 1;
        }
    return seen[0] && seen[1] ? blur_sigma : 0.0f;
}

#endif
