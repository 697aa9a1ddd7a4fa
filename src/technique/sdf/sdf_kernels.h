/* fovea — the sphere-tracing family's device kernels, declared once (device/kernel_decl.h): every
 * pass technique/sdf/sdf_device.c's frame launches, each one item a cell or pixel of its grid and each
 * the kernel code the CPU pipeline's passes are made of (technique/sdf/ksdf_pixel.h, kpyr.h,
 * filter/kblur.h), so the portable backend, CUDA and the CPU run one source:
 *
 *   level      a ray of pyramid level k below the target (ipr, fipr; Polychronakis et al. 2023,
 *              Sec. 3.1), the middle level's shading into fipr's history;
 *   far_rows,  pass 2's sky: the farthest finite depth of the tip, as a maximum per row, then
 *   far        the maximum of the rows (one item); a maximum is the same in any order;
 *   sobel      pass 2's edges of the tip (Sec. 3.2.2);
 *   mask       pass 3, a pixel of the foveation mask (Sec. 3.2.3, Eq. 1);
 *   need       which middle-level rays pass 4 traces (the refresh);
 *   forget     fipr's history at a sequence's first frame: no middle-level ray shaded yet;
 *   target     a pixel of the target level: every sample from the camera (sdf-gt, sdf-relaxed) or
 *              from the level below (ipr, fipr), or reconstructed outside fipr's mask;
 *   sigma      fipr's pass 5: the transitions' sigma (the blur's two passes are
 *              filter/blur_kernels.h's, shared with the Visual-Polar family).
 *
 * The marching kernels count FV_SDF_COUNTS costs (the CPU pipeline's counters); a frame gives each
 * pass its own slot of counters, so a level's rays and steps are its slot's.
 */
#ifndef FV_TECHNIQUE_SDF_KERNELS_H
#define FV_TECHNIQUE_SDF_KERNELS_H

#include <limits.h>
#include <string.h>
#include "device/kernel_decl.h"
#include "technique/sdf/ksdf_pixel.h"
#include "filter/kblur.h"

/* A marching pass's counters, in this order. */
enum {
    FV_SDF_COUNT_RAYS,
    FV_SDF_COUNT_STEPS,
    FV_SDF_COUNT_EXHAUSTED,
    FV_SDF_COUNT_NAN,
    FV_SDF_COUNT_SHADOW_RAYS,
    FV_SDF_COUNT_SHADOW_STEPS,
    FV_SDF_COUNT_NORMAL_EVALS,
    FV_SDF_COUNTS
};
/* The mask's (masked pixels, edge pixels) and the refresh's (refreshed rays). */
enum { FV_SDF_COUNT_MASKED, FV_SDF_COUNT_EDGES, FV_SDF_MASK_COUNTS };
enum { FV_SDF_COUNT_REFRESHED, FV_SDF_NEED_COUNTS };

FV_HD static inline void fv_sdf_counts_add(uint64_t *c, const fv_ksdf_counts *k)
{
    c[FV_SDF_COUNT_RAYS] += k->rays;
    c[FV_SDF_COUNT_STEPS] += k->steps;
    c[FV_SDF_COUNT_EXHAUSTED] += k->exhausted;
    c[FV_SDF_COUNT_NAN] += k->nan;
    c[FV_SDF_COUNT_SHADOW_RAYS] += k->shade.shadow_rays;
    c[FV_SDF_COUNT_SHADOW_STEPS] += k->shade.shadow_steps;
    c[FV_SDF_COUNT_NORMAL_EVALS] += k->shade.normal_evals;
}

/* ---- the marching passes ---- */

typedef struct fv_sdf_level_args {
    fv_ksdf_world world; /* device pointers */
    fv_ksdf_frame f;
    fv_kpyr k;           /* device buffers; hist_* this eye's */
    int level, index;    /* the level; the frame's index in its sequence (fipr's refresh) */
} fv_sdf_level_args;

FV_HD static inline void fv_sdf_level_item(const fv_sdf_level_args *a, int x, int y, uint64_t *c)
{
    fv_ksdf_counts k;
    memset(&k, 0, sizeof k);
    fv_ksdf_level_cell(&a->world, &a->f, &a->k, a->level, x, y, a->index, &k);
    fv_sdf_counts_add(c, &k);
}

typedef struct fv_sdf_target_args {
    fv_ksdf_world world;
    fv_ksdf_frame f;
    fv_kpyr k;
    int pyramid;         /* 0: sdf-gt, sdf-relaxed (k unused) */
    fv_film_views out;   /* device buffers */
} fv_sdf_target_args;

FV_HD static inline void fv_sdf_target_item(const fv_sdf_target_args *a, int x, int y, uint64_t *c)
{
    fv_ksdf_counts k;
    memset(&k, 0, sizeof k);
    fv_ksdf_target_pixel(&a->world, &a->f, a->pyramid ? &a->k : NULL, x, y, &a->out, &k);
    fv_sdf_counts_add(c, &k);
}

