/* fovea — the sphere-tracing family on the portable and CUDA backends (device.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/blur.h"
#include "device/calls_report.h"
#include "device/cuda_backend.h"
#include "kernel/sdf_pixel.h"
#include "technique/kit.h"
#include "technique/sdf/device.h"
#include "technique/sdf/world.h"

struct fv_sdf_device {
    const fv_scene *scene;
    fv_sdf_opts o;
    fv_cuda_sdf *cuda;          /* NULL: the portable backend */
    /* ipr and fipr */
    fv_kpyr k;                  /* portable: the pyramid's host buffers */
    fv_pyramid_history hist[2]; /* portable, fipr: the middle level kept per eye */
    float *sigma, *blur_tmp;    /* portable, fipr with blur: pass 5's sigma and horizontal pass */
    size_t blur_pixels;         /* the size sigma and blur_tmp have */
    /* The world, kept between frames: rebuilt (fv_sdf_world_refresh) only when the scene's time
     * changed and something in it moves, so a still scene builds it once. */
    fv_sdf_world world;
    bool world_ok;              /* world holds the scene at world_time */
    double world_time;
    bool moves;                 /* an SDF object or a delta light is animated */
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
    if (device == FV_DEVICE_CUDA) {
        fv_status s = fv_cuda_sdf_create(&d->cuda, err);
        if (s != FV_OK) {
            free(d);
            return s;
        }
    }
    *out = d;
    return FV_OK;
}

void fv_sdf_device_destroy(fv_sdf_device *d)
{
    if (!d) return;
    fv_cuda_sdf_destroy(d->cuda);
    fv_pyramid_free(&d->k);
    fv_pyramid_history_free(&d->hist[0]);
    fv_pyramid_history_free(&d->hist[1]);
    fv_sdf_world_free(&d->world);
    free(d->sigma);
    free(d->blur_tmp);
    free(d);
}

/* ---- the portable backend: each pass's kernel steps over tiles of its grid on the CPU's threads ---- */

typedef enum pass { PASS_LEVEL, PASS_SOBEL, PASS_MASK, PASS_NEED, PASS_TARGET, PASS_SIGMA } pass;

typedef struct tile_job {
    const fv_ksdf_world *world;
    fv_ksdf_frame f;
    fv_film_views out;
    const fv_kpyr *k;         /* NULL: sdf-gt, sdf-relaxed */
    const fv_kpyr_fovea *fov; /* fipr */
    pass what;
    int level;                /* PASS_LEVEL */
    float sky, edge;          /* PASS_SOBEL */
    float *sigma, blur_sigma; /* PASS_SIGMA */
    fv_ksdf_counts *c;        /* per thread: the pass's costs */
    uint64_t *n;              /* per thread: mask pixels (PASS_MASK), edge pixels (PASS_MASK), refreshed rays (PASS_NEED) */
} tile_job;

static void pass_tile(void *ctx, const fv_tile *tile)
{
    tile_job *j = ctx;
    const fv_kpyr *k = j->k;
    fv_ksdf_counts *c = &j->c[tile->thread];
    uint64_t *n = &j->n[2 * tile->thread];
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++) switch (j->what) {
            case PASS_LEVEL: fv_ksdf_level_cell(j->world, &j->f, k, j->level, x, y, j->fov ? j->fov->index : 0, c); break;
            case PASS_SOBEL:
                k->edge[(size_t)y * k->lv[0].w + x] = fv_kpyr_sobel_cell(k->depth[0], k->lv[0].w, k->lv[0].h, j->sky, j->edge, x, y);
                break;
            case PASS_MASK: {
                uint8_t m = fv_kpyr_mask_pixel(k, j->fov, x, y);
                k->mask[(size_t)y * k->w + x] = m;
                n[0] += m;
                n[1] += fv_kpyr_edge_of_pixel(k, x, y) != 0;
                break;
            }
            case PASS_NEED: {
                uint8_t need = fv_kpyr_need_cell(k, j->fov, x, y);
                k->need[(size_t)y * k->lv[k->L - 2].w + x] = need;
                n[0] += need == 2;
                break;
            }
            case PASS_TARGET: fv_ksdf_target_pixel(j->world, &j->f, k, x, y, &j->out, c); break;
            case PASS_SIGMA: j->sigma[(size_t)y * k->w + x] = fv_kpyr_blur_sigma(k->mask, k->w, k->h, x, y, j->blur_sigma); break;
            }
}

