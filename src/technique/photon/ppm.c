/* fovea — `ppm`, stochastic progressive photon mapping (Knaus & Zwicker, "Progressive Photon
 * Mapping: A Probabilistic Approach", ACM TOG 2011): the photon reference that converges to the
 * truth (docs/photon-mapping.md, "ppm").
 *
 * A pass is plain photon mapping with its own radius: an independent photon map (its own random
 * stream), a fresh jittered eye path per pixel (so pixels are averaged over their area, as pt
 * does), the disc estimate of pm_gather.c. Pass i's radius follows Eq. 15 (ppm.h): the variance of a
 * pass grows as its radius shrinks, slowly enough that the plain average of the passes' estimates
 * converges (Sec. 4) while the bias, which the radius drives (boundaries, blur into shadows),
 * vanishes. Unlike pbrt's SPPM the radius is one per pass, not one per pixel: the probabilistic
 * formulation needs no per-pixel statistics, and every pass stays pm's estimator exactly.
 *
 * Everything is pm's: photon_trace.c traces, photon_map.c grids (a cell of the pass's radius),
 * pm_gather.c follows eye paths and gathers; no filter, which would be a bias of its own. Each eye is
 * rendered on its own, each frame from scratch.
 *
 * Passes are summed in double in blocks of FV_SAMPLE_BLOCK, the blocks along core/blocks.h's fixed
 * tree (up to 64 passes: the plain sum, as always); block_first/block_count render a range of
 * blocks and leave its double sums in the film (film/film_sums.h), which is how an MPI job deals
 * passes to ranks and still adds up to the one-process image bit for bit (docs/distributed.md).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/blocks.h"
#include "core/parallel.h"
#include "core/stage_time.h"
#include "film/film_sums.h"
#include "technique/class.h"
#include "technique/kit.h"
#include "technique/photon/pm_gather.h"
#include "technique/photon/photon_trace.h"
#include "technique/photon/ppm.h"

/* The photon stream of pass i (core/rng.h): above every pm pass's (100 + pass). */
#define PPM_STREAM_BASE (1ULL << 32)

/* Block bounds: 10^7 passes are 156250 blocks of FV_SAMPLE_BLOCK, the most any passes makes. */
#define PPM_MAX_PASSES 10000000
#define PPM_MAX_BLOCKS ((PPM_MAX_PASSES + FV_SAMPLE_BLOCK - 1) / FV_SAMPLE_BLOCK)

typedef struct ppm_opts {
    int photons;      /* per pass */
    int passes;
    double alpha;     /* Eq. 15 */
    double radius;    /* r_1; 0: Eq. 8 */
    int max_depth, eye_depth;
    int block_first, block_count; /* the blocks of passes rendered */
} ppm_opts;

typedef struct ppm_state {
    const fv_scene *scene;
    ppm_opts o;
    fv_photon_map map;
    /* Kept from frame to frame, so that a warmed-up frame allocates nothing (docs/threads.md, "No
     * allocation in a frame"): the light tracer's blocks, the counters, and the images of sums
     * (img_n pixels, 3 doubles each): the running one and the block counter's nodes, at most one
     * per bit (img_take, img_give). */
    fv_photon_room *room;
    fv_kit_counters *counters;
    double *img[FV_BLOCKS_MAX_DEPTH + 1];
    bool img_used[FV_BLOCKS_MAX_DEPTH + 1];
    size_t img_n;
} ppm_state;

/* A zeroed image of n pixels' sums from the state's (allocated on first use), NULL when out of
 * memory. Images are resized only while none is taken (at a frame's start). */
static double *img_take(ppm_state *st, size_t n)
{
    if (n != st->img_n) {
        for (int k = 0; k <= FV_BLOCKS_MAX_DEPTH; k++) free(st->img[k]), st->img[k] = NULL, st->img_used[k] = false;
        st->img_n = n;
    }
    for (int k = 0; k <= FV_BLOCKS_MAX_DEPTH; k++) {
        if (st->img_used[k]) continue;
        if (!st->img[k] && !(st->img[k] = fv_alloc_array(n * 3, sizeof(double)))) return NULL;
        memset(st->img[k], 0, n * 3 * sizeof(double));
        st->img_used[k] = true;
        return st->img[k];
    }
    return NULL;
}

/* Gives back an image img_take returned (NULL: nothing). */
static void img_give(ppm_state *st, const double *img)
{
    for (int k = 0; img && k <= FV_BLOCKS_MAX_DEPTH; k++)
        if (st->img[k] == img) st->img_used[k] = false;
}

