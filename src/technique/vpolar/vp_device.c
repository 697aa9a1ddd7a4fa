/* fovea — the Visual-Polar family's device frame (vp_device.h), one sequence of launches over the
 * backend for portable and CUDA alike.
 *
 * Memory: the grid's eight buffers and the history's coordinates are carved out of one device
 * buffer, SVGF's buffers out of another (its rows' counters last and contiguous, so one download
 * reads them), each cleared when the grid is new; the φ-mip levels are a buffer each. Everything
 * only grows (fv_buffer), so a sequence allocates in its first frame.
 *
 * SVGF's steps are queued in their one order (fv_svgf_kernels_queue, filter/svgf_kernels.h), the
 * order every device runs them in.
 *
 * The tables that follow the gaze are computed here too, in the frame's first launches, each only
 * when its view (or the grid) changed (gaze_tables.h).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "device/fill_kernels.h"
#include "device/film_device.h"
#include "filter/blur_kernels.h"
#include "filter/svgf_kernels.h"
#include "scene/flat_export.h"
#include "scene/flat_export_device.h"
#include "technique/vpolar/vp_device.h"
#include "technique/vpolar/gaze_tables.h"
#include "technique/vpolar/vpolar_kernels.h"

enum { ST_TRACE = 0, ST_DENOISE, ST_MIP, ST_MAP, ST_BLUR, ST_COUNT };
#define MARKS_PER_EYE (ST_COUNT + 1)
#define ALIGN 256 /* bytes: each array carved from a buffer starts on this */

/* A frame in flight (fv_vp_device_submit): its eyes, their frames (the scalars eye_result reads)
 * and films, and what its submit asked of the backend; in staging slot `slot`. */
typedef struct flight {
    int eyes;
    fv_vp_device_eye *eye[2];
    fv_vp_device_frame f[2];
    fv_film *film[2];
} flight;

struct fv_vp_device {
    const fv_scene *scene;
    fv_backend *b;
    fv_scene_export *flat;   /* the flat scene at the frame's time */
    fv_scene_device *dscene; /* its copy on b */
    flight flight[FV_FILM_DEVICE_SLOTS]; /* the frames in flight, oldest first from head */
    int head, in_flight;
};

/* SVGF on the device: filter/ksvgf.h's state with device pointers (the frame's inputs set per
 * frame). */
typedef struct dev_svgf {
    fv_ksvgf k;
    int w, h;          /* the grid the buffers were cleared for, 0: none */
    bool have_history; /* a frame was filtered since */
    fv_buffer mem;     /* every buffer, rows' counters last */
    size_t rows_at;    /* where the rows' counters start in mem */
} dev_svgf;

struct fv_vp_device_eye {
    fv_vp_device *d;
    int gw, gh;               /* the grid mem holds, 0: none */
    fv_buffer grid;           /* the gbuf and the history's coordinates */
    fv_kvp_gbuf g;
    float *prev_coord;        /* 2 per cell */
    fv_buffer sigma, blur_tmp; /* per screen pixel: 1, 3 floats */
    fv_film_device film;
    fv_buffer mip[FV_KPHI_MAX_LEVELS];
    int mip_levels, mip_w, mip_h[FV_KPHI_MAX_LEVELS]; /* the shape the levels were cleared for */
    float *shape_host;        /* the mips' shape packed for one mirror: per level rows, rowsf, inv_src */
    size_t shape_cap;         /* floats */
    fv_mirror col_h, shape, blur_off, blur_k;
    fv_vp_gaze_tables tables; /* the on-screen mask and the radial tables */
    fv_buffer counts;         /* FV_VP_COUNTS */
    fv_buffer host[FV_FILM_DEVICE_SLOTS]; /* pinned, a staging slot each: the counts, then SVGF's rows' counters */
    dev_svgf svgf;
    bool have_image;          /* a frame was traced since the grid was made */
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
    if (s == FV_OK) s = fv_backend_create(device, &d->b, err);
    if (s == FV_OK) s = fv_scene_device_create(d->b, fv_scene_export_view(d->flat), &d->dscene, err);
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
    fv_scene_device_destroy(d->dscene);
    if (d->b) fv_backend_destroy(d->b);
    fv_scene_export_destroy(d->flat);
    free(d);
}

