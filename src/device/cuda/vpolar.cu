/* fovea — the CUDA backend of the Visual-Polar family (see device/cuda_backend.h): a frame of one
 * eye as a sequence of kernels on one stream, the functions the portable backend runs on the CPU
 * (technique/vpolar/device.c), a thread a cell or a pixel:
 *
 *   trace (fv_kvp_trace_sample, pt's path kernel on the flat scene of device/cuda/scene.h)
 *   -> the denoiser: the history's coordinates (fv_kvp_reproject_sample), then SVGF's steps
 *      (kernel/svgf.h: accumulate, the rows' counters, variance, a launch per pass with its
 *      prefilter fused in, the last also remodulating, holes) in the header's order
 *   -> φ-mipmaps (level 0 a copy, then fv_kphi_halve_cell a level per launch, each reading the one
 *      before) -> map (fv_kvp_map_pixel: colour, first-hit buffers, the blur's sigma)
 *   -> foveated blur (fv_kblur_h_pixel into a scratch image, fv_kblur_v_pixel back into the film).
 *
 * Memory: the grid's buffers, the history's coordinates, SVGF's buffers and history, the mipmap
 * levels, the blur's sigma and scratch image and the film keep their GPU buffers between frames, reallocated only when a size
 * changes. What the host builds per screen size or per gaze (column heights, the on-screen mask,
 * the mipmaps' shape, the radial table, the blur's kernels) goes through fv_cuda_mirror, copied only
 * when its bytes changed; the scene only when its time moved. The radial table has two buffers
 * used in turn: the reprojection reads the previous frame's (the previous view's), the map this
 * frame's. Every copy from the host is queued before the frame's first kernel, so none waits for a
 * kernel (a copy from pageable memory may make the host wait for its stream's queued work).
 *
 * The host waits once a frame, at the end, for the film's buffers that are set and the counters
 * (the trace's, and SVGF's per row: res->syncs = 1). A stereo pair (fv_cuda_vp_render with two
 * eyes, each its own fv_cuda_vp: buffers, history and stream) queues both eyes' frames and
 * read-backs, joins eye 1's stream to eye 0's with an event and waits once for eye 0's stream, so
 * the pair costs one wait, as one eye does. SVGF's step 6 (the holes) is launched every
 * frame rather than only when the rows count a hole, which would need a wait; on a frame without
 * holes it changes nothing (kernel/svgf.h). Stage times come from events between the stages.
 *
 * Indices: every kernel bounds its thread to its grid (x < w, y < h; a cell beyond its column's
 * height is not traced; a mip cell beyond its column's rows is left by fv_kphi_halve_cell), the
 * kernels clamp their lookups (kernel/vp_map.h, kernel/vp_space.h), and the blur refuses a sigma
 * beyond its table with a NaN pixel instead of reading past the table (the host sizes the table to a
 * bound of every sigma, so this does not happen).
 */
#include <cuda_runtime.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "device/cuda/common.h"
#include "device/cuda/scene.h"
#include "device/cuda_backend.h"
#include "kernel/svgf.h"
#include "kernel/vp_blur.h"
#include "kernel/vp_map.h"
#include "kernel/vp_reproject.h"
#include "kernel/vp_trace.h"

/* Threads of a block: 8 x 8 cells or pixels, whose camera rays start coherent. */
#define FV_CUDA_VP_BLOCK 8
#define FV_CUDA_VP_THREADS 256 /* one-dimensional launches */

enum { ST_TRACE = 0, ST_DENOISE, ST_MIP, ST_MAP, ST_BLUR, ST_COUNT };

/* SVGF on the GPU for one grid: kernel/svgf.h's state with device pointers (the frame's inputs are
 * set per frame), and the host's copies of the rows' counters. */
typedef struct dev_svgf {
    fv_ksvgf k;
    int w, h;                     /* the grid the buffers are for, 0: none */
    bool have_history;            /* a frame was filtered since the buffers were made */
    float *feat[2][7];            /* nx, ny, nz, z, m1, m2, len: current and previous (swapped) */
    long *row_surface, *row_hist, *row_holes; /* host, h each */
    double *row_len;
} dev_svgf;

struct fv_cuda_vp {
    fv_cuda_tally calls;          /* what it asked of the runtime (device/cuda/common.h) */
    fv_cuda_scene scene;
    cudaStream_t stream;
    cudaEvent_t ev[ST_COUNT + 1]; /* before each stage, and after the last */
    /* the sample grid, gw x gh cells (0: none yet) */
    int gw, gh;
    fv_kvp_gbuf g;                /* device buffers */
    float *prev_coord;            /* 2 per cell */
    /* the screen, sw x sh pixels */
    int sw, sh;
    float *sigma;                 /* the blur's, per pixel */
    float *blur_tmp;              /* the horizontal pass, 3 per pixel */
    fv_cuda_film film;
    /* the φ-mipmaps: level k has mip_h[k] rows of storage, mip_w columns */
    int mip_levels, mip_w, mip_h[FV_KPHI_MAX_LEVELS];
    float *mip_img[FV_KPHI_MAX_LEVELS];
    float *shape_host;            /* the shape packed for one copy: per level rows, rowsf, inv_src */
    size_t shape_cap;             /* floats */
    fv_cuda_mirror col_h, onscreen, shape, blur_off, blur_k;
    fv_cuda_mirror lut[2];        /* the radial tables: this frame's and the previous one's, in turn */
    int lut_prev;                 /* which of them the previous frame mapped with */
    unsigned long long *counts;   /* rays, paths, non-finite paths */
    unsigned long long counts_host[3]; /* their copy, read back with the film (a pair reads both eyes' before its one wait) */
    cudaEvent_t queued;           /* after the frame's read-back: a pair's eye 1 joins eye 0's stream here */
    dev_svgf svgf;
};

