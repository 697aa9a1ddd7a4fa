/* fovea — `pt`, the reference unidirectional path tracer: the ground truth every technique is
 * measured against. The integrator is the shared kernel (kernel/kpath_impl.h through
 * transport/path.h); this file only lays the camera samples out, on one of three devices:
 *  - cpu: pixels eight at a time as Embree ray packets, `spp` jittered samples each;
 *  - portable: the device kernel (kernel/kpt.h) on the CPU, a pixel at a time over the flat scene
 *    (scene/flat_export.h), which is how CI tests the GPU's code;
 *  - cuda: the same kernel on an NVIDIA GPU.
 * The portable and cuda devices share one frame (pt_render_device) over the device backend
 * (device/backend.h), the kernel declared once in technique/pt/pt_kernels.h.
 * All three draw the same random numbers per pixel and sample.
 * On the cpu, more than FV_SAMPLE_BLOCK samples are summed as blocks along core/blocks.h's fixed
 * tree in double, and the parameters block_first/block_count render one range of those blocks,
 * leaving its double sums in the film (film/film_sums.h): how a still is split over processes
 * (src/dist, docs/distributed.md) and still adds up to the one-process image bit for bit.
 */
#include <stdlib.h>
#include <string.h>
#include "core/stage_time.h"
#include "core/blocks.h"
#include "device/backend.h"
#include "device/calls_report.h"
#include "device/film_device.h"
#include "film/film_sums.h"
#include "scene/flat_export.h"
#include "scene/flat_export_device.h"
#include "technique/pt/pt_kernels.h"
#include "technique/class.h"
#include "technique/kit.h"
#include "transport/path.h"

typedef struct pt_state {
    const fv_scene *scene;
    fv_path_opts opt;
    fv_device device;
    int block_first, block_count; /* the blocks rendered: [first, first + count) of the spp's */
    /* portable and cuda: */
    fv_scene_export *flat;     /* the flat scene at the frame's time */
    fv_backend *backend;
    fv_scene_device *dscene;   /* its copy on the backend */
    fv_film_device film[2];    /* per eye: a stereo pair is read back after both ran */
    fv_buffer counts;          /* FV_PT_COUNTS per eye */
    /* The frames in flight (pt_submit), oldest first from `head`, each in its staging slot
     * (device/film_device.h): what collect delivers, and its counters read back (pinned). */
    struct pt_flight {
        int eyes;
        fv_film *films[2];
        fv_stats *stats;
        fv_stage_clock t0;
        fv_buffer counts_host;
    } flight[FV_FILM_DEVICE_SLOTS];
    int head, in_flight;
    fv_kit_counters *counters; /* every frame's, kept (fv_kit_counters_reuse) */
} pt_state;

static void pt_destroy(void *state)
{
    pt_state *st = state;
    if (!st) return;
    if (st->backend) {
        fv_scene_device_destroy(st->dscene);
        /* frames in flight are dropped: nothing queued may outlive the buffers it writes */
        if (st->in_flight) fv_backend_wait(st->backend, "the pt kernel", NULL);
        for (int e = 0; e < 2; e++) fv_film_device_release(st->backend, &st->film[e]);
        fv_buffer_release(st->backend, &st->counts);
        for (int k = 0; k < FV_FILM_DEVICE_SLOTS; k++) fv_pinned_release(st->backend, &st->flight[k].counts_host);
        fv_backend_destroy(st->backend);
    }
    fv_scene_export_destroy(st->flat);
    fv_kit_counters_destroy(st->counters);
    free(st);
}

