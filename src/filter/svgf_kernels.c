/* fovea — SVGF's kernels (svgf_kernels.h): their portable side and descriptors, their one launch
 * order, and the filter over them on the portable backend (a launch per step: a step reads its
 * neighbours' results of the one before, as a GPU launch would). */
#include <stdlib.h>
#include "core/alloc.h"
#include "filter/svgf_kernels.h"

FV_SVGF_KERNELS(FV_KERNEL_DEFINE)

fv_status fv_svgf_kernels_queue(fv_backend *b, fv_ksvgf *k, bool fused, fv_error *err)
{
    const int w = k->g.w, h = k->g.h;
    fv_svgf_step_args a = {*k, 0};
    fv_status s;
    if ((s = fv_backend_launch(b, &fv_svgf_accumulate_kernel, w, h, &a, NULL, err)) != FV_OK ||
        (s = fv_backend_launch(b, &fv_svgf_rows_kernel, h, 1, &a, NULL, err)) != FV_OK ||
        (s = fv_backend_launch(b, &fv_svgf_variance_kernel, w, h, &a, NULL, err)) != FV_OK)
        return s;
    for (a.pass = 0; a.pass < k->iterations; a.pass++) {
        if (fused) {
            const fv_kernel *pass = a.pass == k->iterations - 1 ? &fv_svgf_last_pass_kernel : &fv_svgf_pass_kernel;
            if ((s = fv_backend_launch(b, pass, w, h, &a, NULL, err)) != FV_OK) return s;
            continue;
        }
        if ((s = fv_backend_launch(b, &fv_svgf_prefilter_kernel, w, h, &a, NULL, err)) != FV_OK ||
            (s = fv_backend_launch(b, &fv_svgf_atrous_kernel, w, h, &a, NULL, err)) != FV_OK)
            return s;
    }
    if (((!fused || k->iterations == 0) && (s = fv_backend_launch(b, &fv_svgf_finish_kernel, w, h, &a, NULL, err)) != FV_OK) ||
        (s = fv_backend_launch(b, &fv_svgf_holes_kernel, w, h, &a, NULL, err)) != FV_OK)
        return s;
    fv_ksvgf_swap(k);
    return FV_OK;
}

struct fv_svgf_kernels {
    fv_ksvgf k;         /* the buffers below, the options, and each frame's inputs */
    fv_backend *b;      /* portable: its device memory is host memory */
    bool have_history;
    bool fused;         /* fv_svgf_kernels_set_fused */
    float *feat[2][7];  /* nx, ny, nz, z, m1, m2, len: this frame's and the previous (swapped) */
};

/* Every float buffer and its floats per pixel, for allocation and release in one place. */
#define MAX_BUFFERS 40
static int float_buffers(fv_svgf_kernels *s, float ***ptr, int *per_pixel)
{
    int n = 0;
#define BUF(p, m) (ptr[n] = &(p), per_pixel[n] = (m), n++)
    BUF(s->k.surf, 1);
    BUF(s->k.gvar, 1);
    BUF(s->k.grad, 1);
    BUF(s->k.hist_illum, 3);
    BUF(s->k.hist_pos, 3);
    for (int i = 0; i < 2; i++) {
        for (int c = 0; c < 7; c++) BUF(s->feat[i][c], 1);
        for (int c = 0; c < FV_KSVGF_NVAL; c++) BUF(s->k.val[i][c], 1);
    }
#undef BUF
    return n;
}

static void free_all(fv_svgf_kernels *s)
{
    float **ptr[MAX_BUFFERS];
    int pp[MAX_BUFFERS];
    const int nb = float_buffers(s, ptr, pp);
    for (int i = 0; i < nb; i++) free(*ptr[i]);
    free(s->k.kind), free(s->k.found), free(s->k.hist_id);
    free(s->k.row_surface), free(s->k.row_hist), free(s->k.row_holes), free(s->k.row_len);
    if (s->b) fv_backend_destroy(s->b);
    free(s);
}

