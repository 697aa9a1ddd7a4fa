/* fovea — the CUDA backend's runtime calls (device/cuda/backend.cu): through wrappers that count
 * them (fv_cuda_tally: what fv_backend_calls and --stats-json report), and the error line of a
 * failed CUDA call. Host code only; the simulator's self-test (tests/gpu/cuda_sim_selftest.cpp)
 * checks the counting against the simulator's own.
 */
#ifndef FV_DEVICE_CUDA_COMMON_H
#define FV_DEVICE_CUDA_COMMON_H

#include <cuda_runtime.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "fovea/status.h"
#include "device/cuda/launch.h"
#include "device/backend.h"

/* ---- the runtime calls, counted (fv_backend_calls, device/backend.h) ----
 *
 * Every allocation, copy, clear, synchronize and launch of a backend goes through these, with the
 * backend's tally: the counts are then what the backend did, on a GPU as on the simulator (whose own
 * counts the sim tests compare with them). What CUDA would make the host wait for is the work
 * queued since the host last waited: every queued call takes the next number (seq), and a wait
 * covers the numbers up to `waited` (all of them, or those before a fence: fv_cuda_fence_wait). */
typedef fv_backend_calls fv_cuda_calls;

typedef struct fv_cuda_tally {
    fv_cuda_calls n;
    uint64_t seq, waited; /* calls queued so far; the last one the host has waited for */
} fv_cuda_tally;

static inline bool fv_cuda_queued(const fv_cuda_tally *k) { return k->seq != k->waited; }
static inline void fv_cuda_queue(fv_cuda_tally *k) { k->seq++; }

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
    if (fv_cuda_queued(k) || always) k->n.host_waits++;
    k->waited = k->seq;
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
        fv_cuda_queue(k);
    }
    return e;
}

static inline cudaError_t fv_cuda_clear(fv_cuda_tally *k, void *p, int value, size_t bytes, cudaStream_t st)
{
    if (bytes == 0) return cudaSuccess;
    fv_cuda_queue(k);
    return cudaMemsetAsync(p, value, bytes, st);
}

static inline cudaError_t fv_cuda_wait(fv_cuda_tally *k, cudaStream_t st)
{
    k->n.syncs++;
    fv_cuda_waited(k, false);
    return cudaStreamSynchronize(st);
}

/* cudaEventSynchronize on an event recorded when the tally stood at `at` (its seq then): the host
 * waits only if something queued before the event was not waited for, and what was queued after it
 * stays queued (a frame collected while the next one runs). */
static inline cudaError_t fv_cuda_fence_wait(fv_cuda_tally *k, cudaEvent_t ev, uint64_t at)
{
    k->n.syncs++;
    if (at > k->waited) {
        k->n.host_waits++;
        k->waited = at;
    }
    return cudaEventSynchronize(ev);
}

/* For FV_CUDA_LAUNCH (device/cuda/launch.h): a launch is about to be queued. */
static inline int fv_cuda_launching(fv_cuda_tally *k)
{
    k->n.launches++;
    fv_cuda_queue(k);
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

#endif
