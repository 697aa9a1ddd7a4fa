/* fovea — the Visual-Polar frame pipeline for one eye (see vp_pipeline.h).
 *
 * Reprojection for the denoiser's history (Sec. 3.3, "Temporal accumulation"): each sample's first
 * hit is projected into the previous frame's camera and the resulting screen position is mapped
 * into the previous frame's sample space (the previous gaze's view), where SVGF fetches its history
 * bilinearly. Static geometry reprojects exactly; a moving object's samples fail the denoiser's
 * position test and restart their history (no motion vectors).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/stage_time.h"
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/blur.h"
#include "filter/phi_mips.h"
#include "technique/vpolar/kvp_reproject.h"
#include "technique/vpolar/kvp_tables.h"
#include "device/calls_report.h"
#include "technique/vpolar/vp_device.h"
#include "technique/vpolar/vp_pipeline.h"

#define MAX_MIP_LEVELS 12
#define LUT_STEP 0.5f /* pixels between the entries of the per-frame radial tables */
#define MASK_REACH_PX 6.0f /* see the off-screen mask in fv_vp_pipeline_render */
#define MAP_SPAN 64        /* screen pixels of a row the map stage takes at a time (at most) */

enum { COORDS_NONE = 0, COORDS_STORE, COORDS_READ };

struct fv_vp_pipeline {
    const fv_scene *scene;
    fv_vp_opts o;
    fv_vp_device *dev;      /* NULL: the CPU's own stages; else the method's device (not owned) */
    fv_vp_device_eye *deye; /* this pipeline's buffers and history there */
    /* its frames submitted on the device and not yet collected (fv_vp_pipeline_submit), oldest
     * first from pend_head: where their stats go and what they are reported with */
    struct pending {
        fv_stats *stats;
        double grid_samples, pixels;
    } pend[2];
    int pend_head, pend_count;
    bool fresh;             /* setup made a new grid: the device's next frame starts it afresh */
    int sw, sh;             /* screen size the buffers are for, 0 before the first frame */
    double ppd;
    fv_space *space;
    fv_svgf *svgf;
    fv_phi_mips *mips;
    fv_vp_gbuf g;
    float *prev_coord;
    float *sigma;           /* per screen pixel */
    uint8_t *onscreen;      /* polar spaces on the CPU: per grid cell, fv_space_onscreen_mask at (mask_gx, mask_gy)
                               (a device computes its own: vp_device.h) */
    float mask_gx, mask_gy; /* the gaze onscreen was computed for (NaN: not yet) */
    float *lut;             /* the CPU's, per frame, per radius step: column X, mip level, blur sigma
                               (a device computes its own: vp_device.h) */
    int nlut;
    float lut_gx, lut_gy;   /* the gaze lut was built for (NaN: none) */
    /* The map stage's per-pixel coordinates (X, V, mip level; the blur's sigma is p->sigma) kept
     * while the gaze stays: stored on the second frame at the same gaze, read from the third on. */
    float *coords;          /* 3 per screen pixel, allocated when first stored */
    float map_gx, map_gy;   /* the gaze of the last map stage (NaN: none) */
    int coords_state;       /* COORDS_NONE, _STORE (this frame writes them), _READ */
    uint32_t *perm;
    long nperm;
    int *blur_off;          /* a device's blur kernels for every gaze (fv_blur_table_fill; NULL: no blur, or the CPU) */
    float *blur_k;
    int blur_nq;
    size_t blur_nk;
    fv_kit_counters *counters; /* the trace's, kept from frame to frame (fv_kit_counters_reuse) */
    fv_scratch blur_room;      /* the foveated blur's temporaries, kept from frame to frame */
    bool have_prev;
    fv_camera_basis prev_cam;
    fv_space_view prev_view;
    bool have_image;
};

fv_status fv_vp_pipeline_create(const fv_scene *scene, const fv_vp_opts *o, fv_vp_device *dev, fv_vp_pipeline **out, fv_error *err)
{
    *out = NULL;
    fv_status s = fv_svgf_opts_validate(&o->svgf, err);
    if (s != FV_OK) return s;
    fv_vp_pipeline *p = calloc(1, sizeof *p);
    if (!p) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    p->scene = scene;
    p->o = *o;
    if (o->device != FV_DEVICE_CPU && !dev) s = fv_error_set(err, FV_ERR_INTERNAL, "a Visual-Polar pipeline on device %s without its device", fv_device_name(o->device));
    if (s == FV_OK && dev) {
        p->dev = dev;
        s = fv_vp_device_eye_create(dev, &p->deye, err);
    }
    if (s != FV_OK) {
        free(p);
        return s;
    }
    *out = p;
    return FV_OK;
}

static void free_buffers(fv_vp_pipeline *p)
{
    fv_space_destroy(p->space);
    fv_svgf_destroy(p->svgf);
    fv_phi_mips_destroy(p->mips);
    free(p->g.color), free(p->g.albedo), free(p->g.reflectance), free(p->g.normal), free(p->g.depth), free(p->g.position), free(p->g.id);
    free(p->g.sampled), free(p->prev_coord), free(p->sigma), free(p->perm), free(p->lut), free(p->onscreen);
    free(p->coords), free(p->blur_off), free(p->blur_k);
    p->onscreen = NULL, p->coords = NULL, p->blur_off = NULL, p->blur_k = NULL;
    p->map_gx = p->map_gy = NAN;
    p->lut_gx = p->lut_gy = NAN;
    p->coords_state = COORDS_NONE;
    memset(&p->g, 0, sizeof p->g);
    p->space = NULL, p->svgf = NULL, p->mips = NULL, p->prev_coord = NULL, p->sigma = NULL, p->perm = NULL, p->lut = NULL;
    p->sw = p->sh = 0;
    p->have_prev = p->have_image = false;
}

