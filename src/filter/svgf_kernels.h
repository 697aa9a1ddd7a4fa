/* fovea — SVGF as kernels (filter/ksvgf.h): its steps declared once for every device backend and
 * their one launch order (fv_svgf_kernels_queue), which the Visual-Polar family's device frame
 * queues (technique/vpolar/vp_device.c); and a filter over them on the portable backend, its buffers
 * in host memory, with the same contract and the same bits as fv_svgf (filter/svgf.h) in any of
 * its builds, which tests the kernels against the CPU filter. The CPU filter stays fv_svgf (its
 * vectorised sweeps are several times faster on a CPU).
 */
#ifndef FV_FILTER_SVGF_KERNELS_H
#define FV_FILTER_SVGF_KERNELS_H

#include "device/backend.h"
#include "device/kernel_decl.h"
#include "filter/svgf.h"
#include "filter/ksvgf.h"

/* ---- SVGF's steps declared once (device/kernel_decl.h), a pixel an item (the rows' counters a row
 * an item); svgf_kernels.c makes the portable side, svgf_kernels.cu the CUDA side. pass: the
 * à-trous pass. ---- */

typedef struct fv_svgf_step_args {
    fv_ksvgf k; /* device pointers */
    int pass;
} fv_svgf_step_args;

FV_HD static inline void fv_svgf_accumulate_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    (void)fv_ksvgf_accumulate_pixel(&a->k, x, y);
}

FV_HD static inline void fv_svgf_rows_item(const fv_svgf_step_args *a, int y, int unused, uint64_t *c)
{
    (void)unused, (void)c;
    fv_ksvgf_count_row(&a->k, y);
}

FV_HD static inline void fv_svgf_variance_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_ksvgf_variance_pixel(&a->k, x, y);
}

FV_HD static inline void fv_svgf_prefilter_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_ksvgf_prefilter_pixel(&a->k, a->pass, x, y);
}

FV_HD static inline void fv_svgf_atrous_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_ksvgf_atrous_pixel(&a->k, a->pass, x, y);
}

/* a pass with its own prefilter (it reads its pixel's prefiltered variance only) */
FV_HD static inline void fv_svgf_pass_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_ksvgf_prefilter_atrous_pixel(&a->k, a->pass, x, y);
}

/* the last pass and the finish in one launch: the finish reads and writes its own pixel only (the
 * pass's result there; colour and the history, which no pass reads), so the bits are the two
 * launches' */
FV_HD static inline void fv_svgf_last_pass_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_ksvgf_prefilter_atrous_pixel(&a->k, a->pass, x, y);
    fv_ksvgf_finish_pixel(&a->k, x, y);
}

FV_HD static inline void fv_svgf_finish_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_ksvgf_finish_pixel(&a->k, x, y);
}

FV_HD static inline void fv_svgf_holes_item(const fv_svgf_step_args *a, int x, int y, uint64_t *c)
{
    (void)c;
    fv_ksvgf_hole_pixel(&a->k, x, y);
}

#define FV_SVGF_KERNELS(K)                                                                   \
    K(fv_svgf_accumulate_kernel, fv_svgf_step_args, fv_svgf_accumulate_item, 2, 0)          \
    K(fv_svgf_rows_kernel, fv_svgf_step_args, fv_svgf_rows_item, 1, 0)                      \
    K(fv_svgf_variance_kernel, fv_svgf_step_args, fv_svgf_variance_item, 2, 0)              \
    K(fv_svgf_prefilter_kernel, fv_svgf_step_args, fv_svgf_prefilter_item, 2, 0)            \
    K(fv_svgf_atrous_kernel, fv_svgf_step_args, fv_svgf_atrous_item, 2, 0)                  \
    K(fv_svgf_pass_kernel, fv_svgf_step_args, fv_svgf_pass_item, 2, 0)                      \
    K(fv_svgf_last_pass_kernel, fv_svgf_step_args, fv_svgf_last_pass_item, 2, 0)            \
    K(fv_svgf_finish_kernel, fv_svgf_step_args, fv_svgf_finish_item, 2, 0)                  \
    K(fv_svgf_holes_kernel, fv_svgf_step_args, fv_svgf_holes_item, 2, 0)

FV_SVGF_KERNELS(FV_KERNEL_EXTERN)

/* One frame of SVGF queued on b over k (its buffers b's device memory, its options and this
 * frame's inputs set), in the one step order every device runs: accumulate, the rows' counters,
 * variance, each pass with its prefilter (fused: in the pass's launch, the last pass also
 * finishing its pixel; else a prefilter launch then the pass's, then the finish), the finish alone
 * when there is no pass, holes. The holes step runs every frame: whether a hole exists is known
 * from the rows' counters only after a wait, and a pixel that is no hole is left alone, so a frame
 * without holes is unchanged. Then k's features become the next frame's history (fv_ksvgf_swap:
 * pointers only; the launches hold their copies). */
fv_status fv_svgf_kernels_queue(fv_backend *b, fv_ksvgf *k, bool fused, fv_error *err);

typedef struct fv_svgf_kernels fv_svgf_kernels;

/* As fv_svgf_create (the grid is copied, its col_h must outlive the filter; o NULL: the defaults;
 * the same checks). Every buffer is allocated here, zeroed, none per frame. */
fv_status fv_svgf_kernels_create(const fv_grid *grid, const fv_svgf_opts *o, fv_svgf_kernels **out, fv_error *err);
void fv_svgf_kernels_destroy(fv_svgf_kernels *k);
/* As fv_svgf_set_periphery and fv_svgf_reset. */
void fv_svgf_kernels_set_periphery(fv_svgf_kernels *k, int x_from, int passes);
void fv_svgf_kernels_reset(fv_svgf_kernels *k);
/* How each pass is launched: true (the default) the prefilter inside the pass's launch
 * (fv_ksvgf_prefilter_atrous_pixel), false a prefilter launch then the pass's. The same bits; for
 * the tests. */
void fv_svgf_kernels_set_fused(fv_svgf_kernels *k, bool fused);
/* As fv_svgf_filter. */
fv_status fv_svgf_kernels_filter(fv_svgf_kernels *k, const fv_svgf_frame *fr, int threads, fv_svgf_info *info, fv_error *err);

#endif
