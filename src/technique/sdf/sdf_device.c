/* fovea — the sphere-tracing family on the device backends (sdf_device.h): one frame, written once over
 * device/backend.h, that the portable backend runs at once on the CPU's threads and CUDA queues on
 * its stream; the kernels are declared once in technique/sdf/sdf_kernels.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "device/backend.h"
#include "device/calls_report.h"
#include "device/film_device.h"
#include "filter/blur.h"
#include "filter/blur_kernels.h"
#include "technique/kit.h"
#include "technique/sdf/sdf_device.h"
#include "technique/sdf/sdf_kernels.h"
#include "technique/sdf/world.h"

/* fipr's middle level of one eye, kept between frames (pyramid.h's fv_pyramid_history). */
typedef struct history {
    fv_buffer color, stamp;
    int sw, sh; /* the target grid it belongs to; 0: none yet */
} history;

/* fipr's pass 5: the sigma image, the horizontal pass's image, and the blur's kernels (filter/blur.h's
 * table, built on the host for the image's size and sigma, copied when it was rebuilt). */
typedef struct blur {
    fv_buffer sigma, tmp;
    fv_mirror off, k;
    int *host_off;
    float *host_k;
    int w, h, nq;
    size_t nk;
    float smax;
    bool sent; /* off and k hold the host table */
} blur;

struct fv_sdf_device {
    const fv_scene *scene;
    fv_sdf_opts o;
    fv_backend *b;
    /* The world, kept between frames: rebuilt (fv_sdf_world_refresh) only when the scene's time
     * changed and something in it moves, so a still scene builds it once, and copied to the device
     * only after a rebuild (and then only the arrays whose bytes changed). */
    fv_sdf_world world;
    bool world_ok;   /* world holds the scene at world_time */
    double world_time;
    bool moves;      /* an SDF object or a delta light is animated */
    bool world_sent; /* the mirrors hold world (cuda) */
    fv_mirror ops, objs, lights, mats;
    fv_film_device film[2];        /* per eye: a stereo pair is read back after both ran */
    fv_buffer counts;              /* the frame's counters (counts_of) */
    /* The frames in flight (fv_sdf_device_submit), oldest first from `head`, each in its staging
     * slot (device/film_device.h): what collect delivers, and its counters read back (pinned).
     * A pair of two sizes is rendered at submit (rendered: collect only hands it over). */
    struct flight {
        int eyes;
        bool rendered;
        fv_film *films[2];
        fv_stats *stats;
        double t0, blur_ms;
        fv_buffer counts_host;
    } flight[FV_FILM_DEVICE_SLOTS];
    int head, in_flight;
    /* ipr and fipr: the pyramid's buffers, the eyes' in turn (the queue orders eye 1's passes after
     * eye 0's), and fipr's per eye */
    fv_buffer depth[FV_PYRAMID_MAX_LEVELS], steps[FV_PYRAMID_MAX_LEVELS], need, edge, mask, vis;
    fv_buffer far_rows, far; /* pass 2's sky */
    history hist[2];
    blur blur;
};

fv_status fv_sdf_device_create(const fv_scene *scene, const fv_sdf_opts *o, fv_device device, fv_sdf_device **out, fv_error *err)
{
    *out = NULL;
    fv_sdf_device *d = calloc(1, sizeof *d);
    if (!d) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    d->scene = scene;
    d->o = *o;
    d->moves = fv_scene_lights_move(scene);
    for (int i = 0; i < fv_scene_object_count(scene) && !d->moves; i++)
        d->moves = fv_scene_object_kind(scene, i) == FV_OBJECT_SDF && fv_scene_object_dynamic(scene, i);
    fv_status s = fv_backend_create(device, &d->b, err);
    if (s != FV_OK) {
        free(d);
        return s;
    }
    *out = d;
    return FV_OK;
}