static unsigned blocks_of(size_t n)
{
    return (unsigned)((n + FV_CUDA_VP_THREADS - 1) / FV_CUDA_VP_THREADS);
}

static dim3 tiles_of(int w, int h)
{
    return dim3((unsigned)((w + FV_CUDA_VP_BLOCK - 1) / FV_CUDA_VP_BLOCK), (unsigned)((h + FV_CUDA_VP_BLOCK - 1) / FV_CUDA_VP_BLOCK));
}

/* ---- kernels ---- */

__global__ void fv_cuda_vp_fill(float *p, size_t n, float v)
{
    const size_t i = (size_t)blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) p[i] = v;
}

/* The trace stage: cell (x, y) when it is a valid cell of its column. The counts are summed per
 * block in shared memory, then once per block into the global ones. */
__global__ void fv_cuda_vp_trace(fv_kscene s, fv_kvp_trace_frame f, fv_kvp_gbuf g, unsigned long long *counts)
{
    __shared__ unsigned long long sum[3];
    const int tid = (int)(threadIdx.y * blockDim.x + threadIdx.x);
    if (tid < 3) sum[tid] = 0;
    __syncthreads();
    const int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x < f.space.gw && y < f.space.gh && y < (f.col_h ? f.col_h[x] : f.space.gh)) {
        fv_kvp_trace_counts c;
        c.rays = c.paths = c.nan_paths = 0;
        fv_kvp_trace_sample(&s, &f, &g, (long)y * f.space.gw + x, &c);
        if (c.rays) atomicAdd(&sum[0], (unsigned long long)c.rays);
        if (c.paths) atomicAdd(&sum[1], (unsigned long long)c.paths);
        if (c.nan_paths) atomicAdd(&sum[2], (unsigned long long)c.nan_paths);
    }
    __syncthreads();
    if (tid < 3 && sum[tid]) atomicAdd(&counts[tid], sum[tid]);
}

/* The history coordinates of every cell (NaN where there is none). */
__global__ void fv_cuda_vp_reproject(fv_kvp_reproject_frame f, float *prev_coord)
{
    const size_t i = (size_t)blockIdx.x * blockDim.x + threadIdx.x;
    if (i < (size_t)f.space.gw * (size_t)f.space.gh) fv_kvp_reproject_sample(&f, (long)i, &prev_coord[2 * i]);
}

/* Mip level k >= 1 from level k - 1: cell (x, j) of its h rows of storage. */
__global__ void fv_cuda_vp_halve(fv_kphi_mips m, int k, int h)
{
    const int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), j = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x < m.w && j < h) fv_kphi_halve_cell(&m, k, x, j);
}

/* The map stage at screen pixel (x, y). */
__global__ void fv_cuda_vp_map(fv_kvp_map_frame mf, fv_film_views out)
{
    const int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x < mf.space.sw && y < mf.space.sh) fv_kvp_map_pixel(&mf, x, y, &out);
}

/* A sigma whose kernel is not in the table: the pixel becomes NaN (visible to every check) rather
 * than a read past the table. The host's bound makes this unreachable. */
__device__ static bool fv_cuda_vp_blur_outside(const fv_kblur_table *t, const float *sigma, float *dst, int x, int y)
{
    const size_t pix = (size_t)y * (size_t)t->w + (size_t)x;
    const int q = fv_kblur_quantise(sigma[pix]);
    if (q >= 0 && q < t->nq) return false;
    for (int c = 0; c < 3; c++) dst[3 * pix + c] = NAN;
    return true;
}

__global__ void fv_cuda_vp_blur_h(fv_kblur_table t, const float *sigma, const float *src, float *tmp)
{
    const int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x < t.w && y < t.h && !fv_cuda_vp_blur_outside(&t, sigma, tmp, x, y)) fv_kblur_h_pixel(&t, sigma, src, tmp, x, y);
}

__global__ void fv_cuda_vp_blur_v(fv_kblur_table t, const float *sigma, const float *tmp, float *out)
{
    const int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x < t.w && y < t.h && !fv_cuda_vp_blur_outside(&t, sigma, out, x, y)) fv_kblur_v_pixel(&t, sigma, tmp, out, x, y);
}

/* ---- SVGF (kernel/svgf.h), a launch per step ---- */

enum { SV_ACCUMULATE, SV_VARIANCE, SV_PASS, SV_LAST_PASS, SV_FINISH, SV_HOLES };

__global__ void fv_cuda_vp_svgf_step(fv_ksvgf k, int step, int pass)
{
    const int x = (int)(blockIdx.x * blockDim.x + threadIdx.x), y = (int)(blockIdx.y * blockDim.y + threadIdx.y);
    if (x >= k.g.w || y >= k.g.h) return;
    switch (step) {
    case SV_ACCUMULATE: fv_ksvgf_accumulate_pixel(&k, x, y); break;
    case SV_VARIANCE: fv_ksvgf_variance_pixel(&k, x, y); break;
    /* a pass with its own prefilter (it reads its pixel's prefiltered variance only); the last
     * pass also remodulates its pixel (which reads that pixel only) */
    case SV_PASS: fv_ksvgf_prefilter_atrous_pixel(&k, pass, x, y); break;
    case SV_LAST_PASS:
        fv_ksvgf_prefilter_atrous_pixel(&k, pass, x, y);
        fv_ksvgf_finish_pixel(&k, x, y);
        break;
    case SV_FINISH: fv_ksvgf_finish_pixel(&k, x, y); break;
    default: fv_ksvgf_hole_pixel(&k, x, y); break;
    }
}