void fv_vp_pipeline_destroy(fv_vp_pipeline *p)
{
    if (!p) return;
    free_buffers(p);
    fv_kit_counters_destroy(p->counters);
    fv_scratch_free(&p->blur_room);
    fv_vp_device_eye_destroy(p->deye);
    free(p);
}

/* The blur's largest sigma in pixels (Sec. 3.5: 6.8 at 1280 pixels wide, scaled with the width). */
static double blur_sigma_px(const fv_vp_pipeline *p)
{
    return p->o.blur_sigma * (double)p->sw / 1280.0;
}

/* (Re)builds the space and every buffer for a sw x sh screen. */
static fv_status setup(fv_vp_pipeline *p, int sw, int sh, const fv_eye_model *eye, uint64_t seed, fv_error *err)
{
    free_buffers(p);
    p->ppd = fv_eye_px_per_deg(eye);
    fv_status s = fv_space_create(&p->o.space, sw, sh, p->ppd, &p->space, err);
    if (s != FV_OK) return s;
    const fv_grid *g = fv_space_grid(p->space);
    size_t n = (size_t)g->w * g->h, ns = (size_t)sw * sh;
    /* A device keeps the grid in its own memory (vp_device.h): the host's copy would be written once
     * here and never read (69 bytes a cell; some 300 MB for a stereo pair of cartesian-full at
     * 1440x1600). Its history coordinates and sigma are still allocated, as the frame's
     * description points to them, but never touched, so they cost no memory. */
    const bool host_grid = !p->dev;
    if (host_grid) {
        p->g.color = fv_alloc_array(n, 3 * sizeof(float));
        p->g.albedo = fv_alloc_array(n, 3 * sizeof(float));
        p->g.reflectance = fv_alloc_array(n, 3 * sizeof(float));
        p->g.normal = fv_alloc_array(n, 3 * sizeof(float));
        p->g.position = fv_alloc_array(n, 3 * sizeof(float));
        p->g.depth = fv_alloc_array(n, sizeof(float));
        p->g.id = fv_alloc_array(n, sizeof(uint32_t));
        p->g.sampled = fv_alloc_array(n, 1);
    }
    p->prev_coord = fv_alloc_array(n, 2 * sizeof(float));
    p->sigma = fv_alloc_array(ns, sizeof(float));
    /* The largest radius from any gaze is the diagonal. */
    p->nlut = (int)(sqrt((double)sw * sw + (double)sh * sh) / LUT_STEP) + 3;
    if (host_grid) p->lut = fv_alloc_array((size_t)p->nlut, 3 * sizeof(float));
    if ((host_grid && (!p->g.color || !p->g.albedo || !p->g.reflectance || !p->g.normal || !p->g.position || !p->g.depth || !p->g.id ||
                       !p->g.sampled || !p->lut)) ||
        !p->prev_coord || !p->sigma) {
        free_buffers(p);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d sample grid", g->w, g->h);
    }
    /* "No surface, not sampled" everywhere: the rows beyond a column's height keep it for good,
     * since the trace stage writes only the valid cells. */
    if (host_grid) {
        memset(p->g.color, 0, n * 3 * sizeof(float));
        memset(p->g.albedo, 0, n * 3 * sizeof(float));
        memset(p->g.reflectance, 0, n * 3 * sizeof(float));
        memset(p->g.normal, 0, n * 3 * sizeof(float));
        memset(p->g.position, 0, n * 3 * sizeof(float));
        memset(p->g.id, 0, n * sizeof(uint32_t));
        memset(p->g.sampled, 0, n);
        for (size_t i = 0; i < n; i++) p->g.depth[i] = INFINITY;
    }
    if (host_grid && fv_space_kind_of(p->space) != FV_SPACE_CARTESIAN) {
        if (!(p->onscreen = fv_alloc_array(n, 1))) {
            free_buffers(p);
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d sample grid", g->w, g->h);
        }
        p->mask_gx = p->mask_gy = NAN;
    }
    /* The denoiser: on the host for the CPU; a device keeps its buffers (vp_device.h). */
    if (p->o.denoise && !p->dev && (s = fv_svgf_create(g, &p->o.svgf, &p->svgf, err)) != FV_OK) {
        free_buffers(p);
        return s;
    }
    /* Only the polar spaces need mipmaps along φ; the Cartesian grid is only ever magnified. */
    int levels = fv_space_kind_of(p->space) == FV_SPACE_CARTESIAN ? 1 : MAX_MIP_LEVELS;
    if ((s = fv_phi_mips_create(g, levels, &p->mips, err)) != FV_OK) {
        free_buffers(p);
        return s;
    }
    if (p->o.order == FV_VP_ORDER_RANDOM) {
        p->perm = fv_vp_random_order(g, seed, &p->nperm);
        if (!p->perm) {
            free_buffers(p);
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        }
    }
    p->sw = sw;
    p->sh = sh;
    /* A device's blur kernels, up to the largest sigma any gaze gives: the profile never exceeds its
     * sigma_max (fv_blur_sigma_at), and a pixel's sigma interpolates two of the radial table's
     * entries, so it is at most their larger one plus rounding. A kernel does not depend on how many
     * there are, so the image is the one the kernels up to each gaze's own largest sigma give, and
     * the kernels are built, and copied, once per screen size rather than at every gaze. */
    if (p->dev && p->o.blur) {
        fv_blur_table_size((float)blur_sigma_px(p) * 1.001f, sw, sh, &p->blur_nq, &p->blur_nk);
        p->blur_off = fv_alloc_array((size_t)p->blur_nq, sizeof(int));
        p->blur_k = fv_alloc_array(p->blur_nk, sizeof(float));
        if (!p->blur_off || !p->blur_k) {
            free_buffers(p);
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the blur's kernels");
        }
        fv_blur_table_fill(sw, sh, p->blur_nq, p->blur_off, p->blur_k);
    }
    p->fresh = true;
    return FV_OK;
}