fv_status fv_svgf_kernels_create(const fv_grid *grid, const fv_svgf_opts *o, fv_svgf_kernels **out, fv_error *err)
{
    if (!out) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no output handle");
    *out = NULL;
    fv_svgf_opts def;
    if (!o) {
        fv_svgf_opts_default(&def);
        o = &def;
    }
    fv_status st = fv_svgf_opts_validate(o, err);
    if (st == FV_OK) st = fv_svgf_grid_validate(grid, err);
    if (st != FV_OK) return st;
    fv_svgf_kernels *s = calloc(1, sizeof *s);
    if (!s) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the SVGF filter");
    fv_ksvgf *k = &s->k;
    k->g = *grid;
    k->alpha_color = o->alpha_color, k->alpha_moments = o->alpha_moments;
    k->sigma_depth = o->sigma_depth, k->sigma_normal = o->sigma_normal, k->sigma_lum = o->sigma_lum;
    k->iterations = o->iterations;
    k->sq = fv_ksvgf_squarings(o->sigma_normal);
    k->periph_x = grid->w, k->periph_passes = o->iterations;
    s->fused = true;
    const size_t n = (size_t)grid->w * (size_t)grid->h, h = (size_t)grid->h;
    float **ptr[MAX_BUFFERS];
    int pp[MAX_BUFFERS];
    const int nb = float_buffers(s, ptr, pp);
    bool ok = true;
    for (int i = 0; i < nb && ok; i++) ok = (*ptr[i] = fv_calloc_array(n, pp[i] * sizeof(float))) != NULL;
    ok = ok && (k->kind = fv_calloc_array(n, 1)) && (k->found = fv_calloc_array(n, 1));
    ok = ok && (k->hist_id = fv_calloc_array(n, sizeof(uint32_t)));
    ok = ok && (k->row_surface = fv_calloc_array(h, sizeof(long))) && (k->row_hist = fv_calloc_array(h, sizeof(long)));
    ok = ok && (k->row_holes = fv_calloc_array(h, sizeof(long))) && (k->row_len = fv_calloc_array(h, sizeof(double)));
    if (!ok) {
        free_all(s);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for SVGF buffers of a %dx%d grid", grid->w, grid->h);
    }
    if ((st = fv_backend_create(FV_DEVICE_PORTABLE, &s->b, err)) != FV_OK) {
        free_all(s);
        return st;
    }
    float **cur[7] = {&k->nx, &k->ny, &k->nz, &k->z, &k->m1, &k->m2, &k->len};
    const float **prev[7] = {&k->pnx, &k->pny, &k->pnz, (const float **)&k->pz, &k->pm1, &k->pm2, &k->plen};
    for (int c = 0; c < 7; c++) *cur[c] = s->feat[0][c], *prev[c] = s->feat[1][c];
    *out = s;
    return FV_OK;
}

void fv_svgf_kernels_destroy(fv_svgf_kernels *s)
{
    if (s) free_all(s);
}

void fv_svgf_kernels_set_periphery(fv_svgf_kernels *s, int x_from, int passes)
{
    s->k.periph_x = x_from < 0 ? 0 : (x_from > s->k.g.w ? s->k.g.w : x_from);
    s->k.periph_passes = passes < 0 ? 0 : passes;
}

void fv_svgf_kernels_set_fused(fv_svgf_kernels *s, bool fused)
{
    s->fused = fused;
}

void fv_svgf_kernels_reset(fv_svgf_kernels *s)
{
    if (s) s->have_history = false;
}

fv_status fv_svgf_kernels_filter(fv_svgf_kernels *s, const fv_svgf_frame *fr, int threads, fv_svgf_info *info, fv_error *err)
{
    if (!s) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no filter");
    fv_status st = fv_svgf_frame_validate(fr, err);
    if (st != FV_OK) return st;
    fv_ksvgf *k = &s->k;
    k->color = fr->color, k->albedo = fr->albedo, k->normal = fr->normal, k->depth = fr->depth;
    k->position = fr->position, k->prev_coord = fr->prev_coord, k->id = fr->id;
    k->sampled = fr->sampled, k->active = fr->active;
    k->history = s->have_history && fr->prev_coord;
    fv_backend_set_threads(s->b, threads);
    if ((st = fv_svgf_kernels_queue(s->b, k, s->fused, err)) != FV_OK || (st = fv_backend_wait(s->b, "SVGF", err)) != FV_OK) return st;
    fv_svgf_info in;
    fv_ksvgf_sum_rows(k->g.h, k->row_surface, k->row_hist, k->row_holes, k->row_len, &in.history_fraction, &in.mean_history);
    s->have_history = true;
    if (info) *info = in;
    return FV_OK;
}
