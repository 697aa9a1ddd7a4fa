/* fovea — spatiotemporal variance-guided filtering (Schied et al., HPG 2017, Sec. 4; see svgf.h for
 * the algorithm and the contract). This file is the CPU implementation on an fv_grid.
 *
 * One frame is a few sweeps over the grid, each an OpenMP loop over rows inside the frame's one
 * parallel region (the hole fill, when needed, opens a second); every pixel is computed
 * from its inputs alone, in a fixed order, so the result does not depend on the thread count:
 *  A. classify each pixel, demodulate, fetch and blend its history (Sec. 4.1), keep its features;
 *  B. depth gradient and variance: temporal, or the 7x7 spatial estimate (Sec. 4.2);
 *  C. per À-Trous pass (Sec. 4.3): the 3x3-prefiltered variance, then the pass itself, ping-ponging
 *     between two buffers; the first pass also writes the history;
 *  D. remodulate and store this frame's G-buffer as the next frame's history;
 *  E. fill the pixels that had no path (only when there are some).
 * A, D and E are the kernels' per-pixel steps (filter/ksvgf.h: one implementation for the CPU and
 * the devices), as are the counters' sums and the arithmetic of B and C's weights; B and C are the
 * vectorised sweeps below, which add each pixel's taps in the kernels' order.
 *
 * Speed: rows are processed in chunks of CHUNK pixels with the taps in the outer loop. For most
 * pixels a tap is a plain shift in memory (screen grids; in polar grids, between full-height
 * columns away from the clamped edges), so the inner loop runs over contiguous pixels and the
 * compiler vectorises it (omp simd) from buffers kept as one array per channel. The other pixels
 * (the fovea's short columns, the clamped edges) look their taps up as fv_grid_tap does, from a
 * per-chunk table, and run the same arithmetic on gathered loads. Each pixel adds its taps in the
 * same order either way, so the two paths give the same bits. The normal weight's cosine^128 is
 * seven squarings, unrolled and vectorised; other powers of two are squarings in a plain loop, other
 * exponents powf. The exponential is an inline approximation (exp_neg). Spans of a chunk with no
 * surface (background, rows beyond short columns) are skipped. In the À-Trous pass the pixels whose
 * 24 taps are all shifts go 4 or 8 at a time with every tap inner, the sums in registers
 * (atrous_block). A polar grid's short columns and the columns within two taps of them are
 * filtered along column-major copies instead, where their taps lie close together (the fovea's
 * lines, C2 in svgf_sweeps.h). B and C live in svgf_sweeps.h, built here for the baseline x86-64
 * and in svgf_avx2.c for AVX2; fv_svgf_set_isa picks one (issue 16: same bits, twice the lanes).
 *
 * Choices the paper leaves open, and why:
 *  - Depth gradient: per axis (along the column and across columns, through the grid's own taps) the
 *    smaller of the two one-sided differences to neighbouring surface pixels, then the larger of the
 *    two axes, times the tap's Euclidean distance in grid pixels (2^i sqrt(dx^2 + dy^2)). A central
 *    difference would straddle a silhouette and make the depth test of exactly the pixels next to
 *    it blind; on a smooth surface the one-sided differences agree with the central one.
 *  - Spatial variance (history shorter than 4 frames, counting this one): moments averaged over the
 *    7x7 neighbourhood with the depth and normal weights only. A luminance term would need a scale
 *    that linear radiance with no fixed exposure does not have, and the albedo is already divided
 *    out, so texture does not inflate the estimate.
 *  - History length: the renormalised bilinear average of the taps' lengths plus one, capped at
 *    LEN_MAX (beyond 1 / alpha it only feeds the counters).
 *  - History consistency uses this frame's depth for the position tolerance (5% of the distance: a
 *    point that moved further than that in one frame is a different point for the history).
 *  - Polar grids: a history coordinate X outside [0, w] is clamped to the edge columns (as the
 *    lookup clamps them) and V is wrapped; the consistency test decides. Screen grids refuse
 *    coordinates outside the image.
 *  - Non-finite input (colour, albedo, normal, depth or position of a sampled surface pixel) is
 *    treated like an unsampled pixel: one NaN would otherwise spread through the history forever.
 *  - Every pixel that is not a surface (background, holes, rows beyond their column's height) has a
 *    zero normal and zero values in the working buffers, so as a tap its weight is exactly 0 and
 *    the inner loops need no test.
 *
 * Memory: about 140 bytes per grid pixel, plus the fovea's lines (68 bytes per cell of the short
 * columns and the 64 columns beyond them, padded to h + 64 rows), all allocated by fv_svgf_create;
 * nothing is allocated per frame (the per-chunk scratch is on the stack, about 12 KB).
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/demod.h"
#include "filter/svgf_impl.h"

#define SVGF_ISA(name) fv_svgf_##name##_base
#define SVGF_VW 4 /* floats per SSE vector */
#include "filter/svgf_sweeps.h"
#undef SVGF_ISA

