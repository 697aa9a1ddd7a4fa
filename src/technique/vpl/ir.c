/* fovea — `ir` and `ir-low`: classic instant radiosity, the baselines of Foveated Instant Radiosity
 * (Sec. 4: IR with 1024^2 VPL shadow maps and IR' with 128^2, both with 2000 VPLs, all regenerated
 * every frame, every VPL shading every pixel).
 *
 * ir's visibility is exact: shadow rays to the VPLs, eight per Embree packet (a shadow map of
 * unlimited resolution). ir-low builds a 128^2 depth cube map per VPL every frame (cubemap.h:
 * rasterised like the paper's shadow maps, or by casting rays in large scenes) and looks
 * visibility up in it; maps are built and used in batches so memory stays bounded whatever the VPL count.
 * Both add the family's direct light (direct.h) and use the same clamped geometry term (vpl_gather.h).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "core/stage_time.h"
#include "core/alloc.h"
#include "scene/light.h"
#include "technique/class.h"
#include "technique/vpl/lightvpl.h"
#include "technique/vpl/vpl_shade.h"

/* ir-low's maps are built this many at a time (about 100 MB of 128^2 maps). */
#define IR_LOW_BATCH_BYTES (100u << 20)

typedef struct ir_state {
    const fv_scene *scene;
    bool low; /* ir-low: cube maps */
    int vpls, bounces, area_samples, cube_size;
    int cube_filter;
    int show; /* fv_vpl_show */
    float clamp;
    fv_vpl_frame vf;
    fv_vpl_light *lights;
    int *ident;       /* 0 .. vpls-1, the lists of one tile */
    fv_cubemaps *maps; /* ir-low: one batch */
    int batch;
    fv_vec3 *pos, *nrm; /* ir-low: a batch's centres for build_many */
    int *slots;
} ir_state;

static void ir_destroy(void *state)
{
    ir_state *st = state;
    if (!st) return;
    fv_vpl_frame_free(&st->vf);
    free(st->lights);
    free(st->ident);
    fv_cubemaps_destroy(st->maps);
    free(st->pos);
    free(st->nrm);
    free(st->slots);
    free(st);
}

