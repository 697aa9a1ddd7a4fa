/* fovea — the CUDA backend of the sphere-tracing family (see device/cuda_backend.h): the world's
 * flat form on the GPU, `sdf-gt` and `sdf-relaxed` as the pixel kernel of kernel/sdf_pixel.h (one
 * thread a pixel), and `ipr` and `fipr` as one kernel per pass of the pyramid (a thread a cell):
 * the levels (fv_ksdf_level_cell), fipr's sky reduction, Sobel edges, mask and refresh
 * (kernel/sdf_pyramid.h), its middle level, then the target (fv_ksdf_target_pixel): the very
 * functions the portable backend runs on the CPU (docs/gpu.md).
 *
 * Memory: the world's arrays (programs, moving objects, lights, materials), a film per eye, the
 * pyramid's levels, edges, mask and visibility, pass 5's sigma, scratch image and kernels, and
 * fipr's history per eye keep their GPU buffers between frames, reallocated only when a frame needs
 * another size. The world and the blur's kernels are copied in only when their bytes changed since
 * the last copy (a host mirror is compared: a moving object or light changes the world, a still
 * scene is copied once). A frame's passes, for one eye or both eyes of a stereo pair, are launched
 * on one stream with no host wait between them; the host waits once, for the displayed buffers of
 * every eye and the counters (pass 5 blurs on the GPU, so the mask never comes back). The costs
 * are summed per block in shared memory, then once per block into the global counters.
 */
#include <cuda_runtime.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "device/cuda/common.h"
#include "device/cuda_backend.h"
#include "filter/blur.h"
#include "kernel/sdf_pixel.h"
#include "kernel/vp_blur.h"

/* Threads of a block: 8 x 8 pixels, whose rays start coherent. */
#define FV_CUDA_SDF_BLOCK 8
/* The counters, in this order: rays, steps, exhausted, nan, shadow rays, shadow steps, normal evaluations. */
#define FV_CUDA_SDF_COUNTS 7

/* A pyramid frame's counters: the first FV_CUDA_SDF_COUNTS as above, then fipr's mask pixels, edge
 * pixels and refreshed rays, then each level's rays and each level's steps. */
#define FV_CUDA_PYR_MASKED 7
#define FV_CUDA_PYR_EDGES 8
#define FV_CUDA_PYR_REFRESHED 9
#define FV_CUDA_PYR_LEVEL_RAYS 10
#define FV_CUDA_PYR_LEVEL_STEPS (FV_CUDA_PYR_LEVEL_RAYS + FV_PYRAMID_MAX_LEVELS)
#define FV_CUDA_PYR_COUNTS (FV_CUDA_PYR_LEVEL_STEPS + FV_PYRAMID_MAX_LEVELS)

/* fipr's middle level of one eye on the GPU (pyramid.h's fv_pyramid_history). */
typedef struct dev_history {
    int sw, sh;
    float *color;
    int *stamp;
} dev_history;

/* fipr's pass 5 on the GPU: the sigma image, the horizontal pass's image, and the kernels
 * (filter/blur.h's table, built on the host for the image's size and sigma, copied when changed). */
typedef struct dev_blur {
    float *sigma, *tmp;
    size_t pixels;
    fv_cuda_mirror off, k;
    int *host_off;          /* the table on the host, for (w, h, smax) */
    float *host_k;
    int w, h, nq;
    size_t nk;
    float smax;
} dev_blur;

struct fv_cuda_sdf {
    fv_cuda_tally calls;        /* what it asked of the runtime (device/cuda/common.h) */
    fv_cuda_mirror ops, objs, lights, mats;
    fv_cuda_film film[2];       /* per eye: a stereo pair is read back after both eyes ran */
    unsigned long long *counts; /* FV_CUDA_PYR_COUNTS */
    cudaEvent_t start, stop;
    cudaStream_t stream;        /* the pyramid's passes */
    /* ipr and fipr: the buffers' shape and the buffers */
    fv_kpyr k;                  /* device pointers; hist_* point at the frame's eye */
    bool k_fipr, k_vis;
    unsigned *far;              /* pass 2's farthest tip depth, as float bits */
    dev_history hist[2];
    dev_blur blur;
};