fv_device fv_vp_device_kind(const fv_vp_device *d)
{
    return fv_backend_device(d->b);
}

fv_status fv_vp_device_eye_create(fv_vp_device *d, fv_vp_device_eye **out, fv_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    (*out)->d = d;
    return FV_OK;
}

void fv_vp_device_eye_destroy(fv_vp_device_eye *e)
{
    if (!e) return;
    fv_backend *b = e->d->b;
    /* nothing queued may outlive its buffers (frames in flight are dropped) */
    fv_backend_wait(b, "the Visual-Polar frame", NULL);
    fv_buffer_release(b, &e->grid);
    fv_buffer_release(b, &e->sigma);
    fv_buffer_release(b, &e->blur_tmp);
    fv_film_device_release(b, &e->film);
    for (int k = 0; k < FV_KPHI_MAX_LEVELS; k++) fv_buffer_release(b, &e->mip[k]);
    free(e->shape_host);
    fv_mirror *const m[] = {&e->col_h, &e->shape, &e->blur_off, &e->blur_k};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) fv_mirror_release(b, m[i]);
    fv_vp_gaze_tables_release(b, &e->tables);
    fv_buffer_release(b, &e->counts);
    for (int k = 0; k < FV_FILM_DEVICE_SLOTS; k++) fv_pinned_release(b, &e->host[k]);
    fv_buffer_release(b, &e->svgf.mem);
    free(e);
}

const float *fv_vp_device_eye_image(const fv_vp_device_eye *e)
{
    return e->have_image && fv_backend_device(e->d->b) == FV_DEVICE_PORTABLE ? e->g.color : NULL;
}

/* ---- buffers ---- */

static size_t aligned(size_t bytes)
{
    return (bytes + ALIGN - 1) / ALIGN * ALIGN;
}

/* The grid's buffers for gw x gh cells, "no surface, not sampled" everywhere (depth +inf): the rows
 * beyond a column's height keep that for good (the trace writes only valid cells), as on the host. */
static fv_status grid_ensure(fv_vp_device_eye *e, int gw, int gh, bool fresh, fv_error *err)
{
    if (!fresh && e->gw == gw && e->gh == gh) return FV_OK;
    fv_backend *b = e->d->b;
    const size_t n = (size_t)gw * (size_t)gh;
    /* color, albedo, reflectance, normal, position (3 floats), depth (1), id (4 bytes), sampled
     * (1 byte), prev_coord (2 floats) */
    const size_t bytes[9] = {3 * n * 4, 3 * n * 4, 3 * n * 4, 3 * n * 4, 3 * n * 4, n * 4, n * 4, n, 2 * n * 4};
    size_t total = 0;
    for (int i = 0; i < 9; i++) total += aligned(bytes[i]);
    fv_status s = fv_buffer_ensure(b, &e->grid, total, "the sample grid", err);
    if (s != FV_OK) return s;
    void *p[9];
    char *c = e->grid.p;
    for (int i = 0; i < 9; i++) p[i] = c, c += aligned(bytes[i]);
    e->g = (fv_kvp_gbuf){p[0], p[1], p[3], p[5], p[4], p[2], p[6], p[7]};
    e->prev_coord = p[8];
    e->gw = e->gh = 0;
    /* a new grid (or screen: the pipeline's setup makes both) recomputes every table */
    fv_vp_gaze_tables_forget(&e->tables);
    if ((s = fv_backend_clear(b, e->grid.p, 0, total, "the sample grid", err)) != FV_OK) return s;
    const fv_fill_f32_args fill = {e->g.depth, INFINITY};
    if ((s = fv_backend_launch(b, &fv_fill_f32_kernel, (int)n, 1, &fill, NULL, err)) != FV_OK) return s;
    e->gw = gw, e->gh = gh;
    e->have_image = false;
    return FV_OK;
}