__global__ void fv_cuda_vp_svgf_rows(fv_ksvgf k)
{
    const int y = (int)(blockIdx.x * blockDim.x + threadIdx.x);
    if (y < k.g.h) fv_ksvgf_count_row(&k, y);
}

/* ---- buffers ---- */

static void grid_free(fv_cuda_vp *c)
{
    fv_kvp_gbuf *g = &c->g;
    void *const bufs[] = {g->color, g->albedo, g->normal, g->depth, g->position, g->reflectance, g->id, g->sampled, c->prev_coord};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++) fv_cuda_release(&c->calls, bufs[i]);
    memset(g, 0, sizeof *g);
    c->prev_coord = NULL;
    c->gw = c->gh = 0;
}

/* The grid's buffers for gw x gh cells, "no surface, not sampled" everywhere when new: the rows
 * beyond a column's height keep that for good (the trace writes only valid cells), as on the host. */
static fv_status grid_ensure(fv_cuda_vp *c, int gw, int gh, fv_error *err)
{
    if (c->gw == gw && c->gh == gh && c->g.color) return FV_OK;
    grid_free(c);
    const size_t n = (size_t)gw * (size_t)gh;
    fv_kvp_gbuf *g = &c->g;
    cudaStream_t st = c->stream;
    cudaError_t e;
    if ((e = fv_cuda_alloc(&c->calls, (void **)&g->color, 3 * n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&g->albedo, 3 * n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&g->reflectance, 3 * n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&g->normal, 3 * n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&g->position, 3 * n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&g->depth, n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&g->id, n * sizeof(uint32_t))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&g->sampled, n)) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&c->prev_coord, 2 * n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_clear(&c->calls, g->color, 0, 3 * n * sizeof(float), st)) != cudaSuccess ||
        (e = fv_cuda_clear(&c->calls, g->albedo, 0, 3 * n * sizeof(float), st)) != cudaSuccess ||
        (e = fv_cuda_clear(&c->calls, g->reflectance, 0, 3 * n * sizeof(float), st)) != cudaSuccess ||
        (e = fv_cuda_clear(&c->calls, g->normal, 0, 3 * n * sizeof(float), st)) != cudaSuccess ||
        (e = fv_cuda_clear(&c->calls, g->position, 0, 3 * n * sizeof(float), st)) != cudaSuccess ||
        (e = fv_cuda_clear(&c->calls, g->id, 0, n * sizeof(uint32_t), st)) != cudaSuccess ||
        (e = fv_cuda_clear(&c->calls, g->sampled, 0, n, st)) != cudaSuccess) {
        grid_free(c);
        return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for a %dx%d sample grid", gw, gh)
                                              : fv_cuda_fail(e, "allocating the sample grid", err);
    }
    FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_fill, blocks_of(n), FV_CUDA_VP_THREADS, st)(g->depth, n, INFINITY);
    c->gw = gw, c->gh = gh;
    return FV_OK;
}

/* Every device buffer of the SVGF state with its size for a w x h grid (n pixels), for allocation
 * and release in one place. */
#define SVGF_MAX_BUFFERS 48
static int svgf_buffers(dev_svgf *d, size_t n, size_t h, void ***ptr, size_t *bytes)
{
    int m = 0;
    fv_ksvgf *k = &d->k;
#define BUF(p, b) (ptr[m] = (void **)&(p), bytes[m] = (b), m++)
    BUF(k->surf, n * sizeof(float)); /* (gvar: none, the passes prefilter their own pixel) */
    BUF(k->grad, n * sizeof(float));
    BUF(k->hist_illum, 3 * n * sizeof(float));
    BUF(k->hist_pos, 3 * n * sizeof(float));
    for (int i = 0; i < 2; i++) {
        for (int c = 0; c < 7; c++) BUF(d->feat[i][c], n * sizeof(float));
        for (int c = 0; c < FV_KSVGF_NVAL; c++) BUF(k->val[i][c], n * sizeof(float));
    }
    BUF(k->kind, n);
    BUF(k->found, n);
    BUF(k->hist_id, n * sizeof(uint32_t));
    BUF(k->row_surface, h * sizeof(long));
    BUF(k->row_hist, h * sizeof(long));
    BUF(k->row_holes, h * sizeof(long));
    BUF(k->row_len, h * sizeof(double));
#undef BUF
    return m;
}

static void svgf_free(fv_cuda_tally *k, dev_svgf *d)
{
    void **ptr[SVGF_MAX_BUFFERS];
    size_t bytes[SVGF_MAX_BUFFERS];
    const int m = svgf_buffers(d, 0, 0, ptr, bytes);
    for (int i = 0; i < m; i++) fv_cuda_release(k, *ptr[i]);
    free(d->row_surface), free(d->row_hist), free(d->row_holes), free(d->row_len);
    memset(d, 0, sizeof *d);
}

/* SVGF's buffers for a gw x gh grid, all zeroed (kernel/svgf.h: pixels that are never surfaces keep
 * zero features and weigh 0 as taps) and without history when new. */
