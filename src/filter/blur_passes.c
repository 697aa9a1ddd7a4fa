/* fovea — the foveated blur as its kernels' two passes (kernel/vp_blur.h) on the CPU's threads: the
 * portable backends' blur (the Visual-Polar family's, fipr's pass 5), the same per-pixel functions
 * CUDA launches, where filter/blur.c runs their arithmetic over vector runs for speed. */
#include <stdlib.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/blur.h"
#include "kernel/vp_blur.h"

typedef struct blur_job {
    fv_kblur_table t;
    const float *sigma;
    float *rgb, *tmp;
    int vertical;
} blur_job;

static void blur_tile(void *ctx, const fv_tile *t)
{
    const blur_job *j = ctx;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++)
            if (j->vertical)
                fv_kblur_v_pixel(&j->t, j->sigma, j->tmp, j->rgb, x, y);
            else
                fv_kblur_h_pixel(&j->t, j->sigma, j->rgb, j->tmp, x, y);
}

fv_status fv_blur_kernel_passes(float *rgb, float *tmp, int w, int h, const float *sigma, float smax, int threads, fv_error *err)
{
    blur_job j;
    int nq;
    size_t nk;
    fv_blur_table_size(smax, w, h, &nq, &nk);
    int *off = fv_alloc_array((size_t)nq, sizeof(int));
    float *k = fv_alloc_array(nk, sizeof(float));
    if (!off || !k) {
        free(off), free(k);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the blur's kernels");
    }
    fv_blur_table_fill(w, h, nq, off, k);
    j.t = (fv_kblur_table){w, h, (w > h ? w : h) - 1, nq, off, k};
    j.sigma = sigma;
    j.rgb = rgb;
    j.tmp = tmp;
    /* the vertical pass reads the horizontal one's whole neighbourhood: two passes */
    for (j.vertical = 0; j.vertical < 2; j.vertical++) fv_parallel_tiles(w, h, threads, blur_tile, &j, NULL, NULL);
    free(off), free(k);
    return FV_OK;
}