static void pyramid_free(fv_cuda_sdf *c)
{
    for (int i = 0; i < FV_PYRAMID_MAX_LEVELS; i++) {
        fv_cuda_release(&c->calls, c->k.depth[i]);
        fv_cuda_release(&c->calls, c->k.steps[i]);
    }
    fv_cuda_release(&c->calls, c->k.need);
    fv_cuda_release(&c->calls, c->k.edge);
    fv_cuda_release(&c->calls, c->k.mask);
    fv_cuda_release(&c->calls, c->k.vis);
    memset(&c->k, 0, sizeof c->k);
}

static void history_free(fv_cuda_tally *k, dev_history *h)
{
    fv_cuda_release(k, h->color);
    fv_cuda_release(k, h->stamp);
    memset(h, 0, sizeof *h);
}

static void blur_free(fv_cuda_tally *k, dev_blur *b)
{
    fv_cuda_release(k, b->sigma);
    fv_cuda_release(k, b->tmp);
    fv_cuda_mirror_free(k, &b->off);
    fv_cuda_mirror_free(k, &b->k);
    free(b->host_off);
    free(b->host_k);
    memset(b, 0, sizeof *b);
}

extern "C" void fv_cuda_sdf_destroy(fv_cuda_sdf *c)
{
    if (!c) return;
    fv_cuda_mirror_free(&c->calls, &c->ops);
    fv_cuda_mirror_free(&c->calls, &c->objs);
    fv_cuda_mirror_free(&c->calls, &c->lights);
    fv_cuda_mirror_free(&c->calls, &c->mats);
    fv_cuda_film_free(&c->calls, &c->film[0]);
    fv_cuda_film_free(&c->calls, &c->film[1]);
    blur_free(&c->calls, &c->blur);
    pyramid_free(c);
    history_free(&c->calls, &c->hist[0]);
    history_free(&c->calls, &c->hist[1]);
    fv_cuda_release(&c->calls, c->far);
    if (c->stream) cudaStreamDestroy(c->stream);
    fv_cuda_release(&c->calls, c->counts);
    if (c->start) cudaEventDestroy(c->start);
    if (c->stop) cudaEventDestroy(c->stop);
    free(c);
}

extern "C" void fv_cuda_sdf_calls(const fv_cuda_sdf *c, fv_cuda_calls *out) { *out = c->calls.n; }

extern "C" fv_status fv_cuda_sdf_create(fv_cuda_sdf **out, fv_error *err)
{
    *out = NULL;
    fv_cuda_sdf *c = (fv_cuda_sdf *)calloc(1, sizeof *c);
    if (!c) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    cudaError_t e;
    fv_status s = FV_OK;
    if ((e = fv_cuda_alloc(&c->calls, (void **)&c->counts, FV_CUDA_PYR_COUNTS * sizeof(unsigned long long))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&c->far, sizeof(unsigned))) != cudaSuccess)
        s = fv_cuda_fail(e, "allocating counters", err);
    if (s == FV_OK && (e = cudaStreamCreate(&c->stream)) != cudaSuccess) s = fv_cuda_fail(e, "creating a stream", err);
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

