/* fovea — `pt`, the reference unidirectional path tracer: the ground truth every technique is
 * measured against. The integrator is the shared kernel (kernel/path_impl.h through
 * transport/path.h); this file only lays the camera samples out, on one of three devices:
 *  - cpu: pixels eight at a time as Embree ray packets, `spp` jittered samples each;
 *  - portable: the device kernel (kernel/pt.h) on the CPU, a pixel at a time over the flat scene
 *    (scene/export.h), which is how CI tests the GPU's code;
 *  - cuda: the same kernel on an NVIDIA GPU (device/cuda_backend.h).
 * All three draw the same random numbers per pixel and sample.
 */
#include <stdlib.h>
#include <string.h>
#include "device/cuda_backend.h"
#include "kernel/pt.h"
#include "scene/export.h"
#include "technique/class.h"
#include "technique/kit.h"
#include "transport/path.h"

typedef struct pt_state {
    const fv_scene *scene;
    fv_path_opts opt;
    fv_device device;
    fv_scene_export *flat; /* portable and cuda: the flat scene at the frame's time */
    fv_cuda_pt *cuda;      /* cuda: the GPU's copy of it */
} pt_state;

static void pt_destroy(void *state)
{
    pt_state *st = state;
    if (!st) return;
    fv_cuda_pt_destroy(st->cuda);
    fv_scene_export_destroy(st->flat);
    free(st);
}

static fv_status pt_create(const fv_scene *scene, fv_params *params, fv_device device, const fv_log *log, void **state, fv_error *err)
{
    pt_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    st->device = device;
    fv_status s = fv_path_read_opts(params, &st->opt, err);
    if (s == FV_OK && device != FV_DEVICE_CPU) s = fv_scene_export_create(scene, &st->flat, err);
    if (s == FV_OK && device == FV_DEVICE_CUDA) s = fv_cuda_pt_create(fv_scene_export_view(st->flat), &st->cuda, err);
    if (s != FV_OK) {
        pt_destroy(st);
        return s;
    }
    *state = st;
    return FV_OK;
}

typedef struct pt_job {
    const pt_state *st;
    const fv_frame *frame;
    fv_camera_basis cam;
    fv_film_views out;
    fv_kit_counters *counters;
} pt_job;

/* Pixels go eight at a time: their camera rays share an origin and a direction, so Embree traces
 * them as one packet; the rest of each path is traced alone. Each pixel keeps its own random
 * stream, so the image does not depend on the packing. */
static void pt_tile(void *ctx, const fv_tile *tile)
{
    pt_job *j = ctx;
    const fv_path_opts *opt = &j->st->opt;
    const int w = j->cam.width;
    uint64_t rays = 0, bad = 0;
    for (int y = tile->y0; y < tile->y1; y++) {
        for (int x0 = tile->x0; x0 < tile->x1; x0 += 8) {
            int n = tile->x1 - x0 < 8 ? tile->x1 - x0 : 8;
            fv_vec3 sum[8], dir[8];
            fv_path_first_hit first[8];
            fv_rng rng[8];
            fv_hit hits[8];
            bool ok[8];
            memset(first, 0, sizeof first);
            for (int k = 0; k < n; k++) sum[k] = fv_v3s(0.0f);
            for (int sidx = 0; sidx < opt->spp; sidx++) {
                for (int k = 0; k < n; k++) {
                    size_t pix = (size_t)y * (size_t)w + (size_t)(x0 + k);
                    rng[k] = fv_kit_rng(j->frame, pix, (uint64_t)sidx);
                    float jx = fv_rng_next(&rng[k]), jy = fv_rng_next(&rng[k]);
                    dir[k] = fv_camera_dir(&j->cam, (float)(x0 + k) + jx, (float)y + jy);
                }
                fv_scene_intersect8(j->st->scene, j->cam.pos, dir, n, hits, ok);
                for (int k = 0; k < n; k++) {
                    fv_vec3 L = fv_path_trace_from(j->st->scene, opt, j->cam.pos, dir[k], &hits[k], ok[k], &rng[k],
                                                   sidx == 0 ? &first[k] : NULL, &rays);
                    sum[k] = fv_add(sum[k], fv_kit_guard(L, &bad));
                }
            }
            for (int k = 0; k < n; k++) {
                size_t pix = (size_t)y * (size_t)w + (size_t)(x0 + k);
                /* finite samples can still sum past the float range */
                fv_vec3 v = fv_kit_guard(fv_scale(sum[k], 1.0f / (float)opt->spp), &bad);
                const fv_path_first_hit *f = &first[k];
                j->out.color[3 * pix] = v.x;
                j->out.color[3 * pix + 1] = v.y;
                j->out.color[3 * pix + 2] = v.z;
                fv_film_store_first_hit(&j->out, pix, f->hit, f->t, f->p, f->n, f->albedo, f->obj);
            }
        }
    }
    fv_kit_count(j->counters, tile->thread, FV_KIT_RAYS, rays);
    fv_kit_count(j->counters, tile->thread, FV_KIT_NAN, bad);
}