/* SVGF's buffers for a gw x gh grid, all zeroed (filter/ksvgf.h: pixels that are never surfaces keep
 * zero features and weigh 0 as taps), without history when new. The passes prefilter their own
 * pixel, so there is no gvar. */
static fv_status svgf_ensure(fv_vp_device_eye *e, int gw, int gh, bool fresh, fv_error *err)
{
    dev_svgf *d = &e->svgf;
    if (!fresh && d->w == gw && d->h == gh) return FV_OK;
    fv_backend *b = e->d->b;
    const size_t n = (size_t)gw * (size_t)gh, h = (size_t)gh;
    fv_ksvgf *k = &d->k;
    float *feat[2][7];
    /* the arrays in order, then the rows' counters contiguous (longs and doubles, 8 bytes each) */
    enum { NF = 4 + 2 * (7 + FV_KSVGF_NVAL) };
    void **fp[NF];
    size_t fb[NF];
    int m = 0;
#define BUF(p, bytes) (fp[m] = (void **)&(p), fb[m] = (bytes), m++)
    BUF(k->surf, n * sizeof(float));
    BUF(k->grad, n * sizeof(float));
    BUF(k->hist_illum, 3 * n * sizeof(float));
    BUF(k->hist_pos, 3 * n * sizeof(float));
    for (int i = 0; i < 2; i++) {
        for (int c = 0; c < 7; c++) BUF(feat[i][c], n * sizeof(float));
        for (int c = 0; c < FV_KSVGF_NVAL; c++) BUF(k->val[i][c], n * sizeof(float));
    }
#undef BUF
    size_t total = 0;
    for (int i = 0; i < m; i++) total += aligned(fb[i]);
    total += aligned(n) * 2 + aligned(n * sizeof(uint32_t)); /* kind, found, hist_id */
    const size_t rows_at = total;
    total += 4 * h * 8;
    fv_status s = fv_buffer_ensure(b, &d->mem, total, "SVGF's buffers", err);
    if (s != FV_OK) return s;
    char *c = d->mem.p;
    for (int i = 0; i < m; i++) *fp[i] = c, c += aligned(fb[i]);
    k->kind = (uint8_t *)c, c += aligned(n);
    k->found = (uint8_t *)c, c += aligned(n);
    k->hist_id = (uint32_t *)c;
    c = (char *)d->mem.p + rows_at;
    k->row_surface = (long *)c, k->row_hist = (long *)(c + h * 8), k->row_holes = (long *)(c + 2 * h * 8);
    k->row_len = (double *)(c + 3 * h * 8);
    k->gvar = NULL;
    float **cur[7] = {&k->nx, &k->ny, &k->nz, &k->z, &k->m1, &k->m2, &k->len};
    const float **prev[7] = {&k->pnx, &k->pny, &k->pnz, (const float **)&k->pz, &k->pm1, &k->pm2, &k->plen};
    for (int i = 0; i < 7; i++) *cur[i] = feat[0][i], *prev[i] = feat[1][i];
    d->rows_at = rows_at;
    d->w = d->h = 0;
    if ((s = fv_backend_clear(b, d->mem.p, 0, total, "SVGF's buffers", err)) != FV_OK) return s;
    d->w = gw, d->h = gh;
    d->have_history = false;
    return FV_OK;
}

/* The mip levels' storage for the frame's shape (cleared when it changes) and the shape (rows,
 * rowsf, inv_src of every level, packed) through its mirror; *dm the chain with device pointers. */