/* The world on the GPU (copied only where it changed) as *dw, with device pointers. */
static fv_status upload_world(fv_cuda_sdf *c, const fv_ksdf_world *w, fv_ksdf_world *dw, fv_error *err)
{
    *dw = *w;
    fv_status s;
    if ((s = fv_cuda_mirror_fill(&c->calls, &c->ops, w->ops, (size_t)w->nops * sizeof(fv_sdf_op), c->stream, "the world", err)) != FV_OK ||
        (s = fv_cuda_mirror_fill(&c->calls, &c->objs, w->objs, (size_t)w->count * sizeof(fv_ksdf_object), c->stream, "the world", err)) != FV_OK ||
        (s = fv_cuda_mirror_fill(&c->calls, &c->lights, w->lights, (size_t)w->nlights * sizeof(fv_ksdf_light), c->stream, "the world", err)) != FV_OK ||
        (s = fv_cuda_mirror_fill(&c->calls, &c->mats, w->mats, (size_t)w->nmat * sizeof(fv_material), c->stream, "the world", err)) != FV_OK)
        return s;
    dw->ops = (const fv_sdf_op *)c->ops.p;
    dw->objs = (const fv_ksdf_object *)c->objs.p;
    dw->lights = (const fv_ksdf_light *)c->lights.p;
    dw->mats = (const fv_material *)c->mats.p;
    return FV_OK;
}

/* The end of a frame: every eye's film and the first `ncounts` counters into kc, enqueued after
 * the kernels, then the frame's one host wait (*syncs = 1); *kernel_ms from the events. */
static fv_status finish(fv_cuda_sdf *c, int eyes, const fv_film_views *out, const size_t *n, unsigned long long *kc, int ncounts,
                        double *kernel_ms, int *syncs, const char *what, fv_error *err)
{
    cudaStream_t st = c->stream;
    cudaError_t e = cudaSuccess;
    for (int i = 0; i < eyes && e == cudaSuccess; i++) e = fv_cuda_film_read_async(&c->calls, &c->film[i], &out[i], n[i], st);
    if (e == cudaSuccess) e = fv_cuda_copy(&c->calls, kc, c->counts, (size_t)ncounts * sizeof *kc, cudaMemcpyDeviceToHost, st);
    if (e == cudaSuccess) e = fv_cuda_wait(&c->calls, st);
    *syncs = 1;
    if (e != cudaSuccess) return fv_cuda_fail(e, what, err);
    float ms = 0.0f;
    cudaEventElapsedTime(&ms, c->start, c->stop);
    *kernel_ms = ms;
    return FV_OK;
}

extern "C" fv_status fv_cuda_sdf_render(fv_cuda_sdf *c, const fv_ksdf_world *w, int eyes, const fv_ksdf_frame *f, const fv_film_views *out,
                                        fv_ksdf_counts *counts, double *kernel_ms, int *syncs, fv_error *err)
{
    *syncs = 0;
    if (eyes < 1 || eyes > 2) return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %d eyes", eyes);
    fv_cuda_forget_error();
    fv_ksdf_world dw;
    fv_status s = upload_world(c, w, &dw, err);
    if (s != FV_OK) return s;
    /* every eye's film first: nothing between the launches but launches */
    size_t n[2];
    fv_film_views dv[2];
    for (int i = 0; i < eyes; i++) {
        n[i] = (size_t)f[i].cam.width * (size_t)f[i].cam.height;
        if ((s = fv_cuda_film_prepare(&c->calls, &c->film[i], &out[i], n[i], &dv[i], err)) != FV_OK) return s;
    }
    cudaStream_t st = c->stream;
    cudaError_t e;
    if ((e = fv_cuda_clear(&c->calls, c->counts, 0, FV_CUDA_SDF_COUNTS * sizeof(unsigned long long), st)) != cudaSuccess)
        return fv_cuda_fail(e, "clearing counters", err);
    dim3 block(FV_CUDA_SDF_BLOCK, FV_CUDA_SDF_BLOCK);
    cudaEventRecord(c->start, st);
    for (int i = 0; i < eyes; i++) {
        dim3 grid((unsigned)((f[i].cam.width + FV_CUDA_SDF_BLOCK - 1) / FV_CUDA_SDF_BLOCK),
                  (unsigned)((f[i].cam.height + FV_CUDA_SDF_BLOCK - 1) / FV_CUDA_SDF_BLOCK));
        FV_CUDA_LAUNCH(&c->calls, fv_cuda_sdf_kernel, grid, block, st)(dw, f[i], dv[i], c->counts);
    }
    cudaEventRecord(c->stop, st);
    if ((e = cudaGetLastError()) != cudaSuccess) return fv_cuda_fail(e, "launching the sphere-tracing kernel", err);
    unsigned long long k[FV_CUDA_SDF_COUNTS];
    if ((s = finish(c, eyes, out, n, k, FV_CUDA_SDF_COUNTS, kernel_ms, syncs, "running the sphere-tracing kernel", err)) != FV_OK) return s;
    counts->rays += k[0];
    counts->steps += k[1];
    counts->exhausted += k[2];
    counts->nan += k[3];
    counts->shade.shadow_rays += k[4];
    counts->shade.shadow_steps += k[5];
    counts->shade.normal_evals += k[6];
    return FV_OK;
}