static void add_counts(fv_ksdf_counts *to, const fv_ksdf_counts *c)
{
    to->rays += c->rays;
    to->steps += c->steps;
    to->exhausted += c->exhausted;
    to->nan += c->nan;
    to->shade.shadow_rays += c->shade.shadow_rays;
    to->shade.shadow_steps += c->shade.shadow_steps;
    to->shade.normal_evals += c->shade.normal_evals;
}

/* One pass over a gw x gh grid; its costs into *sum (and, for a level, the level's share), its
 * counts into n[0], n[1]. */
static fv_status run_pass(tile_job *j, pass what, int level, int gw, int gh, const fv_frame *frame, fv_kit_progress *prog, double base,
                          double span, fv_ksdf_pyr_counts *sum, uint64_t n[2], fv_error *err)
{
    const int nt = fv_thread_count(frame->threads);
    memset(j->c, 0, (size_t)nt * sizeof *j->c);
    memset(j->n, 0, (size_t)nt * 2 * sizeof *j->n);
    j->what = what;
    j->level = level;
    fv_kit_phase(prog, frame, base, span);
    fv_parallel_tiles(gw, gh, frame->threads, pass_tile, j, fv_kit_progress_fn, prog);
    fv_ksdf_counts c;
    memset(&c, 0, sizeof c);
    for (int t = 0; t < nt; t++) {
        add_counts(&c, &j->c[t]);
        if (n) n[0] += j->n[2 * t], n[1] += j->n[2 * t + 1];
    }
    add_counts(&sum->all, &c);
    if (level >= 0) {
        sum->level_rays[level] += c.rays;
        sum->level_steps[level] += c.steps;
    }
    return fv_kit_phase_end(prog, err);
}

