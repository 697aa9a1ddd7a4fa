/* fovea — the Visual-Polar family's device kernels, declared once (device/kernel_decl.h), in the
 * order its device frame (technique/vpolar/vp_device.c) launches them:
 *
 *   per gaze (Sec. 3.2) the tables that follow the gaze, when it moved (technique/vpolar/kvp_tables.h, the
 *                       CPU's own per-entry and per-cell functions): the full-height rows' angles
 *                       (once per grid), the on-screen mask's column bounds and cells, the radial
 *                       table;
 *   trace (Sec. 3.1)    a grid cell a thread, pt's path kernel on the flat scene (technique/vpolar/kvp_trace.h),
 *                       counting rays, paths and non-finite paths;
 *   reproject           the denoiser's history coordinates of a cell (technique/vpolar/kvp_reproject.h);
 *   SVGF (Sec. 3.3)     filter/ksvgf.h's steps, declared with their one order in
 *                       filter/svgf_kernels.h;
 *   φ-mip halve         a cell of mip level k from level k - 1 (Sec. 3.4, technique/vpolar/kvp_map.h);
 *   map                 a screen pixel from the sample space (Sec. 3.4, technique/vpolar/kvp_map.h);
 * (the foveated blur's two passes, Sec. 3.5, are filter/blur_kernels.h's, shared with fipr).
 *
 * vpolar_kernels.c makes the portable side and the descriptors, vpolar_kernels.cu the CUDA side.
 * Each argument struct is copied into its launch, so the kernels see device pointers only.
 */
#ifndef FV_TECHNIQUE_VPOLAR_KERNELS_H
#define FV_TECHNIQUE_VPOLAR_KERNELS_H

#include <math.h>
#include "device/kernel_decl.h"
#include "filter/kblur.h"
#include "technique/vpolar/kvp_map.h"
#include "technique/vpolar/kvp_reproject.h"
#include "technique/vpolar/kvp_tables.h"
#include "technique/vpolar/kvp_trace.h"

enum { FV_VP_COUNT_RAYS, FV_VP_COUNT_PATHS, FV_VP_COUNT_NAN, FV_VP_COUNTS };

/* ---- the tables that follow the gaze (technique/vpolar/kvp_tables.h) ---- */

/* The full-height rows' angles, a row an item (gh): what space.c tabulates at create. */
typedef struct fv_vp_rows_args {
    int h;
    float *row_cs; /* 2 per row */
} fv_vp_rows_args;

FV_HD static inline void fv_vp_rows_item(const fv_vp_rows_args *a, int y, int unused, uint64_t *c)
{
    (void)unused, (void)c;
    fv_kvp_row_angle(y, a->h, &a->row_cs[2 * y], &a->row_cs[2 * y + 1]);
}

/* The on-screen mask at a view: each column's bound (a column an item, gw), then each cell (gw x gh;
 * the rows beyond a column's height 0). */
typedef struct fv_vp_onscreen_args {
    fv_kvp_space space;
    fv_kvp_view view;
    float reach;
    const int *col_h;           /* gw heights, NULL: every column full */
    const float *row_cs;        /* the rows' angles (fv_vp_rows_args) */
    fv_kvp_onscreen_col *col;   /* gw */
    uint8_t *mask;              /* gw * gh */
} fv_vp_onscreen_args;

FV_HD static inline void fv_vp_onscreen_col_item(const fv_vp_onscreen_args *a, int x, int unused, uint64_t *c)
{
    (void)unused, (void)c;
    a->col[x] = fv_kvp_onscreen_column(&a->space, &a->view, a->reach, x, a->col_h ? a->col_h[x] : a->space.gh);
}

FV_HD static inline void fv_vp_onscreen_item(const fv_vp_onscreen_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    const int n = a->col_h ? a->col_h[x] : a->space.gh;
    a->mask[(size_t)y * (size_t)a->space.gw + (size_t)x] = y < n ? fv_kvp_onscreen_cell(&a->space, &a->view, a->reach, &a->col[x], n, a->space.gh, y, a->row_cs) : 0;
}

