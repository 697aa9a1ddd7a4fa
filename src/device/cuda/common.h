/* fovea — what the CUDA code shares (device/cuda/backend.cu, and the family frames not yet over the
 * backend, sdf.cu and vpolar.cu): the launch macro
 * (device/cuda/launch.h, FV_CUDA_LAUNCH), the runtime calls through wrappers that count them
 * (fv_cuda_tally: what --stats-json reports), the error line of a failed CUDA call, a device array
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
#include "device/cuda_backend.h"

/* ---- the runtime calls, counted (fv_cuda_calls, device/cuda_backend.h) ----
 *
 * Every allocation, copy, clear, synchronize and launch of a backend goes through these, with the
 * backend's tally: the counts are then what the backend did, on a GPU as on the simulator (whose own
 * counts the sim tests compare with them). `queued` follows what CUDA would make the host wait for:
 * work queued since the host last waited. */
typedef struct fv_cuda_tally {
    fv_cuda_calls n;
    bool queued;
} fv_cuda_tally;

/* Whether host memory p is pageable (neither cudaHostAlloc's nor registered): a copy between it and
 * the device blocks the host. An address CUDA cannot classify counts as pageable. */
static inline bool fv_cuda_pageable(const void *p)
{
    cudaPointerAttributes a;
    if (cudaPointerGetAttributes(&a, p) != cudaSuccess) {
        (void)cudaGetLastError(); /* not the frame's error */
        return true;
    }
    return a.type == cudaMemoryTypeUnregistered;
}

/* The host waited: for the queued work, and with `always` for the call's own transfer too. */
static inline void fv_cuda_waited(fv_cuda_tally *k, bool always)
{
    if (k->queued || always) k->n.host_waits++;
    k->queued = false;
}

static inline cudaError_t fv_cuda_alloc(fv_cuda_tally *k, void **p, size_t bytes)
{
    cudaError_t e = cudaMalloc(p, bytes);
    if (e == cudaSuccess && *p) k->n.allocations++;
    return e;
}

/* cudaFree, which waits for the device (nothing for NULL). */
static inline void fv_cuda_release(fv_cuda_tally *k, void *p)
{
    if (!p) return;
    cudaFree(p);
    k->n.frees++;
    fv_cuda_waited(k, false);
}

/* A copy's bytes, each way, and whether its host side is pageable (then it is counted as such). */
static inline bool fv_cuda_count_copy(fv_cuda_tally *k, void *dst, const void *src, size_t bytes, enum cudaMemcpyKind kind)
{
    bool pageable = false;
    if (kind == cudaMemcpyHostToDevice) {
        k->n.bytes_h2d += bytes;
        pageable = fv_cuda_pageable(src);
    } else if (kind == cudaMemcpyDeviceToHost) {
        k->n.bytes_d2h += bytes;
        pageable = fv_cuda_pageable(dst);
    }
    if (pageable) k->n.pageable_copies++;
    return pageable;
}

/* cudaMemcpyAsync on st, host to device or device to host (or device to device). */
static inline cudaError_t fv_cuda_copy(fv_cuda_tally *k, void *dst, const void *src, size_t bytes, enum cudaMemcpyKind kind, cudaStream_t st)
{
    if (bytes == 0) return cudaSuccess;
    const bool pageable = fv_cuda_count_copy(k, dst, src, bytes, kind);
    cudaError_t e = cudaMemcpyAsync(dst, src, bytes, kind, st);
    if (pageable) {
        fv_cuda_waited(k, true);
    } else {
        k->queued = true;
    }
    return e;
}

/* cudaMemcpy: the host waits for the work before it and for the copy. */
static inline cudaError_t fv_cuda_copy_now(fv_cuda_tally *k, void *dst, const void *src, size_t bytes, enum cudaMemcpyKind kind)
{
    if (bytes == 0) return cudaSuccess;
    fv_cuda_count_copy(k, dst, src, bytes, kind);
    cudaError_t e = cudaMemcpy(dst, src, bytes, kind);
    fv_cuda_waited(k, true);
    return e;
}

static inline cudaError_t fv_cuda_clear(fv_cuda_tally *k, void *p, int value, size_t bytes, cudaStream_t st)
{
    if (bytes == 0) return cudaSuccess;
    k->queued = true;
    return cudaMemsetAsync(p, value, bytes, st);
}