/* ipr and fipr on the portable backend: the CPU pipeline's passes in its order (pipeline.c). */
static fv_status portable_pyramid(fv_sdf_device *d, tile_job *j, const fv_frame *frame, fv_ksdf_pyr_counts *sum, fv_error *err)
{
    const fv_sdf_opts *o = &d->o;
    const bool fipr = o->method == FV_SDF_FIPR;
    const int L = o->levels, w = j->f.cam.width, h = j->f.cam.height;
    fv_kpyr *k = &d->k;
    fv_status s = fv_pyramid_alloc(k, w, h, j->f.S, L, fipr, o->shadow_reuse, err);
    if (s != FV_OK) return s;
    k->min_filter = o->min_filter;
    fv_kpyr_fovea fov;
    if (fipr) {
        if ((s = fv_pyramid_history_attach(&d->hist[frame->eye], k, frame->index, err)) != FV_OK) return s;
        fv_sdf_fovea_of(frame, o, w, h, &fov);
        j->fov = &fov;
    }
    j->k = k;
    const int nt = fv_thread_count(frame->threads);
    j->c = fv_calloc_array((size_t)nt, sizeof *j->c);
    j->n = fv_calloc_array((size_t)nt * 2, sizeof *j->n);
    if (!j->c || !j->n) {
        s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        goto done;
    }
    double total = 0.0, base = 0.0;
    for (int i = 0; i < L; i++) total += (double)k->lv[i].w * k->lv[i].h;
    fv_kit_progress prog = {0};
    const int full_below = fipr ? L - 2 : L - 1;
    for (int i = 0; i < full_below && s == FV_OK; i++) {
        double span = (double)k->lv[i].w * k->lv[i].h / total;
        s = run_pass(j, PASS_LEVEL, i, k->lv[i].w, k->lv[i].h, frame, &prog, base, span, sum, NULL, err);
        base += span;
    }
    if (s == FV_OK && fipr) {
        const fv_pyramid_level *low = &k->lv[0], *mid = &k->lv[L - 2];
        /* pass 2's sky: a maximum, the same in any order */
        float far = 0.0f;
        for (size_t i = 0; i < (size_t)low->w * low->h; i++)
            if (isfinite(k->depth[0][i]) && k->depth[0][i] > far) far = k->depth[0][i];
        j->sky = fv_kpyr_sky(far);
        j->edge = o->edge;
        uint64_t mask_n[2] = {0, 0}, need_n[2] = {0, 0};
        s = run_pass(j, PASS_SOBEL, -1, low->w, low->h, frame, &prog, base, 0.0, sum, NULL, err);
        if (s == FV_OK) s = run_pass(j, PASS_MASK, -1, w, h, frame, &prog, base, 0.0, sum, mask_n, err);
        if (s == FV_OK) s = run_pass(j, PASS_NEED, -1, mid->w, mid->h, frame, &prog, base, 0.0, sum, need_n, err);
        sum->masked += mask_n[0];
        sum->edges += mask_n[1];
        sum->refreshed += need_n[0];
        double span = (double)mid->w * mid->h / total;
        if (s == FV_OK) s = run_pass(j, PASS_LEVEL, L - 2, mid->w, mid->h, frame, &prog, base, span, sum, NULL, err);
        base += span;
    }
    if (s == FV_OK) s = run_pass(j, PASS_TARGET, L - 1, w, h, frame, &prog, base, 1.0 - base, sum, NULL, err);
done:
    free(j->c);
    free(j->n);
    j->c = NULL;
    j->n = NULL;
    return s;
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

/* fipr's pass 5 on the portable backend, on this eye's mask (the pyramid's, until the next eye):
 * the transitions' sigma a pixel at a time, then the blur's two kernel passes (filter/blur.h),
 * the steps CUDA launches. */
static fv_status portable_blur(fv_sdf_device *d, tile_job *j, const fv_frame *frame, fv_error *err)
{
    const int w = j->f.cam.width, h = j->f.cam.height;
    j->sigma = d->sigma;
    j->blur_sigma = d->o.blur_sigma;
    fv_ksdf_pyr_counts none;
    memset(&none, 0, sizeof none);
    fv_kit_progress prog = {0};
    const int nt = fv_thread_count(frame->threads);
    j->c = fv_calloc_array((size_t)nt, sizeof *j->c);
    j->n = fv_calloc_array((size_t)nt * 2, sizeof *j->n);
    fv_status s = j->c && j->n ? run_pass(j, PASS_SIGMA, -1, w, h, frame, &prog, 1.0, 0.0, &none, NULL, err)
                               : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    free(j->c);
    free(j->n);
    j->c = NULL;
    j->n = NULL;
    return s == FV_OK ? fv_blur_kernel_passes(j->out.color, d->blur_tmp, w, h, d->sigma, d->o.blur_sigma, frame->threads, err) : s;
}

/* The world at the scene's current time: the kept one while it stands for it. */
static fv_status world_at_time(fv_sdf_device *d, fv_stats *stats, fv_error *err)
{
    const double t = fv_scene_time(d->scene);
    if (d->world_ok && (!d->moves || t == d->world_time)) return FV_OK;
    d->world_ok = false;
    double t0 = fv_time_ms();
    fv_status s = fv_sdf_world_refresh(&d->world, d->scene, err);
    if (s != FV_OK) return s;
    d->world_ok = true;
    d->world_time = t;
    fv_stats_add_ms(stats, "scene", fv_time_ms() - t0);
    fv_stats_add_count(stats, "world_builds", 1.0);
    return FV_OK;
}

/* Renders `eyes` eyes of one frame (1, or a stereo pair of one size): the world built once for
 * them; on CUDA every eye's passes are launched before the one host wait, on the portable backend
 * the eyes run one after the other through the same passes. */
static fv_status render_eyes(fv_sdf_device *d, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    tile_job j[2];
    memset(j, 0, sizeof j);
    fv_status s;
    for (int e = 0; e < eyes; e++)
        if ((s = fv_frame_camera(frames[e].camera, films[e], &j[e].f.cam, err)) != FV_OK) return s;
    const fv_sdf_opts *o = &d->o;
    const bool pyramid = o->method == FV_SDF_IPR || o->method == FV_SDF_FIPR;
    const bool fipr = o->method == FV_SDF_FIPR, blurred = fipr && o->blur;
    const int w = j[0].f.cam.width, h = j[0].f.cam.height;
    const size_t np = (size_t)w * h;
    if (blurred && !d->cuda && d->blur_pixels != np) {
        free(d->sigma);
        free(d->blur_tmp);
        d->sigma = fv_alloc_array(np, sizeof(float));
        d->blur_tmp = fv_alloc_array(np, 3 * sizeof(float));
        d->blur_pixels = d->sigma && d->blur_tmp ? np : 0;
        if (!d->blur_pixels) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for fipr's blur");
    }
    if ((s = world_at_time(d, stats, err)) != FV_OK) return s;
    const fv_sdf_world *world = &d->world;
    double t0;
    const int S = fv_sdf_samples_per_axis(o->spp);
    fv_ksdf_frame f[2];
    fv_film_views out[2];
    for (int e = 0; e < eyes; e++) {
        j[e].world = &world->k;
        j[e].f.S = S;
        /* a target sample's angular footprint per unit distance, as the CPU pipeline's */
        j[e].f.eps_k = o->hit * (2.0f * j[e].f.cam.tan_half_x / (float)(w * S));
        j[e].f.march = o->march;
        j[e].f.shade = o->shade;
        j[e].out = fv_film_views_of(films[e]);
        f[e] = j[e].f;
        out[e] = j[e].out;
    }
    const double samples = (double)w * h * o->spp * eyes;
    fv_ksdf_pyr_counts c;
    memset(&c, 0, sizeof c);
    double blur_ms = 0.0;
    t0 = fv_time_ms();
    if (d->cuda) {
        double kernel_ms = 0.0;
        int syncs = 0;
        fv_cuda_calls before, after;
        fv_cuda_sdf_calls(d->cuda, &before);
        if (!pyramid) {
            s = fv_cuda_sdf_render(d->cuda, &world->k, eyes, f, out, &c.all, &kernel_ms, &syncs, err);
            c.level_rays[0] = c.all.rays;
            c.level_steps[0] = c.all.steps;
        } else {
            fv_kpyr shape;
            memset(&shape, 0, sizeof shape);
            shape.L = o->levels;
            shape.S = S;
            shape.w = w;
            shape.h = h;
            shape.sw = w * S;
            shape.sh = h * S;
            shape.min_filter = o->min_filter;
            fv_kpyr_levels(shape.sw, shape.sh, shape.L, shape.lv);
            fv_kpyr_fovea fov[2];
            for (int e = 0; e < eyes && fipr; e++) fv_sdf_fovea_of(&frames[e], o, w, h, &fov[e]);
            const fv_cuda_pyr_opts po = {o->edge, o->shadow_reuse, blurred, o->blur_sigma};
            s = fv_cuda_sdf_pyramid_render(d->cuda, &world->k, eyes, f, &shape, fipr ? fov : NULL, &po, out, &c, &kernel_ms, &syncs, err);
        }
        fv_stats_add_ms(stats, "kernel", kernel_ms);
        fv_stats_add_count(stats, "host_syncs", (double)syncs);
        fv_cuda_sdf_calls(d->cuda, &after);
        fv_backend_calls_report(stats, &before, &after);
    } else {
        for (int e = 0; e < eyes && s == FV_OK; e++) {
            if (!pyramid) {
                const int nt = fv_thread_count(frames[e].threads);
                j[e].c = fv_calloc_array((size_t)nt, sizeof *j[e].c);
                j[e].n = fv_calloc_array((size_t)nt * 2, sizeof *j[e].n);
                fv_kit_progress prog = {0};
                s = j[e].c && j[e].n ? run_pass(&j[e], PASS_TARGET, 0, w, h, &frames[e], &prog, 0.0, 1.0, &c, NULL, err)
                                     : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
                free(j[e].c);
                free(j[e].n);
            } else {
                s = portable_pyramid(d, &j[e], &frames[e], &c, err);
            }
            if (s == FV_OK && blurred) {
                double tb = fv_time_ms();
                s = portable_blur(d, &j[e], &frames[e], err);
                blur_ms += fv_time_ms() - tb;
            }
        }
    }
    fv_stats_add_ms(stats, "target", fv_time_ms() - t0 - blur_ms);
    if (blurred && !d->cuda) fv_stats_add_ms(stats, "blur", blur_ms);
    if (s != FV_OK) return s;
    report(o, &c, samples, stats);
    return FV_OK;
}

fv_status fv_sdf_device_render(fv_sdf_device *d, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    return render_eyes(d, 1, frame, &film, stats, err);
}

fv_status fv_sdf_device_render_pair(fv_sdf_device *d, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    /* the pair shares the pyramid's buffers: eyes of different sizes go one at a time */
    if (fv_film_width(films[0]) != fv_film_width(films[1]) || fv_film_height(films[0]) != fv_film_height(films[1])) {
        fv_status s = render_eyes(d, 1, &frames[0], &films[0], stats, err);
        return s == FV_OK ? render_eyes(d, 1, &frames[1], &films[1], stats, err) : s;
    }
    return render_eyes(d, 2, frames, films, stats, err);
}
