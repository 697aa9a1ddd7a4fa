/* fovea — the Visual-Polar family's stages on the portable backend (device.h): the kernels of
 * kernel/vp_trace.h, vp_reproject.h, svgf.h (through filter/svgf_kernels.c), phi_mips, vp_map.h and
 * vp_blur.h, a cell or pixel at a time over tiles on the CPU's threads; on cuda the flat scene
 * handed to device/cuda/vpolar.cu, which runs whole frames (its SVGF buffers its own). */
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/blur.h"
#include "filter/svgf_kernels.h"
#include "kernel/vp_reproject.h"
#include "scene/export.h"
#include "technique/vpolar/device.h"

struct fv_vp_device {
    const fv_scene *scene;
    fv_scene_export *flat;
    fv_cuda_vp *cuda;      /* cuda: the GPU's frames (device/cuda_backend.h) */
    float *blur_tmp;       /* the horizontal pass's image, kept between frames */
    size_t blur_pixels;
    fv_svgf_kernels *svgf; /* the denoiser's buffers and history (NULL: no stage set up) */
};

fv_status fv_vp_device_create(const fv_scene *scene, fv_device device, fv_vp_device **out, fv_error *err)
{
    *out = NULL;
    if (device != FV_DEVICE_PORTABLE && device != FV_DEVICE_CUDA)
        return fv_error_set(err, FV_ERR_INVALID, "the Visual-Polar family runs on devices portable and cuda only");
    fv_vp_device *d = calloc(1, sizeof *d);
    if (!d) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    d->scene = scene;
    fv_status s = fv_scene_export_create(scene, &d->flat, err);
    if (s == FV_OK && device == FV_DEVICE_CUDA) s = fv_cuda_vp_create(fv_scene_export_view(d->flat), &d->cuda, err);
    if (s != FV_OK) {
        fv_vp_device_destroy(d);
        return s;
    }
    *out = d;
    return FV_OK;
}

void fv_vp_device_destroy(fv_vp_device *d)
{
    if (!d) return;
    fv_cuda_vp_destroy(d->cuda);
    fv_scene_export_destroy(d->flat);
    fv_svgf_kernels_destroy(d->svgf);
    free(d->blur_tmp);
    free(d);
}

typedef struct trace_job {
    const fv_kscene *scene;
    fv_kvp_trace_frame f;
    fv_kvp_gbuf g;
    fv_kvp_trace_counts *c; /* per thread */
} trace_job;

static void trace_tile(void *ctx, const fv_tile *t)
{
    trace_job *j = ctx;
    const int w = j->f.space.gw;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++)
            if (y < (j->f.col_h ? j->f.col_h[x] : j->f.space.gh)) fv_kvp_trace_sample(j->scene, &j->f, &j->g, (long)y * w + x, &j->c[t->thread]);
}

fv_status fv_vp_device_trace(fv_vp_device *d, const fv_vp_trace_job *job, const fv_vp_gbuf *g, fv_vp_trace_result *res, bool *done,
                             fv_error *err)
{
    memset(res, 0, sizeof *res);
    *done = false;
    /* the flat scene at the frame's time (moving instances) */
    fv_status s = fv_scene_export_update(d->flat, d->scene, err);
    if (s != FV_OK) return s;
    trace_job j;
    j.scene = fv_scene_export_view(d->flat);
    fv_vp_trace_kframe(job, &j.f);
    j.g = *g;
    const int nt = fv_thread_count(job->frame->threads);
    if (!(j.c = calloc((size_t)nt, sizeof *j.c))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    *done = fv_parallel_tiles(j.f.space.gw, j.f.space.gh, job->frame->threads, trace_tile, &j, fv_kit_progress_fn, job->progress);
    for (int t = 0; t < nt; t++) res->rays += j.c[t].rays, res->paths += j.c[t].paths, res->nan_paths += j.c[t].nan_paths;
    free(j.c);
    return FV_OK;
}

typedef struct mips_job {
    fv_kphi_mips m;
    const float *rgb;
    int level;
} mips_job;

static void mips_tile(void *ctx, const fv_tile *t)
{
    const mips_job *j = ctx;
    const size_t stride = 3 * (size_t)j->m.w;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++) {
            if (j->level > 0) {
                fv_kphi_halve_cell(&j->m, j->level, x, y);
                continue;
            }
            const size_t i = (size_t)y * stride + 3 * (size_t)x;
            for (int c = 0; c < 3; c++) j->m.img[0][i + c] = j->rgb[i + c];
        }
}