void fv_sdf_device_destroy(fv_sdf_device *d)
{
    if (!d) return;
    fv_backend *b = d->b;
    /* frames in flight are dropped: nothing queued may outlive the buffers it writes */
    if (d->in_flight) fv_backend_wait(b, "the sphere tracers' kernels", NULL);
    fv_mirror_release(b, &d->ops);
    fv_mirror_release(b, &d->objs);
    fv_mirror_release(b, &d->lights);
    fv_mirror_release(b, &d->mats);
    for (int e = 0; e < 2; e++) {
        fv_film_device_release(b, &d->film[e]);
        fv_buffer_release(b, &d->hist[e].color);
        fv_buffer_release(b, &d->hist[e].stamp);
    }
    fv_buffer_release(b, &d->counts);
    for (int k = 0; k < FV_FILM_DEVICE_SLOTS; k++) fv_pinned_release(b, &d->flight[k].counts_host);
    for (int i = 0; i < FV_PYRAMID_MAX_LEVELS; i++) {
        fv_buffer_release(b, &d->depth[i]);
        fv_buffer_release(b, &d->steps[i]);
    }
    fv_buffer_release(b, &d->need);
    fv_buffer_release(b, &d->edge);
    fv_buffer_release(b, &d->mask);
    fv_buffer_release(b, &d->vis);
    fv_buffer_release(b, &d->far_rows);
    fv_buffer_release(b, &d->far);
    fv_buffer_release(b, &d->blur.sigma);
    fv_buffer_release(b, &d->blur.tmp);
    fv_mirror_release(b, &d->blur.off);
    fv_mirror_release(b, &d->blur.k);
    free(d->blur.host_off);
    free(d->blur.host_k);
    fv_backend_destroy(b);
    fv_sdf_world_free(&d->world);
    free(d);
}

/* ---- what the frame's kernels read: the world, the pyramid, the histories, the blur's table ---- */

/* The world at the scene's current time: the kept one while it stands for it. */
static fv_status world_at_time(fv_sdf_device *d, fv_stats *stats, fv_error *err)
{
    const double t = fv_scene_time(d->scene);
    if (d->world_ok && (!d->moves || t == d->world_time)) return FV_OK;
    d->world_ok = false;
    d->world_sent = false;
    double t0 = fv_time_ms();
    fv_status s = fv_sdf_world_refresh(&d->world, d->scene, err);
    if (s != FV_OK) return s;
    d->world_ok = true;
    d->world_time = t;
    fv_stats_add_ms(stats, "scene", fv_time_ms() - t0);
    fv_stats_add_count(stats, "world_builds", 1.0);
    return FV_OK;
}

/* *dw: the world as the kernels read it. On portable the host's own arrays; elsewhere the mirrors,
 * filled after a rebuild (a mirror copies only when its bytes changed, through pinned memory). */
static fv_status world_on_device(fv_sdf_device *d, fv_ksdf_world *dw, fv_error *err)
{
    const fv_ksdf_world *w = &d->world.k;
    *dw = *w;
    if (fv_backend_device(d->b) == FV_DEVICE_PORTABLE) return FV_OK;
    const void *p;
    fv_status s;
    if (!d->world_sent) {
        if ((s = fv_mirror_fill(d->b, &d->ops, w->ops, (size_t)w->nops * sizeof(fv_sdf_op), &p, "the world", err)) != FV_OK ||
            (s = fv_mirror_fill(d->b, &d->objs, w->objs, (size_t)w->count * sizeof(fv_ksdf_object), &p, "the world", err)) != FV_OK ||
            (s = fv_mirror_fill(d->b, &d->lights, w->lights, (size_t)w->nlights * sizeof(fv_ksdf_light), &p, "the world", err)) != FV_OK ||
            (s = fv_mirror_fill(d->b, &d->mats, w->mats, (size_t)w->nmat * sizeof(fv_material), &p, "the world", err)) != FV_OK)
            return s;
        d->world_sent = true;
    }
    dw->ops = (const fv_sdf_op *)d->ops.dev.p;
    dw->objs = (const fv_ksdf_object *)d->objs.dev.p;
    dw->lights = (const fv_ksdf_light *)d->lights.dev.p;
    dw->mats = (const fv_material *)d->mats.dev.p;
    return FV_OK;
}