void fv_svgf_opts_default(fv_svgf_opts *o)
{
    o->alpha_color = 0.2f;
    o->alpha_moments = 0.2f;
    o->iterations = 5;
    o->sigma_depth = 1.0f;
    o->sigma_normal = 128.0f;
    o->sigma_lum = 4.0f;
}

fv_status fv_svgf_opts_validate(const fv_svgf_opts *o, fv_error *err)
{
    if (!o) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no options");
    const struct {
        const char *name;
        float v;
    } alphas[2] = {{"alpha_color", o->alpha_color}, {"alpha_moments", o->alpha_moments}},
      sigmas[3] = {{"sigma_depth", o->sigma_depth}, {"sigma_normal", o->sigma_normal}, {"sigma_lum", o->sigma_lum}};
    for (int i = 0; i < 2; i++)
        if (!(alphas[i].v > 0.0f && alphas[i].v <= 1.0f))
            return fv_error_set(err, FV_ERR_INVALID, "SVGF: %s %g not in (0, 1]", alphas[i].name, (double)alphas[i].v);
    if (o->iterations < 0 || o->iterations > 10)
        return fv_error_set(err, FV_ERR_INVALID, "SVGF: iterations %d not in [0, 10]", o->iterations);
    for (int i = 0; i < 3; i++)
        if (!(sigmas[i].v > 0.0f && isfinite(sigmas[i].v)))
            return fv_error_set(err, FV_ERR_INVALID, "SVGF: %s %g must be positive and finite", sigmas[i].name,
                                (double)sigmas[i].v);
    return FV_OK;
}

/* ---- create / destroy */

/* Every float buffer with its length in floats per pixel, for allocation and release in one place. */
static int float_buffers(fv_svgf *f, float ***ptr, int *per_pixel)
{
    int k = 0;
#define BUF(p, m) (ptr[k] = &(p), per_pixel[k] = (m), k++)
    BUF(f->surf, 1);
    BUF(f->gvar, 1);
    BUF(f->grad, 1);
    BUF(f->hist_illum, 3);
    BUF(f->hist_pos, 3);
    for (int i = 0; i < 2; i++) {
        BUF(f->nx[i], 1);
        BUF(f->ny[i], 1);
        BUF(f->nz[i], 1);
        BUF(f->z[i], 1);
        BUF(f->m1[i], 1);
        BUF(f->m2[i], 1);
        BUF(f->len[i], 1);
        for (int c = 0; c < NVAL; c++) BUF(f->val[i][c], 1);
    }
#undef BUF
    return k;
}

#define MAX_BUFFERS 40

static void free_buffers(fv_svgf *f)
{
    float **ptr[MAX_BUFFERS];
    int pp[MAX_BUFFERS];
    int nb = float_buffers(f, ptr, pp);
    for (int i = 0; i < nb; i++) free(*ptr[i]);
    free(f->kind), free(f->hist_id);
    free(f->row_surface), free(f->row_hist), free(f->row_holes), free(f->row_len);
    for (int i = 0; i < LN_COUNT; i++) free(f->ln[i]);
}

/* FOVEA_SVGF_LINES=off: no fovea lines (C2 in svgf_sweeps.h) in the filters created while it is set;
 * the same bits, for measuring what the lines save (docs/filters.md). */
static bool lines_off(void)
{
    const char *v = getenv("FOVEA_SVGF_LINES");
    return v && strcmp(v, "off") == 0;
}

