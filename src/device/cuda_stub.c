/* fovea — the CUDA backend of a build without CUDA (see cuda_backend.h): every entry refuses with
 * "fovea was built without CUDA", so --device cuda exits 2 with that line. */
#ifndef FOVEA_HAVE_CUDA
#include <stdio.h>
#include <string.h>
#include "device/cuda_backend.h"

static const char k_no_cuda[] = "fovea was built without CUDA (configure with a CUDA compiler on the PATH, or -DFOVEA_CUDA=ON; docs/gpu.md)";

fv_status fv_cuda_sdf_create(fv_cuda_sdf **out, fv_error *err)
{
    *out = NULL;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

fv_status fv_cuda_sdf_render(fv_cuda_sdf *c, const struct fv_ksdf_world *w, int eyes, const struct fv_ksdf_frame *f, const fv_film_views *out,
                             struct fv_ksdf_counts *counts, double *kernel_ms, int *syncs, fv_error *err)
{
    (void)c, (void)w, (void)eyes, (void)f, (void)out, (void)counts, (void)kernel_ms, (void)syncs;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

fv_status fv_cuda_sdf_pyramid_render(fv_cuda_sdf *c, const struct fv_ksdf_world *w, int eyes, const struct fv_ksdf_frame *f, const struct fv_kpyr *shape,
                                     const struct fv_kpyr_fovea *fov, const fv_cuda_pyr_opts *po, const fv_film_views *out,
                                     struct fv_ksdf_pyr_counts *counts, double *kernel_ms, int *syncs, fv_error *err)
{
    (void)c, (void)w, (void)eyes, (void)f, (void)shape, (void)fov, (void)po, (void)out, (void)counts, (void)kernel_ms, (void)syncs;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

void fv_cuda_sdf_destroy(fv_cuda_sdf *c) { (void)c; }

/* Nothing is ever created here, so nothing has been asked of a runtime. */
void fv_cuda_sdf_calls(const fv_cuda_sdf *c, fv_cuda_calls *out)
{
    (void)c;
    memset(out, 0, sizeof *out);
}
#else
typedef int fv_cuda_stub_unused; /* ISO C: a translation unit is not empty */
#endif
