/* fovea — `sdf-gt` and `sdf-relaxed` on the portable and CUDA backends (device.h). */
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "device/cuda_backend.h"
#include "kernel/sdf_pixel.h"
#include "technique/kit.h"
#include "technique/sdf/device.h"
#include "technique/sdf/world.h"

struct fv_sdf_device {
    const fv_scene *scene;
    fv_sdf_opts o;
    fv_cuda_sdf *cuda; /* NULL: the portable backend */
};

fv_status fv_sdf_device_create(const fv_scene *scene, const fv_sdf_opts *o, fv_device device, fv_sdf_device **out, fv_error *err)
{
    *out = NULL;
    fv_sdf_device *d = calloc(1, sizeof *d);
    if (!d) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    d->scene = scene;
    d->o = *o;
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
    free(d);
}

/* The counters a pixel adds, in the kit's per-thread slots. */
enum { C_STEPS = FV_KIT_USER0, C_SHADOW = FV_KIT_USER1, C_NORMAL = FV_KIT_USER2, C_EXHAUSTED = FV_KIT_USER3, C_SHADOW_RAYS = FV_KIT_USER4 };

typedef struct tile_job {
    const fv_ksdf_world *world;
    fv_ksdf_frame f;
    fv_film_views out;
    fv_kit_counters *c;
} tile_job;

static void pixel_tile(void *ctx, const fv_tile *tile)
{
    tile_job *j = ctx;
    fv_ksdf_counts c;
    memset(&c, 0, sizeof c);
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++) fv_ksdf_pixel(j->world, &j->f, x, y, &j->out, &c);
    fv_kit_count(j->c, tile->thread, FV_KIT_RAYS, c.rays);
    fv_kit_count(j->c, tile->thread, FV_KIT_NAN, c.nan);
    fv_kit_count(j->c, tile->thread, C_STEPS, c.steps);
    fv_kit_count(j->c, tile->thread, C_EXHAUSTED, c.exhausted);
    fv_kit_count(j->c, tile->thread, C_SHADOW, c.shade.shadow_steps);
    fv_kit_count(j->c, tile->thread, C_NORMAL, c.shade.normal_evals);
    fv_kit_count(j->c, tile->thread, C_SHADOW_RAYS, c.shade.shadow_rays);
}

/* The counters as the CPU pipeline names them (one level: the target). */
static void report(const fv_ksdf_counts *c, double samples, fv_stats *stats)
{
    fv_stats_add_count(stats, "rays", (double)c->rays);
    fv_stats_add_count(stats, "nan_samples", (double)c->nan);
    fv_stats_add_count(stats, "samples", samples);
    fv_stats_add_count(stats, "steps", (double)c->steps);
    fv_stats_add_count(stats, "shadow_steps", (double)c->shade.shadow_steps);
    fv_stats_add_count(stats, "normal_evals", (double)c->shade.normal_evals);
    fv_stats_add_count(stats, "exhausted_rays", (double)c->exhausted);
    fv_stats_add_count(stats, "shadow_rays", (double)c->shade.shadow_rays);
    fv_stats_add_count(stats, "rays_level0", (double)c->rays);
    fv_stats_add_count(stats, "steps_level0", (double)c->steps);
}

fv_status fv_sdf_device_render(fv_sdf_device *d, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    tile_job j;
    memset(&j, 0, sizeof j);
    fv_status s = fv_frame_camera(frame->camera, film, &j.f.cam, err);
    if (s != FV_OK) return s;
    fv_sdf_world world;
    double t0 = fv_time_ms();
    if ((s = fv_sdf_world_build(&world, d->scene, err)) != FV_OK) return s;
    fv_stats_add_ms(stats, "scene", fv_time_ms() - t0);
    const int S = d->o.spp >= 16 ? 4 : d->o.spp >= 4 ? 2 : 1;
    j.world = &world.k;
    j.f.S = S;
    /* a target sample's angular footprint per unit distance, as the CPU pipeline's */
    j.f.eps_k = d->o.hit * (2.0f * j.f.cam.tan_half_x / (float)(j.f.cam.width * S));
    j.f.march = d->o.march;
    j.f.shade = d->o.shade;
    j.out = fv_film_views_of(film);
    const double samples = (double)j.f.cam.width * j.f.cam.height * d->o.spp;
    fv_ksdf_counts c;
    memset(&c, 0, sizeof c);
    if (d->cuda) {
        double kernel_ms = 0.0;
        t0 = fv_time_ms();
        s = fv_cuda_sdf_render(d->cuda, &world.k, &j.f, &j.out, &c, &kernel_ms, err);
        fv_stats_add_ms(stats, "target", fv_time_ms() - t0);
        fv_stats_add_ms(stats, "kernel", kernel_ms);
        fv_sdf_world_free(&world);
        if (s == FV_OK) report(&c, samples, stats);
        return s;
    }
    if (!(j.c = fv_kit_counters_create())) {
        fv_sdf_world_free(&world);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    fv_kit_progress prog = {0};
    fv_kit_phase(&prog, frame, 0.0, 1.0);
    t0 = fv_time_ms();
    fv_parallel_tiles(j.f.cam.width, j.f.cam.height, frame->threads, pixel_tile, &j, fv_kit_progress_fn, &prog);
    fv_stats_add_ms(stats, "target", fv_time_ms() - t0);
    c.rays = fv_kit_sum(j.c, FV_KIT_RAYS);
    c.nan = fv_kit_sum(j.c, FV_KIT_NAN);
    c.steps = fv_kit_sum(j.c, C_STEPS);
    c.exhausted = fv_kit_sum(j.c, C_EXHAUSTED);
    c.shade.shadow_steps = fv_kit_sum(j.c, C_SHADOW);
    c.shade.normal_evals = fv_kit_sum(j.c, C_NORMAL);
    c.shade.shadow_rays = fv_kit_sum(j.c, C_SHADOW_RAYS);
    fv_kit_counters_destroy(j.c);
    fv_sdf_world_free(&world);
    if ((s = fv_kit_phase_end(&prog, err)) != FV_OK) return s;
    report(&c, samples, stats);
    return FV_OK;
}