static fv_status pt_create(const fv_scene *scene, fv_params *params, fv_device device, const fv_log *log, void **state, fv_error *err)
{
    pt_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    st->device = device;
    fv_status s = fv_path_read_opts(params, &st->opt, err);
    int nb = s == FV_OK ? fv_blocks_count(st->opt.spp) : 1;
    if (s == FV_OK) s = fv_params_int(params, "block_first", 0, 0, nb - 1, &st->block_first, err);
    if (s == FV_OK) s = fv_params_int(params, "block_count", nb - st->block_first, 1, nb - st->block_first, &st->block_count, err);
    if (s == FV_OK && device != FV_DEVICE_CPU && st->block_count != nb)
        s = fv_error_set(err, FV_ERR_INVALID, "parameters block_first/block_count: only the cpu device renders a range of sample blocks");
    if (s == FV_OK && device != FV_DEVICE_CPU) s = fv_scene_export_create(scene, &st->flat, err);
    if (s == FV_OK && device != FV_DEVICE_CPU) s = fv_backend_create(device, &st->backend, err);
    if (s == FV_OK && device != FV_DEVICE_CPU) s = fv_scene_device_create(st->backend, fv_scene_export_view(st->flat), &st->dscene, err);
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
    double *sums; /* the range's double sums, when the film has them */
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
    const int nb = fv_blocks_count(opt->spp), b0 = j->st->block_first, b1 = b0 + j->st->block_count;
    int range_spp = 0;
    for (int b = b0; b < b1; b++) range_spp += fv_blocks_samples(opt->spp, b);
    uint64_t rays = 0, bad = 0;
    for (int y = tile->y0; y < tile->y1; y++) {
        for (int x0 = tile->x0; x0 < tile->x1; x0 += 8) {
            int n = tile->x1 - x0 < 8 ? tile->x1 - x0 : 8;
            fv_vec3 sum[8], dir[8];
            fv_path_first_hit first[8];
            fv_rng rng[8];
            fv_hit hits[8];
            bool ok[8];
            fv_blocks_acc acc[8];
            memset(first, 0, sizeof first);
            for (int k = 0; k < n; k++) acc[k].n = 0;
            for (int b = b0; b < b1; b++) {
                const int s0 = b * FV_SAMPLE_BLOCK, s1 = s0 + fv_blocks_samples(opt->spp, b);
                for (int k = 0; k < n; k++) sum[k] = fv_v3s(0.0f);
                for (int sidx = s0; sidx < s1; sidx++) {
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
                if (nb > 1)
                    for (int k = 0; k < n; k++) fv_blocks_acc_push(&acc[k], sum[k].x, sum[k].y, sum[k].z);
            }
            for (int k = 0; k < n; k++) {
                size_t pix = (size_t)y * (size_t)w + (size_t)(x0 + k);
                double tot[3] = {sum[k].x, sum[k].y, sum[k].z};
                fv_vec3 v;
                if (nb == 1) {
                    /* finite samples can still sum past the float range */
                    v = fv_kit_guard(fv_scale(sum[k], 1.0f / (float)opt->spp), &bad);
                } else {
                    float c[3];
                    fv_blocks_acc_total(&acc[k], tot);
                    bad += (uint64_t)fv_blocks_pixel(tot, range_spp, c);
                    v = fv_v3(c[0], c[1], c[2]);
                }
                j->out.color[3 * pix] = v.x;
                j->out.color[3 * pix + 1] = v.y;
                j->out.color[3 * pix + 2] = v.z;
                if (j->sums) j->sums[3 * pix] = tot[0], j->sums[3 * pix + 1] = tot[1], j->sums[3 * pix + 2] = tot[2];
                const fv_path_first_hit *f = &first[k];
                if (b0 == 0) fv_film_store_first_hit(&j->out, pix, f->hit, f->t, f->p, f->n, f->albedo, f->obj);
            }
        }
    }
    fv_kit_count(j->counters, tile->thread, FV_KIT_RAYS, rays);
    fv_kit_count(j->counters, tile->thread, FV_KIT_NAN, bad);
}

/* Queues `eyes` eyes of one frame (1, or both of a stereo pair) on a device backend, the scene
 * brought to the frame's time once: every eye's launch, then the films' and counters' read-back
 * into the next staging slot, then a fence; no host wait (on the portable backend each launch
 * runs at once, with progress and cancel). A failure or a cancel waits for what was queued and
 * leaves nothing of this frame in flight. */
static fv_status pt_submit_device(pt_state *st, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    fv_backend *b = st->backend;
    if (st->in_flight >= FV_FILM_DEVICE_SLOTS) return fv_error_set(err, FV_ERR_INTERNAL, "pt: %d frames in flight already", st->in_flight);
    const int slot = (st->head + st->in_flight) % FV_FILM_DEVICE_SLOTS;
    struct pt_flight *fl = &st->flight[slot];
    fv_pt_pixel_args a[2];
    fv_film_views host[2];
    size_t n[2];
    memset(a, 0, sizeof a);
    fv_status s;
    for (int e = 0; e < eyes; e++)
        if ((s = fv_frame_camera(frames[e].camera, films[e], &a[e].f.cam, err)) != FV_OK) return s;
    fv_backend_calls before;
    fv_backend_calls_get(b, &before);
    fv_backend_set_threads(b, frames[0].threads);
    fv_stage_clock t0 = fv_stage_clock_now();
    if ((s = fv_scene_export_update(st->flat, st->scene, err)) != FV_OK ||
        (s = fv_scene_device_update(st->dscene, fv_scene_export_view(st->flat), err)) != FV_OK)
        return s;
    fv_stage_stop(stats, "scene", t0);
    const size_t count_bytes = (size_t)eyes * FV_PT_COUNTS * sizeof(uint64_t), count_max = 2 * FV_PT_COUNTS * sizeof(uint64_t);
    /* room for a pair in every slot at once, so that no later frame allocates */
    for (int k = 0; k < FV_FILM_DEVICE_SLOTS && s == FV_OK; k++) s = fv_pinned_ensure(b, &st->flight[k].counts_host, count_max, "pt's counters", err);
    if (s != FV_OK || (s = fv_buffer_ensure(b, &st->counts, count_max, "pt's counters", err)) != FV_OK ||
        (s = fv_backend_clear(b, st->counts.p, 0, count_bytes, "pt's counters", err)) != FV_OK)
        return s;
    uint64_t *counts = st->counts.p;
    t0 = fv_stage_clock_now();
    fv_backend_mark(b, 2 * slot);
    bool done = true;
    for (int e = 0; e < eyes && s == FV_OK && done; e++) {
        const fv_camera *cam = frames[e].camera;
        a[e].scene = *fv_scene_device_view(st->dscene);
        a[e].f.seed = frames[e].seed;
        a[e].f.eye = frames[e].eye;
        a[e].f.frame = frames[e].index;
        a[e].f.opt = st->opt;
        host[e] = fv_film_views_of(films[e]);
        n[e] = (size_t)cam->width * (size_t)cam->height;
        fv_stats_add_count(stats, "samples", (double)cam->width * cam->height * st->opt.spp);
        fv_kit_progress prog = {0};
        fv_kit_phase(&prog, &frames[e], 0.0, 1.0);
        const fv_launch_progress lp = {fv_kit_progress_fn, &prog};
        if ((s = fv_film_device_views(b, &st->film[e], &host[e], n[e], &a[e].out, err)) == FV_OK)
            s = fv_backend_launch_progress(b, &fv_pt_pixel_kernel, cam->width, cam->height, &a[e], counts + e * FV_PT_COUNTS, &lp, &done, err);
    }
    fv_backend_mark(b, 2 * slot + 1);
    for (int e = 0; e < eyes && s == FV_OK && done; e++) s = fv_film_device_download_film(b, &st->film[e], slot, films[e], err);
    if (s == FV_OK) s = fv_backend_download(b, fl->counts_host.p, st->counts.p, count_bytes, "pt's counters", err);
    if (s != FV_OK || !done) {
        /* the wait even after a failure: nothing queued may write into a film the caller has back */
        fv_backend_wait(b, "the pt kernel", NULL);
        return s != FV_OK ? s : fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    }
    fv_backend_fence(b, slot);
    fl->eyes = eyes;
    fl->films[0] = films[0], fl->films[1] = eyes == 2 ? films[1] : NULL;
    fl->stats = stats;
    fl->t0 = t0;
    st->in_flight++;
    if (st->device == FV_DEVICE_CUDA) {
        fv_backend_calls after;
        fv_backend_calls_get(b, &after);
        fv_backend_calls_report(stats, &before, &after);
    }
    return FV_OK;
}

/* The oldest frame in flight: its fence waited for, its films and counters delivered. */
static fv_status pt_collect_device(pt_state *st, fv_error *err)
{
    fv_backend *b = st->backend;
    if (!st->in_flight) return fv_error_set(err, FV_ERR_INTERNAL, "pt: no frame in flight");
    const int slot = st->head;
    struct pt_flight *fl = &st->flight[slot];
    st->head = (st->head + 1) % FV_FILM_DEVICE_SLOTS;
    st->in_flight--;
    fv_stats *stats = fl->stats;
    fv_backend_calls before, after;
    fv_backend_calls_get(b, &before);
    const fv_status s = fv_backend_wait_fence(b, slot, "the pt kernel", err);
    fv_backend_calls_get(b, &after);
    if (s != FV_OK) return s;
    uint64_t rays = 0, bad = 0;
    const uint64_t *c = fl->counts_host.p;
    for (int e = 0; e < fl->eyes; e++) {
        fv_film_device_deliver_film(b, &st->film[e], slot, fl->films[e]);
        rays += c[e * FV_PT_COUNTS + FV_PT_COUNT_RAYS], bad += c[e * FV_PT_COUNTS + FV_PT_COUNT_NAN];
    }
    fv_stage_stop(stats, "trace", fl->t0);
    fv_stats_add_count(stats, "rays", (double)rays);
    fv_stats_add_count(stats, "nan_samples", (double)bad);
    if (st->device == FV_DEVICE_CUDA) {
        fv_stats_add_ms(stats, "kernel", fv_backend_elapsed_ms(b, 2 * slot, 2 * slot + 1));
        fv_stats_add_count(stats, "host_syncs", 1.0);
        fv_backend_calls_report(stats, &before, &after);
    }
    return FV_OK;
}

/* A device frame rendered now: submitted, then collected. */
static fv_status pt_render_device(pt_state *st, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    const fv_status s = pt_submit_device(st, eyes, frames, films, stats, err);
    return s == FV_OK ? pt_collect_device(st, err) : s;
}

static fv_status pt_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    pt_state *st = state;
    if (st->device != FV_DEVICE_CPU) return pt_render_device(st, 1, frame, &film, stats, err);
    const fv_camera *cam = frame->camera;
    pt_job j;
    memset(&j, 0, sizeof j);
    fv_status s = fv_frame_camera(cam, film, &j.cam, err);
    if (s != FV_OK) return s;
    if (!(j.counters = fv_kit_counters_reuse(&st->counters))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    j.st = st;
    j.frame = frame;
    j.out = fv_film_views_of(film);
    j.sums = fv_film_sums(film);
    fv_kit_progress prog = {0};
    fv_kit_phase(&prog, frame, 0.0, 1.0);
    fv_stage_clock t0 = fv_stage_clock_now();
    bool done = fv_parallel_tiles(cam->width, cam->height, frame->threads, pt_tile, &j, fv_kit_progress_fn, &prog);
    fv_stage_stop(stats, "trace", t0);
    fv_kit_report(j.counters, stats);
    int range_spp = 0;
    for (int b = st->block_first; b < st->block_first + st->block_count; b++) range_spp += fv_blocks_samples(st->opt.spp, b);
    fv_stats_add_count(stats, "samples", (double)cam->width * cam->height * range_spp);
    return done ? FV_OK : fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
}

/* A stereo frame: on a device both eyes at once (one host wait on CUDA); on the CPU one after the
 * other, as two render calls do. */
static fv_status pt_render_pair(void *state, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    pt_state *st = state;
    if (st->device != FV_DEVICE_CPU) return pt_render_device(st, 2, frames, films, stats, err);
    fv_status s = pt_render(state, &frames[0], films[0], stats, err);
    return s == FV_OK ? pt_render(state, &frames[1], films[1], stats, err) : s;
}

/* A frame queued (docs/gpu.md, "Frames in flight"): on a device without a host wait; on the CPU
 * rendered now, collect then only hands it over. */
static fv_status pt_submit(void *state, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    pt_state *st = state;
    if (st->device != FV_DEVICE_CPU) return pt_submit_device(st, eyes, frames, films, stats, err);
    return eyes == 2 ? pt_render_pair(state, frames, films, stats, err) : pt_render(state, frames, films[0], stats, err);
}

static fv_status pt_collect(void *state, fv_error *err)
{
    pt_state *st = state;
    return st->device != FV_DEVICE_CPU ? pt_collect_device(st, err) : FV_OK;
}

/* transport/path.c reads the first three (fv_path_read_opts), this file the blocks: 2^20 samples
 * are 16384 blocks of FV_SAMPLE_BLOCK, the most any spp makes. */
static const fv_param_info k_params[] = {
    FV_PARAM_INT("spp", "16", 1, 1 << 20, "samples per pixel"),
    FV_PARAM_INT("max_depth", "8", 1, 1024, "path vertices that gather light, 1 = direct light only"),
    FV_PARAM_INT("rr_depth", "3", 1, 1024, "depth from which Russian roulette may end paths"),
    FV_PARAM_INT("block_first", "0", 0, (1 << 20) / FV_SAMPLE_BLOCK - 1,
                 "first block of 64 samples rendered (cpu; a still split over MPI ranks), below the spp's blocks"),
    {.key = "block_count", .type = FV_PARAM_INT, .def_note = "all from block_first", .min = 1, .max = (1 << 20) / FV_SAMPLE_BLOCK,
     .help = "blocks rendered, at most those from block_first on; the image is their mean"},
};

const fv_technique_class fv_technique_pt = {
    .name = "pt",
    .summary = "reference path tracer: NEE + MIS, Russian roulette (ground truth)",
    .family = FV_FAMILY_PT,
    .baseline = NULL, /* the reference every chain of baselines ends at */
    FV_CLASS_PARAMS(k_params),
    /* The viewer starts it at 1 spp and averages its frames while nothing moves. */
    .main = {"spp", {"1", "2", "4", "8", "16", "32", "64"}, true},
    .create_on = pt_create,
    .devices = (1u << FV_DEVICE_PORTABLE) | (1u << FV_DEVICE_CUDA),
    .render = pt_render,
    .render_pair = pt_render_pair,
    .submit = pt_submit,
    .collect = pt_collect,
    .destroy = pt_destroy,
    /* furnace: 1 - 0.5^9 with 8 vertices, Russian roulette unbiased */
    .test_params = "spp=64",
    .furnace_radiance = 0.998046875,
    .furnace_tolerance = 0.02,
    .spp_param = "spp",
};
