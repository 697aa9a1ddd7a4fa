/* fovea — fpm-guided: foveated photon mapping designed for where a CPU spends its time
 * (docs/photon-mapping.md, "fpm-guided"; the measurements that motivate it: docs/results.md).
 *
 * On our CPU a pm frame is mostly camera rays and gathers (about 76%), light tracing about 10%,
 * and pm's fovea error is camera-ray noise through glass, not photon noise. fpm (the paper's
 * method, pm.c) spends its foveation on photons, copies a light photon's flux onto them and is
 * biased. fpm-guided keeps the paper's regions and its maps and spends the budget where the error
 * and the time are:
 *   - eye side: in the focus region (the fovea and the transition of Eq. 6) `fovea_spp` eye paths
 *     per pixel, ramping down to one across the transition with Eq. 6's b(x), each split at its
 *     first dielectric (pm_gather.h) instead of choosing reflection or refraction at random; in the
 *     periphery the gather is made only on a lattice of every `periphery_step`-th pixel, filtered
 *     at that resolution and filled in at full resolution from the first-hit buffers
 *     (filter/lattice.h); the full-resolution filter runs only over the focus region;
 *   - photon side: light photons guided towards the grid cells the focus region's gather discs
 *     touch, their flux divided by the guiding density so the map stays unbiased (guide.h), in
 *     place of fpm's flux-copying foveated photons (M_g), and plain light photons (M_ls), joined
 *     into one map by the balance heuristic over the emission numbers, gathered by every pixel.
 *     Both sets are photon paths traced once through the static objects and kept (M_g until the
 *     gaze moves on to other cells); each frame only the paths that pass a dynamic object are
 *     traced again, so the map is what a full trace of the current scene gives (path_store.h),
 *     not pm-t's static map plus negative photons, which leaves light a moving object blocks
 *     after a bounce and adds noise in its shadow (docs/results.md).
 * Everything else (tracer, grids, gather, filters) is pm's.
 *
 * Stereo: the right eye of a frame reuses the left eye's photon maps (same time, same lights).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/stage_time.h"
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/atrous.h"
#include "filter/demod.h"
#include "filter/lattice.h"
#include "scene/light.h"
#include "technique/class.h"
#include "technique/kit.h"
#include "technique/photon/pm_gather.h"
#include "technique/photon/guide.h"
#include "technique/photon/path_store.h"

typedef struct gd_opts {
    int photons;             /* per frame: light photons (M_ls + M_ld) plus guided ones (M_g, with the pilot) */
    double radius;           /* gather radius; 0: Eq. 8 */
    int max_depth, eye_depth;
    bool filter, split;
    double guided_fraction;  /* share of the photons that are guided (fpm's foveated share, Sec. 4: 40%) */
    double alpha;            /* share of the guided photons the learnt cells get */
    double pilot_fraction;   /* share of the guided budget spent learning the guide */
    double retrace_overlap;  /* keep M_g while at least this share of the focus cells were guided for */
    int fovea_spp;           /* eye paths per fovea pixel */
    int periphery_step;      /* lattice spacing of the periphery's gathers next to the transition */
    int acuity_levels;       /* how often the spacing may double further out, as acuity falls */
    int focus_passes;        /* A-Trous passes over the focus region (0: none) */
} gd_opts;

typedef struct gd_state {
    const fv_scene *scene;
    gd_opts o;
    fv_path_store *ls_store;   /* M_ls's paths, traced once through the static objects */
    fv_path_store *g_store;    /* M_g's paths: guided, traced again when the focus moves on */
    fv_dyn_dirs *dirs;         /* the dynamic objects' bounding spheres this frame */
    bool lights_move;
    fv_photon_map map;         /* this frame's map: both stores' photons, weighted (below) */
    double n_ls, n_g;          /* how many paths each store traced */
    int map_ls_n;              /* how many of map's photons came from M_ls; -1: map must be made */
    bool mg_valid;
    fv_focus_cells *focus;     /* this frame's focus cells */
    fv_focus_cells *mg_focus;  /* the cells M_g was guided towards */
    fv_photon_guide *guide;
    int maps_index;            /* the frame whose light maps are current, -1: none */
    float maps_gamma;
    /* per pixel: first-hit normal and position (filters, fill), albedo and emission of the first
     * surface, the periphery's demodulated reflected light; masks */
    float *nbuf, *pbuf, *alb, *emit, *refl;
    fv_atrous *atrous; /* the filters' scratch, kept from frame to frame */
    uint8_t *need, *focus_px, *lattice_px, *level;
    fv_vec3 *focus_pts; /* focus pass: up to two gather points per sampled pixel (NaN: none) */
    float *box;         /* the lattice's images, then the focus region's box: 9 floats per pixel */
    size_t bufn;
    fv_kit_counters *counters; /* the frame's, zeroed at its start */
} gd_state;