/* The portable backend: the device kernel, a pixel at a time, on the CPU's threads. */
typedef struct pt_flat_job {
    const fv_kscene *scene;
    fv_kpt_frame f;
    fv_film_views out;
    fv_kit_counters *counters;
} pt_flat_job;

static void pt_flat_tile(void *ctx, const fv_tile *tile)
{
    pt_flat_job *j = ctx;
    uint64_t rays = 0, bad = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++) fv_kpt_pixel(j->scene, &j->f, x, y, &j->out, &rays, &bad);
    fv_kit_count(j->counters, tile->thread, FV_KIT_RAYS, rays);
    fv_kit_count(j->counters, tile->thread, FV_KIT_NAN, bad);
}

static fv_status pt_render_flat(pt_state *st, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    const fv_camera *cam = frame->camera;
    pt_flat_job j;
    memset(&j, 0, sizeof j);
    fv_status s = fv_frame_camera(cam, film, &j.f.cam, err);
    if (s != FV_OK) return s;
    double t0 = fv_time_ms();
    if ((s = fv_scene_export_update(st->flat, st->scene, err)) != FV_OK) return s;
    if (st->cuda && (s = fv_cuda_pt_update(st->cuda, fv_scene_export_view(st->flat), err)) != FV_OK) return s;
    fv_stats_add_ms(stats, "scene", fv_time_ms() - t0);
    j.scene = fv_scene_export_view(st->flat);
    j.f.seed = frame->seed;
    j.f.eye = frame->eye;
    j.f.frame = frame->index;
    j.f.opt = st->opt;
    j.out = fv_film_views_of(film);
    fv_stats_add_count(stats, "samples", (double)cam->width * cam->height * st->opt.spp);
    if (st->cuda) {
        uint64_t rays = 0, bad = 0;
        double kernel_ms = 0.0;
        t0 = fv_time_ms();
        if ((s = fv_cuda_pt_render(st->cuda, &j.f, &j.out, &rays, &bad, &kernel_ms, err)) != FV_OK) return s;
        fv_stats_add_ms(stats, "trace", fv_time_ms() - t0);
        fv_stats_add_ms(stats, "kernel", kernel_ms);
        fv_stats_add_count(stats, "rays", (double)rays);
        fv_stats_add_count(stats, "nan_samples", (double)bad);
        return FV_OK;
    }
    if (!(j.counters = fv_kit_counters_create())) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_kit_progress prog = {0};
    fv_kit_phase(&prog, frame, 0.0, 1.0);
    t0 = fv_time_ms();
    bool done = fv_parallel_tiles(cam->width, cam->height, frame->threads, pt_flat_tile, &j, fv_kit_progress_fn, &prog);
    fv_stats_add_ms(stats, "trace", fv_time_ms() - t0);
    fv_kit_report(j.counters, stats);
    fv_kit_counters_destroy(j.counters);
    return done ? FV_OK : fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
}

static fv_status pt_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    pt_state *st = state;
    if (st->device != FV_DEVICE_CPU) return pt_render_flat(st, frame, film, stats, err);
    const fv_camera *cam = frame->camera;
    pt_job j;
    memset(&j, 0, sizeof j);
    fv_status s = fv_frame_camera(cam, film, &j.cam, err);
    if (s != FV_OK) return s;
    if (!(j.counters = fv_kit_counters_create())) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    j.st = st;
    j.frame = frame;
    j.out = fv_film_views_of(film);
    fv_kit_progress prog = {0};
    fv_kit_phase(&prog, frame, 0.0, 1.0);
    double t0 = fv_time_ms();
    bool done = fv_parallel_tiles(cam->width, cam->height, frame->threads, pt_tile, &j, fv_kit_progress_fn, &prog);
    fv_stats_add_ms(stats, "trace", fv_time_ms() - t0);
    fv_kit_report(j.counters, stats);
    fv_stats_add_count(stats, "samples", (double)cam->width * cam->height * st->opt.spp);
    fv_kit_counters_destroy(j.counters);
    return done ? FV_OK : fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
}

const fv_technique_class fv_technique_pt = {
    .name = "pt",
    .summary = "reference path tracer: NEE + MIS, Russian roulette (ground truth)",
    .params_help = "spp=int (16): samples per pixel\n"
                   "max_depth=int (8): path vertices that gather light, 1 = direct light only\n"
                   "rr_depth=int (3): depth from which Russian roulette may end paths\n",
    .create_on = pt_create,
    .devices = (1u << FV_DEVICE_PORTABLE) | (1u << FV_DEVICE_CUDA),
    .render = pt_render,
    .destroy = pt_destroy,
    /* furnace: 1 - 0.5^9 with 8 vertices, Russian roulette unbiased */
    .test_params = "spp=64",
    .furnace_radiance = 0.998046875,
    .furnace_tolerance = 0.02,
    .spp_param = "spp",
};