static fv_status svgf_ensure(fv_cuda_vp *c, int gw, int gh, fv_error *err)
{
    dev_svgf *d = &c->svgf;
    if (d->w == gw && d->h == gh && d->k.surf) return FV_OK;
    svgf_free(&c->calls, d);
    const size_t n = (size_t)gw * (size_t)gh, h = (size_t)gh;
    void **ptr[SVGF_MAX_BUFFERS];
    size_t bytes[SVGF_MAX_BUFFERS];
    const int m = svgf_buffers(d, n, h, ptr, bytes);
    cudaError_t e = cudaSuccess;
    for (int i = 0; i < m && e == cudaSuccess; i++)
        if ((e = fv_cuda_alloc(&c->calls, ptr[i], bytes[i])) == cudaSuccess) e = fv_cuda_clear(&c->calls, *ptr[i], 0, bytes[i], c->stream);
    if (e != cudaSuccess) {
        svgf_free(&c->calls, d);
        return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for SVGF on a %dx%d grid", gw, gh)
                                              : fv_cuda_fail(e, "allocating SVGF's buffers", err);
    }
    if (!(d->row_surface = (long *)calloc(h, sizeof(long))) || !(d->row_hist = (long *)calloc(h, sizeof(long))) ||
        !(d->row_holes = (long *)calloc(h, sizeof(long))) || !(d->row_len = (double *)calloc(h, sizeof(double)))) {
        svgf_free(&c->calls, d);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    fv_ksvgf *k = &d->k;
    float **cur[7] = {&k->nx, &k->ny, &k->nz, &k->z, &k->m1, &k->m2, &k->len};
    const float **prev[7] = {&k->pnx, &k->pny, &k->pnz, (const float **)&k->pz, &k->pm1, &k->pm2, &k->plen};
    for (int i = 0; i < 7; i++) *cur[i] = d->feat[0][i], *prev[i] = d->feat[1][i];
    d->w = gw, d->h = gh;
    d->have_history = false;
    return FV_OK;
}

/* The denoiser's launches for the frame (after the reprojection): kernel/svgf.h's sequence over the
 * grid in place. The rows' counters are read with the film at the end (a copy to the host's
 * pageable memory returns only when done: here it would be a wait between the stages). */
static void svgf_launch(fv_cuda_vp *c, const fv_cuda_vp_frame *f, const int *dcol_h, const uint8_t *dmask)
{
    dev_svgf *d = &c->svgf;
    fv_ksvgf *k = &d->k;
    cudaStream_t st = c->stream;
    k->g.w = c->gw, k->g.h = c->gh, k->g.col_h = dcol_h;
    k->g.wrap = f->trace.space.kind != FV_KVP_CARTESIAN; /* the polar spaces' grids wrap (space.c) */
    k->alpha_color = f->svgf.alpha_color, k->alpha_moments = f->svgf.alpha_moments;
    k->sigma_depth = f->svgf.sigma_depth, k->sigma_normal = f->svgf.sigma_normal, k->sigma_lum = f->svgf.sigma_lum;
    k->iterations = f->svgf.iterations;
    k->sq = fv_ksvgf_squarings(f->svgf.sigma_normal);
    /* as fv_svgf_kernels_set_periphery */
    k->periph_x = f->periph_x < 0 ? 0 : (f->periph_x > c->gw ? c->gw : f->periph_x);
    k->periph_passes = f->periph_passes < 0 ? 0 : f->periph_passes;
    /* the frame's inputs: the grid's buffers (SVGF demodulates by the reflectance) */
    k->color = c->g.color, k->albedo = c->g.reflectance, k->normal = c->g.normal, k->depth = c->g.depth;
    k->position = c->g.position, k->id = c->g.id;
    k->prev_coord = f->history ? c->prev_coord : NULL;
    k->sampled = f->trace.kill ? c->g.sampled : NULL;
    k->active = dmask;
    k->history = d->have_history && f->history;
    const dim3 tiles = tiles_of(c->gw, c->gh), block(FV_CUDA_VP_BLOCK, FV_CUDA_VP_BLOCK);
    FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_svgf_step, tiles, block, st)(*k, SV_ACCUMULATE, 0);
    FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_svgf_rows, blocks_of((size_t)c->gh), FV_CUDA_VP_THREADS, st)(*k);
    FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_svgf_step, tiles, block, st)(*k, SV_VARIANCE, 0);
    for (int pass = 0; pass < k->iterations; pass++)
        FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_svgf_step, tiles, block, st)(*k, pass == k->iterations - 1 ? SV_LAST_PASS : SV_PASS, pass);
    if (k->iterations == 0) FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_svgf_step, tiles, block, st)(*k, SV_FINISH, 0);
    FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_svgf_step, tiles, block, st)(*k, SV_HOLES, 0);
    /* this frame's features become the next frame's history (pointers only: the launches above
     * already hold their copies of the struct) */
    fv_ksvgf_swap(k);
    d->have_history = true;
}

/* Queues the copies of the rows' counters to the host (the frame's end). */
static cudaError_t svgf_read_rows(fv_cuda_tally *t, dev_svgf *d, cudaStream_t st)
{
    const size_t h = (size_t)d->h;
    const fv_ksvgf *k = &d->k;
    cudaError_t e;
    if ((e = fv_cuda_copy(t, d->row_surface, k->row_surface, h * sizeof(long), cudaMemcpyDeviceToHost, st)) != cudaSuccess ||
        (e = fv_cuda_copy(t, d->row_hist, k->row_hist, h * sizeof(long), cudaMemcpyDeviceToHost, st)) != cudaSuccess ||
        (e = fv_cuda_copy(t, d->row_holes, k->row_holes, h * sizeof(long), cudaMemcpyDeviceToHost, st)) != cudaSuccess)
        return e;
    return fv_cuda_copy(t, d->row_len, k->row_len, h * sizeof(double), cudaMemcpyDeviceToHost, st);
}