static fv_status read_opts(fv_params *p, ppm_opts *o, fv_error *err)
{
    fv_status s;
    memset(o, 0, sizeof *o);
    if ((s = fv_params_int(p, "photons", 100000, 1, 500000000, &o->photons, err)) ||
        (s = fv_params_int(p, "passes", 64, 1, PPM_MAX_PASSES, &o->passes, err)) ||
        (s = fv_params_float(p, "alpha", 2.0 / 3.0, 0.0, 1.0, &o->alpha, err)) ||
        (s = fv_photon_read_radius(p, "initial gather radius", &o->radius, err)) ||
        (s = fv_params_int(p, "max_depth", 8, 1, 64, &o->max_depth, err)) || (s = fv_params_int(p, "eye_depth", 8, 1, 64, &o->eye_depth, err)))
        return s;
    const int nb = fv_blocks_count(o->passes);
    if ((s = fv_params_int(p, "block_first", 0, 0, nb - 1, &o->block_first, err)) ||
        (s = fv_params_int(p, "block_count", nb - o->block_first, 1, nb - o->block_first, &o->block_count, err)))
        return s;
    /* The readers' bounds are inclusive; Eq. 15 needs both ends open: alpha = 0 would shrink the
     * radius as fast as the photons accumulate (no variance reduction), 1 would never shrink it. */
    if (!(o->alpha > 0.0 && o->alpha < 1.0))
        return fv_error_set(err, FV_ERR_INVALID, "parameter alpha=%g: must lie strictly between 0 and 1 (2/3 by default)", o->alpha);
    return FV_OK;
}

static fv_status ppm_create(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err)
{
    (void)log;
    ppm_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    fv_photon_map_init(&st->map);
    fv_status s = read_opts(params, &st->o, err);
    if (s == FV_OK && !(st->room = fv_photon_room_create())) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (s != FV_OK) {
        fv_photon_room_destroy(st->room);
        free(st);
        return s;
    }
    *state = st;
    return FV_OK;
}

static void ppm_destroy(void *state)
{
    ppm_state *st = state;
    if (!st) return;
    fv_photon_map_free(&st->map);
    fv_photon_room_destroy(st->room);
    fv_kit_counters_destroy(st->counters);
    for (int k = 0; k <= FV_BLOCKS_MAX_DEPTH; k++) free(st->img[k]);
    free(st);
}

typedef struct pass_ctx {
    const ppm_state *st;
    const fv_frame *frame;
    fv_camera_basis cam;
    fv_film_views out;
    double *sum;            /* per pixel and channel, over the passes so far */
    int pass;
    float r, norm;          /* this pass's radius and 1 / (pi r^2) */
    fv_kit_counters *counters;
} pass_ctx;

/* One pass's estimate for every pixel of the tile, added to the sums. */
static void pass_tile(void *ctx, const fv_tile *tile)
{
    pass_ctx *c = ctx;
    const int w = c->cam.width;
    uint64_t rays = 0, bad = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++) {
            size_t pix = (size_t)y * w + x;
            fv_rng rng = fv_kit_rng(c->frame, pix, (uint64_t)c->pass);
            float jx = fv_rng_next(&rng), jy = fv_rng_next(&rng);
            fv_pm_hit h;
            fv_pm_eye_path(c->st->scene, c->cam.pos, fv_camera_dir(&c->cam, (float)x + jx, (float)y + jy), c->st->o.eye_depth, &rng, &h);
            rays++;
            fv_vec3 L = h.emitted;
            if (h.hit) L = fv_add(L, fv_mul(h.weight, fv_scale(fv_pm_gather(c->st->scene, &c->st->map, &h, c->r, NULL), c->norm)));
            L = fv_kit_guard(L, &bad);
            double *s = &c->sum[3 * pix];
            s[0] += L.x, s[1] += L.y, s[2] += L.z;
            if (c->pass == 0) fv_film_store_first_hit(&c->out, pix, h.first_obj >= 0, h.first_t, h.first_p, h.first_n, h.albedo, h.first_obj);
        }
    fv_kit_count(c->counters, tile->thread, FV_KIT_RAYS, rays);
    fv_kit_count(c->counters, tile->thread, FV_KIT_NAN, bad);
}