fv_status fv_svgf_grid_validate(const fv_grid *grid, fv_error *err)
{
    if (!grid || grid->w < 1 || grid->h < 1)
        return fv_error_set(err, FV_ERR_INVALID, "SVGF: grid size %dx%d", grid ? grid->w : 0, grid ? grid->h : 0);
    if (grid->col_h)
        for (int x = 0; x < grid->w; x++)
            if (grid->col_h[x] < 1 || grid->col_h[x] > grid->h)
                return fv_error_set(err, FV_ERR_INVALID, "SVGF: column %d has %d rows, not in [1, %d]", x, grid->col_h[x],
                                    grid->h);
    /* Pixel indices are ints in the inner loops (what the vectoriser can gather with). */
    if ((long long)grid->w * grid->h > INT32_MAX)
        return fv_error_set(err, FV_ERR_INVALID, "SVGF: grid %dx%d is too large", grid->w, grid->h);
    return FV_OK;
}

fv_status fv_svgf_create(const fv_grid *grid, const fv_svgf_opts *o, fv_svgf **out, fv_error *err)
{
    if (!out) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no output handle");
    *out = NULL;
    fv_svgf_opts def;
    if (!o) {
        fv_svgf_opts_default(&def);
        o = &def;
    }
    fv_status s = fv_svgf_opts_validate(o, err);
    if (s != FV_OK) return s;
    if ((s = fv_svgf_grid_validate(grid, err)) != FV_OK) return s;
    fv_svgf *f = calloc(1, sizeof *f);
    if (!f) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the SVGF filter");
    f->g = *grid;
    f->o = *o;
    f->n = (size_t)grid->w * (size_t)grid->h;
    f->normal_squarings = fv_ksvgf_squarings(o->sigma_normal);
    f->full_from = grid->w;
    while (f->full_from > 0 && fv_grid_col_h(grid, f->full_from - 1) == grid->h) f->full_from--;
    /* Zeroed memory: the pixels that are never surfaces keep zero features and values. */
    size_t n = f->n, h = (size_t)grid->h;
    float **ptr[MAX_BUFFERS];
    int pp[MAX_BUFFERS];
    int nb = float_buffers(f, ptr, pp);
    bool ok = true;
    for (int i = 0; i < nb && ok; i++) ok = (*ptr[i] = fv_calloc_array(n, pp[i] * sizeof(float))) != NULL;
    ok = ok && (f->kind = fv_calloc_array(n, 1)) != NULL;
    ok = ok && (f->hist_id = fv_calloc_array(n, sizeof(uint32_t))) != NULL;
    ok = ok && (f->row_surface = fv_calloc_array(h, sizeof(long))) != NULL;
    ok = ok && (f->row_hist = fv_calloc_array(h, sizeof(long))) != NULL;
    ok = ok && (f->row_holes = fv_calloc_array(h, sizeof(long))) != NULL;
    ok = ok && (f->row_len = fv_calloc_array(h, sizeof(double))) != NULL;
    /* The fovea's lines: the short columns and the columns their passes reach (C2 in
     * svgf_sweeps.h), for polar grids that have short columns. */
    const long long ln_size = (long long)imin(grid->w, f->full_from + 4 * LINE_STEP_MAX) * (grid->h + 2 * LINE_GHOST) + CHUNK;
    if (grid->wrap && f->full_from > 0 && ln_size <= INT32_MAX && !lines_off()) {
        f->lines_w = imin(grid->w, f->full_from + 4 * LINE_STEP_MAX);
        f->line_stride = grid->h + 2 * LINE_GHOST;
        /* CHUNK floats more: a vector's lanes past the last line's end (never stored). */
        for (int i = 0; i < LN_COUNT && ok; i++) ok = (f->ln[i] = fv_calloc_array((size_t)ln_size, sizeof(float))) != NULL;
    }
    if (!ok) {
        free_buffers(f);
        free(f);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for SVGF buffers of a %dx%d grid", grid->w, grid->h);
    }
    fv_svgf_set_isa(f, FV_SVGF_ISA_AUTO);
    f->periph_x = f->pass_cut = grid->w;
    f->periph_passes = o->iterations;
    /* For end-to-end comparisons (docs/filters.md): FOVEA_SVGF_ISA=baseline forces the baseline
     * build in every filter created while it is set. */
    const char *isa = getenv("FOVEA_SVGF_ISA");
    if (isa && strcmp(isa, "baseline") == 0) fv_svgf_set_isa(f, FV_SVGF_ISA_BASELINE);
    *out = f;
    return FV_OK;
}