static void screen_free(fv_cuda_vp *c)
{
    fv_cuda_release(&c->calls, c->sigma), fv_cuda_release(&c->calls, c->blur_tmp);
    c->sigma = c->blur_tmp = NULL;
    c->sw = c->sh = 0;
}

static fv_status screen_ensure(fv_cuda_vp *c, int sw, int sh, fv_error *err)
{
    if (c->sw == sw && c->sh == sh && c->sigma) return FV_OK;
    screen_free(c);
    const size_t n = (size_t)sw * (size_t)sh;
    cudaError_t e;
    if ((e = fv_cuda_alloc(&c->calls, (void **)&c->sigma, n * sizeof(float))) != cudaSuccess ||
        (e = fv_cuda_alloc(&c->calls, (void **)&c->blur_tmp, 3 * n * sizeof(float))) != cudaSuccess) {
        screen_free(c);
        return fv_cuda_fail(e, "allocating the blur's buffers", err);
    }
    c->sw = sw, c->sh = sh;
    return FV_OK;
}

static void mips_free(fv_cuda_vp *c)
{
    for (int k = 0; k < FV_KPHI_MAX_LEVELS; k++) fv_cuda_release(&c->calls, c->mip_img[k]), c->mip_img[k] = NULL;
    c->mip_levels = c->mip_w = 0;
    memset(c->mip_h, 0, sizeof c->mip_h);
}

/* The mip levels' storage for the frame's shape, and the shape (rows, rowsf, inv_src of every level,
 * packed) on the GPU; *dm the chain with device pointers. */
static fv_status mips_ensure(fv_cuda_vp *c, const fv_cuda_vp_frame *f, fv_kphi_mips *dm, fv_error *err)
{
    const fv_kphi_mips *m = &f->mip_shape;
    const int L = m->levels, w = m->w;
    if (L < 1 || L > FV_KPHI_MAX_LEVELS || w != f->trace.space.gw || f->mip_h[0] != f->trace.space.gh)
        return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: the φ-mipmaps' shape does not match the grid");
    for (int k = 0; k < L; k++)
        if (f->mip_h[k] < 1 || !m->rows[k] || !m->rowsf[k] || (k > 0 && !m->inv_src[k]))
            return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: the φ-mipmaps' level %d has no shape", k);
    cudaError_t e;
    if (L != c->mip_levels || w != c->mip_w || memcmp(f->mip_h, c->mip_h, (size_t)L * sizeof(int)) != 0) {
        mips_free(c);
        for (int k = 0; k < L; k++) {
            /* 3 floats a pixel on w columns, one float of padding (filter/phi_mips.c's layout) */
            const size_t floats = 3 * (size_t)w * (size_t)f->mip_h[k] + 1;
            if ((e = fv_cuda_alloc(&c->calls, (void **)&c->mip_img[k], floats * sizeof(float))) != cudaSuccess ||
                (e = fv_cuda_clear(&c->calls, c->mip_img[k], 0, floats * sizeof(float), c->stream)) != cudaSuccess) {
                mips_free(c);
                return fv_cuda_fail(e, "allocating the φ-mipmaps", err);
            }
        }
        c->mip_levels = L, c->mip_w = w;
        memcpy(c->mip_h, f->mip_h, (size_t)L * sizeof(int));
    }
    /* level k's rows (ints), rowsf and inv_src (floats; level 0 has no source): 3 w words a level */
    const size_t words = 3 * (size_t)w * (size_t)L;
    if (words > c->shape_cap) {
        free(c->shape_host);
        if (!(c->shape_host = (float *)malloc(words * sizeof(float)))) {
            c->shape_cap = 0;
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        }
        c->shape_cap = words;
    }
    for (int k = 0; k < L; k++) {
        float *o = c->shape_host + 3 * (size_t)w * (size_t)k;
        memcpy(o, m->rows[k], (size_t)w * sizeof(int));
        memcpy(o + w, m->rowsf[k], (size_t)w * sizeof(float));
        if (k > 0)
            memcpy(o + 2 * w, m->inv_src[k], (size_t)w * sizeof(float));
        else
            memset(o + 2 * w, 0, (size_t)w * sizeof(float));
    }
    fv_status s = fv_cuda_mirror_fill(&c->calls, &c->shape, c->shape_host, words * sizeof(float), c->stream, "the φ-mipmaps' shape", err);
    if (s != FV_OK) return s;
    memset(dm, 0, sizeof *dm);
    dm->levels = L, dm->w = w, dm->wrap = m->wrap;
    float *base = (float *)c->shape.p;
    for (int k = 0; k < L; k++) {
        float *o = base + 3 * (size_t)w * (size_t)k;
        dm->rows[k] = (const int *)o;
        dm->rowsf[k] = o + w;
        dm->inv_src[k] = k > 0 ? o + 2 * w : NULL;
        dm->img[k] = c->mip_img[k];
    }
    return FV_OK;
}