static fv_status mips_ensure(fv_vp_device_eye *e, const fv_vp_device_frame *f, bool fresh, fv_kphi_mips *dm, fv_error *err)
{
    fv_backend *b = e->d->b;
    const fv_kphi_mips *m = &f->mip_shape;
    const int L = m->levels, w = m->w;
    if (L < 1 || L > FV_KPHI_MAX_LEVELS || w != f->trace.space.gw || f->mip_h[0] != f->trace.space.gh)
        return fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar device frame: the φ-mipmaps' shape does not match the grid");
    for (int k = 0; k < L; k++)
        if (f->mip_h[k] < 1 || !m->rows[k] || !m->rowsf[k] || (k > 0 && !m->inv_src[k]))
            return fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar device frame: the φ-mipmaps' level %d has no shape", k);
    fv_status s;
    if (fresh || L != e->mip_levels || w != e->mip_w || memcmp(f->mip_h, e->mip_h, (size_t)L * sizeof(int)) != 0) {
        e->mip_levels = 0;
        for (int k = 0; k < L; k++) {
            /* 3 floats a pixel on w columns, one float of padding (filter/phi_mips.c's layout) */
            const size_t bytes = (3 * (size_t)w * (size_t)f->mip_h[k] + 1) * sizeof(float);
            if ((s = fv_buffer_ensure(b, &e->mip[k], bytes, "the φ-mipmaps", err)) != FV_OK ||
                (s = fv_backend_clear(b, e->mip[k].p, 0, bytes, "the φ-mipmaps", err)) != FV_OK)
                return s;
        }
        e->mip_levels = L, e->mip_w = w;
        memcpy(e->mip_h, f->mip_h, (size_t)L * sizeof(int));
    }
    const size_t words = 3 * (size_t)w * (size_t)L;
    if (words > e->shape_cap) {
        free(e->shape_host);
        if (!(e->shape_host = malloc(words * sizeof(float)))) {
            e->shape_cap = 0;
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        }
        e->shape_cap = words;
    }
    for (int k = 0; k < L; k++) {
        float *o = e->shape_host + 3 * (size_t)w * (size_t)k;
        memcpy(o, m->rows[k], (size_t)w * sizeof(int));
        memcpy(o + w, m->rowsf[k], (size_t)w * sizeof(float));
        if (k > 0)
            memcpy(o + 2 * w, m->inv_src[k], (size_t)w * sizeof(float));
        else
            memset(o + 2 * w, 0, (size_t)w * sizeof(float));
    }
    const void *shape;
    if ((s = fv_mirror_fill(b, &e->shape, e->shape_host, words * sizeof(float), &shape, "the φ-mipmaps' shape", err)) != FV_OK) return s;
    memset(dm, 0, sizeof *dm);
    dm->levels = L, dm->w = w, dm->wrap = m->wrap;
    const float *base = shape;
    for (int k = 0; k < L; k++) {
        const float *o = base + 3 * (size_t)w * (size_t)k;
        dm->rows[k] = (const int *)o;
        dm->rowsf[k] = o + w;
        dm->inv_src[k] = k > 0 ? o + 2 * w : NULL;
        dm->img[k] = e->mip[k].p;
    }
    return FV_OK;
}

/* ---- a frame ---- */

/* The frame's sizes and tables agree with one another (what the kernels' indices rely on). */
static fv_status check_frame(const fv_vp_device_frame *f, fv_error *err)
{
    const fv_kvp_space *sp = &f->trace.space;
    const char *bad = NULL;
    if (sp->gw < 1 || sp->gh < 1 || sp->sw < 1 || sp->sh < 1) bad = "an empty grid or screen";
    else if (f->map.space.gw != sp->gw || f->map.space.gh != sp->gh || f->map.space.sw != sp->sw || f->map.space.sh != sp->sh)
        bad = "the map's space is not the trace's";
    else if (f->map.col_h != f->trace.col_h) bad = "the map's column heights are not the trace's";
    else if (f->map.nlut < 3 || f->radial.n != f->map.nlut || f->radial.step * f->map.inv_step != 1.0f) bad = "no radial table, or not the map's";
    else if (f->map.identity && (sp->gw != sp->sw || sp->gh != sp->sh)) bad = "an identity map on a grid not the screen's size";
    else if (!f->map.identity && !f->mips) bad = "a map without φ-mipmaps";
    else if (f->history && (f->reproject.space.gw != sp->gw || f->reproject.space.gh != sp->gh || f->reproject.nlut != f->map.nlut))
        bad = "the reprojection's space or table is not the frame's";
    else if (f->trace_skip && !f->onscreen) bad = "a trace that skips the cells off screen without the on-screen mask";
    else if (f->history && !f->denoise) bad = "a history without the denoiser";
    else if (f->denoise && (f->grid.w != sp->gw || f->grid.h != sp->gh || f->grid.col_h != f->trace.col_h)) bad = "the denoiser's grid is not the trace's";
    else if (f->blur && (!f->map.sigma || f->blur_table.w != sp->sw || f->blur_table.h != sp->sh || f->blur_table.nq < 1 ||
                         !f->blur_table.off || !f->blur_table.k || f->blur_nk < 1))
        bad = "a blur without its table or sigma";
    return bad ? fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar device frame: %s", bad) : FV_OK;
}