static fv_status read_opts(fv_params *p, gd_opts *o, fv_error *err)
{
    fv_status s;
    memset(o, 0, sizeof *o);
    if ((s = fv_params_int(p, "photons", 300000, 1, 500000000, &o->photons, err)) ||
        (s = fv_photon_read_radius(p, "gather radius", &o->radius, err)) ||
        (s = fv_params_int(p, "max_depth", 8, 1, 64, &o->max_depth, err)) ||
        (s = fv_params_int(p, "eye_depth", 8, 1, 64, &o->eye_depth, err)) || (s = fv_params_bool(p, "filter", true, &o->filter, err)) ||
        (s = fv_params_bool(p, "split", true, &o->split, err)) ||
        (s = fv_params_float(p, "guided_fraction", 0.4, 0.0, 0.95, &o->guided_fraction, err)) ||
        (s = fv_params_float(p, "alpha", 0.8, 0.0, 0.99, &o->alpha, err)) ||
        (s = fv_params_float(p, "pilot_fraction", 0.125, 0.01, 0.9, &o->pilot_fraction, err)) ||
        (s = fv_params_float(p, "retrace_overlap", 0.75, 0.0, 1.0, &o->retrace_overlap, err)) ||
        (s = fv_params_int(p, "fovea_spp", 4, 1, 256, &o->fovea_spp, err)) ||
        (s = fv_params_int(p, "periphery_step", 2, 1, 16, &o->periphery_step, err)) ||
        (s = fv_params_int(p, "acuity_levels", 1, 0, 3, &o->acuity_levels, err)) ||
        (s = fv_params_int(p, "focus_passes", 1, 0, 8, &o->focus_passes, err)))
        return s;
    return FV_OK;
}

static void gd_destroy(void *state)
{
    gd_state *st = state;
    if (!st) return;
    fv_path_store_destroy(st->ls_store);
    fv_path_store_destroy(st->g_store);
    fv_dyn_dirs_destroy(st->dirs);
    fv_photon_map_free(&st->map);
    fv_focus_cells_destroy(st->focus);
    fv_focus_cells_destroy(st->mg_focus);
    fv_photon_guide_destroy(st->guide);
    fv_atrous_destroy(st->atrous);
    fv_kit_counters_destroy(st->counters);
    free(st->nbuf), free(st->pbuf), free(st->alb), free(st->emit), free(st->refl);
    free(st->need), free(st->focus_px), free(st->lattice_px), free(st->level);
    free(st->focus_pts), free(st->box);
    free(st);
}

static fv_status gd_create(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err)
{
    gd_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    st->maps_index = -1;
    fv_photon_map_init(&st->map);
    st->map_ls_n = -1;
    st->lights_move = fv_scene_lights_move(scene);
    fv_status s = read_opts(params, &st->o, err);
    if (s == FV_OK) s = fv_path_store_create(&st->ls_store, err);
    if (s == FV_OK) s = fv_path_store_create(&st->g_store, err);
    if (s == FV_OK) s = fv_dyn_dirs_create(&st->dirs, err);
    if (s == FV_OK) s = fv_focus_cells_create(&st->focus, err);
    if (s == FV_OK) s = fv_focus_cells_create(&st->mg_focus, err);
    if (s == FV_OK) s = fv_photon_guide_create(st->o.alpha, &st->guide, err);
    if (s == FV_OK) s = fv_atrous_create(&st->atrous, err);
    if (s == FV_OK && !(st->counters = fv_kit_counters_create())) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (s != FV_OK) {
        gd_destroy(st);
        return s;
    }
    if (st->lights_move) fv_log_warn(log, "fpm-guided: the scene's lights move, so its light and guided photons are retraced every frame");
    *state = st;
    return FV_OK;
}

/* The frame's buffers, made when the image size changes and kept while it does not, so that a
 * frame allocates nothing once warmed up (docs/threads.md). */
static fv_status ensure_buffers(gd_state *st, size_t n, fv_error *err)
{
    if (st->bufn == n) return FV_OK;
    free(st->nbuf), free(st->pbuf), free(st->alb), free(st->emit), free(st->refl);
    free(st->need), free(st->focus_px), free(st->lattice_px), free(st->level);
    free(st->focus_pts), free(st->box);
    st->nbuf = fv_alloc_array(n, 3 * sizeof(float));
    st->pbuf = fv_alloc_array(n, 3 * sizeof(float));
    st->alb = fv_alloc_array(n, 3 * sizeof(float));
    st->emit = fv_alloc_array(n, 3 * sizeof(float));
    st->refl = fv_alloc_array(n, 3 * sizeof(float));
    st->need = fv_alloc_array(n, 1);
    st->focus_px = fv_alloc_array(n, 1);
    st->lattice_px = fv_alloc_array(n, 1);
    st->level = fv_alloc_array(n, 1);
    st->focus_pts = fv_alloc_array(n, 2 * sizeof(fv_vec3));
    /* a lattice (step >= 1) and the focus region's box are both at most the image */
    st->box = fv_alloc_array(n, 9 * sizeof(float));
    bool ok = st->nbuf && st->pbuf && st->alb && st->emit && st->refl && st->need && st->focus_px && st->lattice_px && st->level &&
              st->focus_pts && st->box;
    st->bufn = ok ? n : 0;
    return ok ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory for fpm-guided's %zu-pixel buffers", n);
}