/* The radial table, an entry an item (its n). */
typedef struct fv_vp_radial_args {
    fv_kvp_radial t;
} fv_vp_radial_args;

FV_HD static inline void fv_vp_radial_item(const fv_vp_radial_args *a, int i, int unused, uint64_t *c)
{
    (void)unused, (void)c;
    fv_kvp_radial_entry(&a->t, i);
}

/* ---- trace ---- */

typedef struct fv_vp_trace_args {
    fv_kscene scene; /* device pointers */
    fv_kvp_trace_frame f;
    fv_kvp_gbuf g;
} fv_vp_trace_args;

/* Cell (x, y) when it is a valid cell of its column (the rows beyond keep "no surface"). */
FV_HD static inline void fv_vp_trace_item(const fv_vp_trace_args *a, int x, int y, uint64_t *c)
{
    if (y >= (a->f.col_h ? a->f.col_h[x] : a->f.space.gh)) return;
    fv_kvp_trace_counts k;
    k.rays = k.paths = k.nan_paths = 0;
    fv_kvp_trace_sample(&a->scene, &a->f, &a->g, (long)y * a->f.space.gw + x, &k);
    c[FV_VP_COUNT_RAYS] += k.rays, c[FV_VP_COUNT_PATHS] += k.paths, c[FV_VP_COUNT_NAN] += k.nan_paths;
}

/* ---- the denoiser's history coordinates, a cell an item (gw * gh) ---- */

typedef struct fv_vp_reproject_args {
    fv_kvp_reproject_frame f;
    float *prev_coord; /* 2 per cell */
} fv_vp_reproject_args;

FV_HD static inline void fv_vp_reproject_item(const fv_vp_reproject_args *a, int i, int y, uint64_t *c)
{
    (void)y, (void)c;
    fv_kvp_reproject_sample(&a->f, (long)i, &a->prev_coord[2 * (size_t)i]);
}

/* ---- φ-mipmaps: level k >= 1 from level k - 1, over w x (level k's rows of storage) ---- */

typedef struct fv_vp_halve_args {
    fv_kphi_mips m;
    int k;
} fv_vp_halve_args;

FV_HD static inline void fv_vp_halve_item(const fv_vp_halve_args *a, int x, int j, uint64_t *c)
{
    (void)c;
    fv_kphi_halve_cell(&a->m, a->k, x, j);
}

/* ---- map to the screen, a pixel an item ---- */

typedef struct fv_vp_map_args {
    fv_kvp_map_frame mf;
    fv_film_views out; /* device buffers */
} fv_vp_map_args;

FV_HD static inline void fv_vp_map_item(const fv_vp_map_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_kvp_map_pixel(&a->mf, x, y, &a->out);
}

#define FV_VP_KERNELS(K)                                                                          \
    K(fv_vp_rows_kernel, fv_vp_rows_args, fv_vp_rows_item, 1, 0)                                  \
    K(fv_vp_onscreen_col_kernel, fv_vp_onscreen_args, fv_vp_onscreen_col_item, 1, 0)              \
    K(fv_vp_onscreen_kernel, fv_vp_onscreen_args, fv_vp_onscreen_item, 2, 0)                      \
    K(fv_vp_radial_kernel, fv_vp_radial_args, fv_vp_radial_item, 1, 0)                            \
    K(fv_vp_trace_kernel, fv_vp_trace_args, fv_vp_trace_item, 2, FV_VP_COUNTS)                    \
    K(fv_vp_reproject_kernel, fv_vp_reproject_args, fv_vp_reproject_item, 1, 0)                   \
    K(fv_vp_halve_kernel, fv_vp_halve_args, fv_vp_halve_item, 2, 0)                               \
    K(fv_vp_map_kernel, fv_vp_map_args, fv_vp_map_item, 2, 0)

FV_VP_KERNELS(FV_KERNEL_EXTERN)

#endif