static fv_status ppm_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    ppm_state *st = state;
    const int w = fv_film_width(film), h = fv_film_height(film), passes = st->o.passes;
    const int nb = fv_blocks_count(passes), b0 = st->o.block_first, b1 = b0 + st->o.block_count;
    const int p0 = b0 * FV_SAMPLE_BLOCK, p1 = b1 == nb ? passes : b1 * FV_SAMPLE_BLOCK, range = p1 - p0;
    pass_ctx c;
    memset(&c, 0, sizeof c);
    fv_status rc = fv_frame_camera(frame->camera, film, &c.cam, err);
    if (rc != FV_OK) return rc;
    const size_t n = (size_t)w * h;
    c.st = st;
    c.frame = frame;
    c.out = fv_film_views_of(film);
    for (int k = 0; k <= FV_BLOCKS_MAX_DEPTH; k++) st->img_used[k] = false;
    c.sum = img_take(st, n);
    c.counters = fv_kit_counters_reuse(&st->counters);
    /* Finished blocks as a binary counter of node images (core/blocks.h): at most one per bit. */
    double *node[FV_BLOCKS_MAX_DEPTH] = {0};
    int node_size[FV_BLOCKS_MAX_DEPTH], nodes = 0;
    if (!c.sum || !c.counters) {
        img_give(st, c.sum);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for %dx%d progressive photon mapping", w, h);
    }
    fv_vec3 lo, hi;
    fv_scene_bounds(st->scene, &lo, &hi);
    const double r1 = st->o.radius > 0.0 ? st->o.radius : fv_photon_radius_eq8(lo, hi, w, h);
    double r2 = r1 * r1;
    for (int pass = 0; pass < p0; pass++) r2 = fv_ppm_next_r2(r2, st->o.alpha, pass + 1); /* Eq. 15 up to the range */
    fv_kit_progress prog = {0};
    uint64_t rays = 0;
    double photons = 0.0;
    /* the passes' stage times and serial parts, summed (core/stage_time.h) */
    fv_stats pass_sum;
    fv_stats_clear(&pass_sum);
    for (int pass = p0; pass < p1 && rc == FV_OK; pass++) {
        /* Progress: each pass an equal share; in it, tracing light the first 40%, pixels the rest. */
        const double base = (double)(pass - p0) / range, span = 1.0 / range;
        c.pass = pass;
        c.r = (float)sqrt(r2);
        c.norm = 1.0f / (FV_PI * c.r * c.r);
        fv_kit_phase(&prog, frame, base, 0.4 * span);
        fv_stage_clock t0 = fv_stage_clock_now();
        fv_photon_map_clear(&st->map);
        fv_photon_job job = {.scene = st->scene, .count = st->o.photons, .seed = frame->seed, .frame = frame->index,
                             .max_depth = st->o.max_depth, .threads = frame->threads, .stream = PPM_STREAM_BASE + (uint64_t)pass,
                             .progress = &prog, .room = st->room};
        rc = fv_photon_trace_lights(&job, FV_TRACE_ALL, &st->map, &rays, err);
        if (rc == FV_OK) rc = fv_photon_map_build_mt(&st->map, c.r, frame->threads, err);
        photons += st->map.n;
        fv_stage_stop(&pass_sum, "light_tracing", t0);
        if (rc != FV_OK) break;
        fv_kit_phase(&prog, frame, base + 0.4 * span, 0.6 * span);
        t0 = fv_stage_clock_now();
        if (!fv_parallel_tiles(w, h, frame->threads, pass_tile, &c, fv_kit_progress_fn, &prog))
            rc = fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
        fv_stage_stop(&pass_sum, "render", t0);
        r2 = fv_ppm_next_r2(r2, st->o.alpha, pass + 1);
        if (nb > 1 && ((pass + 1) % FV_SAMPLE_BLOCK == 0 || pass + 1 == p1)) {
            /* a block done: onto the counter, merged with equal neighbours (left += right) */
            node[nodes] = c.sum;
            node_size[nodes++] = 1;
            while (nodes >= 2 && node_size[nodes - 1] == node_size[nodes - 2]) {
                double *l = node[nodes - 2], *r = node[nodes - 1];
                for (size_t i = 0; i < 3 * n; i++) l[i] += r[i];
                img_give(st, r);
                node_size[nodes - 2] *= 2;
                nodes--;
            }
            c.sum = pass + 1 < p1 ? img_take(st, n) : NULL;
            if (pass + 1 < p1 && !c.sum) rc = fv_error_set(err, FV_ERR_NOMEM, "out of memory for %dx%d progressive photon mapping", w, h);
        }
    }
    if (rc == FV_OK && nb > 1) {
        /* the counter's nodes folded right to left: the tree's order */
        for (int k = nodes - 2; k >= 0; k--) {
            for (size_t i = 0; i < 3 * n; i++) node[k][i] = node[k][i] + node[k + 1][i];
            img_give(st, node[k + 1]);
        }
        img_give(st, c.sum);
        c.sum = node[0];
        nodes = 0;
    }
    double *sums = fv_film_sums(film);
    if (rc == FV_OK && sums) memcpy(sums, c.sum, n * 3 * sizeof *sums);
    if (rc == FV_OK) {
        /* The mean of the passes' estimates (Knaus & Zwicker Eq. 5); finite sums can still
         * overflow float when divided back. */
        uint64_t bad = 0;
        for (size_t i = 0; i < n; i++) {
            fv_vec3 v = fv_kit_guard(fv_v3((float)(c.sum[3 * i] / range), (float)(c.sum[3 * i + 1] / range), (float)(c.sum[3 * i + 2] / range)), &bad);
            c.out.color[3 * i] = v.x, c.out.color[3 * i + 1] = v.y, c.out.color[3 * i + 2] = v.z;
        }
        fv_kit_count(c.counters, 0, FV_KIT_NAN, bad);
    }
    const char *const stages[] = {"light_tracing", "render"};
    for (int k = 0; k < 2; k++) {
        const double serial = fv_stats_get_serial_ms(&pass_sum, stages[k]);
        fv_stats_add_ms(stats, stages[k], fv_stats_get_ms(&pass_sum, stages[k]));
        fv_stats_add_serial_ms(stats, stages[k], serial > 0.0 ? serial : 0.0);
    }
    fv_kit_report(c.counters, stats);
    fv_stats_add_count(stats, "rays", (double)rays);
    fv_stats_add_count(stats, "light_photons", photons);
    fv_stats_add_count(stats, "radius_first", r1);
    fv_stats_add_count(stats, "radius_last", c.r);
    for (int k = 0; k < nodes; k++) img_give(st, node[k]);
    img_give(st, c.sum);
    return rc;
}