static inline cudaError_t fv_cuda_wait(fv_cuda_tally *k, cudaStream_t st)
{
    k->n.syncs++;
    fv_cuda_waited(k, false);
    return cudaStreamSynchronize(st);
}

/* For FV_CUDA_LAUNCH (device/cuda/launch.h): a launch is about to be queued. */
static inline int fv_cuda_launching(fv_cuda_tally *k)
{
    k->n.launches++;
    k->queued = true;
    return 1;
}

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
static inline fv_status fv_cuda_mirror_fill(fv_cuda_tally *k, fv_cuda_mirror *a, const void *src, size_t bytes, cudaStream_t st, const char *what,
                                           fv_error *err)
{
    if (bytes == 0) return FV_OK;
    if (a->p && bytes == a->bytes && memcmp(a->mirror, src, bytes) == 0) return FV_OK; /* unchanged since the last copy */
    cudaError_t e;
    if (bytes > a->cap) {
        fv_cuda_release(k, a->p);
        free(a->mirror);
        a->p = a->mirror = NULL;
        a->cap = a->bytes = 0;
        if (!(a->mirror = malloc(bytes))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        if ((e = fv_cuda_alloc(k, &a->p, bytes)) != cudaSuccess)
            return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for %s", what)
                                                  : fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %s while allocating %s", cudaGetErrorString(e), what);
        a->cap = bytes;
    }
    a->bytes = 0; /* stale until the copy succeeds */
    if ((e = fv_cuda_copy(k, a->p, src, bytes, cudaMemcpyHostToDevice, st)) != cudaSuccess)
        return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %s while copying %s", cudaGetErrorString(e), what);
    memcpy(a->mirror, src, bytes);
    a->bytes = bytes;
    return FV_OK;
}

static inline void fv_cuda_mirror_free(fv_cuda_tally *k, fv_cuda_mirror *a)
{
    fv_cuda_release(k, a->p);
    free(a->mirror);
    memset(a, 0, sizeof *a);
}

typedef struct fv_cuda_film {
    float *color, *depth, *normal, *albedo, *position;
    uint32_t *id;
    size_t pixels; /* the size the buffers have, 0: none */
} fv_cuda_film;

/* (Re)allocates a device buffer for a host buffer that is set, none for one that is not. */
static inline cudaError_t fv_cuda_film_buffer(fv_cuda_tally *k, void **dev, const void *host, size_t bytes, bool resize)
{
    if (resize || !host) {
        fv_cuda_release(k, *dev);
        *dev = NULL;
    }
    if (host && !*dev) return fv_cuda_alloc(k, dev, bytes);
    return cudaSuccess;
}

/* Makes the device film match host's buffers for n pixels; *dv receives its views. */
static inline fv_status fv_cuda_film_prepare(fv_cuda_tally *k, fv_cuda_film *f, const fv_film_views *host, size_t n, fv_film_views *dv, fv_error *err)
{
    bool resize = n != f->pixels;
    cudaError_t e;
    if ((e = fv_cuda_film_buffer(k, (void **)&f->color, host->color, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer(k, (void **)&f->depth, host->depth, n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer(k, (void **)&f->normal, host->normal, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer(k, (void **)&f->albedo, host->albedo, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer(k, (void **)&f->position, host->position, 3 * n * sizeof(float), resize)) != cudaSuccess ||
        (e = fv_cuda_film_buffer(k, (void **)&f->id, host->id, n * sizeof(uint32_t), resize)) != cudaSuccess) {
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
static inline cudaError_t fv_cuda_film_read_async(fv_cuda_tally *k, const fv_cuda_film *f, const fv_film_views *host, size_t n, cudaStream_t st)
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
        if (back[i].host) e = fv_cuda_copy(k, back[i].host, back[i].dev, back[i].bytes, cudaMemcpyDeviceToHost, st);
    return e;
}

static inline void fv_cuda_film_free(fv_cuda_tally *k, fv_cuda_film *f)
{
    fv_cuda_release(k, f->color);
    fv_cuda_release(k, f->depth);
    fv_cuda_release(k, f->normal);
    fv_cuda_release(k, f->albedo);
    fv_cuda_release(k, f->position);
    fv_cuda_release(k, f->id);
    f->color = f->depth = f->normal = f->albedo = f->position = NULL;
    f->id = NULL;
    f->pixels = 0;
}

#endif