/* ---- ipr and fipr: a kernel per pass ---- */

/* A block's sums of the pyramid counters: zeroed by sum_begin, added to by every thread, flushed
 * into the global counters by sum_end; every thread of the block calls begin and end. */
__device__ static inline void sum_begin(unsigned long long *sum)
{
    const int tid = (int)(threadIdx.y * blockDim.x + threadIdx.x);
    if (tid < FV_CUDA_PYR_COUNTS) sum[tid] = 0;
    __syncthreads();
}

__device__ static inline void sum_add(unsigned long long *sum, int i, unsigned long long v)
{
    if (v) atomicAdd(&sum[i], v);
}

/* A cell's marching and shading costs, its camera rays and steps also as level `level`'s. */
__device__ static inline void sum_counts(unsigned long long *sum, const fv_ksdf_counts *c, int level)
{
    sum_add(sum, 0, c->rays);
    sum_add(sum, 1, c->steps);
    sum_add(sum, 2, c->exhausted);
    sum_add(sum, 3, c->nan);
    sum_add(sum, 4, c->shade.shadow_rays);
    sum_add(sum, 5, c->shade.shadow_steps);
    sum_add(sum, 6, c->shade.normal_evals);
    sum_add(sum, FV_CUDA_PYR_LEVEL_RAYS + level, c->rays);
    sum_add(sum, FV_CUDA_PYR_LEVEL_STEPS + level, c->steps);
}

__device__ static inline void sum_end(unsigned long long *sum, unsigned long long *counts)
{
    __syncthreads();
    const int tid = (int)(threadIdx.y * blockDim.x + threadIdx.x);
    if (tid < FV_CUDA_PYR_COUNTS && sum[tid]) atomicAdd(&counts[tid], sum[tid]);
}

#define CELL_XY                                                      \
    const int x = (int)(blockIdx.x * blockDim.x + threadIdx.x);      \
    const int y = (int)(blockIdx.y * blockDim.y + threadIdx.y)

/* Pass 1 (and each level below the target): ray (x, y) of level k. */
__global__ void fv_cuda_pyr_level(fv_ksdf_world w, fv_ksdf_frame f, fv_kpyr k, int level, int index, unsigned long long *counts)
{
    __shared__ unsigned long long sum[FV_CUDA_PYR_COUNTS];
    sum_begin(sum);
    CELL_XY;
    if (x < k.lv[level].w && y < k.lv[level].h) {
        fv_ksdf_counts c;
        memset(&c, 0, sizeof c);
        fv_ksdf_level_cell(&w, &f, &k, level, x, y, index, &c);
        sum_counts(sum, &c, level);
    }
    sum_end(sum, counts);
}

/* Pass 2's sky: the farthest finite depth of the tip (depths are >= 0, so their bits order as
 * unsigned integers do). Each block takes its maximum in shared memory first, then one atomic per
 * block meets the others': millions of atomics on one global address would queue behind each
 * other. A maximum does not depend on the order, so the bits are the same. */
__global__ void fv_cuda_pyr_far(const float *depth, int n, unsigned *far)
{
    __shared__ unsigned block_far;
    if (threadIdx.x == 0) block_far = 0u;
    __syncthreads();
    const int i = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    if (i < n && isfinite(depth[i]) && depth[i] > 0.0f) atomicMax(&block_far, __float_as_uint(depth[i]));
    __syncthreads();
    if (threadIdx.x == 0 && block_far) atomicMax(far, block_far);
}

