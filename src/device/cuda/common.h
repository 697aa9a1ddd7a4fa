/* fovea — what the CUDA backends share (device/cuda/pt.cu, sdf.cu, vpolar.cu): the launch macro
 * (device/cuda/launch.h, FV_CUDA_LAUNCH), the error line of a failed CUDA call, a device array
 * refilled from the host only when its bytes changed, and a film on the GPU, its buffers kept
 * between frames of one size and read back into the host film's buffers that are set. Host code
 * only; included by .cu files.
 */
#ifndef FV_DEVICE_CUDA_COMMON_H
#define FV_DEVICE_CUDA_COMMON_H

#include <cuda_runtime.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "fovea/film.h"
#include "fovea/status.h"
#include "device/cuda/launch.h"

static inline fv_status fv_cuda_fail(cudaError_t e, const char *what, fv_error *err)
{
    return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %s while %s", cudaGetErrorString(e), what);
}

/* Forgets the error an earlier failed call left for cudaGetLastError. CUDA keeps the last error of
 * any runtime call, a cudaMalloc out of memory included, until cudaGetLastError reads it; a frame
 * checks cudaGetLastError after its launches, so without this the frame after a failed one (a
 * retry once memory was freed, the next method of a bench) would report the old failure as its
 * launch's. Every render calls it before its first CUDA call; what that failure was has been
 * returned already. A sticky error (the context lost) is not forgotten: every later call returns it. */
static inline void fv_cuda_forget_error(void) { (void)cudaGetLastError(); }

/* A device array that grows and is refilled from the host when what it holds changed. */
typedef struct fv_cuda_mirror {
    void *p;
    size_t cap;   /* bytes */
    void *mirror; /* host copy of what p holds, bytes long */
    size_t bytes;
} fv_cuda_mirror;

/* Makes a hold src's bytes: nothing happens when it already does (the host mirror is compared), so
 * what does not change between frames is copied once. The copy is queued on stream st (0: the
 * legacy stream); from pageable memory it is staged before this returns, so src may change after.
 * what names the data in the error line. */
static inline fv_status fv_cuda_mirror_fill(fv_cuda_mirror *a, const void *src, size_t bytes, cudaStream_t st, const char *what, fv_error *err)
{
    if (bytes == 0) return FV_OK;
    if (a->p && bytes == a->bytes && memcmp(a->mirror, src, bytes) == 0) return FV_OK; /* unchanged since the last copy */
    cudaError_t e;
    if (bytes > a->cap) {
        cudaFree(a->p);
        free(a->mirror);
        a->p = a->mirror = NULL;
        a->cap = a->bytes = 0;
        if (!(a->mirror = malloc(bytes))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        if ((e = cudaMalloc(&a->p, bytes)) != cudaSuccess)
            return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for %s", what)
                                                  : fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %s while allocating %s", cudaGetErrorString(e), what);
        a->cap = bytes;
    }
    a->bytes = 0; /* stale until the copy succeeds */
    if ((e = cudaMemcpyAsync(a->p, src, bytes, cudaMemcpyHostToDevice, st)) != cudaSuccess)
        return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %s while copying %s", cudaGetErrorString(e), what);
    memcpy(a->mirror, src, bytes);
    a->bytes = bytes;
    return FV_OK;
}

static inline void fv_cuda_mirror_free(fv_cuda_mirror *a)
{
    cudaFree(a->p);
    free(a->mirror);
    memset(a, 0, sizeof *a);
}

typedef struct fv_cuda_film {
    float *color, *depth, *normal, *albedo, *position;
    uint32_t *id;
    size_t pixels; /* the size the buffers have, 0: none */
} fv_cuda_film;

/* (Re)allocates a device buffer for a host buffer that is set, none for one that is not. */
static inline cudaError_t fv_cuda_film_buffer(void **dev, const void *host, size_t bytes, bool resize)
{
    if (resize || !host) {
        cudaFree(*dev);
        *dev = NULL;
    }
    if (host && !*dev) return cudaMalloc(dev, bytes);
    return cudaSuccess;
}

/* Makes the device film match host's buffers for n pixels; *dv receives its views. */
static inline fv_status fv_cuda_film_prepare(fv_cuda_film *f, const fv_film_views *host, size_t n, fv_film_views *dv, fv_error *err)
{
    bool resize = n != f->pixels;
    cudaError_t e;
    if ((e = fv_cuda_film_buffer((void **)&f->color, host->color, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer((void **)&f->depth, host->depth, n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer((void **)&f->normal, host->normal, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer((void **)&f->albedo, host->albedo, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer((void **)&f->position, host->position, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer((void **)&f->id, host->id, n * sizeof(uint32_t), resize)) != cudaSuccess) {
        f->pixels = 0;
        return fv_cuda_fail(e, "allocating the film", err);
    }
    f->pixels = n;
    dv->color = f->color;
    dv->depth = f->depth;
    dv->normal = f->normal;
    dv->albedo = f->albedo;
    dv->position = f->position;
    dv->id = f->id;
    return FV_OK;
}

/* Queues the copies of the device film's n pixels into host's buffers that are set on stream st; the
 * caller waits for the stream once, after whatever else it reads back. */
static inline cudaError_t fv_cuda_film_read_async(const fv_cuda_film *f, const fv_film_views *host, size_t n, cudaStream_t st)
{
    struct {
        void *host;
        const void *dev;
        size_t bytes;
    } back[6] = {{host->color, f->color, 3 * n * sizeof(float)},       {host->depth, f->depth, n * sizeof(float)},
                 {host->normal, f->normal, 3 * n * sizeof(float)},     {host->albedo, f->albedo, 3 * n * sizeof(float)},
                 {host->position, f->position, 3 * n * sizeof(float)}, {host->id, f->id, n * sizeof(uint32_t)}};
    cudaError_t e = cudaSuccess;
    for (int i = 0; i < 6 && e == cudaSuccess; i++)
        if (back[i].host) e = cudaMemcpyAsync(back[i].host, back[i].dev, back[i].bytes, cudaMemcpyDeviceToHost, st);
    return e;
}

static inline void fv_cuda_film_free(fv_cuda_film *f)
{
    cudaFree(f->color);
    cudaFree(f->depth);
    cudaFree(f->normal);
    cudaFree(f->albedo);
    cudaFree(f->position);
    cudaFree(f->id);
    f->color = f->depth = f->normal = f->albedo = f->position = NULL;
    f->id = NULL;
    f->pixels = 0;
}

#endif