/* The denoiser's launches (after the reprojection): filter/ksvgf.h's steps over the grid in place. */
static fv_status svgf_queue(fv_vp_device_eye *e, const fv_vp_device_frame *f, const int *dcol_h, const uint8_t *dmask, fv_error *err)
{
    fv_backend *b = e->d->b;
    dev_svgf *d = &e->svgf;
    fv_ksvgf *k = &d->k;
    k->g = f->grid;
    k->g.col_h = dcol_h;
    k->alpha_color = f->svgf.alpha_color, k->alpha_moments = f->svgf.alpha_moments;
    k->sigma_depth = f->svgf.sigma_depth, k->sigma_normal = f->svgf.sigma_normal, k->sigma_lum = f->svgf.sigma_lum;
    k->iterations = f->svgf.iterations;
    k->sq = fv_ksvgf_squarings(f->svgf.sigma_normal);
    /* as fv_svgf_set_periphery */
    k->periph_x = f->periph_x < 0 ? 0 : (f->periph_x > f->grid.w ? f->grid.w : f->periph_x);
    k->periph_passes = f->periph_passes < 0 ? 0 : f->periph_passes;
    /* the frame's inputs: the grid's buffers (SVGF demodulates by the reflectance) */
    k->color = e->g.color, k->albedo = e->g.reflectance, k->normal = e->g.normal, k->depth = e->g.depth;
    k->position = e->g.position, k->id = e->g.id;
    k->prev_coord = f->history ? e->prev_coord : NULL;
    k->sampled = f->trace.kill ? e->g.sampled : NULL;
    k->active = dmask;
    k->history = d->have_history && f->history;
    fv_status s = fv_svgf_kernels_queue(b, k, true, err);
    if (s != FV_OK) return s;
    d->have_history = true;
    return FV_OK;
}

/* Queues one eye's frame, marks from slot m0; nothing waits. *done false: the trace was cancelled
 * (portable) and nothing after it was queued. */