/* ---- one frame ---- */

typedef struct gd_ctx {
    gd_state *st;
    const fv_frame *frame;
    fv_camera_basis cam;
    const fv_eye_model *eye;
    fv_gaze gaze;
    float gamma, norm;
    double e_t;               /* eccentricity of the transition's outer edge, degrees */
    float *color;
    fv_film_views out;
    fv_vec3 *focus_pts;       /* the state's, for the focus pass */
    fv_kit_counters *counters; /* rays, NaN, gathers (USER0), fovea paths (USER1) */
    fv_kit_progress prog;
} gd_ctx;

static inline fv_vec3 nan3(void) { return fv_v3s(NAN); }

/* The density estimate at gather point x (Eq. 5 over the frame's one map), f_r-weighted, divided
 * by pi gamma^2. */
static fv_vec3 estimate(const gd_ctx *c, const fv_pm_hit *x)
{
    return fv_scale(fv_pm_gather(c->st->scene, &c->st->map, x, c->gamma, NULL), c->norm);
}

/* The focus pass: one split eye path at every other pixel of every other row of the focus region,
 * its gather points kept to mark the cells the region gathers from. */
static void focus_tile(void *ctx, const fv_tile *t)
{
    gd_ctx *c = ctx;
    const int w = c->cam.width;
    uint64_t rays = 0;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++) {
            size_t pix = (size_t)y * w + x;
            fv_vec3 *pts = &c->focus_pts[2 * pix];
            pts[0] = pts[1] = nan3();
            if ((x | y) & 1 || fv_eye_blend(c->eye, c->gaze, x + 0.5, y + 0.5) >= 1.0) continue;
            fv_rng rng = fv_kit_rng(c->frame, pix, 1000);
            fv_pm_hit h[2];
            int n = fv_pm_eye_path_split(c->st->scene, c->cam.pos, fv_camera_dir(&c->cam, x + 0.5f, y + 0.5f), c->st->o.eye_depth, &rng, h);
            rays++;
            for (int k = 0; k < n; k++)
                if (h[k].hit) pts[k] = h[k].p;
        }
    fv_kit_count(c->counters, t->thread, FV_KIT_RAYS, rays);
}

/* The main pass: every pixel's eye path and first-hit buffers; gathers in the focus region and on
 * the periphery's lattice. Focus pixels get their colour; periphery pixels their emission, albedo
 * and (lattice) demodulated reflected light, composed after the fill. */