__global__ void fv_cuda_pyr_sobel(fv_kpyr k, const unsigned *far, float threshold)
{
    CELL_XY;
    const fv_pyramid_level *low = &k.lv[0];
    if (x >= low->w || y >= low->h) return;
    k.edge[(size_t)y * low->w + x] = fv_kpyr_sobel_cell(k.depth[0], low->w, low->h, fv_kpyr_sky(__uint_as_float(*far)), threshold, x, y);
}

__global__ void fv_cuda_pyr_mask(fv_kpyr k, fv_kpyr_fovea fov, unsigned long long *counts)
{
    __shared__ unsigned long long sum[FV_CUDA_PYR_COUNTS];
    sum_begin(sum);
    CELL_XY;
    if (x < k.w && y < k.h) {
        uint8_t m = fv_kpyr_mask_pixel(&k, &fov, x, y);
        k.mask[(size_t)y * k.w + x] = m;
        sum_add(sum, FV_CUDA_PYR_MASKED, m);
        sum_add(sum, FV_CUDA_PYR_EDGES, fv_kpyr_edge_of_pixel(&k, x, y) != 0);
    }
    sum_end(sum, counts);
}

__global__ void fv_cuda_pyr_need(fv_kpyr k, fv_kpyr_fovea fov, unsigned long long *counts)
{
    __shared__ unsigned long long sum[FV_CUDA_PYR_COUNTS];
    sum_begin(sum);
    CELL_XY;
    const fv_pyramid_level *mid = &k.lv[k.L - 2];
    if (x < mid->w && y < mid->h) {
        uint8_t need = fv_kpyr_need_cell(&k, &fov, x, y);
        k.need[(size_t)y * mid->w + x] = need;
        sum_add(sum, FV_CUDA_PYR_REFRESHED, need == 2);
    }
    sum_end(sum, counts);
}

__global__ void fv_cuda_pyr_target(fv_ksdf_world w, fv_ksdf_frame f, fv_kpyr k, fv_film_views out, unsigned long long *counts)
{
    __shared__ unsigned long long sum[FV_CUDA_PYR_COUNTS];
    sum_begin(sum);
    CELL_XY;
    if (x < k.w && y < k.h) {
        fv_ksdf_counts c;
        memset(&c, 0, sizeof c);
        fv_ksdf_target_pixel(&w, &f, &k, x, y, &out, &c);
        sum_counts(sum, &c, k.L - 1);
    }
    sum_end(sum, counts);
}

/* A sequence's first frame, or a new size: no middle-level ray has been shaded. */
__global__ void fv_cuda_pyr_forget(int *stamp, int n)
{
    const int i = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    if (i < n) stamp[i] = INT_MIN;
}

static dim3 grid_of(int w, int h)
{
    return dim3((unsigned)((w + FV_CUDA_SDF_BLOCK - 1) / FV_CUDA_SDF_BLOCK), (unsigned)((h + FV_CUDA_SDF_BLOCK - 1) / FV_CUDA_SDF_BLOCK));
}

static unsigned blocks_of(size_t n) { return (unsigned)((n + 255) / 256); }

