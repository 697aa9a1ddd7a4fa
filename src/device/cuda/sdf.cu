/* fovea — the CUDA backend of `sdf-gt` and `sdf-relaxed` (see device/cuda_backend.h): the world's
 * flat form copied to the GPU each frame, and the pixel kernel of kernel/sdf_pixel.h launched one
 * thread a pixel, the very function the portable backend runs on the CPU (docs/gpu.md).
 *
 * Memory: the world's arrays (programs, moving objects, lights, materials) and the film keep
 * their GPU buffers between frames, grown only when a frame needs more; a frame copies the
 * world in (a few kilobytes: the programs do not change with time, the transforms and lights may)
 * and the displayed buffers out. The costs are summed per block in shared memory, then once per
 * block into the global counters.
 */
#include <cuda_runtime.h>
#include <stdio.h>
#include <string.h>
#include "device/cuda/common.h"
#include "device/cuda_backend.h"
#include "kernel/sdf_pixel.h"

/* Threads of a block: 8 x 8 pixels, whose rays start coherent. */
#define FV_CUDA_SDF_BLOCK 8
/* The counters, in this order: rays, steps, exhausted, nan, shadow rays, shadow steps, normal evaluations. */
#define FV_CUDA_SDF_COUNTS 7

/* A device array that grows and is refilled from the host. */
typedef struct dev_array {
    void *p;
    size_t cap; /* bytes */
} dev_array;

struct fv_cuda_sdf {
    dev_array ops, objs, lights, mats;
    fv_cuda_film film;
    unsigned long long *counts;
    cudaEvent_t start, stop;
};

static fv_status fill(dev_array *a, const void *src, size_t bytes, fv_error *err)
{
    if (bytes == 0) return FV_OK;
    cudaError_t e;
    if (bytes > a->cap) {
        cudaFree(a->p);
        a->p = NULL;
        a->cap = 0;
        if ((e = cudaMalloc(&a->p, bytes)) != cudaSuccess)
            return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for the world")
                                                  : fv_cuda_fail(e, "allocating the world", err);
        a->cap = bytes;
    }
    if ((e = cudaMemcpy(a->p, src, bytes, cudaMemcpyHostToDevice)) != cudaSuccess) return fv_cuda_fail(e, "copying the world", err);
    return FV_OK;
}

extern "C" void fv_cuda_sdf_destroy(fv_cuda_sdf *c)
{
    if (!c) return;
    cudaFree(c->ops.p);
    cudaFree(c->objs.p);
    cudaFree(c->lights.p);
    cudaFree(c->mats.p);
    fv_cuda_film_free(&c->film);
    cudaFree(c->counts);
    if (c->start) cudaEventDestroy(c->start);
    if (c->stop) cudaEventDestroy(c->stop);
    free(c);
}

extern "C" fv_status fv_cuda_sdf_create(fv_cuda_sdf **out, fv_error *err)
{
    *out = NULL;
    fv_cuda_sdf *c = (fv_cuda_sdf *)calloc(1, sizeof *c);
    if (!c) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    cudaError_t e;
    fv_status s = FV_OK;
    if ((e = cudaMalloc((void **)&c->counts, FV_CUDA_SDF_COUNTS * sizeof(unsigned long long))) != cudaSuccess)
        s = fv_cuda_fail(e, "allocating counters", err);
    if (s == FV_OK && ((e = cudaEventCreate(&c->start)) != cudaSuccess || (e = cudaEventCreate(&c->stop)) != cudaSuccess))
        s = fv_cuda_fail(e, "creating events", err);
    if (s != FV_OK) {
        fv_cuda_sdf_destroy(c);
        return s;
    }
    *out = c;
    return FV_OK;
}