/* Where each sample's first hit was in the previous frame's sample space. */
typedef struct reproject_ctx {
    fv_vp_pipeline *p;
    bool lut;               /* p->lut is the previous view's radial table (polar spaces) */
} reproject_ctx;

#define REPROJECT_SPAN 256

/* Polar spaces take the column from the previous frame's radial table, as its map stage did
 * (issue 16: fv_space_from_screen's logarithm per sample was 2% of a frame), and the angle from
 * fv_space_turns, in a loop that vectorises; the samples that did not project get NaN. */
static void reproject_range(void *ctx, int64_t b, int64_t e, int thread)
{
    const reproject_ctx *rc = ctx;
    fv_vp_pipeline *p = rc->p;
    float px[REPROJECT_SPAN], py[REPROJECT_SPAN];
    uint8_t ok[REPROJECT_SPAN];
    const float inv_step = 1.0f / LUT_STEP, gx = p->prev_view.gx, gy = p->prev_view.gy;
    for (int64_t i0 = b; i0 < e; i0 += REPROJECT_SPAN) {
        const int n = e - i0 < REPROJECT_SPAN ? (int)(e - i0) : REPROJECT_SPAN;
        for (int k = 0; k < n; k++) {
            float qx, qy;
            ok[k] = 0, px[k] = gx, py[k] = gy;
            if (!fv_kvp_reproject_screen(&p->g, p->onscreen, &p->prev_cam, p->sw, p->sh, (long)(i0 + k), &qx, &qy)) continue;
            ok[k] = 1, px[k] = qx, py[k] = qy;
        }
        float *pc = &p->prev_coord[2 * i0];
        if (!rc->lut) {
            for (int k = 0; k < n; k++) {
                pc[2 * k] = pc[2 * k + 1] = NAN;
                if (ok[k]) fv_space_from_screen(&p->prev_view, px[k], py[k], &pc[2 * k], &pc[2 * k + 1], NULL);
            }
            continue;
        }
        #pragma omp simd
        for (int k = 0; k < n; k++) {
            float X, V;
            fv_kvp_table_coords(p->lut, p->nlut, inv_step, px[k] - gx, py[k] - gy, &X, &V, NULL, NULL);
            pc[2 * k] = ok[k] ? X : NAN;
            pc[2 * k + 1] = ok[k] ? V : NAN;
        }
    }
}

typedef struct map_ctx {
    fv_vp_pipeline *p;
    const fv_space_view *view;
    fv_film_views out;
    bool identity, polar;
    fv_kvp_map_frame mf;  /* the frame as the map kernels read it (technique/vpolar/kvp_map.h) */
} map_ctx;

/* Visual-Polar stretches its profile (and so its fovea) from the centre gaze's largest ρ to this
 * gaze's; the blur's fovea follows: screen distances are multiplied by this before they become
 * degrees of the blur's profile. */
static double blur_scale(const fv_vp_pipeline *p, const fv_space_view *view)
{
    if (!p->o.blur_follows_space) return 1.0;
    return 0.5 * sqrt((double)p->sw * p->sw + (double)p->sh * p->sh) / view->rho_max;
}

/* The screen distance from the gaze of eccentricity e_deg on the blur's profile (Sec. 3.5), which
 * stretches with the space. */
static double blur_profile_radius(const fv_vp_pipeline *p, const fv_space_view *view, double e_deg)
{
    return e_deg * p->ppd / blur_scale(p, view);
}

/* Everything the map stage needs that depends only on the distance from the gaze, tabulated for
 * this frame every LUT_STEP pixels: the column X, the φ-mip level (log2 of the rows one pixel spans
 * along φ) and the blur's sigma (Sec. 3.5). The per-pixel work is then a square root, an arc
 * tangent and two table lookups instead of Eq. 2's logarithm. The table's description (its
 * entries are technique/vpolar/kvp_tables.h's, computed by the CPU here and by the device frame's kernel);
 * table NULL. */
static void radial_frame(const fv_vp_pipeline *p, const fv_space_view *view, fv_kvp_radial *rf)
{
    memset(rf, 0, sizeof *rf);
    rf->space = *fv_space_kernel(p->space);
    rf->view = fv_space_kview(view);
    rf->step = LUT_STEP;
    rf->n = p->nlut;
    rf->blur = p->o.blur;
    rf->px_per_deg = p->ppd;
    rf->scale = blur_scale(p, view);
    rf->fovea_deg = p->o.blur_fovea_deg, rf->ramp_deg = p->o.blur_ramp_deg;
    rf->sigma_px = blur_sigma_px(p);
}