static fv_status queue_eye(fv_vp_device_eye *e, const fv_vp_device_frame *f, fv_film *film, int slot, int m0, bool *done, fv_error *err)
{
    fv_backend *b = e->d->b;
    const int gw = f->trace.space.gw, gh = f->trace.space.gh, sw = f->trace.space.sw, sh = f->trace.space.sh;
    const size_t n = (size_t)gw * (size_t)gh, ns = (size_t)sw * (size_t)sh;
    const bool fresh = f->fresh != 0;
    /* the film's buffers as the kernels write them; a display-only film (fv_film_set_display) then
     * has its colour converted on the device and read back as RGBA8 (fv_film_device_download_film) */
    const fv_film_views out = fv_film_views_of(film);
    const size_t rows_bytes = f->denoise ? 4 * (size_t)gh * 8 : 0, counts_bytes = FV_VP_COUNTS * sizeof(uint64_t);
    *done = true;

    /* What the frame needs on the device: buffers (kept), the host's per-size tables where they
     * changed, then the tables that follow the gaze, computed there. */
    const void *dcol_h_v = NULL, *doff = NULL, *dk = NULL;
    fv_kphi_mips dm;
    memset(&dm, 0, sizeof dm);
    fv_film_views dv;
    fv_status s;
    if ((f->trace.col_h && (s = fv_mirror_fill(b, &e->col_h, f->trace.col_h, (size_t)gw * sizeof(int), &dcol_h_v, "the column heights", err)) != FV_OK) ||
        (f->blur && ((s = fv_mirror_fill(b, &e->blur_off, f->blur_table.off, (size_t)f->blur_table.nq * sizeof(int), &doff, "the blur's kernels", err)) != FV_OK ||
                     (s = fv_mirror_fill(b, &e->blur_k, f->blur_table.k, f->blur_nk * sizeof(float), &dk, "the blur's kernels", err)) != FV_OK)) ||
        (s = grid_ensure(e, gw, gh, fresh, err)) != FV_OK ||
        (s = fv_vp_gaze_tables_queue(b, &e->tables, &f->map.space, &f->map.view, dcol_h_v, f->onscreen != 0, f->onscreen_reach, &f->radial, err)) != FV_OK ||
        (f->denoise && (s = svgf_ensure(e, gw, gh, fresh, err)) != FV_OK) ||
        (f->mips && (s = mips_ensure(e, f, fresh, &dm, err)) != FV_OK) ||
        (s = fv_buffer_ensure(b, &e->sigma, ns * sizeof(float), "the blur's sigma", err)) != FV_OK ||
        (f->blur && (s = fv_buffer_ensure(b, &e->blur_tmp, 3 * ns * sizeof(float), "the blur's image", err)) != FV_OK) ||
        (s = fv_buffer_ensure(b, &e->counts, counts_bytes, "the trace's counters", err)) != FV_OK ||
        /* every staging slot's now, so that no later frame allocates */
        (s = fv_pinned_ensure(b, &e->host[0], counts_bytes + rows_bytes, "the frame's counters", err)) != FV_OK ||
        (s = fv_pinned_ensure(b, &e->host[1], counts_bytes + rows_bytes, "the frame's counters", err)) != FV_OK ||
        (s = fv_film_device_views(b, &e->film, &out, ns, &dv, err)) != FV_OK ||
        (s = fv_backend_clear(b, e->counts.p, 0, counts_bytes, "the trace's counters", err)) != FV_OK)
        return s;
    const int *dcol_h = dcol_h_v;
    const uint8_t *dmask = fv_vp_gaze_tables_mask(&e->tables);

    /* 1. trace */
    fv_backend_mark(b, m0 + ST_TRACE);
    fv_vp_trace_args ta;
    ta.scene = *fv_scene_device_view(e->d->dscene);
    ta.f = f->trace;
    ta.f.col_h = dcol_h;
    ta.f.onscreen = f->trace_skip ? dmask : NULL;
    ta.g = e->g;
    if ((s = fv_backend_launch_progress(b, &fv_vp_trace_kernel, gw, gh, &ta, e->counts.p, f->progress.fn ? &f->progress : NULL, done, err)) != FV_OK)
        return s;
    if (!*done) return FV_OK;
    e->have_image = true;

    /* 2. the denoiser: the history's coordinates, then SVGF */
    fv_backend_mark(b, m0 + ST_DENOISE);
    if (f->denoise && f->history) {
        fv_vp_reproject_args ra;
        ra.f = f->reproject;
        ra.f.g = e->g;
        ra.f.onscreen = dmask;
        ra.f.prev_lut = fv_vp_gaze_tables_prev_lut(&e->tables);
        ra.prev_coord = e->prev_coord;
        if (!ra.f.prev_lut && ra.f.space.kind != FV_KVP_CARTESIAN)
            return fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar device frame: a history without the previous frame's radial table");
        if ((s = fv_backend_launch(b, &fv_vp_reproject_kernel, (int)n, 1, &ra, NULL, err)) != FV_OK) return s;
    }
    if (f->denoise && (s = svgf_queue(e, f, dcol_h, dmask, err)) != FV_OK) return s;

    /* 3. φ-mipmaps: level 0 the grid's colour, then each level from the one before */
    fv_backend_mark(b, m0 + ST_MIP);
    if (f->mips) {
        if ((s = fv_backend_copy(b, dm.img[0], e->g.color, 3 * n * sizeof(float), "the φ-mipmaps' level 0", err)) != FV_OK) return s;
        for (int k = 1; k < dm.levels; k++) {
            const fv_vp_halve_args ha = {dm, k};
            if ((s = fv_backend_launch(b, &fv_vp_halve_kernel, dm.w, f->mip_h[k], &ha, NULL, err)) != FV_OK) return s;
        }
    }

    /* 4. map, with this frame's radial table */
    fv_backend_mark(b, m0 + ST_MAP);
    fv_vp_map_args ma;
    ma.mf = f->map;
    ma.mf.col_h = dcol_h;
    ma.mf.g = e->g;
    ma.mf.mips = dm;
    ma.mf.lut = fv_vp_gaze_tables_lut(&e->tables);
    ma.mf.sigma = f->blur ? e->sigma.p : NULL;
    ma.out = dv;
    if ((s = fv_backend_launch(b, &fv_vp_map_kernel, sw, sh, &ma, NULL, err)) != FV_OK) return s;

    /* 5. the foveated blur, in place in the film's colour through the scratch image */
    fv_backend_mark(b, m0 + ST_BLUR);
    if (f->blur) {
        fv_kblur_table bt = f->blur_table;
        bt.off = doff;
        bt.k = dk;
        const fv_blur_args h = {bt, e->sigma.p, dv.color, e->blur_tmp.p}, v = {bt, e->sigma.p, e->blur_tmp.p, dv.color};
        if ((s = fv_backend_launch(b, &fv_blur_h_kernel, sw, sh, &h, NULL, err)) != FV_OK ||
            (s = fv_backend_launch(b, &fv_blur_v_kernel, sw, sh, &v, NULL, err)) != FV_OK)
            return s;
    }
    fv_backend_mark(b, m0 + ST_COUNT);
    fv_vp_gaze_tables_advance(&e->tables); /* the next frame's reprojection reads this frame's table */

    /* the read-back, into pinned memory */
    char *host = e->host[slot].p;
    if ((s = fv_film_device_download_film(b, &e->film, slot, film, err)) != FV_OK ||
        (s = fv_backend_download(b, host, e->counts.p, counts_bytes, "the trace's counters", err)) != FV_OK ||
        (f->denoise && (s = fv_backend_download(b, host + counts_bytes, (char *)e->svgf.mem.p + e->svgf.rows_at, rows_bytes, "SVGF's counters", err)) != FV_OK))
        return s;
    return FV_OK;
}