static fv_status ir_create_common(const fv_scene *scene, fv_params *params, bool low, void **state, fv_error *err)
{
    ir_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    st->low = low;
    double clamp = 0.03;
    int cube_build = FV_CUBE_BUILD_AUTO;
    fv_status s;
    if ((s = fv_params_int(params, "vpls", 2000, 1, 1000000, &st->vpls, err)) != FV_OK ||
        (s = fv_params_int(params, "bounces", 7, 1, 64, &st->bounces, err)) != FV_OK ||
        (s = fv_params_int(params, "area_samples", 16, 1, 4096, &st->area_samples, err)) != FV_OK ||
        (s = fv_params_float(params, "clamp", 0.03, 0.0, 1.0, &clamp, err)) != FV_OK ||
        (s = fv_params_choice(params, "show", 0, fv_vpl_show_names, &st->show, err)) != FV_OK)
        goto fail;
    st->clamp = (float)clamp;
    if (low) {
        if ((s = fv_params_int(params, "cube_size", 128, FV_CUBE_MIN_SIZE, FV_CUBE_MAX_SIZE, &st->cube_size, err)) != FV_OK ||
            (s = fv_params_choice(params, "cube_filter", 0, fv_cube_filter_names, &st->cube_filter, err)) != FV_OK ||
            (s = fv_params_choice(params, "cube_build", FV_CUBE_BUILD_AUTO, fv_cube_build_names, &cube_build, err)) != FV_OK)
            goto fail;
        size_t per_map = 6u * (size_t)st->cube_size * (size_t)st->cube_size * sizeof(float);
        size_t batch = IR_LOW_BATCH_BYTES / per_map;
        st->batch = (int)(batch < 1 ? 1 : batch > (size_t)st->vpls ? (size_t)st->vpls : batch);
        if ((s = fv_vpl_cubemaps_create(st->batch, st->cube_size, &st->maps, err)) != FV_OK) goto fail;
        fv_cubemaps_set_build(st->maps, (fv_cube_build)cube_build);
        st->pos = malloc((size_t)st->batch * sizeof *st->pos);
        st->nrm = malloc((size_t)st->batch * sizeof *st->nrm);
        st->slots = malloc((size_t)st->batch * sizeof *st->slots);
        if (!st->pos || !st->nrm || !st->slots) {
            s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (int i = 0; i < st->batch; i++) st->slots[i] = i;
    }
    st->lights = malloc((size_t)st->vpls * sizeof *st->lights);
    st->ident = malloc((size_t)st->vpls * sizeof *st->ident);
    if (!st->lights || !st->ident) {
        s = fv_error_set(err, FV_ERR_NOMEM, "out of memory for %d VPLs", st->vpls);
        goto fail;
    }
    for (int i = 0; i < st->vpls; i++) st->ident[i] = i;
    *state = st;
    return FV_OK;
fail:
    ir_destroy(st);
    return s;
}

static fv_status ir_create(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err)
{
    (void)log;
    return ir_create_common(scene, params, false, state, err);
}

static fv_status ir_low_create(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err)
{
    (void)log;
    return ir_create_common(scene, params, true, state, err);
}

/* A stage's time and serial part summed over ir-low's batches (none: 0 ms, 0 serial). */
static void add_batches(fv_stats *stats, const fv_stats *sum, const char *stage)
{
    const double serial = fv_stats_get_serial_ms(sum, stage);
    fv_stats_add_ms(stats, stage, fv_stats_get_ms(sum, stage));
    fv_stats_add_serial_ms(stats, stage, serial > 0.0 ? serial : 0.0);
}

static fv_status ir_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    ir_state *st = state;
    const fv_scene *s = st->scene;
    fv_vpl_frame *vf = &st->vf;
    fv_status status = fv_vpl_frame_begin(vf, s, frame, film, stats, err);
    if (status != FV_OK) return status;

    /* The same VPLs for both eyes of a frame: they depend on the frame, not the eye. */
    fv_stage_clock t1 = fv_stage_clock_now();
    int64_t walks = 0;
    int n = fv_vpl_from_light_walks(s, frame->seed, (uint64_t)frame->index, st->vpls, st->bounces, st->lights, &walks, &vf->rays);
    fv_stage_clock t2 = fv_stage_clock_now();
    fv_stage_add(stats, "vpls", t1, t2);

    fv_vpl_gather g = {s, st->lights, NULL, FV_CUBE_NEAREST, 0.0f};
    const float c = fv_vpl_clamp_distance(s, st->clamp);
    g.clamp2 = c * c;
    bool ok = true;
    if (!st->low) {
        fv_kit_phase(&vf->prog, frame, 0.0, 0.1);
        ok = fv_vpl_pass_direct(s, &vf->gb, frame, st->area_samples, vf->direct, vf->counters, &vf->prog);
        fv_stage_clock t3 = fv_stage_clock_now();
        fv_stage_add(stats, "direct", t2, t3);
        int offset[2] = {0, n};
        fv_vpl_tiles all = {1, 1, st->ident, offset};
        fv_kit_phase(&vf->prog, frame, 0.1, 0.9);
        if (ok) ok = fv_vpl_pass_indirect(&g, &vf->gb, &all, frame->threads, vf->indirect, vf->counters, &vf->prog);
        fv_stage_stop(stats, "shading", t3);
    } else {
        /* ir-low: a batch of maps is built, every pixel gathers from it, then the next batch; the
         * direct pass and every batch in one parallel region (docs/threads.md): each parallel step
         * is a work-sharing loop of the team whose barrier orders it before the next, each serial
         * step (a batch's centres, the progress phase, the clocks) is done by the thread that opened
         * the region while the others wait at the barrier after it. Same sums in the same order as
         * a region per pass: a pixel's batches are added in batch order, each by one thread. */
        g.maps = st->maps;
        g.filter = (fv_cube_filter)st->cube_filter;
        fv_stats cube = {0}, shade = {0}; /* the batches' sums, stage by stage */
        int built = 0;
        fv_tri_soup *soup = NULL; /* the frame's triangles (the pool's, refreshed), rasterised into every batch's maps */
        status = n > 0 ? fv_cubemaps_prepare(st->maps, s, &soup, err) : FV_OK;
        fv_team_progress tp;
        fv_team_progress_init(&tp, fv_kit_progress_fn, &vf->prog);
        fv_stage_clock t3 = t2, ta = t2, tb = t2;
        fv_kit_phase(&vf->prog, frame, 0.0, 0.1);
        if (status == FV_OK) {
            fv_region_begin();
#pragma omp parallel num_threads(fv_thread_count(frame->threads))
            {
                bool go = fv_vpl_pass_direct_team(s, &vf->gb, frame, st->area_samples, vf->direct, vf->counters, &tp);
#pragma omp master
                {
                    t3 = fv_stage_clock_now();
                    fv_stage_add(stats, "direct", t2, t3);
                }
                /* every thread reads `status` after the barrier that follows its only writer */
                for (int b0 = 0; go && b0 < n; b0 += st->batch) {
                    const int m = n - b0 < st->batch ? n - b0 : st->batch;
#pragma omp master
                    {
                        const double ts = fv_time_ms();
                        ta = fv_stage_clock_now();
                        for (int k = 0; k < m; k++) {
                            st->lights[b0 + k].map = k;
                            st->pos[k] = st->lights[b0 + k].p;
                            st->nrm[k] = st->lights[b0 + k].n;
                        }
                        status = fv_cubemaps_check(st->maps, st->slots, st->pos, st->nrm, m, err);
                        fv_kit_phase(&vf->prog, frame, 0.1 + 0.9 * b0 / n, 0.9 * m / n);
                        fv_region_serial(fv_time_ms() - ts);
                    }
#pragma omp barrier
                    if (status != FV_OK) break;
                    fv_cubemaps_build_team(st->maps, s, soup, st->slots, st->pos, st->nrm, m);
#pragma omp master
                    {
                        built += m;
                        tb = fv_stage_clock_now();
                        fv_stage_add(&cube, "cube_maps", ta, tb);
                    }
                    int offset[2] = {0, m};
                    fv_vpl_tiles batch = {1, 1, st->ident + b0, offset};
                    go = fv_vpl_pass_indirect_team(&g, &vf->gb, &batch, vf->indirect, vf->counters, &tp);
#pragma omp master
                    fv_stage_stop(&shade, "shading", tb);
                }
#pragma omp master
                ok = go;
            }
            fv_region_end();
        }
        add_batches(stats, &cube, "cube_maps");
        add_batches(stats, &shade, "shading");
        fv_stats_add_count(stats, "cube_maps_built", built);
    }
    if (status == FV_OK && ok) {
        fv_stats_add_count(stats, "vpls", n);
        fv_stats_add_count(stats, "walks", (double)walks);
    }
    return fv_vpl_frame_end(vf, (fv_vpl_show)st->show, ok, status, stats, err);
}