/* The pyramid of a w x h film at S samples per pixel along each axis: its shape in *k, its buffers
 * (grown, never shrunk) the device's; the pointers a method does not use stay NULL. */
static fv_status pyramid_on_device(fv_sdf_device *d, int w, int h, int S, fv_kpyr *k, fv_error *err)
{
    const fv_sdf_opts *o = &d->o;
    const bool fipr = o->method == FV_SDF_FIPR;
    memset(k, 0, sizeof *k);
    k->L = o->levels;
    k->S = S;
    k->w = w;
    k->h = h;
    k->sw = w * S;
    k->sh = h * S;
    k->min_filter = o->min_filter;
    fv_kpyr_levels(k->sw, k->sh, k->L, k->lv);
    const int L = k->L;
    fv_backend *b = d->b;
    fv_status s = FV_OK;
    for (int i = 0; i + 1 < L && s == FV_OK; i++) {
        const size_t n = (size_t)k->lv[i].w * k->lv[i].h;
        if ((s = fv_buffer_ensure(b, &d->depth[i], n * sizeof(float), "the pyramid", err)) == FV_OK)
            s = fv_buffer_ensure(b, &d->steps[i], n * sizeof(uint16_t), "the pyramid", err);
        k->depth[i] = d->depth[i].p;
        k->steps[i] = d->steps[i].p;
    }
    if (s != FV_OK || L < 2) return s;
    const size_t nmid = (size_t)k->lv[L - 2].w * k->lv[L - 2].h, ntip = (size_t)k->lv[0].w * k->lv[0].h;
    if (o->shadow_reuse) {
        if ((s = fv_buffer_ensure(b, &d->vis, nmid * sizeof(uint32_t), "the pyramid", err)) != FV_OK) return s;
        k->vis = d->vis.p;
    }
    if (!fipr) return FV_OK;
    if ((s = fv_buffer_ensure(b, &d->need, nmid, "fipr's refresh", err)) != FV_OK ||
        (s = fv_buffer_ensure(b, &d->edge, ntip, "fipr's edges", err)) != FV_OK ||
        (s = fv_buffer_ensure(b, &d->mask, (size_t)w * h, "fipr's mask", err)) != FV_OK ||
        (s = fv_buffer_ensure(b, &d->far_rows, (size_t)k->lv[0].h * sizeof(float), "fipr's edges", err)) != FV_OK ||
        (s = fv_buffer_ensure(b, &d->far, sizeof(float), "fipr's edges", err)) != FV_OK)
        return s;
    k->need = d->need.p;
    k->edge = d->edge.p;
    k->mask = d->mask.p;
    return FV_OK;
}

/* fipr's history of eye `eye` for pyramid k (a new size starts afresh: nothing shaded, as at a
 * sequence's first frame, index 0), pointed at by k. */
static fv_status history_on_device(fv_sdf_device *d, int eye, int index, fv_kpyr *k, fv_error *err)
{
    history *hs = &d->hist[eye];
    const size_t n = (size_t)k->lv[k->L - 2].w * k->lv[k->L - 2].h;
    fv_status s;
    if (hs->sw != k->sw || hs->sh != k->sh) {
        hs->sw = hs->sh = 0;
        if ((s = fv_buffer_ensure(d->b, &hs->color, 3 * n * sizeof(float), "fipr's history", err)) != FV_OK ||
            (s = fv_buffer_ensure(d->b, &hs->stamp, n * sizeof(int), "fipr's history", err)) != FV_OK ||
            (s = fv_backend_clear(d->b, hs->color.p, 0, 3 * n * sizeof(float), "fipr's history", err)) != FV_OK)
            return s;
        hs->sw = k->sw;
        hs->sh = k->sh;
        index = 0;
    }
    k->hist_color = hs->color.p;
    k->hist_stamp = hs->stamp.p;
    if (index != 0) return FV_OK;
    const fv_sdf_forget_args a = {hs->stamp.p};
    return fv_backend_launch(d->b, &fv_sdf_forget_kernel, (int)n, 1, &a, NULL, err);
}