static void main_tile(void *ctx, const fv_tile *t)
{
    gd_ctx *c = ctx;
    gd_state *st = c->st;
    const fv_scene *s = st->scene;
    const int w = c->cam.width, S = st->o.periphery_step;
    uint64_t rays = 0, gathers = 0, fov_paths = 0, bad = 0;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++) {
            size_t pix = (size_t)y * w + x;
            float b = (float)fv_eye_blend(c->eye, c->gaze, x + 0.5, y + 0.5);
            fv_vec3 d = fv_camera_dir(&c->cam, x + 0.5f, y + 0.5f);
            fv_rng rng = fv_kit_rng(c->frame, pix, 0);
            fv_pm_hit h[2];
            int n = st->o.split ? fv_pm_eye_path_split(s, c->cam.pos, d, st->o.eye_depth, &rng, h)
                                : (fv_pm_eye_path(s, c->cam.pos, d, st->o.eye_depth, &rng, &h[0]), 1);
            rays++;
            bool any = h[0].first_obj >= 0;
            fv_vec3 zero = fv_v3s(0.0f), nrm = any ? h[0].first_n : zero, pos = any ? h[0].first_p : zero;
            memcpy(&st->nbuf[3 * pix], &nrm, sizeof nrm);
            memcpy(&st->pbuf[3 * pix], &pos, sizeof pos);
            fv_film_store_first_hit(&c->out, pix, any, h[0].first_t, h[0].first_p, h[0].first_n, h[0].albedo, h[0].first_obj);
            st->focus_px[pix] = b < 1.0f;
            /* Lattice spacing ~ 1 / acuity (Visual-Polar's Eq. 1, cycles per degree), relative to the
             * transition's edge, in doublings of periphery_step. */
            int lv = 0;
            if (b >= 1.0f && st->o.acuity_levels > 0) {
                double ratio = fv_acuity_v(c->e_t) / fv_acuity_v(fv_eye_eccentricity_deg(c->eye, c->gaze, x + 0.5, y + 0.5));
                while (lv < st->o.acuity_levels && ratio >= (double)(2 << lv)) lv++;
            }
            st->level[pix] = (uint8_t)lv;
            const int step = S << lv;
            st->lattice_px[pix] = b >= 1.0f && x % step == 0 && y % step == 0;
            if (b < 1.0f) {
                /* Eq. 6's b ramps the paths from fovea_spp in the fovea down to one at the periphery. */
                int spp = (int)lroundf((float)st->o.fovea_spp * (1.0f - b) + b);
                spp = spp < 1 ? 1 : spp;
                fv_vec3 L = fv_v3s(0.0f);
                for (int k = 0; k < spp; k++) {
                    if (k > 0) {
                        rng = fv_kit_rng(c->frame, pix, (uint64_t)k);
                        n = st->o.split ? fv_pm_eye_path_split(s, c->cam.pos, d, st->o.eye_depth, &rng, h)
                                        : (fv_pm_eye_path(s, c->cam.pos, d, st->o.eye_depth, &rng, &h[0]), 1);
                        rays++;
                    }
                    for (int j = 0; j < n; j++) {
                        L = fv_add(L, h[j].emitted);
                        if (h[j].hit) {
                            L = fv_add(L, fv_mul(h[j].weight, estimate(c, &h[j])));
                            gathers++;
                        }
                    }
                }
                fov_paths += (uint64_t)spp;
                L = fv_kit_guard(fv_scale(L, 1.0f / (float)spp), &bad);
                memcpy(&c->color[3 * pix], &L, sizeof L);
                continue;
            }
            /* The periphery: one path (the split's branches summed as one), gathered on the lattice. */
            fv_vec3 E = zero, R = zero;
            bool hit = false;
            for (int j = 0; j < n; j++) {
                E = fv_add(E, h[j].emitted);
                hit = hit || h[j].hit;
            }
            if (hit && st->lattice_px[pix])
                for (int j = 0; j < n; j++)
                    if (h[j].hit) {
                        R = fv_add(R, fv_mul(h[j].weight, estimate(c, &h[j])));
                        gathers++;
                    }
            /* Demodulated by the first surface's colour, so the fill carries light, not texture. */
            R = fv_kit_guard(R, &bad);
            fv_demod_factors(&h[0].reflectance.x, &st->alb[3 * pix]);
            for (int k = 0; k < 3; k++) st->refl[3 * pix + k] = (&R.x)[k] / st->alb[3 * pix + k];
            E = fv_kit_guard(E, &bad);
            memcpy(&st->emit[3 * pix], &E, sizeof E);
        }
    fv_kit_count(c->counters, t->thread, FV_KIT_RAYS, rays);
    fv_kit_count(c->counters, t->thread, FV_KIT_NAN, bad);
    fv_kit_count(c->counters, t->thread, FV_KIT_USER0, gathers);
    fv_kit_count(c->counters, t->thread, FV_KIT_USER1, fov_paths);
}

/* Periphery pixels the fill could not reach: gathered after all, with the main pass's path. A step
 * of the frame's region (every thread): adds its gathers to *gathers (shared), the team's barrier
 * after. */
static void gather_needed_team(gd_ctx *c, uint64_t *gathers)
{
    gd_state *st = c->st;
    const int w = c->cam.width;
    long n = (long)st->bufn;
    uint64_t g = 0;
    #pragma omp for schedule(dynamic, 64) nowait
    for (long i = 0; i < n; i++) {
        const float *nq = &st->nbuf[3 * i];
        if (!st->need[i] || st->focus_px[i] || (nq[0] == 0.0f && nq[1] == 0.0f && nq[2] == 0.0f)) continue; /* no surface: no light to gather */
        int x = (int)(i % w), y = (int)(i / w);
        fv_rng rng = fv_kit_rng(c->frame, (uint64_t)i, 0);
        fv_pm_hit h[2];
        fv_vec3 d = fv_camera_dir(&c->cam, x + 0.5f, y + 0.5f);
        int k = st->o.split ? fv_pm_eye_path_split(st->scene, c->cam.pos, d, st->o.eye_depth, &rng, h)
                            : (fv_pm_eye_path(st->scene, c->cam.pos, d, st->o.eye_depth, &rng, &h[0]), 1);
        fv_vec3 R = fv_v3s(0.0f);
        for (int j = 0; j < k; j++)
            if (h[j].hit) {
                R = fv_add(R, fv_mul(h[j].weight, estimate(c, &h[j])));
                g++;
            }
        if (!fv_is_finite3(R)) R = fv_v3s(0.0f); /* counted when the colour is composed */
        for (int q = 0; q < 3; q++) st->refl[3 * i + q] = (&R.x)[q] / st->alb[3 * i + q];
    }
    #pragma omp atomic
    *gathers += g;
    #pragma omp barrier
}