extern "C" void fv_cuda_vp_destroy(fv_cuda_vp *c)
{
    if (!c) return;
    if (c->stream) fv_cuda_wait(&c->calls, c->stream); /* nothing queued may outlive its buffers */
    fv_cuda_scene_free(&c->calls, &c->scene);
    grid_free(c);
    screen_free(c);
    mips_free(c);
    svgf_free(&c->calls, &c->svgf);
    free(c->shape_host);
    fv_cuda_film_free(&c->calls, &c->film);
    fv_cuda_mirror_free(&c->calls, &c->col_h);
    fv_cuda_mirror_free(&c->calls, &c->onscreen);
    fv_cuda_mirror_free(&c->calls, &c->shape);
    fv_cuda_mirror_free(&c->calls, &c->lut[0]);
    fv_cuda_mirror_free(&c->calls, &c->lut[1]);
    fv_cuda_mirror_free(&c->calls, &c->blur_off);
    fv_cuda_mirror_free(&c->calls, &c->blur_k);
    fv_cuda_release(&c->calls, c->counts);
    for (int i = 0; i <= ST_COUNT; i++)
        if (c->ev[i]) cudaEventDestroy(c->ev[i]);
    if (c->queued) cudaEventDestroy(c->queued);
    if (c->stream) cudaStreamDestroy(c->stream);
    free(c);
}

extern "C" void fv_cuda_vp_calls(const fv_cuda_vp *c, fv_cuda_calls *out) { *out = c->calls.n; }

extern "C" fv_status fv_cuda_vp_create(const fv_kscene *host, fv_cuda_vp **out, fv_error *err)
{
    *out = NULL;
    fv_cuda_vp *c = (fv_cuda_vp *)calloc(1, sizeof *c);
    if (!c) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_status s = fv_cuda_scene_upload(&c->calls, &c->scene, host, err);
    cudaError_t e = cudaSuccess;
    if (s == FV_OK && (e = cudaStreamCreate(&c->stream)) != cudaSuccess) s = fv_cuda_fail(e, "creating a stream", err);
    for (int i = 0; s == FV_OK && i <= ST_COUNT; i++)
        if ((e = cudaEventCreate(&c->ev[i])) != cudaSuccess) s = fv_cuda_fail(e, "creating events", err);
    if (s == FV_OK && (e = cudaEventCreate(&c->queued)) != cudaSuccess) s = fv_cuda_fail(e, "creating events", err);
    if (s == FV_OK && (e = fv_cuda_alloc(&c->calls, (void **)&c->counts, 3 * sizeof(unsigned long long))) != cudaSuccess)
        s = fv_cuda_fail(e, "allocating counters", err);
    if (s != FV_OK) {
        fv_cuda_vp_destroy(c);
        return s;
    }
    *out = c;
    return FV_OK;
}

/* ---- a frame ---- */

/* The frame's sizes and tables agree with one another (what the kernels' indices rely on). */
static fv_status check_frame(const fv_cuda_vp_frame *f, fv_error *err)
{
    const fv_kvp_space *sp = &f->trace.space;
    const char *bad = NULL;
    if (sp->gw < 1 || sp->gh < 1 || sp->sw < 1 || sp->sh < 1) bad = "an empty grid or screen";
    else if (f->map.space.gw != sp->gw || f->map.space.gh != sp->gh || f->map.space.sw != sp->sw || f->map.space.sh != sp->sh)
        bad = "the map's space is not the trace's";
    else if (f->map.col_h != f->trace.col_h) bad = "the map's column heights are not the trace's";
    else if (!f->map.lut || f->map.nlut < 3) bad = "no radial table";
    else if (f->map.identity && (sp->gw != sp->sw || sp->gh != sp->sh)) bad = "an identity map on a grid not the screen's size";
    else if (!f->map.identity && !f->mips) bad = "a map without φ-mipmaps";
    else if (f->history && (f->reproject.space.gw != sp->gw || f->reproject.space.gh != sp->gh || f->reproject.nlut != f->map.nlut))
        bad = "the reprojection's space or table is not the frame's";
    else if ((f->trace.onscreen && f->trace.onscreen != f->onscreen) || (f->history && f->reproject.onscreen && f->reproject.onscreen != f->onscreen))
        bad = "a second on-screen mask";
    else if (f->history && !f->denoise) bad = "a history without the denoiser";
    else if (f->denoise && (f->svgf.iterations < 0 || f->svgf.iterations > 10)) bad = "SVGF's iterations outside 0..10";
    else if (f->blur && (!f->map.sigma || f->blur_table.w != sp->sw || f->blur_table.h != sp->sh || f->blur_table.nq < 1 ||
                         !f->blur_table.off || !f->blur_table.k || f->blur_nk < 1))
        bad = "a blur without its table or sigma";
    return bad ? fv_error_set(err, FV_ERR_INTERNAL, "CUDA: Visual-Polar frame: %s", bad) : FV_OK;
}