/* The pyramid's buffers for shape (kept when they fit). */
static fv_status pyramid_ensure(fv_cuda_sdf *c, const fv_kpyr *shape, bool fipr, bool vis, fv_error *err)
{
    fv_kpyr *k = &c->k;
    if (k->w > 0 && k->w == shape->w && k->h == shape->h && k->S == shape->S && k->L == shape->L && c->k_fipr == fipr && c->k_vis == vis) {
        k->min_filter = shape->min_filter;
        return FV_OK;
    }
    pyramid_free(c);
    *k = *shape;
    for (int i = 0; i < FV_PYRAMID_MAX_LEVELS; i++) k->depth[i] = NULL, k->steps[i] = NULL;
    k->need = k->edge = k->mask = NULL;
    k->vis = NULL;
    k->hist_color = NULL;
    k->hist_stamp = NULL;
    const int L = k->L;
    cudaError_t e = cudaSuccess;
    for (int i = 0; i + 1 < L && e == cudaSuccess; i++) {
        size_t n = (size_t)k->lv[i].w * k->lv[i].h;
        if ((e = fv_cuda_alloc(&c->calls, (void **)&k->depth[i], n * sizeof(float))) == cudaSuccess)
            e = fv_cuda_alloc(&c->calls, (void **)&k->steps[i], n * sizeof(uint16_t));
    }
    const size_t nmid = L > 1 ? (size_t)k->lv[L - 2].w * k->lv[L - 2].h : 0;
    if (e == cudaSuccess && vis) e = fv_cuda_alloc(&c->calls, (void **)&k->vis, nmid * sizeof(uint32_t));
    if (e == cudaSuccess && fipr) e = fv_cuda_alloc(&c->calls, (void **)&k->need, nmid);
    if (e == cudaSuccess && fipr) e = fv_cuda_alloc(&c->calls, (void **)&k->edge, (size_t)k->lv[0].w * k->lv[0].h);
    if (e == cudaSuccess && fipr) e = fv_cuda_alloc(&c->calls, (void **)&k->mask, (size_t)k->w * k->h);
    if (e != cudaSuccess) {
        pyramid_free(c);
        return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for a %dx%d pyramid", shape->w, shape->h)
                                              : fv_cuda_fail(e, "allocating the pyramid", err);
    }
    c->k_fipr = fipr;
    c->k_vis = vis;
    return FV_OK;
}

/* fipr's history of eye `eye` sized for the pyramid (new: every stamp forgotten, as at index 0). */
static fv_status history_ensure(fv_cuda_sdf *c, int eye, int index, fv_error *err)
{
    dev_history *h = &c->hist[eye];
    fv_kpyr *k = &c->k;
    const size_t n = (size_t)k->lv[k->L - 2].w * k->lv[k->L - 2].h;
    if (h->sw != k->sw || h->sh != k->sh || !h->color) {
        history_free(&c->calls, h);
        cudaError_t e;
        if ((e = fv_cuda_alloc(&c->calls, (void **)&h->color, 3 * n * sizeof(float))) != cudaSuccess ||
            (e = fv_cuda_alloc(&c->calls, (void **)&h->stamp, n * sizeof(int))) != cudaSuccess ||
            (e = fv_cuda_clear(&c->calls, h->color, 0, 3 * n * sizeof(float), c->stream)) != cudaSuccess) {
            history_free(&c->calls, h);
            return fv_cuda_fail(e, "allocating fipr's history", err);
        }
        h->sw = k->sw;
        h->sh = k->sh;
        index = 0;
    }
    if (index == 0) FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_forget, blocks_of(n), 256, c->stream)(h->stamp, (int)n);
    k->hist_color = h->color;
    k->hist_stamp = h->stamp;
    return FV_OK;
}

/* ---- fipr's pass 5: the transitions' sigma, then the blur's two passes (kernel/vp_blur.h) ---- */

__global__ void fv_cuda_pyr_sigma(const uint8_t *mask, int w, int h, float blur_sigma, float *sigma)
{
    CELL_XY;
    if (x < w && y < h) sigma[(size_t)y * w + x] = fv_kpyr_blur_sigma(mask, w, h, x, y, blur_sigma);
}

__global__ void fv_cuda_blur_h(fv_kblur_table t, const float *sigma, const float *src, float *tmp)
{
    CELL_XY;
    if (x < t.w && y < t.h) fv_kblur_h_pixel(&t, sigma, src, tmp, x, y);
}

__global__ void fv_cuda_blur_v(fv_kblur_table t, const float *sigma, const float *tmp, float *out)
{
    CELL_XY;
    if (x < t.w && y < t.h) fv_kblur_v_pixel(&t, sigma, tmp, out, x, y);
}