/* The two photon sets as one (multiple importance sampling, the balance heuristic over the
 * emission numbers u): M_ls's N_ls paths drew u uniformly, M_g's N_g from the guide's q, so a path
 * of either set carries f(u) / (N_ls + N_g q(u)) once its flux (f / N_ls, resp. f / (N_g q)) is
 * scaled as below. The sum stays unbiased, and is never much worse than the better set alone:
 * where the guide aims well M_g's photons dominate, elsewhere (light the pilot rarely saw reach the
 * focus) M_ls keeps the noise at a plain map's. */
static float scale_ls(const void *ctx, const float u[5])
{
    const gd_state *st = ctx;
    double q = st->n_g > 0 ? fv_photon_guide_density(st->guide, u) : 0.0;
    return (float)(st->n_ls / (st->n_ls + st->n_g * q));
}

static float scale_g(const void *ctx, const float u[5])
{
    const gd_state *st = ctx;
    double q = fv_photon_guide_density(st->guide, u);
    return (float)(st->n_g * q / (st->n_ls + st->n_g * q));
}

/* This frame's maps: M_ls (its paths traced once), then M_g, learnt and traced again when the
 * focus cells moved on; both refreshed near the dynamic objects (path_store.h). */
static fv_status update_maps(gd_ctx *c, fv_stats *stats, fv_error *err)
{
    gd_state *st = c->st;
    const fv_frame *f = c->frame;
    const int w = c->cam.width, h = c->cam.height;
    double n_guided = st->o.photons * st->o.guided_fraction, n_light = st->o.photons - n_guided;
    /* Paths kept for every frame use frame 0's random numbers, unless the lights move. */
    const int path_frame = st->lights_move ? f->index : 0;
    fv_photon_job job = {st->scene, (int64_t)n_light, f->seed, path_frame, st->o.max_depth, f->threads, 1, &c->prog, NULL, NULL, NULL};
    uint64_t rays = 0;
    int64_t again = 0, again_g = 0;
    fv_kit_phase(&c->prog, f, 0.0, 0.2);
    fv_stage_clock t0 = fv_stage_clock_now();
    fv_status rc = fv_dyn_dirs_build(st->dirs, st->scene, err);
    if (rc == FV_OK && (!fv_path_store_ready(st->ls_store) || st->lights_move)) {
        rc = fv_path_store_trace(st->ls_store, &job, &rays, err);
        st->map_ls_n = -1;
    }
    st->n_ls = (double)job.count;
    fv_stage_stop(stats, "light_tracing", t0);

    /* The cells the focus region gathers from. */
    t0 = fv_stage_clock_now();
    c->focus_pts = st->focus_pts;
    if (rc == FV_OK && !fv_parallel_tiles(w, h, f->threads, focus_tile, c, NULL, NULL)) rc = fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    fv_focus_cells_reset(st->focus, c->gamma);
    for (size_t i = 0; rc == FV_OK && i < (size_t)w * h * 2; i++)
        if (!isnan(c->focus_pts[i].x)) rc = fv_focus_cells_add(st->focus, c->focus_pts[i], c->gamma, err);
    double overlap = fv_focus_cells_overlap(st->focus, st->mg_focus);
    fv_stage_stop(stats, "focus_cells", t0);
    fv_stats_add_count(stats, "focus_cells", fv_focus_cells_count(st->focus));

    /* M_g: kept while the focus region gathers from (mostly) the cells it was guided towards. */
    bool retrace = !st->mg_valid || st->lights_move || st->maps_gamma != c->gamma || overlap < st->o.retrace_overlap;
    fv_kit_phase(&c->prog, f, 0.2, 0.2);
    t0 = fv_stage_clock_now();
    if (rc == FV_OK && retrace) {
        st->mg_valid = false;
        st->n_g = 0.0;
        st->map_ls_n = -1;
        int64_t n_pilot = (int64_t)(n_guided * st->o.pilot_fraction);
        fv_photon_job pilot = job;
        pilot.count = n_pilot;
        pilot.stream = 3;
        pilot.frame = f->index;
        rc = fv_photon_guide_learn(st->guide, &pilot, FV_TRACE_STATIC, st->focus, &rays, err);
        if (rc == FV_OK) {
            fv_photon_job gj = job;
            gj.count = (int64_t)n_guided - n_pilot;
            gj.stream = 4;
            gj.frame = f->index;
            gj.warp = fv_photon_guide_warp;
            gj.warp_ctx = st->guide;
            rc = fv_path_store_trace(st->g_store, &gj, &rays, err);
            st->n_g = (double)gj.count;
        }
        if (rc == FV_OK) {
            st->mg_valid = true;
            fv_focus_cells *tmp = st->mg_focus; /* M_g now serves this frame's cells */
            st->mg_focus = st->focus;
            st->focus = tmp;
        }
    }
    fv_stage_stop(stats, "guided_tracing", t0);
    /* The frame's map: both sets, refreshed near the dynamic objects, weighted, in one grid; kept
     * as it is while nothing moves and neither set was traced again. */
    t0 = fv_stage_clock_now();
    bool remake = st->map_ls_n < 0 || fv_dyn_dirs_count(st->dirs) > 0 || st->map.cell != c->gamma;
    if (rc == FV_OK && remake) {
        fv_photon_map_clear(&st->map);
        rc = fv_path_store_frame(st->ls_store, st->dirs, scale_ls, st, f->threads, &st->map, &again, &rays, err);
        st->map_ls_n = st->map.n;
        if (rc == FV_OK && st->mg_valid) rc = fv_path_store_frame(st->g_store, st->dirs, scale_g, st, f->threads, &st->map, &again_g, &rays, err);
        if (rc == FV_OK) rc = fv_photon_map_build_mt(&st->map, c->gamma, f->threads, err);
    }
    const int n_ls = st->map_ls_n;
    if (rc != FV_OK) {
        st->mg_valid = false;
        st->map_ls_n = -1;
        fv_photon_map_clear(&st->map);
    }
    fv_stage_stop(stats, "photon_map", t0);
    fv_stats_add_count(stats, "light_photons", n_ls);
    fv_stats_add_count(stats, "guided_photons", st->map.n - n_ls);
    fv_stats_add_count(stats, "guided_retraced", retrace ? 1.0 : 0.0);
    fv_stats_add_count(stats, "paths_retraced", (double)(again + again_g));
    fv_stats_add_count(stats, "guide_focus_share", fv_photon_guide_focus_share(st->guide));
    fv_stats_add_count(stats, "focus_overlap", overlap);
    fv_stats_add_count(stats, "rays", (double)rays);
    if (rc == FV_OK) {
        st->maps_index = f->index;
        st->maps_gamma = c->gamma;
    }
    return rc;
}