__global__ void fv_cuda_sdf_kernel(fv_ksdf_world w, fv_ksdf_frame f, fv_film_views out, unsigned long long *counts)
{
    __shared__ unsigned long long sum[FV_CUDA_SDF_COUNTS];
    const int tid = (int)(threadIdx.y * blockDim.x + threadIdx.x);
    if (tid < FV_CUDA_SDF_COUNTS) sum[tid] = 0;
    __syncthreads();
    int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x < f.cam.width && y < f.cam.height) {
        fv_ksdf_counts c;
        memset(&c, 0, sizeof c);
        fv_ksdf_pixel(&w, &f, x, y, &out, &c);
        atomicAdd(&sum[0], (unsigned long long)c.rays);
        atomicAdd(&sum[1], (unsigned long long)c.steps);
        if (c.exhausted) atomicAdd(&sum[2], (unsigned long long)c.exhausted);
        if (c.nan) atomicAdd(&sum[3], (unsigned long long)c.nan);
        atomicAdd(&sum[4], (unsigned long long)c.shade.shadow_rays);
        atomicAdd(&sum[5], (unsigned long long)c.shade.shadow_steps);
        atomicAdd(&sum[6], (unsigned long long)c.shade.normal_evals);
    }
    __syncthreads();
    if (tid < FV_CUDA_SDF_COUNTS && sum[tid]) atomicAdd(&counts[tid], sum[tid]);
}

extern "C" fv_status fv_cuda_sdf_render(fv_cuda_sdf *c, const fv_ksdf_world *w, const fv_ksdf_frame *f, const fv_film_views *out,
                                        fv_ksdf_counts *counts, double *kernel_ms, fv_error *err)
{
    /* the world with device pointers */
    fv_ksdf_world dw = *w;
    fv_status s;
    if ((s = fill(&c->ops, w->ops, (size_t)w->nops * sizeof(fv_sdf_op), err)) != FV_OK ||
        (s = fill(&c->objs, w->objs, (size_t)w->count * sizeof(fv_ksdf_object), err)) != FV_OK ||
        (s = fill(&c->lights, w->lights, (size_t)w->nlights * sizeof(fv_ksdf_light), err)) != FV_OK ||
        (s = fill(&c->mats, w->mats, (size_t)w->nmat * sizeof(fv_material), err)) != FV_OK)
        return s;
    dw.ops = (const fv_sdf_op *)c->ops.p;
    dw.objs = (const fv_ksdf_object *)c->objs.p;
    dw.lights = (const fv_ksdf_light *)c->lights.p;
    dw.mats = (const fv_material *)c->mats.p;
    const size_t n = (size_t)f->cam.width * (size_t)f->cam.height;
    fv_film_views dv;
    if ((s = fv_cuda_film_prepare(&c->film, out, n, &dv, err)) != FV_OK) return s;
    cudaError_t e;
    if ((e = cudaMemset(c->counts, 0, FV_CUDA_SDF_COUNTS * sizeof(unsigned long long))) != cudaSuccess)
        return fv_cuda_fail(e, "clearing counters", err);
    dim3 block(FV_CUDA_SDF_BLOCK, FV_CUDA_SDF_BLOCK);
    dim3 grid((unsigned)((f->cam.width + FV_CUDA_SDF_BLOCK - 1) / FV_CUDA_SDF_BLOCK),
              (unsigned)((f->cam.height + FV_CUDA_SDF_BLOCK - 1) / FV_CUDA_SDF_BLOCK));
    cudaEventRecord(c->start);
    fv_cuda_sdf_kernel<<<grid, block>>>(dw, *f, dv, c->counts);
    cudaEventRecord(c->stop);
    if ((e = cudaGetLastError()) != cudaSuccess) return fv_cuda_fail(e, "launching the sphere-tracing kernel", err);
    if ((e = cudaEventSynchronize(c->stop)) != cudaSuccess) return fv_cuda_fail(e, "running the sphere-tracing kernel", err);
    float ms = 0.0f;
    cudaEventElapsedTime(&ms, c->start, c->stop);
    *kernel_ms = ms;
    unsigned long long k[FV_CUDA_SDF_COUNTS];
    if ((e = cudaMemcpy(k, c->counts, sizeof k, cudaMemcpyDeviceToHost)) != cudaSuccess) return fv_cuda_fail(e, "reading counters", err);
    counts->rays += k[0];
    counts->steps += k[1];
    counts->exhausted += k[2];
    counts->nan += k[3];
    counts->shade.shadow_rays += k[4];
    counts->shade.shadow_steps += k[5];
    counts->shade.normal_evals += k[6];
    return fv_cuda_film_read(&c->film, out, n, err);
}