static void build_radial_lut(fv_vp_pipeline *p, const fv_space_view *view)
{
    fv_kvp_radial rf;
    radial_frame(p, view, &rf);
    rf.table = p->lut;
    p->lut_gx = view->gx, p->lut_gy = view->gy;
    for (int i = 0; i < p->nlut; i++) fv_kvp_radial_entry(&rf, i);
}

/* Row y's pixels [x0, x0 + n) on a polar space: column X, angle V and mip level from the radial
 * table, and the blur's sigma. One vectorised loop: a gather from the table and fv_space_turns,
 * no call per pixel. */
static void map_coords(const map_ctx *c, int64_t y, int x0, int n, float *X, float *V, float *level)
{
    const fv_vp_pipeline *p = c->p;
    float *kept = p->coords ? &p->coords[3 * ((size_t)y * p->sw + x0)] : NULL;
    if (p->coords_state == COORDS_READ) {
        for (int k = 0; k < n; k++) X[k] = kept[3 * k], V[k] = kept[3 * k + 1], level[k] = kept[3 * k + 2];
        return; /* p->sigma is as the frame that stored them left it */
    }
    const float inv_step = 1.0f / LUT_STEP, gx = c->view->gx, gy = c->view->gy;
    const float *lut = p->lut;
    float sigma[MAP_SPAN];
    const float dy = (float)y + 0.5f - gy;
    /* The table's three entries (column, mip level, blur sigma) read the same way. */
    #pragma omp simd
    for (int k = 0; k < n; k++) fv_kvp_table_coords(lut, p->nlut, inv_step, (float)(x0 + k) + 0.5f - gx, dy, &X[k], &V[k], &level[k], &sigma[k]);
    if (p->o.blur) memcpy(&p->sigma[(size_t)y * p->sw + x0], sigma, (size_t)n * sizeof(float));
    if (p->coords_state == COORDS_STORE)
        for (int k = 0; k < n; k++) kept[3 * k] = X[k], kept[3 * k + 1] = V[k], kept[3 * k + 2] = level[k];
}

/* Screen pixel colours from the sample space (Sec. 3.4), the film's first-hit buffers from the
 * nearest sample, and the blur's sigma (Sec. 3.5), MAP_SPAN pixels of a row at a time: a polar
 * space's coordinates in one vectorised loop (or kept from the last frame), then each pixel's
 * output with the kernel's step. */
static void map_rows(void *ctx, int64_t b, int64_t e, int thread)
{
    map_ctx *c = ctx;
    fv_vp_pipeline *p = c->p;
    float X[MAP_SPAN], V[MAP_SPAN], level[MAP_SPAN];
    for (int64_t y = b; y < e; y++)
        for (int x0 = 0; x0 < p->sw; x0 += MAP_SPAN) {
            const int n = p->sw - x0 < MAP_SPAN ? p->sw - x0 : MAP_SPAN;
            if (c->polar)
                map_coords(c, y, x0, n, X, V, level);
            else
                for (int k = 0; k < n; k++) fv_kvp_map_coords(&c->mf, x0 + k, (int)y, &X[k], &V[k], &level[k]);
            for (int k = 0; k < n; k++) fv_kvp_map_out(&c->mf, (size_t)y * p->sw + x0 + k, X[k], V[k], level[k], &c->out);
        }
}

/* The map stage's frame for the kernels. */
static void map_frame(const fv_vp_pipeline *p, const fv_space_view *view, bool identity, fv_kvp_map_frame *mf)
{
    memset(mf, 0, sizeof *mf);
    mf->space = *fv_space_kernel(p->space);
    mf->view = fv_space_kview(view);
    mf->col_h = fv_space_grid(p->space)->col_h;
    mf->g = p->g;
    fv_phi_mips_kernel(p->mips, &mf->mips);
    mf->lut = p->lut;
    mf->nlut = p->nlut;
    mf->inv_step = 1.0f / LUT_STEP;
    mf->polar = fv_space_kind_of(p->space) != FV_SPACE_CARTESIAN;
    mf->identity = identity;
    mf->sigma = p->o.blur ? p->sigma : NULL;
}

/* SVGF's periphery (fv_svgf_set_periphery): with the blur and fewer passes there, the columns
 * wholly beyond periphery_deg (by default where the blur reaches its full sigma). False: every pass
 * everywhere (*x_from and *passes untouched). */
static bool periphery(const fv_vp_pipeline *p, const fv_space_view *view, int *x_from, int *passes)
{
    if (!(p->o.blur && p->o.periphery_passes < p->o.svgf.iterations && fv_space_kind_of(p->space) != FV_SPACE_CARTESIAN)) return false;
    float X, V;
    fv_space_from_screen(view, view->gx + (float)blur_profile_radius(p, view, p->o.periphery_deg), view->gy, &X, &V, NULL);
    *x_from = (int)ceilf(X);
    *passes = p->o.periphery_passes;
    return true;
}