/* Pass 5's buffers for a w x h image and its kernels up to smax (the table rebuilt on the host only
 * when the size or sigma changes, copied only then); *t the table's device views. */
static fv_status blur_on_device(fv_sdf_device *d, int w, int h, float smax, fv_kblur_table *t, fv_error *err)
{
    blur *bl = &d->blur;
    const size_t n = (size_t)w * h;
    fv_status s;
    if ((s = fv_buffer_ensure(d->b, &bl->sigma, n * sizeof(float), "fipr's blur", err)) != FV_OK ||
        (s = fv_buffer_ensure(d->b, &bl->tmp, 3 * n * sizeof(float), "fipr's blur", err)) != FV_OK)
        return s;
    if (!bl->host_off || bl->w != w || bl->h != h || bl->smax != smax) {
        free(bl->host_off);
        free(bl->host_k);
        bl->sent = false;
        fv_blur_table_size(smax, w, h, &bl->nq, &bl->nk);
        bl->host_off = malloc((size_t)bl->nq * sizeof(int));
        bl->host_k = malloc(bl->nk * sizeof(float));
        if (!bl->host_off || !bl->host_k) {
            free(bl->host_off), free(bl->host_k);
            bl->host_off = NULL, bl->host_k = NULL;
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the blur's kernels");
        }
        fv_blur_table_fill(w, h, bl->nq, bl->host_off, bl->host_k);
        bl->w = w, bl->h = h, bl->smax = smax;
    }
    const void *p;
    if (!bl->sent) {
        if ((s = fv_mirror_fill(d->b, &bl->off, bl->host_off, (size_t)bl->nq * sizeof(int), &p, "fipr's blur kernels", err)) != FV_OK ||
            (s = fv_mirror_fill(d->b, &bl->k, bl->host_k, bl->nk * sizeof(float), &p, "fipr's blur kernels", err)) != FV_OK)
            return s;
        bl->sent = true;
    }
    t->w = w;
    t->h = h;
    t->rcap = (w > h ? w : h) - 1;
    t->nq = bl->nq;
    t->off = (const int *)bl->off.dev.p;
    t->k = (const float *)bl->k.dev.p;
    return FV_OK;
}

/* ---- the frame ---- */

/* The frame's counters: a slot of FV_SDF_COUNTS per pass kind, both eyes adding into the same:
 * slot l the rays of level l (l = L-1 the target; sdf-gt and sdf-relaxed have L = 1), then fipr's
 * mask (slot L) and refresh (slot L+1). */
static int slots_of(const fv_sdf_opts *o) { return o->method == FV_SDF_FIPR ? o->levels + 2 : o->levels; }

/* The slots as the CPU pipeline sums them. */
static void counts_of(const fv_sdf_opts *o, const uint64_t *slots, fv_ksdf_pyr_counts *pc)
{
    memset(pc, 0, sizeof *pc);
    fv_ksdf_counts *c = &pc->all;
    for (int l = 0; l < o->levels; l++) {
        const uint64_t *s = slots + (size_t)l * FV_SDF_COUNTS;
        c->rays += s[FV_SDF_COUNT_RAYS];
        c->steps += s[FV_SDF_COUNT_STEPS];
        c->exhausted += s[FV_SDF_COUNT_EXHAUSTED];
        c->nan += s[FV_SDF_COUNT_NAN];
        c->shade.shadow_rays += s[FV_SDF_COUNT_SHADOW_RAYS];
        c->shade.shadow_steps += s[FV_SDF_COUNT_SHADOW_STEPS];
        c->shade.normal_evals += s[FV_SDF_COUNT_NORMAL_EVALS];
        pc->level_rays[l] = s[FV_SDF_COUNT_RAYS];
        pc->level_steps[l] = s[FV_SDF_COUNT_STEPS];
    }
    if (o->method != FV_SDF_FIPR) return;
    const uint64_t *m = slots + (size_t)o->levels * FV_SDF_COUNTS, *n = m + FV_SDF_COUNTS;
    pc->masked = m[FV_SDF_COUNT_MASKED];
    pc->edges = m[FV_SDF_COUNT_EDGES];
    pc->refreshed = n[FV_SDF_COUNT_REFRESHED];
}