/* Queues one eye's frame on its stream; nothing waits. */
static fv_status launch_frame(fv_cuda_vp *c, const fv_cuda_vp_frame *f, const fv_film_views *out, fv_error *err)
{
    fv_status s;
    const int gw = f->trace.space.gw, gh = f->trace.space.gh, sw = f->trace.space.sw, sh = f->trace.space.sh;
    const size_t n = (size_t)gw * (size_t)gh, ns = (size_t)sw * (size_t)sh;
    cudaStream_t st = c->stream;
    cudaError_t e;

    /* What the frame needs on the GPU: buffers (kept), the scene at the frame's time, the host's
     * tables where they changed. */
    fv_film_views dv;
    const uint8_t *mask = f->onscreen;
    fv_kphi_mips dm;
    memset(&dm, 0, sizeof dm);
    /* Every copy from the host first, the radial table included (into the buffer the previous
     * frame did not map with, which the reprojection still reads), then what launches (the grid's
     * first clear): a copy from pageable memory queued behind a kernel of its stream may make the
     * host wait for that kernel, and a pair's second eye would then be queued only once the first
     * eye's trace had run. The simulator counts such copies (uploads_behind_kernels). */
    const int lut_now = c->lut_prev ^ 1;
    if ((s = fv_cuda_scene_update(&c->calls, &c->scene, f->scene, st, err)) != FV_OK ||
        (f->trace.col_h && (s = fv_cuda_mirror_fill(&c->calls, &c->col_h, f->trace.col_h, (size_t)gw * sizeof(int), st, "the column heights", err)) != FV_OK) ||
        (mask && (s = fv_cuda_mirror_fill(&c->calls, &c->onscreen, mask, n, st, "the on-screen mask", err)) != FV_OK) ||
        (f->mips && (s = mips_ensure(c, f, &dm, err)) != FV_OK) ||
        (f->blur && ((s = fv_cuda_mirror_fill(&c->calls, &c->blur_off, f->blur_table.off, (size_t)f->blur_table.nq * sizeof(int), st, "the blur's kernels", err)) != FV_OK ||
                     (s = fv_cuda_mirror_fill(&c->calls, &c->blur_k, f->blur_table.k, f->blur_nk * sizeof(float), st, "the blur's kernels", err)) != FV_OK)) ||
        (s = fv_cuda_mirror_fill(&c->calls, &c->lut[lut_now], f->map.lut, (size_t)f->map.nlut * 3 * sizeof(float), st, "the radial table", err)) != FV_OK ||
        (s = grid_ensure(c, gw, gh, err)) != FV_OK || (s = screen_ensure(c, sw, sh, err)) != FV_OK ||
        (s = fv_cuda_film_prepare(&c->calls, &c->film, out, ns, &dv, err)) != FV_OK || (f->denoise && (s = svgf_ensure(c, gw, gh, err)) != FV_OK))
        return s;
    const int *dcol_h = f->trace.col_h ? (const int *)c->col_h.p : NULL;
    const uint8_t *dmask = mask ? (const uint8_t *)c->onscreen.p : NULL;
    if ((e = fv_cuda_clear(&c->calls, c->counts, 0, 3 * sizeof(unsigned long long), st)) != cudaSuccess) return fv_cuda_fail(e, "clearing counters", err);

    /* 1. trace */
    cudaEventRecord(c->ev[ST_TRACE], st);
    fv_kvp_trace_frame tf = f->trace;
    tf.col_h = dcol_h;
    tf.onscreen = f->trace.onscreen ? dmask : NULL;
    FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_trace, tiles_of(gw, gh), dim3(FV_CUDA_VP_BLOCK, FV_CUDA_VP_BLOCK), st)(c->scene.dev, tf, c->g, c->counts);

    /* 2. the denoiser: the history's coordinates, then SVGF's launches */
    cudaEventRecord(c->ev[ST_DENOISE], st);
    if (f->denoise && f->history) {
        fv_kvp_reproject_frame rf = f->reproject;
        rf.g = c->g;
        rf.onscreen = f->reproject.onscreen ? dmask : NULL;
        rf.prev_lut = c->lut[c->lut_prev].p ? (const float *)c->lut[c->lut_prev].p : NULL;
        if (!rf.prev_lut && rf.space.kind != FV_KVP_CARTESIAN)
            return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: a history without the previous frame's radial table");
        FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_reproject, blocks_of(n), FV_CUDA_VP_THREADS, st)(rf, c->prev_coord);
    }
    if (f->denoise) svgf_launch(c, f, dcol_h, dmask);

    /* 3. φ-mipmaps: level 0 the grid's colour, then each level from the one before */
    cudaEventRecord(c->ev[ST_MIP], st);
    if (f->mips) {
        if ((e = fv_cuda_copy(&c->calls, dm.img[0], c->g.color, 3 * n * sizeof(float), cudaMemcpyDeviceToDevice, st)) != cudaSuccess)
            return fv_cuda_fail(e, "copying the φ-mipmaps' level 0", err);
        for (int k = 1; k < dm.levels; k++)
            FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_halve, tiles_of(dm.w, f->mip_h[k]), dim3(FV_CUDA_VP_BLOCK, FV_CUDA_VP_BLOCK), st)(dm, k, f->mip_h[k]);
    }

    /* 4. map, with this frame's radial table */
    cudaEventRecord(c->ev[ST_MAP], st);
    fv_kvp_map_frame mf = f->map;
    mf.col_h = dcol_h;
    mf.g = c->g;
    mf.mips = dm;
    mf.lut = (const float *)c->lut[lut_now].p;
    mf.sigma = f->blur ? c->sigma : NULL;
    FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_map, tiles_of(sw, sh), dim3(FV_CUDA_VP_BLOCK, FV_CUDA_VP_BLOCK), st)(mf, dv);

    /* 5. the foveated blur, in place in the film's colour through the scratch image */
    cudaEventRecord(c->ev[ST_BLUR], st);
    if (f->blur) {
        fv_kblur_table bt = f->blur_table;
        bt.off = (const int *)c->blur_off.p;
        bt.k = (const float *)c->blur_k.p;
        FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_blur_h, tiles_of(sw, sh), dim3(FV_CUDA_VP_BLOCK, FV_CUDA_VP_BLOCK), st)(bt, c->sigma, dv.color, c->blur_tmp);
        FV_CUDA_LAUNCH(&c->calls, fv_cuda_vp_blur_v, tiles_of(sw, sh), dim3(FV_CUDA_VP_BLOCK, FV_CUDA_VP_BLOCK), st)(bt, c->sigma, c->blur_tmp, dv.color);
    }
    cudaEventRecord(c->ev[ST_COUNT], st);
    if ((e = cudaGetLastError()) != cudaSuccess) return fv_cuda_fail(e, "launching the Visual-Polar kernels", err);
    c->lut_prev = lut_now; /* the next frame's reprojection reads it */
    return FV_OK;
}