/* The trace stage's job for this frame (its progress and counters are the caller's). */
static void trace_job(const fv_vp_pipeline *p, const fv_frame *frame, const fv_camera_basis *basis, const fv_space_view *view,
                      fv_vp_trace_job *job)
{
    memset(job, 0, sizeof *job);
    job->scene = p->scene;
    job->pt = p->o.pt;
    job->cam = *basis;
    job->view = *view;
    job->screen_w = p->sw;
    job->screen_h = p->sh;
    job->order = p->o.order;
    job->perm = p->perm;
    job->nperm = p->nperm;
    job->skip_offscreen = p->o.skip_offscreen;
    job->onscreen = p->onscreen;
    job->kill = p->o.kill;
    job->kill_e0 = p->o.kill_e0, job->kill_e1 = p->o.kill_e1, job->kill_p = p->o.kill_p;
    job->px_per_deg = p->ppd;
    job->frame = frame;
}

/* The previous frame's reprojection into its grid, as the kernels read it (its radial table p->lut,
 * still the previous view's). */
static void reproject_frame(const fv_vp_pipeline *p, fv_kvp_reproject_frame *rf)
{
    memset(rf, 0, sizeof *rf);
    rf->space = *fv_space_kernel(p->space);
    rf->g = p->g;
    rf->onscreen = p->onscreen;
    rf->prev_cam = p->prev_cam;
    rf->prev_view = fv_space_kview(&p->prev_view);
    rf->prev_lut = p->lut;
    rf->nlut = p->nlut;
    rf->inv_step = 1.0f / LUT_STEP;
}

/* A frame on a device (vp_device.h), as the host prepared it (the film goes to the device frame as
 * it is: a display-only one is read back as RGBA8). */
typedef struct device_frame {
    fv_vp_device_frame f;
} device_frame;

/* A frame on the device: the host describes it (the view, the radial table's and the on-screen
 * mask's parameters; per screen size the blur's kernels) and receives the film and the counts; the
 * tables that follow the gaze are computed there, and the grid, the denoiser's history
 * coordinates, SVGF's buffers and history and the mipmaps stay there (the host keeps no copy of the
 * grid: setup). device_prepare builds the frame,
 * fv_vp_device_frames renders it (with the other eye's, for a stereo pair), device_finish takes its
 * result. The stage times are the device's (the backend's marks). */
static fv_status device_prepare(fv_vp_pipeline *p, const fv_frame *frame, fv_stats *stats, const fv_vp_trace_job *job,
                                const fv_space_view *view, device_frame *w, fv_error *err)
{
    memset(w, 0, sizeof *w);
    const fv_grid *g = fv_space_grid(p->space);
    const bool polar = fv_space_kind_of(p->space) != FV_SPACE_CARTESIAN;
    fv_vp_device_frame f;
    memset(&f, 0, sizeof f);
    f.fresh = p->fresh;
    f.threads = frame->threads;
    f.progress = (fv_launch_progress){fv_kit_progress_fn, job->progress};
    /* the tables that follow the gaze, computed on the device (its trace and reprojection read
     * its own mask: the host has none) */
    f.onscreen = polar;
    f.trace_skip = polar && p->o.skip_offscreen;
    f.onscreen_reach = MASK_REACH_PX;
    radial_frame(p, view, &f.radial);
    fv_vp_trace_kframe(job, &f.trace);
    if (p->o.denoise) {
        f.denoise = 1;
        f.grid = *g;
        f.svgf = p->o.svgf;
        f.periph_x = g->w, f.periph_passes = p->o.svgf.iterations;
        periphery(p, view, &f.periph_x, &f.periph_passes);
        /* The previous frame mapped with its view's radial table, which the device keeps. */
        f.history = p->have_prev && frame->prev_camera != NULL;
        if (f.history) reproject_frame(p, &f.reproject);
    }
    const bool identity = !polar && g->w == p->sw && g->h == p->sh;
    f.mips = !identity;
    if (f.mips) {
        fv_phi_mips_kernel(p->mips, &f.mip_shape);
        for (int k = 0; k < f.mip_shape.levels; k++) f.mip_h[k] = fv_phi_mips_grid(p->mips, k)->h;
    }
    /* the map: a device recomputes the coordinates every frame */
    p->coords_state = COORDS_NONE;
    p->map_gx = view->gx, p->map_gy = view->gy;
    fv_stats_add_count(stats, "map_reused", 0.0);
    map_frame(p, view, identity, &f.map);
    if (p->o.blur) {
        f.blur = 1;
        f.blur_table = (fv_kblur_table){p->sw, p->sh, (p->sw > p->sh ? p->sw : p->sh) - 1, p->blur_nq, p->blur_off, p->blur_k};
        f.blur_nk = p->blur_nk;
    }
    w->f = f;
    return FV_OK;
}

/* A device frame's results as stats, the pipeline's figures (grid samples, screen pixels) those it
 * was submitted with. */
static void device_stats(fv_stats *stats, const fv_vp_device_result *res, double grid_samples, double pixels, bool denoise, bool cuda)
{
    const fv_vp_device_result r = *res;
    static const char *const stage[5] = {"trace", "denoise", "mip", "map", "blur"};
    for (int i = 0; i < 5; i++) fv_stats_add_ms(stats, stage[i], r.stage_ms[i]);
    if (cuda) fv_stats_add_ms(stats, "kernel", r.kernel_ms);
    fv_stats_add_count(stats, "rays", (double)r.rays);
    fv_stats_add_count(stats, "samples", (double)r.paths);
    fv_stats_add_count(stats, "grid_samples", grid_samples);
    fv_stats_add_count(stats, "sample_share", (double)r.paths / pixels);
    fv_stats_add_count(stats, "mrays_per_s", r.stage_ms[0] > 0.0 ? (double)r.rays / r.stage_ms[0] / 1000.0 : 0.0);
    fv_stats_add_count(stats, "nan_samples", (double)r.nan_paths);
    if (denoise) fv_stats_add_count(stats, "history_fraction", r.history_fraction);
}