/* The counters as the CPU pipeline names them. */
static void report(const fv_sdf_opts *o, const fv_ksdf_pyr_counts *pc, double samples, fv_stats *stats)
{
    const fv_ksdf_counts *c = &pc->all;
    char key[32];
    fv_stats_add_count(stats, "rays", (double)c->rays);
    fv_stats_add_count(stats, "nan_samples", (double)c->nan);
    fv_stats_add_count(stats, "samples", samples);
    fv_stats_add_count(stats, "steps", (double)c->steps);
    fv_stats_add_count(stats, "shadow_steps", (double)c->shade.shadow_steps);
    fv_stats_add_count(stats, "normal_evals", (double)c->shade.normal_evals);
    fv_stats_add_count(stats, "exhausted_rays", (double)c->exhausted);
    fv_stats_add_count(stats, "shadow_rays", (double)c->shade.shadow_rays);
    for (int k = 0; k < o->levels; k++) {
        snprintf(key, sizeof key, "rays_level%d", k);
        fv_stats_add_count(stats, key, (double)pc->level_rays[k]);
        snprintf(key, sizeof key, "steps_level%d", k);
        fv_stats_add_count(stats, key, (double)pc->level_steps[k]);
    }
    if (o->method == FV_SDF_FIPR) {
        fv_stats_add_count(stats, "mask_pixels", (double)pc->masked);
        fv_stats_add_count(stats, "edge_pixels", (double)pc->edges);
        fv_stats_add_count(stats, "refreshed_pixels", (double)pc->refreshed);
    }
}

/* One eye's passes, queued: ipr and fipr in the CPU pipeline's order (sdf_pipeline.c): the levels traced
 * whole (fipr: all but the middle), fipr's sky, edges, mask, refresh and middle level, then the
 * target, then fipr's pass 5 on the eye's colour (in place, through the scratch image). slots: the
 * frame's counters; prog: the portable backend's progress and cancel (*done false: cancelled). */
