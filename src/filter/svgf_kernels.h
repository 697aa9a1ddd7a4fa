/* fovea — SVGF as kernels (kernel/svgf.h) on the portable backend: the filter's buffers in host
 * memory, and a frame as the kernels' launch sequence, each step a pixel at a time over tiles of
 * the grid on the CPU's threads. The same contract and the same bits as fv_svgf (filter/svgf.h) in
 * any of its builds; this is what the Visual-Polar family's portable device runs
 * (technique/vpolar/device.c) and what tests the kernels against the CPU filter. The CPU filter
 * stays fv_svgf (its vectorised sweeps are several times faster on a CPU).
 */
#ifndef FV_FILTER_SVGF_KERNELS_H
#define FV_FILTER_SVGF_KERNELS_H

#include "filter/svgf.h"

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