/* Pass 5's buffers for a w x h image and its kernels up to smax (the table rebuilt on the host
 * only when the size or sigma changes, copied only when its bytes do); *t the table's views. */
static fv_status blur_ensure(fv_cuda_sdf *c, int w, int h, float smax, fv_kblur_table *t, fv_error *err)
{
    dev_blur *b = &c->blur;
    const size_t n = (size_t)w * h;
    cudaError_t e;
    if (b->pixels != n) {
        fv_cuda_release(&c->calls, b->sigma);
        fv_cuda_release(&c->calls, b->tmp);
        b->sigma = b->tmp = NULL;
        b->pixels = 0;
        if ((e = fv_cuda_alloc(&c->calls, (void **)&b->sigma, n * sizeof(float))) != cudaSuccess ||
            (e = fv_cuda_alloc(&c->calls, (void **)&b->tmp, 3 * n * sizeof(float))) != cudaSuccess)
            return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for fipr's blur")
                                                  : fv_cuda_fail(e, "allocating fipr's blur", err);
        b->pixels = n;
    }
    if (!b->host_off || b->w != w || b->h != h || b->smax != smax) {
        free(b->host_off);
        free(b->host_k);
        b->host_k = NULL;
        fv_blur_table_size(smax, w, h, &b->nq, &b->nk);
        b->host_off = (int *)malloc((size_t)b->nq * sizeof(int));
        b->host_k = (float *)malloc(b->nk * sizeof(float));
        if (!b->host_off || !b->host_k) {
            free(b->host_off), free(b->host_k);
            b->host_off = NULL, b->host_k = NULL;
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the blur's kernels");
        }
        fv_blur_table_fill(w, h, b->nq, b->host_off, b->host_k);
        b->w = w, b->h = h, b->smax = smax;
    }
    fv_status s;
    if ((s = fv_cuda_mirror_fill(&c->calls, &b->off, b->host_off, (size_t)b->nq * sizeof(int), c->stream, "fipr's blur kernels", err)) != FV_OK ||
        (s = fv_cuda_mirror_fill(&c->calls, &b->k, b->host_k, b->nk * sizeof(float), c->stream, "fipr's blur kernels", err)) != FV_OK)
        return s;
    t->w = w;
    t->h = h;
    t->rcap = (w > h ? w : h) - 1;
    t->nq = b->nq;
    t->off = (const int *)b->off.p;
    t->k = (const float *)b->k.p;
    return FV_OK;
}