static fv_status eye_passes(fv_sdf_device *d, const fv_frame *frame, const fv_ksdf_world *world, const fv_ksdf_frame *f, fv_kpyr *k,
                            const fv_kblur_table *bt, const fv_film_views *out, uint64_t *slots, double *blur_ms, bool *done, fv_error *err)
{
    const fv_sdf_opts *o = &d->o;
    const bool pyramid = o->method == FV_SDF_IPR || o->method == FV_SDF_FIPR;
    const bool fipr = o->method == FV_SDF_FIPR, blurred = fipr && o->blur;
    const int L = o->levels, w = f->cam.width, h = f->cam.height;
    fv_backend *b = d->b;
    fv_status s = FV_OK;
    fv_kpyr_fovea fov;
    if (fipr) {
        fv_sdf_fovea_of(frame, o, w, h, &fov);
        if ((s = history_on_device(d, fov.eye_index, fov.index, k, err)) != FV_OK) return s;
    }
    /* progress: each marching pass's share of the eye's rays */
    double total = 0.0, base = 0.0;
    for (int i = 0; pyramid && i < L; i++) total += (double)k->lv[i].w * k->lv[i].h;
    fv_kit_progress prog = {0};
    const fv_launch_progress lp = {fv_kit_progress_fn, &prog};
    fv_sdf_level_args la;
    memset(&la, 0, sizeof la);
    la.world = *world;
    la.f = *f;
    la.k = *k;
    la.index = fipr ? fov.index : 0;
    const int full_below = !pyramid ? 0 : fipr ? L - 2 : L - 1;
    for (int l = 0; l < full_below && s == FV_OK && *done; l++) {
        const double span = (double)k->lv[l].w * k->lv[l].h / total;
        fv_kit_phase(&prog, frame, base, span);
        la.level = l;
        s = fv_backend_launch_progress(b, &fv_sdf_level_kernel, k->lv[l].w, k->lv[l].h, &la, slots + (size_t)l * FV_SDF_COUNTS, &lp, done, err);
        base += span;
    }
    if (s == FV_OK && *done && fipr) {
        const fv_pyramid_level *low = &k->lv[0], *mid = &k->lv[L - 2];
        const fv_sdf_far_args fa = {k->depth[0], low->w, low->h, d->far_rows.p, d->far.p};
        const fv_sdf_sobel_args sa = {*k, d->far.p, o->edge};
        const fv_sdf_fovea_args ma = {*k, fov};
        uint64_t *mask_slot = slots + (size_t)L * FV_SDF_COUNTS;
        if ((s = fv_backend_launch(b, &fv_sdf_far_rows_kernel, low->h, 1, &fa, NULL, err)) == FV_OK &&
            (s = fv_backend_launch(b, &fv_sdf_far_kernel, 1, 1, &fa, NULL, err)) == FV_OK &&
            (s = fv_backend_launch(b, &fv_sdf_sobel_kernel, low->w, low->h, &sa, NULL, err)) == FV_OK &&
            (s = fv_backend_launch(b, &fv_sdf_mask_kernel, w, h, &ma, mask_slot, err)) == FV_OK &&
            (s = fv_backend_launch(b, &fv_sdf_need_kernel, mid->w, mid->h, &ma, mask_slot + FV_SDF_COUNTS, err)) == FV_OK) {
            const double span = (double)mid->w * mid->h / total;
            fv_kit_phase(&prog, frame, base, span);
            la.level = L - 2;
            s = fv_backend_launch_progress(b, &fv_sdf_level_kernel, mid->w, mid->h, &la, slots + (size_t)(L - 2) * FV_SDF_COUNTS, &lp, done, err);
            base += span;
        }
    }
    if (s == FV_OK && *done) {
        fv_sdf_target_args ta;
        memset(&ta, 0, sizeof ta);
        ta.world = *world;
        ta.f = *f;
        ta.k = *k;
        ta.pyramid = pyramid;
        ta.out = *out;
        fv_kit_phase(&prog, frame, base, 1.0 - base);
        s = fv_backend_launch_progress(b, &fv_sdf_target_kernel, w, h, &ta, slots + (size_t)(L - 1) * FV_SDF_COUNTS, &lp, done, err);
    }
    if (s != FV_OK || !*done || !blurred) return s;
    /* pass 5 (on portable each launch runs at once: its time is the blur's) */
    const double t0 = fv_time_ms();
    const fv_sdf_sigma_args sg = {k->mask, w, h, o->blur_sigma, d->blur.sigma.p};
    const fv_blur_args bh = {*bt, d->blur.sigma.p, out->color, d->blur.tmp.p};
    const fv_blur_args bv = {*bt, d->blur.sigma.p, d->blur.tmp.p, out->color};
    if ((s = fv_backend_launch(b, &fv_sdf_sigma_kernel, w, h, &sg, NULL, err)) == FV_OK &&
        (s = fv_backend_launch(b, &fv_blur_h_kernel, w, h, &bh, NULL, err)) == FV_OK)
        s = fv_backend_launch(b, &fv_blur_v_kernel, w, h, &bv, NULL, err);
    *blur_ms += fv_time_ms() - t0;
    return s;
}

/* Queues `eyes` eyes of one frame (1, or a stereo pair of one size): the world brought to the
 * frame's time once, every eye's passes, then the films' and counters' read-back into the next
 * staging slot's pinned memory, then a fence; no host wait (on the portable backend each launch
 * runs at once, with progress and cancel, and nothing is copied). A failure or a cancel waits for
 * what was queued and leaves nothing of this frame in flight. */