/* The main pass and the filters, in one parallel region (docs/threads.md): the main pass's tiles,
 * then the periphery's lattice filtered at its own resolution and filled in, the pixels the fill
 * could not reach gathered, the periphery's colour composed, and the focus region filtered at full
 * resolution over its bounding box only. Each step is a work-sharing loop of the team whose
 * barrier orders it before the next (or a step of the lattice or A-Trous filter, which end with
 * one); every pixel's value is what a region per step gave (each is written by one thread, and the
 * counts and the box's extent are sums and minima), so the image is the same bit for bit whatever
 * the thread count. Nothing is allocated: the scratch is the state's (ensure_buffers). */
static fv_status frame_passes(gd_ctx *c, fv_stats *stats, fv_error *err)
{
    gd_state *st = c->st;
    const fv_frame *f = c->frame;
    const int w = c->cam.width, h = c->cam.height;
    const bool lattice_filter = st->o.filter && st->o.periphery_step > 1;
    /* One pass (taps one lattice pixel apart): more smooth the periphery's light into blotches and
     * raise its MSE (0.000303 with one pass, 0.000354 with four, cornell-fpm at 270x300) without
     * lowering its temporal error. */
    fv_atrous_opts lao;
    fv_atrous_opts_default(&lao);
    lao.sigma_position = 2.0f * c->gamma;
    lao.iterations = 1;
    lao.threads = f->threads;
    lao.workspace = st->atrous;
    fv_atrous_opts ao;
    fv_atrous_opts_default(&ao);
    ao.sigma_position = 2.0f * c->gamma; /* as pm's filter: surfaces further apart than the disc do not mix */
    /* Four split paths per fovea pixel over a denser map leave little noise, and every pass blurs
     * what the reference keeps sharp: in cornell-fpm at 270x300 one pass gave the lowest fovea MSE
     * over the caustic (0.000121; 0.000142 with three, 0.000248 with none) and nearly the lowest on
     * a wall (1.6e-5; 3.2e-5 with three, 7.0e-6 with none). */
    ao.iterations = st->o.focus_passes;
    ao.threads = f->threads;
    ao.workspace = st->atrous;
    /* the workspace grown once for the largest image either filter sees (the whole frame) */
    fv_status rc = fv_atrous_prepare(st->atrous, w, h, &lao, err);
    if (rc == FV_OK && ao.iterations > 0) rc = fv_atrous_prepare(st->atrous, w, h, &ao, err);
    if (rc != FV_OK) return rc;
    /* The fill reads lattice pixels only: focus pixels hold colour, not demodulated light. */
    const fv_lattice_opts lo = {st->o.periphery_step, st->level, 8.0f, 2.0f * c->gamma};
    fv_team_progress tp;
    fv_team_progress_init(&tp, fv_kit_progress_fn, &c->prog);
    long missing = 0;
    uint64_t gathers = 0, bad = 0;
    /* The focus region's bounding box, a few pixels wider so its edge pixels see neighbours on every
     * side. Wider boxes pull the periphery's filled light into the transition (its MSE grew 25%
     * with 32 pixels in cornell-fpm at 270x300, docs/results.md). */
    const int reach = 4;
    int x0 = w, y0 = h, x1 = -1, y1 = -1;
    bool ok = true;
    fv_stage_clock t0 = fv_stage_clock_now(), t1 = t0, t2 = t0, t3 = t0;
    fv_region_begin();
#pragma omp parallel num_threads(fv_thread_count(f->threads))
    {
        const bool go = fv_team_tiles(w, h, main_tile, c, &tp);
#pragma omp master
        {
            ok = go;
            t1 = fv_stage_clock_now();
        }
        if (go) {
            if (lattice_filter) fv_lattice_filter_team(st->refl, st->lattice_px, st->lattice_px, st->nbuf, st->pbuf, w, h, st->o.periphery_step, &lao, st->box);
#pragma omp master
            t2 = fv_stage_clock_now();
            fv_lattice_fill_team(st->refl, st->lattice_px, st->focus_px, st->nbuf, st->pbuf, w, h, &lo, st->need, &missing);
            gather_needed_team(c, &gathers);
            uint64_t my_bad = 0;
            int bx0 = w, by0 = h, bx1 = -1, by1 = -1;
#pragma omp for schedule(static) nowait
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    const size_t i = (size_t)y * w + x;
                    if (st->focus_px[i]) {
                        bx0 = x < bx0 ? x : bx0, bx1 = x > bx1 ? x : bx1;
                        by0 = y < by0 ? y : by0, by1 = y > by1 ? y : by1;
                        continue;
                    }
                    fv_vec3 L;
                    for (int k = 0; k < 3; k++) (&L.x)[k] = st->emit[3 * i + k] + st->alb[3 * i + k] * st->refl[3 * i + k];
                    L = fv_kit_guard(L, &my_bad);
                    memcpy(&c->color[3 * i], &L, sizeof L);
                }
#pragma omp critical
            {
                bad += my_bad;
                x0 = bx0 < x0 ? bx0 : x0, x1 = bx1 > x1 ? bx1 : x1;
                y0 = by0 < y0 ? by0 : y0, y1 = by1 > y1 ? by1 : y1;
            }
#pragma omp barrier
#pragma omp master
            t3 = fv_stage_clock_now();
            if (st->o.filter && x1 >= 0 && ao.iterations > 0) {
                const int bx = x0 - reach < 0 ? 0 : x0 - reach, by = y0 - reach < 0 ? 0 : y0 - reach;
                const int ex = x1 + reach >= w ? w - 1 : x1 + reach, ey = y1 + reach >= h ? h - 1 : y1 + reach;
                const int bw = ex - bx + 1, bh = ey - by + 1;
                const size_t bn = (size_t)bw * bh;
                float *cc = st->box, *cn = st->box + 3 * bn, *cp = st->box + 6 * bn;
#pragma omp for schedule(static)
                for (int y = 0; y < bh; y++) {
                    size_t src = 3 * ((size_t)(by + y) * w + bx), dst = 3 * (size_t)y * bw;
                    memcpy(&cc[dst], &c->color[src], 3 * sizeof(float) * bw);
                    memcpy(&cn[dst], &st->nbuf[src], 3 * sizeof(float) * bw);
                    memcpy(&cp[dst], &st->pbuf[src], 3 * sizeof(float) * bw);
                }
                fv_atrous_team(cc, cn, cp, bw, bh, &ao);
#pragma omp for schedule(static)
                for (int y = 0; y < bh; y++)
                    for (int x = 0; x < bw; x++) {
                        size_t i = (size_t)(by + y) * w + bx + x;
                        if (st->focus_px[i]) memcpy(&c->color[3 * i], &cc[3 * ((size_t)y * bw + x)], 3 * sizeof(float));
                    }
            }
        }
    }
    fv_region_end();
    fv_stage_clock t4 = fv_stage_clock_now();
    /* the stages and counts in the order a region per step reported them */
    fv_stage_add(stats, "render", t0, t1);
    fv_kit_report(c->counters, stats);
    fv_stats_add_count(stats, "fovea_paths", (double)fv_kit_sum(c->counters, FV_KIT_USER1));
    if (!ok) return fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    fv_stage_add(stats, "lattice_filter", t1, t2);
    fv_stats_add_count(stats, "fill_gathered", (double)missing);
    fv_stats_add_count(stats, "gathers", (double)fv_kit_sum(c->counters, FV_KIT_USER0) + (double)gathers);
    fv_stats_add_count(stats, "nan_samples", (double)bad);
    fv_stage_add(stats, "fill", t2, t3);
    if (st->o.filter) fv_stage_add(stats, "filter", t3, t4);
    return FV_OK;
}

