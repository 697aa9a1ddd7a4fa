/* fovea — `pt`, the reference unidirectional path tracer: the ground truth every technique is
 * measured against. The integrator is the shared kernel (transport/path.h); this file only lays
 * the camera samples out: pixels eight at a time as ray packets, `spp` jittered samples each.
 */
#include <stdlib.h>
#include <string.h>
#include "technique/class.h"
#include "technique/kit.h"
#include "transport/path.h"

typedef struct pt_state {
    const fv_scene *scene;
    fv_path_opts opt;
} pt_state;

static fv_status pt_create(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err)
{
    pt_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    fv_status s = fv_path_read_opts(params, &st->opt, err);
    if (s != FV_OK) {
        free(st);
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

static fv_status pt_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    const pt_state *st = state;
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

static void pt_destroy(void *state) { free(state); }

const fv_technique_class fv_technique_pt = {
    .name = "pt",
    .summary = "reference path tracer: NEE + MIS, Russian roulette (ground truth)",
    .params_help = "spp=int (16): samples per pixel\n"
                   "max_depth=int (8): path vertices that gather light, 1 = direct light only\n"
                   "rr_depth=int (3): depth from which Russian roulette may end paths\n",
    .create = pt_create,
    .render = pt_render,
    .destroy = pt_destroy,
    /* furnace: 1 - 0.5^9 with 8 vertices, Russian roulette unbiased */
    .test_params = "spp=64",
    .furnace_radiance = 0.998046875,
    .furnace_tolerance = 0.02,
    .spp_param = "spp",
};
