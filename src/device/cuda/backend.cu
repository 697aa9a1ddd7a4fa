/* fovea — the device backend on CUDA (device/backend.h, device/cuda/backend_api.h): one stream per
 * backend, on which every copy, clear and launch is queued in order; the host waits only in
 * fv_cuda_backend_wait and _wait_fence, in a free after queued work, and in a copy whose host side is pageable
 * (which CUDA makes blocking: the families use pinned memory, fv_pinned_ensure, so they have none).
 * Every runtime call goes through device/cuda/common.h's counted wrappers, so the figures
 * fv_backend_calls reports are what this code asked of the runtime, on a GPU as on the simulator.
 */
#include <cuda_runtime.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "device/cuda/backend_api.h"
#include "device/cuda/common.h"
#include "device/cuda/kernel_cuda.h"

struct fv_cuda_backend {
    fv_cuda_tally calls;
    cudaStream_t stream;
    cudaEvent_t mark[FV_BACKEND_MARKS];
    unsigned marked; /* slots recorded since the backend was made */
    cudaEvent_t fence[FV_BACKEND_FENCES];
    uint64_t fence_at[FV_BACKEND_FENCES]; /* the tally's seq when each was recorded */
};

extern "C" bool fv_cuda_backend_probe(char *why, size_t why_len)
{
    int n = 0;
    cudaError_t e = cudaGetDeviceCount(&n);
    if (e != cudaSuccess || n == 0) {
        if (why && why_len) snprintf(why, why_len, "no CUDA device (%s)", e != cudaSuccess ? cudaGetErrorString(e) : "none found");
        return false;
    }
    cudaDeviceProp p;
    if ((e = cudaGetDeviceProperties(&p, 0)) != cudaSuccess) {
        if (why && why_len) snprintf(why, why_len, "no CUDA device (%s)", cudaGetErrorString(e));
        return false;
    }
    /* The build carries code for sm_80 and sm_90 (plus PTX for newer): older GPUs cannot run it. */
    if (p.major < 8) {
        if (why && why_len) snprintf(why, why_len, "no CUDA device of compute capability 8.0 or newer (%s is %d.%d)", p.name, p.major, p.minor);
        return false;
    }
    return true;
}

extern "C" void fv_cuda_backend_destroy(fv_cuda_backend *c)
{
    if (!c) return;
    /* nothing queued may outlive its buffers (a frame ends with its wait, so usually nothing is) */
    if (c->stream && fv_cuda_queued(&c->calls)) fv_cuda_wait(&c->calls, c->stream);
    for (int i = 0; i < FV_BACKEND_MARKS; i++)
        if (c->mark[i]) cudaEventDestroy(c->mark[i]);
    for (int i = 0; i < FV_BACKEND_FENCES; i++)
        if (c->fence[i]) cudaEventDestroy(c->fence[i]);
    if (c->stream) cudaStreamDestroy(c->stream);
    free(c);
}

extern "C" fv_status fv_cuda_backend_create(fv_cuda_backend **out, fv_error *err)
{
    *out = NULL;
    char why[256];
    if (!fv_cuda_backend_probe(why, sizeof why)) return fv_error_set(err, FV_ERR_INVALID, "%s", why);
    fv_cuda_backend *c = (fv_cuda_backend *)calloc(1, sizeof *c);
    if (!c) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_cuda_forget_error();
    cudaError_t e = cudaStreamCreate(&c->stream);
    for (int i = 0; e == cudaSuccess && i < FV_BACKEND_MARKS; i++) e = cudaEventCreate(&c->mark[i]);
    for (int i = 0; e == cudaSuccess && i < FV_BACKEND_FENCES; i++) e = cudaEventCreate(&c->fence[i]);
    if (e != cudaSuccess) {
        fv_cuda_backend_destroy(c);
        return fv_cuda_fail(e, "creating a stream and its events", err);
    }
    *out = c;
    return FV_OK;
}

extern "C" void fv_cuda_backend_calls(const fv_cuda_backend *c, fv_backend_calls *out)
{
    const fv_cuda_calls *n = &c->calls.n;
    out->launches = n->launches, out->syncs = n->syncs, out->host_waits = n->host_waits, out->pageable_copies = n->pageable_copies;
    out->bytes_h2d = n->bytes_h2d, out->bytes_d2h = n->bytes_d2h, out->allocations = n->allocations, out->frees = n->frees;
}

extern "C" fv_status fv_cuda_backend_alloc(fv_cuda_backend *c, void **p, size_t bytes, const char *what, fv_error *err)
{
    *p = NULL;
    cudaError_t e = fv_cuda_alloc(&c->calls, p, bytes);
    if (e == cudaSuccess) return FV_OK;
    *p = NULL;
    fv_cuda_forget_error(); /* not the next launch's error */
    return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for %s (%zu bytes)", what, bytes)
                                          : fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %s while allocating %s", cudaGetErrorString(e), what);
}