static fv_status gd_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    gd_state *st = state;
    const int w = fv_film_width(film), h = fv_film_height(film);
    fv_eye_model def;
    gd_ctx ctx, *c = &ctx;
    memset(c, 0, sizeof *c);
    c->st = st;
    c->frame = frame;
    c->eye = fv_frame_eye_model(frame, w, h, &def);
    c->gaze = frame->gaze;
    c->counters = st->counters;
    memset(c->counters, 0, sizeof *c->counters);
    fv_status rc = fv_frame_camera(frame->camera, film, &c->cam, err);
    if (rc == FV_OK) rc = ensure_buffers(st, (size_t)w * h, err);
    if (rc == FV_OK) {
        fv_vec3 lo, hi;
        fv_scene_bounds(st->scene, &lo, &hi);
        c->gamma = st->o.radius > 0.0 ? (float)st->o.radius : fv_photon_radius_eq8(lo, hi, w, h);
        c->norm = 1.0f / (FV_PI * c->gamma * c->gamma);
        c->e_t = fv_eye_transition_radius_px(c->eye) / fv_eye_px_per_deg(c->eye);
        c->color = fv_film_color(film);
        c->out = fv_film_views_of(film);
        memset(c->color, 0, (size_t)w * h * 3 * sizeof(float));
    }
    /* The right eye of a stereo frame reuses the left eye's maps (same time, same radius). */
    bool reuse = frame->eye == 1 && st->maps_index == frame->index && st->maps_gamma == c->gamma;
    if (rc == FV_OK && !reuse) rc = update_maps(c, stats, err);
    if (rc == FV_OK) {
        fv_kit_phase(&c->prog, frame, 0.4, 0.6);
        rc = frame_passes(c, stats, err);
    }
    if (rc != FV_OK) st->maps_index = -1;
    return rc;
}