/* What the pipeline keeps of a frame the device ran (or will run: it is queued whole), which the
 * next frame's preparation reads. */
static void device_state(fv_vp_pipeline *p, const fv_vp_trace_job *job, const fv_space_view *view)
{
    p->fresh = false;
    p->prev_cam = job->cam;
    p->prev_view = *view;
    p->have_prev = true;
    /* the sample-space image where the host can read it (portable; show= is refused on cuda) */
    p->have_image = fv_vp_device_eye_image(p->deye) != NULL;
}

static fv_status device_finish(fv_vp_pipeline *p, const fv_frame *frame, fv_stats *stats, const fv_vp_trace_job *job, const fv_space_view *view,
                               const fv_vp_device_result *res, fv_kit_progress *prog, fv_error *err)
{
    device_stats(stats, res, (double)fv_space_sample_count(p->space), (double)p->sw * p->sh, p->o.denoise,
                 fv_vp_device_kind(p->dev) == FV_DEVICE_CUDA);
    device_state(p, job, view);
    fv_kit_phase(prog, frame, 0.8, 0.2);
    return fv_kit_phase_end(prog, err);
}

/* What a frame of one eye starts from, whichever way it is rendered: the camera, the sample
 * space's view at the gaze, the trace's job and the frame's progress (the job points to it). */
typedef struct eye_frame {
    fv_camera_basis basis;
    fv_space_view view;
    fv_vp_trace_job job;
    fv_kit_progress prog;
} eye_frame;

/* Sets up p for the frame's screen (buffers rebuilt when its size changed) and fills ef. */
static fv_status begin_frame(fv_vp_pipeline *p, const fv_frame *frame, fv_film *film, eye_frame *ef, fv_error *err)
{
    const fv_camera *cam = frame->camera;
    fv_status s = fv_frame_camera(cam, film, &ef->basis, err);
    if (s != FV_OK) return s;
    fv_eye_model def;
    const fv_eye_model *em = fv_frame_eye_model(frame, cam->width, cam->height, &def);
    if (p->sw != cam->width || p->sh != cam->height) {
        if ((s = setup(p, cam->width, cam->height, em, frame->seed, err)) != FV_OK) return s;
    }
    ef->view = fv_space_view_at(p->space, frame->gaze);

    /* The cells of a polar grid that no screen pixel can see (its corners reach beyond the screen
     * wherever the gaze is): the trace skips them with offscreen=skip, the denoiser always (they
     * would only cost time and pull the edge's samples towards values nobody sees). The reach
     * covers the map stage's trilinear φ-mip lookup (two levels, one texel each way, a level's
     * texel about one pixel along φ). Kept while the gaze stays. A device computes its own (its
     * pipeline has no host mask: vp_device.h). */
    if (p->onscreen && !(ef->view.gx == p->mask_gx && ef->view.gy == p->mask_gy)) {
        fv_space_onscreen_mask(&ef->view, MASK_REACH_PX, p->onscreen);
        p->mask_gx = ef->view.gx, p->mask_gy = ef->view.gy;
    }

    trace_job(p, frame, &ef->basis, &ef->view, &ef->job);
    /* Progress: the trace is most of a frame; the filters report at their end. */
    memset(&ef->prog, 0, sizeof ef->prog);
    fv_kit_phase(&ef->prog, frame, 0.0, 0.8);
    ef->job.progress = &ef->prog;
    return FV_OK;
}

/* `eyes` frames (1, or a stereo pair: a pipeline, frame, film and eye_frame each, the pipelines on
 * one device) queued on the device with their read-back and no host wait (*in_flight true;
 * device_collect delivers them); each eye's film, counters and history as if it were rendered
 * alone, eye 0's stats added before eye 1's. The pipelines' state moves on now, as the next
 * frame's preparation needs it. A cancel (portable) or a failure is waited for at once: not in
 * flight, every eye that ran takes its result. */