static fv_status submit_eyes(fv_sdf_device *d, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    fv_backend *b = d->b;
    const fv_sdf_opts *o = &d->o;
    const bool pyramid = o->method == FV_SDF_IPR || o->method == FV_SDF_FIPR;
    const bool blurred = o->method == FV_SDF_FIPR && o->blur;
    const bool portable = fv_backend_device(b) == FV_DEVICE_PORTABLE;
    if (d->in_flight >= FV_FILM_DEVICE_SLOTS) return fv_error_set(err, FV_ERR_INTERNAL, "sphere tracers: %d frames in flight already", d->in_flight);
    const int slot = (d->head + d->in_flight) % FV_FILM_DEVICE_SLOTS;
    struct flight *fl = &d->flight[slot];
    fv_ksdf_frame f[2];
    memset(f, 0, sizeof f);
    fv_status s;
    for (int e = 0; e < eyes; e++)
        if ((s = fv_frame_camera(frames[e].camera, films[e], &f[e].cam, err)) != FV_OK) return s;
    const int w = f[0].cam.width, h = f[0].cam.height;
    const size_t np = (size_t)w * h;
    const int S = fv_sdf_samples_per_axis(o->spp);
    fv_backend_calls before;
    fv_backend_calls_get(b, &before);
    fv_backend_set_threads(b, frames[0].threads);
    if ((s = world_at_time(d, stats, err)) != FV_OK) return s;
    const double t0 = fv_time_ms();
    fv_ksdf_world dw;
    fv_kpyr k;
    memset(&k, 0, sizeof k);
    fv_kblur_table bt;
    memset(&bt, 0, sizeof bt);
    const int nslots = slots_of(o);
    const size_t count_bytes = (size_t)nslots * FV_SDF_COUNTS * sizeof(uint64_t);
    /* every staging slot's counters now, so that no later frame allocates */
    for (int i = 0; i < FV_FILM_DEVICE_SLOTS; i++)
        if ((s = fv_pinned_ensure(b, &d->flight[i].counts_host, count_bytes, "the sphere tracers' counters", err)) != FV_OK) return s;
    if ((s = world_on_device(d, &dw, err)) != FV_OK || (pyramid && (s = pyramid_on_device(d, w, h, S, &k, err)) != FV_OK) ||
        (blurred && (s = blur_on_device(d, w, h, o->blur_sigma, &bt, err)) != FV_OK) ||
        (s = fv_buffer_ensure(b, &d->counts, count_bytes, "the sphere tracers' counters", err)) != FV_OK ||
        (s = fv_backend_clear(b, d->counts.p, 0, count_bytes, "the sphere tracers' counters", err)) != FV_OK)
        return s;
    fv_film_views host[2], out[2];
    for (int e = 0; e < eyes; e++) {
        /* a target sample's angular footprint per unit distance, as the CPU pipeline's */
        f[e].S = S;
        f[e].eps_k = o->hit * (2.0f * f[e].cam.tan_half_x / (float)(w * S));
        f[e].march = o->march;
        f[e].shade = o->shade;
        host[e] = fv_film_views_of(films[e]);
        if ((s = fv_film_device_views(b, &d->film[e], &host[e], np, &out[e], err)) != FV_OK) return s;
    }
    double blur_ms = 0.0;
    bool done = true;
    fv_backend_mark(b, 2 * slot);
    for (int e = 0; e < eyes && s == FV_OK && done; e++)
        s = eye_passes(d, &frames[e], &dw, &f[e], &k, &bt, &out[e], d->counts.p, &blur_ms, &done, err);
    fv_backend_mark(b, 2 * slot + 1);
    for (int e = 0; e < eyes && s == FV_OK && done; e++) s = fv_film_device_download_film(b, &d->film[e], slot, films[e], err);
    if (s == FV_OK) s = fv_backend_download(b, fl->counts_host.p, d->counts.p, count_bytes, "the sphere tracers' counters", err);
    if (s != FV_OK || !done) {
        /* the wait even after a failure: nothing queued may write into a film the caller has back */
        fv_backend_wait(b, "the sphere tracers' kernels", NULL);
        return s != FV_OK ? s : fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    }
    fv_backend_fence(b, slot);
    fl->eyes = eyes;
    fl->rendered = false;
    fl->films[0] = films[0], fl->films[1] = eyes == 2 ? films[1] : NULL;
    fl->stats = stats;
    fl->t0 = t0;
    fl->blur_ms = blur_ms;
    d->in_flight++;
    if (!portable) {
        fv_backend_calls after;
        fv_backend_calls_get(b, &after);
        fv_backend_calls_report(stats, &before, &after);
    }
    return FV_OK;
}