extern "C" fv_status fv_cuda_sdf_pyramid_render(fv_cuda_sdf *c, const fv_ksdf_world *w, int eyes, const fv_ksdf_frame *f, const fv_kpyr *shape,
                                                const fv_kpyr_fovea *fov, const fv_cuda_pyr_opts *po, const fv_film_views *out,
                                                fv_ksdf_pyr_counts *counts, double *kernel_ms, int *syncs, fv_error *err)
{
    *syncs = 0;
    if (eyes < 1 || eyes > 2) return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: %d eyes", eyes);
    fv_cuda_forget_error();
    fv_ksdf_world dw;
    fv_status s = upload_world(c, w, &dw, err);
    if (s != FV_OK) return s;
    const bool fipr = fov != NULL, blurred = fipr && po->blur;
    const int L = shape->L;
    if ((s = pyramid_ensure(c, shape, fipr, po->shadow_reuse && L > 1, err)) != FV_OK) return s;
    const size_t n = (size_t)shape->w * (size_t)shape->h;
    const size_t ns[2] = {n, n};
    fv_film_views dv[2];
    for (int i = 0; i < eyes; i++)
        if ((s = fv_cuda_film_prepare(&c->calls, &c->film[i], &out[i], n, &dv[i], err)) != FV_OK) return s;
    fv_kblur_table bt;
    if (blurred && (s = blur_ensure(c, shape->w, shape->h, po->blur_sigma, &bt, err)) != FV_OK) return s;
    cudaStream_t st = c->stream;
    cudaError_t e;
    if ((e = fv_cuda_clear(&c->calls, c->counts, 0, FV_CUDA_PYR_COUNTS * sizeof(unsigned long long), st)) != cudaSuccess)
        return fv_cuda_fail(e, "clearing counters", err);
    fv_kpyr *k = &c->k;
    const dim3 block(FV_CUDA_SDF_BLOCK, FV_CUDA_SDF_BLOCK);
    cudaEventRecord(c->start, st);
    /* eye after eye on the stream: the pyramid's buffers are the eyes' in turn (the stream orders
     * eye 1's passes after eye 0's), the films and histories are each eye's own */
    for (int i = 0; i < eyes; i++) {
        if (fipr && (s = history_ensure(c, fov[i].eye_index, fov[i].index, err)) != FV_OK) return s;
        const int index = fipr ? fov[i].index : 0;
        /* the levels traced whole (fipr: all but the middle, which the mask decides) */
        const int full_below = fipr ? L - 2 : L - 1;
        for (int l = 0; l < full_below; l++)
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_level, grid_of(k->lv[l].w, k->lv[l].h), block, st)(dw, f[i], *k, l, index, c->counts);
        if (fipr) {
            const size_t ntip = (size_t)k->lv[0].w * k->lv[0].h;
            fv_cuda_clear(&c->calls, c->far, 0, sizeof(unsigned), st);
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_far, blocks_of(ntip), 256, st)(k->depth[0], (int)ntip, c->far);
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_sobel, grid_of(k->lv[0].w, k->lv[0].h), block, st)(*k, c->far, po->edge);
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_mask, grid_of(k->w, k->h), block, st)(*k, fov[i], c->counts);
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_need, grid_of(k->lv[L - 2].w, k->lv[L - 2].h), block, st)(*k, fov[i], c->counts);
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_level, grid_of(k->lv[L - 2].w, k->lv[L - 2].h), block, st)(dw, f[i], *k, L - 2, index, c->counts);
        }
        FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_target, grid_of(k->w, k->h), block, st)(dw, f[i], *k, dv[i], c->counts);
        if (blurred) {
            /* pass 5 on this eye's colour, in place through the scratch image */
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_pyr_sigma, grid_of(k->w, k->h), block, st)(k->mask, k->w, k->h, po->blur_sigma, c->blur.sigma);
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_blur_h, grid_of(k->w, k->h), block, st)(bt, c->blur.sigma, dv[i].color, c->blur.tmp);
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_blur_v, grid_of(k->w, k->h), block, st)(bt, c->blur.sigma, c->blur.tmp, dv[i].color);
        }
    }
    cudaEventRecord(c->stop, st);
    if ((e = cudaGetLastError()) != cudaSuccess) return fv_cuda_fail(e, "launching the pyramid's kernels", err);
    /* what the host receives, then its one wait */
    unsigned long long kc[FV_CUDA_PYR_COUNTS];
    if ((s = finish(c, eyes, out, ns, kc, FV_CUDA_PYR_COUNTS, kernel_ms, syncs, "running the pyramid's kernels", err)) != FV_OK) return s;
    counts->all.rays += kc[0];
    counts->all.steps += kc[1];
    counts->all.exhausted += kc[2];
    counts->all.nan += kc[3];
    counts->all.shade.shadow_rays += kc[4];
    counts->all.shade.shadow_steps += kc[5];
    counts->all.shade.normal_evals += kc[6];
    counts->masked += kc[FV_CUDA_PYR_MASKED];
    counts->edges += kc[FV_CUDA_PYR_EDGES];
    counts->refreshed += kc[FV_CUDA_PYR_REFRESHED];
    for (int i = 0; i < L; i++) {
        counts->level_rays[i] += kc[FV_CUDA_PYR_LEVEL_RAYS + i];
        counts->level_steps[i] += kc[FV_CUDA_PYR_LEVEL_STEPS + i];
    }
    return FV_OK;
}