/* The furnace at r_1 = 0.25, as pm's (FURNACE_TEST in pm.c): 1 - 0.5^9 whatever the radius below 1,
 * the gather keeping every photon of the disc on the unit sphere. */
static const fv_param_info k_params[] = {
    FV_PARAM_INT("passes", "64", 1, PPM_MAX_PASSES, "passes averaged, each with its own photon map and a jittered eye path per pixel (--spp)"),
    FV_PARAM_INT("photons", "100000", 1, 500000000, "photons per pass"),
    FV_PHOTON_RADIUS_PARAM("gather radius of the first pass, in scene units"),
    /* 2/3 to the last bit: what the reader's default is */
    {.key = "alpha", .type = FV_PARAM_FLOAT, .def = "0.66666666666666663", .min = 0.0, .max = 1.0, .min_open = true, .max_open = true,
     .help = "radius shrinking, r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1) (Eq. 15; 2/3)"},
    FV_PARAM_INT("max_depth", "8", 1, 64, "photon bounces"),
    FV_PARAM_INT("eye_depth", "8", 1, 64, "mirror/glass bounces of eye rays"),
    FV_PARAM_INT("block_first", "0", 0, PPM_MAX_BLOCKS - 1,
                 "first block of 64 passes rendered (a reference split over MPI ranks), below the passes' blocks"),
    {.key = "block_count", .type = FV_PARAM_INT, .def_note = "all from block_first", .min = 1, .max = PPM_MAX_BLOCKS,
     .help = "blocks of passes rendered, at most those from block_first on; the image is their mean"},
};

const fv_technique_class fv_technique_ppm = {
    .name = "ppm",
    .summary = "progressive photon mapping: passes with a shrinking radius averaged, converging to the truth (photon reference)",
    .family = FV_FAMILY_PHOTON,
    .baseline = "pt", /* it converges to the path tracer's image (docs/photon-mapping.md, "ppm") */
    FV_CLASS_PARAMS(k_params),
    /* passes cost linearly and each frame starts afresh: a still view may average its frames */
    .main = {"passes", {"1", "4", "16", "64", "256"}, true},
    .create = ppm_create,
    .render = ppm_render,
    .destroy = ppm_destroy,
    .test_params = "photons=20000,passes=4",
    .furnace_params = "radius=0.25",
    .furnace_radiance = 0.998046875,
    .furnace_tolerance = 0.04,
    .spp_param = "passes",
    .gathers_photons = true,
    .bench_scene = FV_PHOTON_BENCH_SCENE,
};