/* A frame in flight in `slot`: its fence waited for (and with it everything queued before), its
 * films and counters delivered into what it was submitted with. */
static fv_status finish(fv_sdf_device *d, int slot, fv_error *err)
{
    fv_backend *b = d->b;
    const fv_sdf_opts *o = &d->o;
    const bool blurred = o->method == FV_SDF_FIPR && o->blur;
    const bool portable = fv_backend_device(b) == FV_DEVICE_PORTABLE;
    struct flight *fl = &d->flight[slot];
    fv_stats *stats = fl->stats;
    fv_backend_calls before, after;
    fv_backend_calls_get(b, &before);
    const fv_status s = fv_backend_wait_fence(b, slot, "the sphere tracers' kernels", err);
    fv_backend_calls_get(b, &after);
    if (s != FV_OK) return s;
    const int w = fv_film_width(fl->films[0]), h = fv_film_height(fl->films[0]);
    for (int e = 0; e < fl->eyes; e++) fv_film_device_deliver_film(b, &d->film[e], slot, fl->films[e]);
    fv_stats_add_ms(stats, "target", fv_time_ms() - fl->t0 - (portable ? fl->blur_ms : 0.0));
    if (blurred && portable) fv_stats_add_ms(stats, "blur", fl->blur_ms);
    fv_ksdf_pyr_counts c;
    counts_of(o, fl->counts_host.p, &c);
    report(o, &c, (double)w * h * o->spp * fl->eyes, stats);
    if (!portable) {
        fv_stats_add_ms(stats, "kernel", fv_backend_elapsed_ms(b, 2 * slot, 2 * slot + 1));
        fv_stats_add_count(stats, "host_syncs", 1.0);
        fv_backend_calls_report(stats, &before, &after);
    }
    return FV_OK;
}

fv_status fv_sdf_device_collect(fv_sdf_device *d, fv_error *err)
{
    if (!d->in_flight) return fv_error_set(err, FV_ERR_INTERNAL, "sphere tracers: no frame in flight");
    const int slot = d->head;
    d->head = (d->head + 1) % FV_FILM_DEVICE_SLOTS;
    d->in_flight--;
    return d->flight[slot].rendered ? FV_OK : finish(d, slot, err);
}

/* The newest frame in flight finished now and taken back: its slot is free again. */
static fv_status finish_newest(fv_sdf_device *d, fv_error *err)
{
    const fv_status s = finish(d, (d->head + d->in_flight - 1) % FV_FILM_DEVICE_SLOTS, err);
    d->in_flight--;
    return s;
}

fv_status fv_sdf_device_submit(fv_sdf_device *d, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    if (eyes == 1 || (fv_film_width(films[0]) == fv_film_width(films[1]) && fv_film_height(films[0]) == fv_film_height(films[1])))
        return submit_eyes(d, eyes, frames, films, stats, err);
    /* The pair shares the pyramid's buffers: eyes of different sizes go one at a time, now, each
     * through the slot this frame takes; the frame is then in flight already rendered, so that
     * the one before it is still collected first. */
    fv_status s = FV_OK;
    for (int e = 0; e < 2 && s == FV_OK; e++)
        if ((s = submit_eyes(d, 1, &frames[e], &films[e], stats, err)) == FV_OK) s = finish_newest(d, err);
    if (s != FV_OK) return s;
    struct flight *fl = &d->flight[(d->head + d->in_flight) % FV_FILM_DEVICE_SLOTS];
    fl->rendered = true;
    d->in_flight++;
    return FV_OK;
}

fv_status fv_sdf_device_render(fv_sdf_device *d, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    const fv_status s = submit_eyes(d, 1, frame, &film, stats, err);
    return s == FV_OK ? fv_sdf_device_collect(d, err) : s;
}

fv_status fv_sdf_device_render_pair(fv_sdf_device *d, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    const fv_status s = fv_sdf_device_submit(d, 2, frames, films, stats, err);
    return s == FV_OK ? fv_sdf_device_collect(d, err) : s;
}