/* Queues the copies of one eye's film buffers that are set and its counters to the host, after its
 * frame on its stream, and marks the stream's end (c->queued). */
static fv_status read_frame(fv_cuda_vp *c, const fv_cuda_vp_frame *f, const fv_film_views *out, fv_error *err)
{
    const size_t ns = (size_t)f->trace.space.sw * (size_t)f->trace.space.sh;
    cudaStream_t st = c->stream;
    memset(c->counts_host, 0, sizeof c->counts_host);
    cudaError_t e = fv_cuda_film_read_async(&c->calls, &c->film, out, ns, st);
    if (e == cudaSuccess) e = fv_cuda_copy(&c->calls, c->counts_host, c->counts, sizeof c->counts_host, cudaMemcpyDeviceToHost, st);
    if (e == cudaSuccess && f->denoise) e = svgf_read_rows(&c->calls, &c->svgf, st);
    if (e == cudaSuccess) e = cudaEventRecord(c->queued, st);
    return e == cudaSuccess ? FV_OK : fv_cuda_fail(e, "reading the Visual-Polar frame back", err);
}

/* One eye's result from what was read back (after the wait). */
static void frame_result(fv_cuda_vp *c, const fv_cuda_vp_frame *f, fv_cuda_vp_result *res)
{
    res->rays = c->counts_host[0], res->paths = c->counts_host[1], res->nan_paths = c->counts_host[2];
    if (f->denoise) {
        const dev_svgf *d = &c->svgf;
        double mean_history;
        fv_ksvgf_sum_rows(d->h, d->row_surface, d->row_hist, d->row_holes, d->row_len, &res->history_fraction, &mean_history);
    }
    for (int i = 0; i < ST_COUNT; i++) {
        float ms = 0.0f;
        cudaEventElapsedTime(&ms, c->ev[i], c->ev[i + 1]);
        res->stage_ms[i] = ms;
    }
    float ms = 0.0f;
    cudaEventElapsedTime(&ms, c->ev[ST_TRACE], c->ev[ST_COUNT]);
    res->kernel_ms = ms;
}

extern "C" fv_status fv_cuda_vp_render(fv_cuda_vp *const *c, int eyes, const fv_cuda_vp_frame *f, const fv_film_views *out, fv_cuda_vp_result *res,
                                       fv_error *err)
{
    if (eyes < 1 || eyes > 2) return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: Visual-Polar frames for %d eyes", eyes);
    fv_status s;
    for (int e = 0; e < eyes; e++) {
        memset(&res[e], 0, sizeof res[e]);
        if ((s = check_frame(&f[e], err)) != FV_OK) return s;
    }
    if (eyes == 2 && c[0] == c[1]) return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: a stereo pair's eyes share their buffers");
    fv_cuda_forget_error();
    fv_cuda_calls before[2];
    for (int e = 0; e < eyes; e++) before[e] = c[e]->calls.n;
    /* Every eye's kernels queued (each on its own stream, so a pair's two eyes may run side by
     * side), then every eye's read-back (a copy into pageable host memory may hold the host until
     * its stream gets there, so none is queued before the last eye's kernels), then the one host
     * wait: eye 0's stream, which waits for eye 1's read-back first. A pair thus costs one round
     * trip, as a single eye does. */
    for (int e = 0; e < eyes; e++)
        if ((s = launch_frame(c[e], &f[e], &out[e], err)) != FV_OK) return s;
    for (int e = 0; e < eyes; e++)
        if ((s = read_frame(c[e], &f[e], &out[e], err)) != FV_OK) {
            /* nothing queued may write into a film after the caller has its error */
            for (int q = 0; q <= e; q++) fv_cuda_wait(&c[q]->calls, c[q]->stream);
            return s;
        }
    cudaError_t ce = eyes == 2 ? cudaStreamWaitEvent(c[0]->stream, c[1]->queued, 0) : cudaSuccess;
    if (ce == cudaSuccess) ce = fv_cuda_wait(&c[0]->calls, c[0]->stream);
    if (eyes == 2) c[1]->calls.queued = false; /* eye 1's work was waited for through eye 0's stream */
    res[0].syncs = 1;
    if (ce != cudaSuccess) return fv_cuda_fail(ce, "running the Visual-Polar kernels", err);
    for (int e = 0; e < eyes; e++) {
        frame_result(c[e], &f[e], &res[e]);
        const fv_cuda_calls *a = &c[e]->calls.n, *b = &before[e];
        fv_cuda_calls *d = &res[e].calls;
        d->launches = a->launches - b->launches, d->syncs = a->syncs - b->syncs, d->host_waits = a->host_waits - b->host_waits;
        d->pageable_copies = a->pageable_copies - b->pageable_copies;
        d->bytes_h2d = a->bytes_h2d - b->bytes_h2d, d->bytes_d2h = a->bytes_d2h - b->bytes_d2h;
        d->allocations = a->allocations - b->allocations, d->frees = a->frees - b->frees;
    }
    return FV_OK;
}