extern "C" void fv_cuda_backend_free(fv_cuda_backend *c, void *p) { fv_cuda_release(&c->calls, p); }

extern "C" fv_status fv_cuda_backend_host_alloc(fv_cuda_backend *c, void **p, size_t bytes, const char *what, fv_error *err)
{
    (void)c;
    *p = NULL;
    cudaError_t e = cudaHostAlloc(p, bytes, cudaHostAllocDefault);
    if (e == cudaSuccess) return FV_OK;
    *p = NULL;
    fv_cuda_forget_error();
    return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of pinned host memory for %s (%zu bytes)", what, bytes)
                                          : fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %s while allocating pinned memory for %s", cudaGetErrorString(e), what);
}

/* cudaFreeHost waits for the device, as cudaFree does. */
extern "C" void fv_cuda_backend_host_free(fv_cuda_backend *c, void *p)
{
    if (!p) return;
    cudaFreeHost(p);
    fv_cuda_waited(&c->calls, false);
}

extern "C" fv_status fv_cuda_backend_copy(fv_cuda_backend *c, void *dst, const void *src, size_t bytes, enum fv_cuda_copy_kind kind,
                                          const char *what, fv_error *err)
{
    const cudaMemcpyKind k = kind == FV_CUDA_H2D ? cudaMemcpyHostToDevice : kind == FV_CUDA_D2H ? cudaMemcpyDeviceToHost : cudaMemcpyDeviceToDevice;
    cudaError_t e = fv_cuda_copy(&c->calls, dst, src, bytes, k, c->stream);
    if (e == cudaSuccess) return FV_OK;
    char msg[160];
    snprintf(msg, sizeof msg, "copying %s", what);
    return fv_cuda_fail(e, msg, err);
}

extern "C" fv_status fv_cuda_backend_clear(fv_cuda_backend *c, void *p, int byte, size_t bytes, const char *what, fv_error *err)
{
    cudaError_t e = fv_cuda_clear(&c->calls, p, byte, bytes, c->stream);
    if (e == cudaSuccess) return FV_OK;
    char msg[160];
    snprintf(msg, sizeof msg, "clearing %s", what);
    return fv_cuda_fail(e, msg, err);
}

extern "C" fv_status fv_cuda_backend_launch(fv_cuda_backend *c, const fv_kernel *k, int w, int h, const void *args, uint64_t *counts, fv_error *err)
{
    if (!k->cuda) return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: kernel %s was built without its CUDA side", k->name);
    fv_cuda_launching(&c->calls);
    k->cuda->launch(args, w, h, (unsigned long long *)counts, c->stream);
    /* a launch of an impossible shape or with a sticky error reports here; an error while the
     * kernel runs reports at the wait */
    cudaError_t e = cudaPeekAtLastError();
    if (e == cudaSuccess) return FV_OK;
    char msg[160];
    snprintf(msg, sizeof msg, "launching %s", k->name);
    return fv_cuda_fail(e, msg, err);
}

extern "C" void fv_cuda_backend_mark(fv_cuda_backend *c, int slot)
{
    if (cudaEventRecord(c->mark[slot], c->stream) == cudaSuccess) c->marked |= 1u << slot;
}

extern "C" double fv_cuda_backend_elapsed_ms(fv_cuda_backend *c, int from, int to)
{
    if (!(c->marked & (1u << from)) || !(c->marked & (1u << to))) return 0.0;
    float ms = 0.0f;
    return cudaEventElapsedTime(&ms, c->mark[from], c->mark[to]) == cudaSuccess ? (double)ms : 0.0;
}

extern "C" void fv_cuda_backend_fence(fv_cuda_backend *c, int slot)
{
    if (cudaEventRecord(c->fence[slot], c->stream) == cudaSuccess) c->fence_at[slot] = c->calls.seq;
}

extern "C" fv_status fv_cuda_backend_wait_fence(fv_cuda_backend *c, int slot, const char *what, fv_error *err)
{
    cudaError_t e = fv_cuda_fence_wait(&c->calls, c->fence[slot], c->fence_at[slot]);
    if (e == cudaSuccess) e = cudaGetLastError();
    if (e == cudaSuccess) return FV_OK;
    char msg[160];
    snprintf(msg, sizeof msg, "running %s", what);
    return fv_cuda_fail(e, msg, err);
}

extern "C" fv_status fv_cuda_backend_wait(fv_cuda_backend *c, const char *what, fv_error *err)
{
    cudaError_t e = fv_cuda_wait(&c->calls, c->stream);
    if (e == cudaSuccess) e = cudaGetLastError();
    if (e == cudaSuccess) return FV_OK;
    char msg[160];
    snprintf(msg, sizeof msg, "running %s", what);
    return fv_cuda_fail(e, msg, err);
}