static fv_status device_submit(fv_vp_pipeline *const *p, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, eye_frame *ef,
                               bool *in_flight, fv_error *err)
{
    *in_flight = false;
    device_frame w[2];
    memset(w, 0, sizeof w);
    fv_status s = FV_OK;
    for (int e = 0; e < eyes && s == FV_OK; e++) s = device_prepare(p[e], &frames[e], stats, &ef[e].job, &ef[e].view, &w[e], err);
    fv_vp_device_frame f[2];
    fv_vp_device_result r[2];
    fv_vp_device_eye *eye[2] = {NULL, NULL};
    fv_backend_calls calls;
    memset(&calls, 0, sizeof calls);
    memset(f, 0, sizeof f);
    for (int e = 0; e < eyes; e++) f[e] = w[e].f, eye[e] = p[e]->deye;
    if (s == FV_OK) s = fv_vp_device_submit(p[0]->dev, eye, eyes, f, films, r, &calls, in_flight, err);
    if (s != FV_OK) return s;
    const bool cuda = fv_vp_device_kind(p[0]->dev) == FV_DEVICE_CUDA;
    /* what the submit asked of the runtime, with eye 0's figures */
    const fv_backend_calls none = {0};
    if (cuda) fv_backend_calls_report(stats, &none, &calls);
    if (*in_flight) {
        for (int e = 0; e < eyes; e++) {
            device_state(p[e], &ef[e].job, &ef[e].view);
            struct pending *q = &p[e]->pend[(p[e]->pend_head + p[e]->pend_count++) % 2];
            *q = (struct pending){stats, (double)fv_space_sample_count(p[e]->space), (double)p[e]->sw * p[e]->sh};
            /* the frame's progress ends here (it is reported within the submit only); a cancel
             * asked now is the registry's to act on: it collects the frame */
            fv_kit_phase(&ef[e].prog, &frames[e], 0.8, 0.2);
            fv_error ignored;
            (void)fv_kit_phase_end(&ef[e].prog, &ignored);
        }
        return FV_OK;
    }
    if (cuda) fv_stats_add_count(stats, "host_syncs", 1.0);
    /* Every eye the device ran takes its result and history, even after a later eye's trace was
     * cancelled (portable): the device's history has moved on for it. A cancelled eye's history
     * is left as it was. */
    for (int e = 0; e < eyes; e++) {
        if (!r[e].done) {
            if (s == FV_OK) s = fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
            continue;
        }
        const fv_status se = device_finish(p[e], &frames[e], stats, &ef[e].job, &ef[e].view, &r[e], &ef[e].prog, s == FV_OK ? err : NULL);
        if (s == FV_OK) s = se;
    }
    return s;
}

/* The oldest frame the device has in flight, its eyes on p[0 .. eyes-1]: waited for, delivered,
 * its stats added to those it was submitted with. */
static fv_status device_collect(fv_vp_pipeline *const *p, int eyes, fv_error *err)
{
    fv_vp_device_result r[2];
    fv_backend_calls calls;
    const fv_status s = fv_vp_device_collect(p[0]->dev, r, &calls, err);
    struct pending q[2];
    for (int e = 0; e < eyes; e++) {
        q[e] = p[e]->pend[p[e]->pend_head];
        p[e]->pend_head = (p[e]->pend_head + 1) % 2;
        p[e]->pend_count--;
    }
    if (s != FV_OK) return s;
    const bool cuda = fv_vp_device_kind(p[0]->dev) == FV_DEVICE_CUDA;
    if (cuda) {
        const fv_backend_calls none = {0};
        fv_stats_add_count(q[0].stats, "host_syncs", 1.0);
        fv_backend_calls_report(q[0].stats, &none, &calls);
    }
    for (int e = 0; e < eyes; e++) device_stats(q[e].stats, &r[e], q[e].grid_samples, q[e].pixels, p[e]->o.denoise, cuda);
    return FV_OK;
}

/* A device frame rendered now: submitted, then collected. */
static fv_status render_device(fv_vp_pipeline *const *p, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, eye_frame *ef,
                               fv_error *err)
{
    bool in_flight = false;
    const fv_status s = device_submit(p, eyes, frames, films, stats, ef, &in_flight, err);
    return s == FV_OK && in_flight ? device_collect(p, eyes, err) : s;
}