#define IR_COMMON_PARAMS                                                                                              \
    FV_PARAM_INT("vpls", "2000", 1, 1000000, "VPLs from light random walks, all regenerated every frame"),                \
        FV_PARAM_INT("bounces", "7", 1, 64, "light-path vertices that become VPLs (1 = one-bounce indirect light)"),      \
        FV_VPL_AREA_SAMPLES_PARAM, FV_VPL_CLAMP_PARAM, FV_VPL_SHOW_PARAM

static const fv_param_info k_ir_params[] = {IR_COMMON_PARAMS};
static const fv_param_info k_ir_low_params[] = {
    IR_COMMON_PARAMS,
    FV_PARAM_INT("cube_size", "128", FV_CUBE_MIN_SIZE, FV_CUBE_MAX_SIZE, "texels per cube-map face edge"),
    FV_CUBE_FILTER_PARAM("cube-map lookup (pcf: 2x2 percentage-closer)"),
    FV_CUBE_BUILD_PARAM,
};

const fv_technique_class fv_technique_ir = {
    .name = "ir",
    .summary = "instant radiosity (Keller): VPLs from light walks, exact shadow rays to every VPL (FIR's IR baseline)",
    .family = FV_FAMILY_VPL,
    .baseline = "pt", /* the reference of the fir-* benchmarks (docs/instant-radiosity.md) */
    FV_CLASS_PARAMS(k_ir_params),
    .main = {"vpls", {FV_VPL_STEPS, "8000"}, false},
    .create = ir_create,
    .render = ir_render,
    .destroy = ir_destroy,
    /* furnace: every bounce through VPLs; the clamp loses a little near each VPL */
    .test_params = "vpls=64,area_samples=2",
    .furnace_params = "vpls=2000,area_samples=16",
    .furnace_radiance = 1.0,
    .furnace_tolerance = 0.03,
    .spp_instead = FV_VPL_SPP_INSTEAD,
    .bench_scene = FV_VPL_BENCH_SCENE,
};

const fv_technique_class fv_technique_ir_low = {
    .name = "ir-low",
    .summary = "instant radiosity with a 128^2 depth cube map per VPL rebuilt every frame (FIR's IR' baseline)",
    .family = FV_FAMILY_VPL,
    .baseline = "ir", /* FIR's IR' beside its IR: the same VPLs, visibility from 128^2 maps */
    FV_CLASS_PARAMS(k_ir_low_params),
    .main = {"vpls", {FV_VPL_STEPS, "8000"}, false},
    .create = ir_low_create,
    .render = ir_render,
    .destroy = ir_destroy,
    .test_params = "vpls=32,area_samples=2,cube_size=16",
    .furnace_params = "vpls=2000,area_samples=16,cube_size=32",
    .furnace_radiance = 1.0,
    .furnace_tolerance = 0.03,
    .spp_instead = FV_VPL_SPP_INSTEAD,
    .bench_scene = FV_VPL_BENCH_SCENE,
};