static bool cpu_has_avx2(void)
{
#if defined(__x86_64__) && defined(__GNUC__)
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

bool fv_svgf_set_isa(fv_svgf *f, fv_svgf_isa isa)
{
    bool can = cpu_has_avx2();
    if (isa == FV_SVGF_ISA_AVX2 && !can) return false;
    f->avx2 = isa == FV_SVGF_ISA_AVX2 || (isa == FV_SVGF_ISA_AUTO && can);
    f->blocks = isa != FV_SVGF_ISA_PLAIN;
    return true;
}

void fv_svgf_set_periphery(fv_svgf *f, int x_from, int passes)
{
    f->periph_x = x_from < 0 ? 0 : (x_from > f->g.w ? f->g.w : x_from);
    f->periph_passes = passes < 0 ? 0 : passes;
}

void fv_svgf_destroy(fv_svgf *f)
{
    if (!f) return;
    free_buffers(f);
    free(f);
}

void fv_svgf_reset(fv_svgf *f)
{
    if (f) f->have_history = false;
}

/* ---- A. classification, demodulation, temporal accumulation */

/* The kernels' view of the filter for this frame (filter/ksvgf.h): the per-pixel steps that are not
 * vectorised sweeps are the kernels' own functions. */
static void kernel_view(const fv_svgf *f, const fv_svgf_frame *fr, bool history, fv_ksvgf *k)
{
    memset(k, 0, sizeof *k);
    k->g = f->g;
    k->alpha_color = f->o.alpha_color, k->alpha_moments = f->o.alpha_moments;
    k->sigma_depth = f->o.sigma_depth, k->sigma_normal = f->o.sigma_normal, k->sigma_lum = f->o.sigma_lum;
    k->iterations = f->o.iterations, k->sq = f->normal_squarings;
    k->periph_x = f->periph_x, k->periph_passes = f->periph_passes;
    k->history = history;
    k->color = fr->color, k->albedo = fr->albedo, k->normal = fr->normal, k->depth = fr->depth;
    k->position = fr->position, k->prev_coord = fr->prev_coord, k->id = fr->id;
    k->sampled = fr->sampled, k->active = fr->active;
    k->kind = f->kind, k->surf = f->surf, k->gvar = f->gvar, k->grad = f->grad;
    k->nx = f->nx[0], k->ny = f->ny[0], k->nz = f->nz[0], k->z = f->z[0], k->m1 = f->m1[0], k->m2 = f->m2[0], k->len = f->len[0];
    k->pnx = f->nx[1], k->pny = f->ny[1], k->pnz = f->nz[1], k->pz = f->z[1], k->pm1 = f->m1[1], k->pm2 = f->m2[1], k->plen = f->len[1];
    for (int i = 0; i < 2; i++)
        for (int c = 0; c < NVAL; c++) k->val[i][c] = f->val[i][c];
    k->hist_illum = f->hist_illum, k->hist_pos = f->hist_pos, k->hist_id = f->hist_id;
    k->row_surface = f->row_surface, k->row_hist = f->row_hist, k->row_holes = f->row_holes, k->row_len = f->row_len;
}

/* Each pixel through the kernel's step, the row's counters as fv_ksvgf_count_row sums them (here
 * from the step's results, with no per-pixel flag). */
static void sweep_accumulate(fv_svgf *f, const fv_ksvgf *k)
{
    const int w = f->g.w, h = f->g.h;
    #pragma omp for schedule(static, ROWS_PER_BLOCK)
    for (int y = 0; y < h; y++) {
        long n_surface = 0, n_hist = 0, n_holes = 0;
        double len_sum = 0.0;
        for (int x = 0; x < w; x++) {
            const int r = fv_ksvgf_accumulate_pixel(k, x, y);
            n_holes += r == FV_KSVGF_HOLE;
            n_surface += r == FV_KSVGF_SURFACE || r == FV_KSVGF_SURFACE_HIST;
            if (r != FV_KSVGF_SURFACE_HIST) continue;
            n_hist++;
            len_sum += f->len[0][(size_t)y * w + x];
        }
        f->row_surface[y] = n_surface;
        f->row_hist[y] = n_hist;
        f->row_holes[y] = n_holes;
        f->row_len[y] = len_sum;
    }
}

/* ---- D. remodulation and the history of the next frame */

static void sweep_finish(const fv_svgf *f, const fv_ksvgf *k)
{
    const int w = f->g.w, h = f->g.h;
    #pragma omp for schedule(static, ROWS_PER_BLOCK)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) fv_ksvgf_finish_pixel(k, x, y);
}

/* ---- E. holes: the B3-weighted mean of the filtered surface pixels at the smallest spacing that
 * reaches any, no edge-stopping (the hole's own features are unknown). */

static void sweep_holes(const fv_svgf *f, const fv_ksvgf *k, int nt)
{
    const int w = f->g.w, h = f->g.h;
    fv_region_begin();
    #pragma omp parallel for schedule(static, ROWS_PER_BLOCK) num_threads(nt)
    for (int y = 0; y < h; y++) {
        if (!f->row_holes[y]) continue;
        for (int x = 0; x < w; x++) fv_ksvgf_hole_pixel(k, x, y);
    }
    fv_region_end();
}

/* ---- the frame */

static void swap_buffers(float *b[2])
{
    float *t = b[0];
    b[0] = b[1];
    b[1] = t;
}

fv_status fv_svgf_frame_validate(const fv_svgf_frame *fr, fv_error *err)
{
    if (!fr) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no frame buffers");
    const struct {
        const char *name;
        const void *p;
    } need[6] = {{"color", fr->color}, {"albedo", fr->albedo}, {"normal", fr->normal},
                 {"depth", fr->depth}, {"position", fr->position}, {"id", fr->id}};
    for (int i = 0; i < 6; i++)
        if (!need[i].p) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no %s buffer", need[i].name);
    return FV_OK;
}

fv_status fv_svgf_filter(fv_svgf *f, const fv_svgf_frame *fr, int threads, fv_svgf_info *info, fv_error *err)
{
    if (!f) return fv_error_set(err, FV_ERR_INVALID, "SVGF: no filter");
    fv_status s = fv_svgf_frame_validate(fr, err);
    if (s != FV_OK) return s;
    const int nt = fv_thread_count(threads);
    const bool history = f->have_history && fr->prev_coord;
    f->ln_features = false;
    fv_ksvgf kv;
    kernel_view(f, fr, history, &kv);

    /* The whole filter but the rare hole fill is one parallel region (docs/threads.md): each sweep
     * is an orphaned `omp for` whose implicit barrier orders it before the next, instead of a
     * region per sweep that wakes the team again (about twenty a frame before). Everything a thread
     * keeps between sweeps (cur) is private and the same on every thread; the state shared between
     * sweeps (pass_cut) is written by one thread inside `single`, whose barrier publishes it. */
    fv_region_begin();
    #pragma omp parallel num_threads(nt)
    {
        sweep_accumulate(f, &kv);
        if (f->avx2)
            fv_svgf_variance_avx2(f);
        else
            fv_svgf_variance_base(f);
        int cur = 0;
        for (int it = 0; it < f->o.iterations; it++) {
            #pragma omp single
            f->pass_cut = fv_ksvgf_pass_cut(&kv, it);
            if (f->avx2) {
                fv_svgf_prefilter_avx2(f, f->val[cur][V_VAR]);
                fv_svgf_atrous_avx2(f, 1 << it, cur, it == 0);
            } else {
                fv_svgf_prefilter_base(f, f->val[cur][V_VAR]);
                fv_svgf_atrous_base(f, 1 << it, cur, it == 0);
            }
            cur = 1 - cur;
        }
        sweep_finish(f, &kv);
    }
    fv_region_end();

    fv_svgf_info in;
    if (fv_ksvgf_sum_rows(f->g.h, f->row_surface, f->row_hist, f->row_holes, f->row_len, &in.history_fraction, &in.mean_history))
        sweep_holes(f, &kv, nt);

    /* This frame's features, moments and lengths become the history (the working values need no
     * swap: sweep A rewrites val[0] whole every frame). */
    swap_buffers(f->nx);
    swap_buffers(f->ny);
    swap_buffers(f->nz);
    swap_buffers(f->z);
    swap_buffers(f->m1);
    swap_buffers(f->m2);
    swap_buffers(f->len);
    f->have_history = true;
    if (info) *info = in;
    return FV_OK;
}