/* ---- fipr's passes 2 and 3 and the refresh ---- */

typedef struct fv_sdf_far_args {
    const float *depth; /* the tip, w x h */
    int w, h;
    float *rows;        /* h: each row's farthest finite depth (0: none) */
    float *far;         /* 1: the tip's */
} fv_sdf_far_args;

/* Row y of the tip (a one-dimensional launch over the rows). */
FV_HD static inline void fv_sdf_far_rows_item(const fv_sdf_far_args *a, int y, int unused, uint64_t *c)
{
    (void)unused, (void)c;
    float m = 0.0f;
    const float *d = a->depth + (size_t)y * (size_t)a->w;
    for (int x = 0; x < a->w; x++)
        if (isfinite(d[x]) && d[x] > m) m = d[x];
    a->rows[y] = m;
}

/* The rows' maximum (one item). */
FV_HD static inline void fv_sdf_far_item(const fv_sdf_far_args *a, int x, int y, uint64_t *c)
{
    (void)x, (void)y, (void)c;
    float m = 0.0f;
    for (int j = 0; j < a->h; j++)
        if (a->rows[j] > m) m = a->rows[j];
    *a->far = m;
}

typedef struct fv_sdf_sobel_args {
    fv_kpyr k;
    const float *far; /* fv_sdf_far_item's */
    float threshold;
} fv_sdf_sobel_args;

FV_HD static inline void fv_sdf_sobel_item(const fv_sdf_sobel_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    const fv_pyramid_level *low = &a->k.lv[0];
    a->k.edge[(size_t)y * low->w + x] = fv_kpyr_sobel_cell(a->k.depth[0], low->w, low->h, fv_kpyr_sky(*a->far), a->threshold, x, y);
}

typedef struct fv_sdf_fovea_args {
    fv_kpyr k;
    fv_kpyr_fovea fov;
} fv_sdf_fovea_args;

FV_HD static inline void fv_sdf_mask_item(const fv_sdf_fovea_args *a, int x, int y, uint64_t *c)
{
    const uint8_t m = fv_kpyr_mask_pixel(&a->k, &a->fov, x, y);
    a->k.mask[(size_t)y * a->k.w + x] = m;
    c[FV_SDF_COUNT_MASKED] += m;
    c[FV_SDF_COUNT_EDGES] += fv_kpyr_edge_of_pixel(&a->k, x, y) != 0;
}

FV_HD static inline void fv_sdf_need_item(const fv_sdf_fovea_args *a, int x, int y, uint64_t *c)
{
    const uint8_t need = fv_kpyr_need_cell(&a->k, &a->fov, x, y);
    a->k.need[(size_t)y * a->k.lv[a->k.L - 2].w + x] = need;
    c[FV_SDF_COUNT_REFRESHED] += need == 2;
}

typedef struct fv_sdf_forget_args {
    int *stamp;
} fv_sdf_forget_args;

FV_HD static inline void fv_sdf_forget_item(const fv_sdf_forget_args *a, int i, int unused, uint64_t *c)
{
    (void)unused, (void)c;
    a->stamp[i] = INT_MIN;
}

/* ---- fipr's pass 5 ---- */

typedef struct fv_sdf_sigma_args {
    const uint8_t *mask; /* w x h */
    int w, h;
    float blur_sigma;
    float *sigma;
} fv_sdf_sigma_args;

FV_HD static inline void fv_sdf_sigma_item(const fv_sdf_sigma_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    a->sigma[(size_t)y * a->w + x] = fv_kpyr_blur_sigma(a->mask, a->w, a->h, x, y, a->blur_sigma);
}

#define FV_SDF_KERNELS(K)                                                                            \
    K(fv_sdf_level_kernel, fv_sdf_level_args, fv_sdf_level_item, 2, FV_SDF_COUNTS)                    \
    K(fv_sdf_target_kernel, fv_sdf_target_args, fv_sdf_target_item, 2, FV_SDF_COUNTS)                 \
    K(fv_sdf_far_rows_kernel, fv_sdf_far_args, fv_sdf_far_rows_item, 1, 0)                            \
    K(fv_sdf_far_kernel, fv_sdf_far_args, fv_sdf_far_item, 1, 0)                                      \
    K(fv_sdf_sobel_kernel, fv_sdf_sobel_args, fv_sdf_sobel_item, 2, 0)                                \
    K(fv_sdf_mask_kernel, fv_sdf_fovea_args, fv_sdf_mask_item, 2, FV_SDF_MASK_COUNTS)                 \
    K(fv_sdf_need_kernel, fv_sdf_fovea_args, fv_sdf_need_item, 2, FV_SDF_NEED_COUNTS)                 \
    K(fv_sdf_forget_kernel, fv_sdf_forget_args, fv_sdf_forget_item, 1, 0)                             \
    K(fv_sdf_sigma_kernel, fv_sdf_sigma_args, fv_sdf_sigma_item, 2, 0)

FV_SDF_KERNELS(FV_KERNEL_EXTERN)

#endif
