/* fovea — the CUDA backend of `pt` (see device/cuda_backend.h): the flat scene copied to the GPU
 * field by field, and the pixel kernel of kernel/pt.h launched one thread a pixel.
 *
 * Design (docs/gpu.md): a megakernel. Each thread runs its pixel's whole paths, the same function
 * the portable backend runs on the CPU, so the GPU's image equals the portable one up to float
 * rounding. A wavefront design (a queue of rays per bounce) would trade this sameness for
 * coherence; it is measured against this one before it replaces it.
 *
 * Memory: the scene's arrays are copied once at create; update re-copies only what time changes
 * (objects' transforms, instances, the top-level BVH, the light table; device/cuda/scene.h). The
 * films' buffers (one per eye) stay allocated between frames of one size; a stereo pair's two
 * kernels are launched before the one host wait that reads both films back.
 */
#include <cuda_runtime.h>
#include <stdio.h>
#include <string.h>
#include "device/cuda/common.h"
#include "device/cuda/scene.h"
#include "device/cuda_backend.h"
#include "kernel/pt.h"

/* Threads of a block: 8 x 8 pixels, a tile whose paths start coherent. */
#define FV_CUDA_BLOCK 8

struct fv_cuda_pt {
    fv_cuda_tally calls;     /* what it asked of the runtime (device/cuda/common.h) */
    fv_cuda_scene scene;     /* the flat scene on the GPU (device/cuda/scene.h) */
    fv_cuda_film film[2];    /* per eye (a stereo pair is read back after both ran), kept between frames of one size */
    unsigned long long *counts; /* rays, non-finite estimates */
    cudaEvent_t start, stop;
};


extern "C" bool fv_cuda_probe(char *why, size_t why_len)
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

extern "C" fv_status fv_cuda_pt_update(fv_cuda_pt *c, const fv_kscene *h, fv_error *err)
{
    return fv_cuda_scene_update(&c->calls, &c->scene, h, 0, err);
}

extern "C" void fv_cuda_pt_destroy(fv_cuda_pt *c)
{
    if (!c) return;
    fv_cuda_scene_free(&c->calls, &c->scene);
    fv_cuda_film_free(&c->calls, &c->film[0]);
    fv_cuda_film_free(&c->calls, &c->film[1]);
    fv_cuda_release(&c->calls, c->counts);
    if (c->start) cudaEventDestroy(c->start);
    if (c->stop) cudaEventDestroy(c->stop);
    free(c);
}

extern "C" void fv_cuda_pt_calls(const fv_cuda_pt *c, fv_cuda_calls *out) { *out = c->calls.n; }

extern "C" fv_status fv_cuda_pt_create(const fv_kscene *host, fv_cuda_pt **out, fv_error *err)
{
    *out = NULL;
    fv_cuda_pt *c = (fv_cuda_pt *)calloc(1, sizeof *c);
    if (!c) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_status s = fv_cuda_scene_upload(&c->calls, &c->scene, host, err);
    cudaError_t e;
    if (s == FV_OK && (e = fv_cuda_alloc(&c->calls, (void **)&c->counts, 2 * sizeof(unsigned long long))) != cudaSuccess) s = fv_cuda_fail(e, "allocating counters", err);
    if (s == FV_OK && ((e = cudaEventCreate(&c->start)) != cudaSuccess || (e = cudaEventCreate(&c->stop)) != cudaSuccess))
        s = fv_cuda_fail(e, "creating events", err);
    if (s != FV_OK) {
        fv_cuda_pt_destroy(c);
        return s;
    }
    *out = c;
    return FV_OK;
}

__global__ void fv_cuda_pt_kernel(fv_kscene s, fv_kpt_frame f, fv_film_views out, unsigned long long *counts)
{
    int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x >= f.cam.width || y >= f.cam.height) return;
    uint64_t rays = 0, bad = 0;
    fv_kpt_pixel(&s, &f, x, y, &out, &rays, &bad);
    atomicAdd(&counts[0], (unsigned long long)rays);
    if (bad) atomicAdd(&counts[1], (unsigned long long)bad);
}

extern "C" fv_status fv_cuda_pt_render(fv_cuda_pt *c, int eyes, const fv_kpt_frame *f, const fv_film_views *out, uint64_t *rays,
                                       uint64_t *nan_samples, double *kernel_ms, int *syncs, fv_error *err)
{
    *syncs = 0;
    if (eyes < 1 || eyes > 2) return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %d eyes", eyes);
    fv_cuda_forget_error();
    /* every eye's film first: nothing between the launches but launches */
    size_t n[2];
    fv_film_views dv[2];
    fv_status s;
    for (int i = 0; i < eyes; i++) {
        n[i] = (size_t)f[i].cam.width * (size_t)f[i].cam.height;
        if ((s = fv_cuda_film_prepare(&c->calls, &c->film[i], &out[i], n[i], &dv[i], err)) != FV_OK) return s;
    }
    cudaStream_t st = 0;
    cudaError_t e;
    if ((e = fv_cuda_clear(&c->calls, c->counts, 0, 2 * sizeof(unsigned long long), st)) != cudaSuccess) return fv_cuda_fail(e, "clearing counters", err);
    dim3 block(FV_CUDA_BLOCK, FV_CUDA_BLOCK);
    cudaEventRecord(c->start, st);
    for (int i = 0; i < eyes; i++) {
        dim3 grid((unsigned)((f[i].cam.width + FV_CUDA_BLOCK - 1) / FV_CUDA_BLOCK), (unsigned)((f[i].cam.height + FV_CUDA_BLOCK - 1) / FV_CUDA_BLOCK));
        FV_CUDA_LAUNCH(&c->calls, fv_cuda_pt_kernel, grid, block, st)(c->scene.dev, f[i], dv[i], c->counts);
    }
    cudaEventRecord(c->stop, st);
    if ((e = cudaGetLastError()) != cudaSuccess) return fv_cuda_fail(e, "launching the pt kernel", err);
    /* what the host receives, enqueued behind the kernels, then its one wait */
    unsigned long long counts[2];
    for (int i = 0; i < eyes && e == cudaSuccess; i++) e = fv_cuda_film_read_async(&c->calls, &c->film[i], &out[i], n[i], st);
    if (e == cudaSuccess) e = fv_cuda_copy(&c->calls, counts, c->counts, sizeof counts, cudaMemcpyDeviceToHost, st);
    if (e == cudaSuccess) e = fv_cuda_wait(&c->calls, st);
    *syncs = 1;
    if (e != cudaSuccess) return fv_cuda_fail(e, "running the pt kernel", err);
    float ms = 0.0f;
    cudaEventElapsedTime(&ms, c->start, c->stop);
    *kernel_ms = ms;
    *rays = counts[0];
    *nan_samples = counts[1];
    return FV_OK;
}