/* One eye's result from what was read back (after the wait). */
static void eye_result(fv_vp_device_eye *e, const fv_vp_device_frame *f, fv_film *film, int slot, int m0, fv_vp_device_result *r)
{
    fv_backend *b = e->d->b;
    fv_film_device_deliver_film(b, &e->film, slot, film);
    uint64_t c[FV_VP_COUNTS];
    memcpy(c, e->host[slot].p, sizeof c);
    r->rays = c[FV_VP_COUNT_RAYS], r->paths = c[FV_VP_COUNT_PATHS], r->nan_paths = c[FV_VP_COUNT_NAN];
    if (f->denoise) {
        const size_t h = (size_t)f->grid.h;
        const char *rows = (const char *)e->host[slot].p + sizeof c;
        double mean_history;
        fv_ksvgf_sum_rows((int)h, (const long *)rows, (const long *)(rows + h * 8), (const long *)(rows + 2 * h * 8), (const double *)(rows + 3 * h * 8),
                          &r->history_fraction, &mean_history);
    }
    for (int i = 0; i < ST_COUNT; i++) r->stage_ms[i] = fv_backend_elapsed_ms(b, m0 + i, m0 + i + 1);
    r->kernel_ms = fv_backend_elapsed_ms(b, m0 + ST_TRACE, m0 + ST_COUNT);
}

/* The marks of eye e of the frame in staging slot `slot`. */
static int marks_of(int slot, int e) { return (slot * 2 + e) * MARKS_PER_EYE; }