/* The furnace (a unit sphere, radius 0.25, as pm's check): every pixel in the focus region or on
 * the lattice gathers like pm, the others are filled from lattice pixels on the same sphere, so
 * the expected radiance is pm's: 0.998047 (pm.c explains the number). */
static const fv_param_info k_params[] = {
    FV_PARAM_INT("photons", "300000", 1, 500000000, "photons per frame (light + guided)"),
    FV_PHOTON_RADIUS_PARAM("gather radius gamma in scene units"),
    FV_PARAM_INT("max_depth", "8", 1, 64, "photon bounces"),
    FV_PARAM_INT("eye_depth", "8", 1, 64, "mirror/glass bounces of eye rays"),
    FV_PARAM_BOOL("filter", "true", "lattice filter in the periphery, A-Trous over the focus region"),
    FV_PARAM_BOOL("split", "true", "follow both reflection and refraction at an eye path's first dielectric"),
    FV_PARAM_FLOAT("guided_fraction", "0.4", 0.0, 0.95, "share of the photons guided towards the focus region"),
    FV_PARAM_FLOAT("alpha", "0.8", 0.0, 0.99, "share of guided photons the learnt cells get (the rest uniform)"),
    FV_PARAM_FLOAT("pilot_fraction", "0.125", 0.01, 0.9, "share of the guided budget spent learning where to guide"),
    FV_PARAM_FLOAT("retrace_overlap", "0.75", 0.0, 1.0, "keep the guided map while this share of the focus cells is unchanged"),
    FV_PARAM_INT("fovea_spp", "4", 1, 256, "eye paths per fovea pixel, ramping to 1 across the transition"),
    FV_PARAM_INT("periphery_step", "2", 1, 16, "the periphery gathers every step-th pixel of every step-th row"),
    FV_PARAM_INT("focus_passes", "1", 0, 8, "A-Trous passes over the focus region (0: none)"),
    FV_PARAM_INT("acuity_levels", "1", 0, 3, "the step doubles up to this many times where acuity falls to 1/2, 1/4, ..."),
};

const fv_technique_class fv_technique_fpm_guided = {
    .name = "fpm-guided",
    .summary = "foveated photon mapping for a CPU: more eye paths in the fovea, a sparse periphery, photons guided to the focus",
    .family = FV_FAMILY_PHOTON,
    /* measured, as fpm, against photon mapping with the same photon count (the fpm-* benchmarks) */
    .baseline = "pm",
    FV_CLASS_PARAMS(k_params),
    .main = {"photons", {"10000", "30000", "100000", "300000", "1000000"}, false},
    .create = gd_create,
    .render = gd_render,
    .destroy = gd_destroy,
    .foveated = true,
    /* fpm's temporal photon management (pm.c), the same warm-up */
    .warmup_frames = 8,
    .test_params = "photons=40000",
    .furnace_params = "radius=0.25",
    .furnace_radiance = 0.998046875, /* pm's: 1 - 0.5^9 (pm.c, FURNACE_TEST) */
    .furnace_tolerance = 0.04,
    .spp_param = "fovea_spp",
    .gathers_photons = true,
    .bench_scene = FV_PHOTON_BENCH_SCENE,
};