void fv_vp_device_mips(fv_vp_device *d, fv_phi_mips *m, const float *rgb, int threads)
{
    (void)d;
    mips_job j;
    fv_phi_mips_kernel(m, &j.m);
    j.rgb = rgb;
    /* a level reads the one before: one pass per level */
    for (j.level = 0; j.level < j.m.levels; j.level++)
        fv_parallel_tiles(j.m.w, fv_phi_mips_grid(m, j.level)->h, threads, mips_tile, &j, NULL, NULL);
}

typedef struct map_job {
    const fv_kvp_map_frame *mf;
    fv_film_views out;
} map_job;

static void map_tile(void *ctx, const fv_tile *t)
{
    const map_job *j = ctx;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++) fv_kvp_map_pixel(j->mf, x, y, &j->out);
}

void fv_vp_device_map(fv_vp_device *d, const fv_kvp_map_frame *mf, const fv_film_views *out, int threads)
{
    (void)d;
    map_job j = {mf, *out};
    fv_parallel_tiles(mf->space.sw, mf->space.sh, threads, map_tile, &j, NULL, NULL);
}

fv_status fv_vp_device_blur(fv_vp_device *d, float *rgb, int w, int h, const float *sigma, int threads, fv_error *err)
{
    const size_t n = (size_t)w * h;
    if (d->blur_pixels != n) {
        free(d->blur_tmp);
        d->blur_tmp = fv_alloc_array(n, 3 * sizeof(float));
        d->blur_pixels = d->blur_tmp ? n : 0;
        if (!d->blur_tmp) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the blur of a %dx%d image", w, h);
    }
    /* the kernels up to the image's largest sigma (the pipeline's sigmas are finite and >= 0) */
    float smax = 0.0f;
    for (size_t i = 0; i < n; i++) smax = sigma[i] > smax ? sigma[i] : smax;
    return fv_blur_kernel_passes(rgb, d->blur_tmp, w, h, sigma, smax, threads, err);
}

typedef struct reproject_job {
    const fv_kvp_reproject_frame *f;
    float *prev_coord;
} reproject_job;

static void reproject_range(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    const reproject_job *j = ctx;
    for (int64_t i = b; i < e; i++) fv_kvp_reproject_sample(j->f, (long)i, &j->prev_coord[2 * i]);
}

void fv_vp_device_reproject(fv_vp_device *d, const fv_kvp_reproject_frame *f, float *prev_coord, int threads)
{
    (void)d;
    reproject_job j = {f, prev_coord};
    fv_parallel_for((int64_t)f->space.gw * f->space.gh, 4096, threads, reproject_range, &j);
}

fv_status fv_vp_device_svgf_setup(fv_vp_device *d, const fv_grid *g, const fv_svgf_opts *o, fv_error *err)
{
    fv_vp_device_svgf_release(d);
    if (d->cuda) return FV_OK; /* the GPU keeps SVGF's buffers itself (device/cuda/vpolar.cu) */
    return fv_svgf_kernels_create(g, o, &d->svgf, err);
}

void fv_vp_device_svgf_release(fv_vp_device *d)
{
    fv_svgf_kernels_destroy(d->svgf);
    d->svgf = NULL;
}

void fv_vp_device_svgf_periphery(fv_vp_device *d, int x_from, int passes)
{
    if (d->svgf) fv_svgf_kernels_set_periphery(d->svgf, x_from, passes);
}

fv_status fv_vp_device_svgf(fv_vp_device *d, const fv_svgf_frame *fr, int threads, fv_svgf_info *info, fv_error *err)
{
    if (!d->svgf) return fv_error_set(err, FV_ERR_INVALID, "the device's denoiser was not set up");
    return fv_svgf_kernels_filter(d->svgf, fr, threads, info, err);
}

bool fv_vp_device_whole_frame(const fv_vp_device *d)
{
    return d->cuda != NULL;
}

fv_status fv_vp_device_frames(fv_vp_device *const *d, int eyes, fv_cuda_vp_frame *f, const fv_film_views *out, fv_cuda_vp_result *res,
                              fv_error *err)
{
    fv_cuda_vp *c[2];
    if (eyes < 1 || eyes > 2) return fv_error_set(err, FV_ERR_INTERNAL, "whole frames for %d eyes", eyes);
    for (int e = 0; e < eyes; e++) {
        if (!d[e]->cuda) return fv_error_set(err, FV_ERR_INTERNAL, "whole frames need device cuda");
        /* the flat scene at the frame's time (moving instances); the GPU copies what moved */
        fv_status s = fv_scene_export_update(d[e]->flat, d[e]->scene, err);
        if (s != FV_OK) return s;
        f[e].scene = fv_scene_export_view(d[e]->flat);
        c[e] = d[e]->cuda;
    }
    return fv_cuda_vp_render(c, eyes, f, out, res, err);
}
