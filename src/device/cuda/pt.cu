/* fovea — the CUDA backend of `pt` (see device/cuda_backend.h): the flat scene copied to the GPU
 * field by field, and the pixel kernel of kernel/pt.h launched one thread a pixel.
 *
 * Design (docs/gpu.md): a megakernel. Each thread runs its pixel's whole paths, the same function
 * the portable backend runs on the CPU, so the GPU's image equals the portable one up to float
 * rounding. A wavefront design (a queue of rays per bounce) would trade this sameness for
 * coherence; it is measured against this one before it replaces it.
 *
 * Memory: the scene's arrays are copied once at create; update re-copies only what time changes
 * (objects' transforms, instances, the top-level BVH, the light table). The films' buffers (one per
 * eye) stay allocated between frames of one size; a stereo pair's two kernels are launched before
 * the one host wait that reads both films back.
 */
#include <cuda_runtime.h>
#include <stdio.h>
#include <string.h>
#include "device/cuda/common.h"
#include "device/cuda_backend.h"
#include "kernel/pt.h"

/* Threads of a block: 8 x 8 pixels, a tile whose paths start coherent. */
#define FV_CUDA_BLOCK 8

struct fv_cuda_pt {
    fv_kscene dev;           /* the scene with device pointers */
    void *owned[32];         /* every device allocation of the scene, freed at destroy */
    int nowned;
    fv_ktexture *tex_host;   /* the texture records with device texel pointers, as uploaded */
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

/* A copy of n elements of `bytes` each to the GPU, remembered for destroy; NULL stays NULL. */
static fv_status upload(fv_cuda_pt *c, const void *src, size_t n, size_t bytes, void **dst, fv_error *err)
{
    *dst = NULL;
    if (!src || n == 0) return FV_OK;
    if (c->nowned == (int)(sizeof c->owned / sizeof c->owned[0]))
        return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: too many scene arrays");
    cudaError_t e = cudaMalloc(dst, n * bytes);
    if (e != cudaSuccess) return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for the scene")
                                                                : fv_cuda_fail(e, "allocating the scene", err);
    c->owned[c->nowned++] = *dst;
    if ((e = cudaMemcpy(*dst, src, n * bytes, cudaMemcpyHostToDevice)) != cudaSuccess) return fv_cuda_fail(e, "copying the scene", err);
    return FV_OK;
}

#define UPLOAD(field, count, type)                                                                      \
    do {                                                                                                \
        void *p_;                                                                                       \
        if ((s = upload(c, h->field, (size_t)(count), sizeof(type), &p_, err)) != FV_OK) return s;      \
        c->dev.field = (const type *)p_;                                                                \
    } while (0)

static fv_status upload_scene(fv_cuda_pt *c, const fv_kscene *h, fv_error *err)
{
    fv_status s;
    c->dev = *h;
    UPLOAD(vtx, h->nvtx, fv_vec3);
    UPLOAD(nrm, h->nnrm, fv_vec3);
    UPLOAD(uv, h->nuv, fv_vec2);
    UPLOAD(tri_vtx, h->ntri_vtx, uint32_t);
    UPLOAD(tri_mat, h->ntri, int32_t);
    UPLOAD(tri_light, h->ntri, int32_t);
    UPLOAD(objs, h->nobj, fv_kobject);
    UPLOAD(sdf_ops, h->nsdf_ops, fv_sdf_op);
    UPLOAD(nodes, h->nnodes, fv_knode);
    UPLOAD(ktris, h->nktris, fv_ktri);
    UPLOAD(inst, h->ninst, fv_kinst);
    UPLOAD(tnodes, h->ntnodes, fv_knode);
    UPLOAD(mats, h->nmat, fv_material);
    void *p;
    if ((s = upload(c, h->lights.light, (size_t)h->lights.n, sizeof(fv_light), &p, err)) != FV_OK) return s;
    c->dev.lights.light = (const fv_light *)p;
    if ((s = upload(c, h->lights.cdf, (size_t)h->lights.n + 1, sizeof(float), &p, err)) != FV_OK) return s;
    c->dev.lights.cdf = (const float *)p;
    if (h->ntex > 0) {
        c->tex_host = (fv_ktexture *)calloc((size_t)h->ntex, sizeof *c->tex_host);
        if (!c->tex_host) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        for (int i = 0; i < h->ntex; i++) {
            c->tex_host[i] = h->tex[i];
            if ((s = upload(c, h->tex[i].rgb, (size_t)h->tex[i].w * (size_t)h->tex[i].h * 3, sizeof(float), &p, err)) != FV_OK) return s;
            c->tex_host[i].rgb = (const float *)p;
        }
        if ((s = upload(c, c->tex_host, (size_t)h->ntex, sizeof(fv_ktexture), &p, err)) != FV_OK) return s;
        c->dev.tex = (const fv_ktexture *)p;
        c->dev.lights.tex = c->dev.tex; /* emission textures, read by light samples */
    }
    return FV_OK;
}

/* Re-copies an array whose contents time changes, in place (its size does not change). */
static fv_status refresh(const void *dst, const void *src, size_t bytes, fv_error *err)
{
    if (!dst || !src || !bytes) return FV_OK;
    cudaError_t e = cudaMemcpy((void *)dst, src, bytes, cudaMemcpyHostToDevice);
    return e == cudaSuccess ? FV_OK : fv_cuda_fail(e, "updating the scene", err);
}

extern "C" fv_status fv_cuda_pt_update(fv_cuda_pt *c, const fv_kscene *h, fv_error *err)
{
    if (h->nobj != c->dev.nobj || h->ninst != c->dev.ninst || h->ntnodes != c->dev.ntnodes || h->lights.n != c->dev.lights.n)
        return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: the scene's shape changed between frames");
    fv_status s;
    if ((s = refresh(c->dev.objs, h->objs, (size_t)h->nobj * sizeof(fv_kobject), err)) != FV_OK) return s;
    if ((s = refresh(c->dev.inst, h->inst, (size_t)h->ninst * sizeof(fv_kinst), err)) != FV_OK) return s;
    if ((s = refresh(c->dev.tnodes, h->tnodes, (size_t)h->ntnodes * sizeof(fv_knode), err)) != FV_OK) return s;
    if ((s = refresh(c->dev.lights.light, h->lights.light, (size_t)h->lights.n * sizeof(fv_light), err)) != FV_OK) return s;
    c->dev.time = h->time;
    return FV_OK;
}

extern "C" void fv_cuda_pt_destroy(fv_cuda_pt *c)
{
    if (!c) return;
    for (int i = 0; i < c->nowned; i++) cudaFree(c->owned[i]);
    fv_cuda_film_free(&c->film[0]);
    fv_cuda_film_free(&c->film[1]);
    cudaFree(c->counts);
    if (c->start) cudaEventDestroy(c->start);
    if (c->stop) cudaEventDestroy(c->stop);
    free(c->tex_host);
    free(c);
}

extern "C" fv_status fv_cuda_pt_create(const fv_kscene *host, fv_cuda_pt **out, fv_error *err)
{
    *out = NULL;
    fv_cuda_pt *c = (fv_cuda_pt *)calloc(1, sizeof *c);
    if (!c) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_status s = upload_scene(c, host, err);
    cudaError_t e;
    if (s == FV_OK && (e = cudaMalloc((void **)&c->counts, 2 * sizeof(unsigned long long))) != cudaSuccess) s = fv_cuda_fail(e, "allocating counters", err);
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
    /* every eye's film first: nothing between the launches but launches */
    size_t n[2];
    fv_film_views dv[2];
    fv_status s;
    for (int i = 0; i < eyes; i++) {
        n[i] = (size_t)f[i].cam.width * (size_t)f[i].cam.height;
        if ((s = fv_cuda_film_prepare(&c->film[i], &out[i], n[i], &dv[i], err)) != FV_OK) return s;
    }
    cudaStream_t st = 0;
    cudaError_t e;
    if ((e = cudaMemsetAsync(c->counts, 0, 2 * sizeof(unsigned long long), st)) != cudaSuccess) return fv_cuda_fail(e, "clearing counters", err);
    dim3 block(FV_CUDA_BLOCK, FV_CUDA_BLOCK);
    cudaEventRecord(c->start, st);
    for (int i = 0; i < eyes; i++) {
        dim3 grid((unsigned)((f[i].cam.width + FV_CUDA_BLOCK - 1) / FV_CUDA_BLOCK), (unsigned)((f[i].cam.height + FV_CUDA_BLOCK - 1) / FV_CUDA_BLOCK));
        FV_CUDA_LAUNCH(fv_cuda_pt_kernel, grid, block, st)(c->dev, f[i], dv[i], c->counts);
    }
    cudaEventRecord(c->stop, st);
    if ((e = cudaGetLastError()) != cudaSuccess) return fv_cuda_fail(e, "launching the pt kernel", err);
    /* what the host receives, enqueued behind the kernels, then its one wait */
    unsigned long long counts[2];
    for (int i = 0; i < eyes && e == cudaSuccess; i++) e = fv_cuda_film_read_async(&c->film[i], &out[i], n[i], st);
    if (e == cudaSuccess) e = cudaMemcpyAsync(counts, c->counts, sizeof counts, cudaMemcpyDeviceToHost, st);
    if (e == cudaSuccess) e = cudaStreamSynchronize(st);
    *syncs = 1;
    if (e != cudaSuccess) return fv_cuda_fail(e, "running the pt kernel", err);
    float ms = 0.0f;
    cudaEventElapsedTime(&ms, c->start, c->stop);
    *kernel_ms = ms;
    *rays = counts[0];
    *nan_samples = counts[1];
    return FV_OK;
}
