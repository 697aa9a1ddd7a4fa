/* fovea — the CUDA backend of a build without CUDA (see cuda_backend.h): every entry refuses with
 * "fovea was built without CUDA", so --device cuda exits 2 with that line. */
#ifndef FOVEA_HAVE_CUDA
#include <stdio.h>
#include <string.h>
#include "device/cuda_backend.h"

static const char k_no_cuda[] = "fovea was built without CUDA (configure with a CUDA compiler on the PATH, or -DFOVEA_CUDA=ON; docs/gpu.md)";

fv_status fv_cuda_vp_create(const struct fv_kscene *host, fv_cuda_vp **out, fv_error *err)
{
    (void)host;
    *out = NULL;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

void fv_cuda_vp_destroy(fv_cuda_vp *c) { (void)c; }

fv_status fv_cuda_vp_render(fv_cuda_vp *const *c, int eyes, const fv_cuda_vp_frame *f, const fv_film_views *out, fv_cuda_vp_result *res,
                            fv_error *err)
{
    (void)c, (void)eyes, (void)f, (void)out, (void)res;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

/* Nothing is ever created here, so nothing has been asked of a runtime. */
void fv_cuda_vp_calls(const fv_cuda_vp *c, fv_cuda_calls *out)
{
    (void)c;
    memset(out, 0, sizeof *out);
}
#else
typedef int fv_cuda_stub_unused; /* ISO C: a translation unit is not empty */
#endif