fv_status fv_vp_device_submit(fv_vp_device *d, fv_vp_device_eye *const *eye, int eyes, const fv_vp_device_frame *f, fv_film *const *films,
                              fv_vp_device_result *res, fv_backend_calls *calls, bool *in_flight, fv_error *err)
{
    *in_flight = false;
    memset(calls, 0, sizeof *calls);
    if (eyes < 1 || eyes > 2) return fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar device frames for %d eyes", eyes);
    if (eyes == 2 && eye[0] == eye[1]) return fv_error_set(err, FV_ERR_INTERNAL, "a stereo pair's eyes share their buffers");
    if (d->in_flight >= FV_FILM_DEVICE_SLOTS) return fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar: %d frames in flight already", d->in_flight);
    fv_status s;
    for (int e = 0; e < eyes; e++) {
        memset(&res[e], 0, sizeof res[e]);
        if (eye[e]->d != d) return fv_error_set(err, FV_ERR_INTERNAL, "an eye of another Visual-Polar device");
        if ((s = check_frame(&f[e], err)) != FV_OK) return s;
    }
    fv_backend *b = d->b;
    const int slot = (d->head + d->in_flight) % FV_FILM_DEVICE_SLOTS;
    fv_backend_calls before;
    fv_backend_calls_get(b, &before);
    fv_backend_set_threads(b, f[0].threads);
    /* the flat scene at the frame's time (moving instances): the device copies what moved */
    if ((s = fv_scene_export_update(d->flat, d->scene, err)) != FV_OK ||
        (s = fv_scene_device_update(d->dscene, fv_scene_export_view(d->flat), err)) != FV_OK)
        return s;
    bool done = true, queued[2] = {false, false};
    for (int e = 0; e < eyes && s == FV_OK && done; e++)
        if ((s = queue_eye(eye[e], &f[e], films[e], slot, marks_of(slot, e), &done, err)) == FV_OK) queued[e] = done;
    if (s == FV_OK && done) {
        /* every eye queued whole: in flight, collected later */
        fv_backend_fence(b, slot);
        flight *fl = &d->flight[slot];
        fl->eyes = eyes;
        for (int e = 0; e < eyes; e++) fl->eye[e] = eye[e], fl->f[e] = f[e], fl->film[e] = films[e];
        d->in_flight++;
        *in_flight = true;
    } else {
        /* a failure or a cancel: waited for now, nothing of this frame left in flight (the wait
         * even after a failure: nothing queued may write into a film the caller has back) */
        const fv_status sw = fv_backend_wait(b, "the Visual-Polar frame", s == FV_OK ? err : NULL);
        if (s == FV_OK) s = sw;
        /* an eye queued whole has run (its device history moved on), even when the next one's
         * trace was cancelled */
        for (int e = 0; e < eyes && s == FV_OK; e++)
            if (queued[e]) {
                eye_result(eye[e], &f[e], films[e], slot, marks_of(slot, e), &res[e]);
                res[e].done = true;
            }
    }
    fv_backend_calls after;
    fv_backend_calls_get(b, &after);
    fv_backend_calls_diff(&after, &before, calls);
    return s;
}

fv_status fv_vp_device_collect(fv_vp_device *d, fv_vp_device_result *res, fv_backend_calls *calls, fv_error *err)
{
    memset(calls, 0, sizeof *calls);
    if (!d->in_flight) return fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar: no frame in flight");
    fv_backend *b = d->b;
    const int slot = d->head;
    const flight *fl = &d->flight[slot];
    d->head = (d->head + 1) % FV_FILM_DEVICE_SLOTS;
    d->in_flight--;
    fv_backend_calls before, after;
    fv_backend_calls_get(b, &before);
    const fv_status s = fv_backend_wait_fence(b, slot, "the Visual-Polar frame", err);
    fv_backend_calls_get(b, &after);
    fv_backend_calls_diff(&after, &before, calls);
    for (int e = 0; e < fl->eyes; e++) {
        memset(&res[e], 0, sizeof res[e]);
        if (s != FV_OK) continue;
        eye_result(fl->eye[e], &fl->f[e], fl->film[e], slot, marks_of(slot, e), &res[e]);
        res[e].done = true;
    }
    return s;
}

int fv_vp_device_in_flight(const fv_vp_device *d) { return d->in_flight; }
