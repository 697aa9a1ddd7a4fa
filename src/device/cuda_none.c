/* fovea — the CUDA backend of a build without CUDA (device/cuda/backend_api.h): the probe says so,
 * and creating one refuses with that line, so --device cuda exits 2 with it. Compiled only where
 * no CUDA backend is built (CMakeLists.txt); the CUDA simulator's test library links the simulated
 * backend instead. The other entries are never reached without a backend and do nothing. */
#ifndef FOVEA_HAVE_CUDA
#include <stdio.h>
#include <string.h>
#include "device/cuda/backend_api.h"

static const char k_no_cuda[] = "fovea was built without CUDA (configure with a CUDA compiler on the PATH, or -DFOVEA_CUDA=ON; docs/gpu.md)";

bool fv_cuda_backend_probe(char *why, size_t why_len)
{
    if (why && why_len) snprintf(why, why_len, "%s", k_no_cuda);
    return false;
}

fv_status fv_cuda_backend_create(fv_cuda_backend **out, fv_error *err)
{
    *out = NULL;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

void fv_cuda_backend_destroy(fv_cuda_backend *c) { (void)c; }

/* Unreachable: there is never a backend to call them with. */
void fv_cuda_backend_calls(const fv_cuda_backend *c, fv_backend_calls *out)
{
    (void)c;
    memset(out, 0, sizeof *out);
}

fv_status fv_cuda_backend_alloc(fv_cuda_backend *c, void **p, size_t bytes, const char *what, fv_error *err)
{
    (void)c, (void)bytes, (void)what;
    *p = NULL;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

void fv_cuda_backend_free(fv_cuda_backend *c, void *p) { (void)c, (void)p; }

fv_status fv_cuda_backend_host_alloc(fv_cuda_backend *c, void **p, size_t bytes, const char *what, fv_error *err)
{
    return fv_cuda_backend_alloc(c, p, bytes, what, err);
}

void fv_cuda_backend_host_free(fv_cuda_backend *c, void *p) { (void)c, (void)p; }

fv_status fv_cuda_backend_copy(fv_cuda_backend *c, void *dst, const void *src, size_t bytes, enum fv_cuda_copy_kind kind, const char *what,
                               fv_error *err)
{
    (void)c, (void)dst, (void)src, (void)bytes, (void)kind, (void)what;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

fv_status fv_cuda_backend_clear(fv_cuda_backend *c, void *p, int byte, size_t bytes, const char *what, fv_error *err)
{
    (void)c, (void)p, (void)byte, (void)bytes, (void)what;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

fv_status fv_cuda_backend_launch(fv_cuda_backend *c, const fv_kernel *k, int w, int h, const void *args, uint64_t *counts, fv_error *err)
{
    (void)c, (void)k, (void)w, (void)h, (void)args, (void)counts;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

void fv_cuda_backend_mark(fv_cuda_backend *c, int slot) { (void)c, (void)slot; }

double fv_cuda_backend_elapsed_ms(fv_cuda_backend *c, int from, int to)
{
    (void)c, (void)from, (void)to;
    return 0.0;
}

void fv_cuda_backend_fence(fv_cuda_backend *c, int slot) { (void)c, (void)slot; }

fv_status fv_cuda_backend_wait_fence(fv_cuda_backend *c, int slot, const char *what, fv_error *err)
{
    (void)c, (void)slot, (void)what;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}

fv_status fv_cuda_backend_wait(fv_cuda_backend *c, const char *what, fv_error *err)
{
    (void)c, (void)what;
    return fv_error_set(err, FV_ERR_INVALID, "%s", k_no_cuda);
}
#endif