fv_status fv_vp_pipeline_render(fv_vp_pipeline *p, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    const fv_camera *prev_cam = frame->prev_camera;
    eye_frame ef;
    fv_status s = begin_frame(p, frame, film, &ef, err);
    if (s != FV_OK) return s;
    const fv_grid *g = fv_space_grid(p->space);
    const fv_camera_basis basis = ef.basis;
    fv_space_view view = ef.view;

    /* a device: the whole frame there (vp_device.h) */
    if (p->dev) return render_device(&p, 1, frame, &film, stats, &ef, err);

    /* 1. trace */
    ef.job.counters = fv_kit_counters_reuse(&p->counters);
    fv_vp_trace_result tr;
    fv_stage_clock t0 = fv_stage_clock_now();
    const bool traced = fv_vp_trace(&ef.job, &p->g, &tr);
    const fv_stage_clock t1 = fv_stage_clock_now();
    const double t_trace = t1.wall - t0.wall;
    fv_stage_add(stats, "trace", t0, t1);
    fv_stats_add_count(stats, "rays", (double)tr.rays);
    fv_stats_add_count(stats, "samples", (double)tr.paths);
    fv_stats_add_count(stats, "grid_samples", (double)fv_space_sample_count(p->space));
    fv_stats_add_count(stats, "sample_share", (double)tr.paths / ((double)p->sw * p->sh));
    fv_stats_add_count(stats, "mrays_per_s", t_trace > 0.0 ? (double)tr.rays / t_trace / 1000.0 : 0.0);
    fv_stats_add_count(stats, "nan_samples", (double)tr.nan_paths);
    if (!traced) return fv_error_set(err, FV_ERR_CANCELLED, "render cancelled"); /* history left as it was */

    /* 2. denoise in the sample space */
    t0 = fv_stage_clock_now();
    if (p->o.denoise) {
        bool hist = p->have_prev && prev_cam != NULL;
        if (hist) {
            /* The map stage of the previous frame built the table for its view (a gaze that
             * stayed kept it). */
            reproject_ctx rc = {p, fv_space_kind_of(p->space) != FV_SPACE_CARTESIAN && p->prev_view.gx == p->lut_gx &&
                                       p->prev_view.gy == p->lut_gy};
            fv_parallel_for((int64_t)g->w * g->h, 4096, frame->threads, reproject_range, &rc);
        }
        fv_svgf_frame fr = {p->g.color, p->g.reflectance, p->g.normal, p->g.depth, p->g.position, p->g.id,
                            hist ? p->prev_coord : NULL, p->o.kill ? p->g.sampled : NULL, p->onscreen};
        int x_from, passes;
        if (periphery(p, &view, &x_from, &passes)) fv_svgf_set_periphery(p->svgf, x_from, passes);
        fv_svgf_info info;
        s = fv_svgf_filter(p->svgf, &fr, frame->threads, &info, err);
        if (s != FV_OK) return s;
        fv_stats_add_count(stats, "history_fraction", info.history_fraction);
    }
    fv_stage_stop(stats, "denoise", t0);
    p->prev_cam = basis;
    p->prev_view = view;
    p->have_prev = true;
    p->have_image = true;

    /* 3. mipmaps along φ (Sec. 3.4) */
    bool identity = fv_space_kind_of(p->space) == FV_SPACE_CARTESIAN && g->w == p->sw && g->h == p->sh;
    t0 = fv_stage_clock_now();
    if (!identity) fv_phi_mips_build(p->mips, p->g.color, frame->threads);
    fv_stage_stop(stats, "mip", t0);

    /* 4. back to the screen */
    t0 = fv_stage_clock_now();
    map_ctx mc;
    mc.p = p;
    mc.view = &view;
    mc.out = fv_film_views_of(film);
    mc.identity = identity;
    mc.polar = fv_space_kind_of(p->space) != FV_SPACE_CARTESIAN;
    /* A gaze that stays (a still eye, a screenshot, the viewer) reuses the coordinates: from the
     * second frame at the same gaze they are kept (if the memory is there), from the third read.
     * A gaze that moves never pays for keeping them. */
    const bool still = view.gx == p->map_gx && view.gy == p->map_gy;
    p->coords_state = !mc.polar || !still ? COORDS_NONE : (p->coords_state == COORDS_NONE ? COORDS_STORE : COORDS_READ);
    if (p->coords_state == COORDS_STORE && !p->coords && !(p->coords = fv_alloc_array((size_t)p->sw * p->sh, 3 * sizeof(float))))
        p->coords_state = COORDS_NONE;
    p->map_gx = view.gx, p->map_gy = view.gy;
    if (p->coords_state != COORDS_READ) build_radial_lut(p, &view);
    fv_stats_add_count(stats, "map_reused", p->coords_state == COORDS_READ);
    map_frame(p, &view, identity, &mc.mf);
    fv_parallel_for(p->sh, 8, frame->threads, map_rows, &mc);
    fv_stage_stop(stats, "map", t0);

    /* 5. foveated blur (Sec. 3.5) */
    t0 = fv_stage_clock_now();
    if (p->o.blur) {
        s = fv_blur_variable_in(fv_film_color(film), p->sw, p->sh, p->sigma, frame->threads, &p->blur_room, err);
        if (s != FV_OK) return s;
    }
    fv_stage_stop(stats, "blur", t0);
    fv_kit_phase(&ef.prog, frame, 0.8, 0.2);
    return fv_kit_phase_end(&ef.prog, err);
}

fv_status fv_vp_pipeline_render_pair(fv_vp_pipeline *const *p, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    if (p[0] == p[1] || !p[0]->dev || p[0]->dev != p[1]->dev) {
        fv_status s = fv_vp_pipeline_render(p[0], &frames[0], films[0], stats, err);
        return s == FV_OK ? fv_vp_pipeline_render(p[1], &frames[1], films[1], stats, err) : s;
    }
    eye_frame ef[2];
    fv_status s;
    for (int e = 0; e < 2; e++)
        if ((s = begin_frame(p[e], &frames[e], films[e], &ef[e], err)) != FV_OK) return s;
    return render_device(p, 2, frames, films, stats, ef, err);
}

fv_status fv_vp_pipeline_submit(fv_vp_pipeline *const *p, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, bool *in_flight,
                                fv_error *err)
{
    *in_flight = false;
    /* the CPU's stages, and a pair not on one device, render now */
    if (!p[0]->dev || (eyes == 2 && (p[0] == p[1] || p[0]->dev != p[1]->dev)))
        return eyes == 2 ? fv_vp_pipeline_render_pair(p, frames, films, stats, err) : fv_vp_pipeline_render(p[0], frames, films[0], stats, err);
    eye_frame ef[2];
    fv_status s;
    for (int e = 0; e < eyes; e++)
        if ((s = begin_frame(p[e], &frames[e], films[e], &ef[e], err)) != FV_OK) return s;
    return device_submit(p, eyes, frames, films, stats, ef, in_flight, err);
}

fv_status fv_vp_pipeline_collect(fv_vp_pipeline *const *p, int eyes, fv_error *err)
{
    for (int e = 0; e < eyes; e++)
        if (!p[e]->dev || !p[e]->pend_count) return fv_error_set(err, FV_ERR_INTERNAL, "Visual-Polar: no frame in flight on this pipeline");
    return device_collect(p, eyes, err);
}

const fv_space *fv_vp_pipeline_space(const fv_vp_pipeline *p, fv_space_view *view, const float **image, double *px_per_deg)
{
    if (!p->have_image) return NULL;
    *view = p->prev_view; /* set by the frame just rendered */
    *image = p->dev ? fv_vp_device_eye_image(p->deye) : p->g.color;
    *px_per_deg = p->ppd;
    return p->space;
}
