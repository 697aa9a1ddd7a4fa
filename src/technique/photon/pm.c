/* fovea — photon mapping techniques of Foveated Photon Mapping (Shi et al., TVCG):
 *   pm   — photon mapping, all photons retraced every frame (the paper's PM_3M);
 *   pm-t — photon mapping with the temporal strategy of its ref. [43]: static light photons (M_ls)
 *          traced once, photons for the dynamic objects (M_ld, positive and negative) every frame,
 *          radiance by Eq. 5 with the static/dynamic blend of Eq. 4 (PM^t);
 *   fpm  — foveated photon mapping (Alg. 1): pm-t's light photons plus foveated photons (M_fs,
 *          M_fd) traced from the eye through the focus region, kept across frames by temporal
 *          photon management (Alg. 2), energy-normalised by eta (Eq. 1); fovea by Eq. 3, periphery
 *          by Eq. 5, transition blended by b(x) (Eq. 6).
 * All three share the photon tracer, the grids, the eye paths, the gather and the filter; they
 * differ only where the paper's methods differ.
 *
 * Our reading of Eq. 3-5: the printed k * sum(M_d) + (1 - k) * sum(M_s) would drop the static
 * photons exactly where dynamic ones matter (W -> 1) and turn a shadow negative; we blend the
 * static-only estimate with the static-plus-dynamic one, sum(M_s) + k * sum(M_d), which is the
 * irradiance-cache blending the paper cites. Eq. 4's W uses sum(M_ld) + sum(M_fd) / eta in the
 * numerator (the seed's README notes the printed duplicate).
 *
 * Moving lights (fv_scene_animate_light) are outside the paper, whose lights stand still: they
 * relight static surfaces, so M_ls is no longer valid for every frame and a kept foveated path's
 * flux goes stale. With them, pm-t and fpm retrace M_ls every frame and fpm keeps no foveated path
 * across frames (as with tpm=false); both say so once when created. Only what the dynamic objects
 * change is still split off into M_ld and M_fd, as in any single frame.
 *
 * Stereo (Sec. 3.3): the left eye is shaded fully; each right-eye pixel whose first surface
 * reprojects onto the same surface in the left image copies that colour, the others are shaded.
 * The driver renders the left eye first: its colour, first hits, gather radius and eta are kept
 * for the right eye of the same frame, which traces no photons of its own.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/stage_time.h"
#include "core/alloc.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "filter/atrous.h"
#include "filter/demod.h"
#include "scene/light.h"
#include "technique/class.h"
#include "technique/kit.h"
#include "technique/photon/foveated.h"
#include "technique/photon/pm_gather.h"
#include "technique/photon/photon_trace.h"
#include "technique/photon/pm_temporal.h"

typedef enum pm_mode { MODE_PM = 0, MODE_PMT, MODE_FPM } pm_mode;

typedef struct pm_opts {
    int photons;          /* total photons per frame (fpm: light + foveated) */
    double fov_fraction;  /* fpm: share of foveated photons (Sec. 4: 40%) */
    double dyn_fraction;  /* pm-t, fpm: share of the light photons sent to dynamic objects */
    double radius;        /* gather radius gamma; 0: Eq. 8 */
    int max_depth;        /* photon bounces (Sec. 4.1: 8) */
    int eye_depth;        /* mirror/glass bounces of eye paths */
    int paths;            /* fpm: N paths per focus pixel; 0: from the budget */
    int light_photons, fov_photons; /* fpm: absolute counts instead of photons x fraction */
    int passes;           /* pm: independent passes averaged (references) */
    bool filter, tpm;
    int eta_region;       /* fpm: 0 fovea, 1 focus region (Eq. 1's r_i) */
    int terms;            /* fpm: 0 all, 1 the light photons' term only, 2 the foveated photons' only
                             (the bias analysis, docs/results.md: eta and k stay those of the whole) */
} pm_opts;

typedef struct pm_state {
    pm_mode mode;
    const fv_scene *scene;
    pm_opts o;
    fv_photon_map all;
    fv_pmt_maps tm;       /* pm-t, fpm: M_ls and M_ld */
    bool lights_move;     /* the scene's lights move: nothing lit by them is kept across frames */
    fv_foveated *fov;
    int fov_w, fov_h;
    /* first-hit buffers of the left eye: normal, position, what it reflects, object id (filter,
     * stereo) */
    float *nbuf, *pbuf, *rbuf;
    fv_atrous *atrous; /* the filter's scratch, kept from frame to frame */
    fv_photon_room *room; /* the light tracer's blocks, kept from frame to frame */
    int32_t *obuf;
    /* fpm: the left eye's gathered sums per pixel and Eq. 1's luminances and mask (finish_fpm) */
    struct px_sums *sums;
    float *eta_l, *eta_f;
    uint8_t *eta_mask;
    size_t bufn;
    fv_kit_counters *counters; /* every frame's, kept (fv_kit_counters_reuse) */
    /* the left eye of a stereo frame, for the right eye (Sec. 3.3) */
    float *left_color;
    bool left_valid;
    int left_index;
    float left_gamma;
    double left_eta;
} pm_state;

/* fpm's choices, in the order of its options' values: the reader and the parameter table share them. */
static const char *const k_regions[] = {"fovea", "focus", NULL};
static const char *const k_terms[] = {"all", "light", "foveated", NULL};

static fv_status read_opts(pm_mode mode, fv_params *p, pm_opts *o, fv_error *err)
{
    fv_status s;
    memset(o, 0, sizeof *o);
    if ((s = fv_params_int(p, "photons", 300000, 1, 500000000, &o->photons, err)) ||
        (s = fv_photon_read_radius(p, "gather radius", &o->radius, err)) ||
        (s = fv_params_int(p, "max_depth", 8, 1, FV_FOV_MAX_DEPTH, &o->max_depth, err)) ||
        (s = fv_params_int(p, "eye_depth", 8, 1, 64, &o->eye_depth, err)) || (s = fv_params_bool(p, "filter", true, &o->filter, err)))
        return s;
    if (mode == MODE_PM && (s = fv_params_int(p, "passes", 1, 1, 100000, &o->passes, err))) return s;
    if (mode != MODE_PM) {
        if ((s = fv_params_float(p, "dyn_fraction", 0.2, 0.0, 0.95, &o->dyn_fraction, err))) return s;
    }
    if (mode == MODE_FPM) {
        if ((s = fv_params_int(p, "light_photons", 0, 0, 500000000, &o->light_photons, err)) ||
            (s = fv_params_int(p, "fov_photons", 0, 0, 500000000, &o->fov_photons, err)) ||
            (s = fv_params_float(p, "fov_fraction", 0.4, 0.0, 1.0, &o->fov_fraction, err)) ||
            (s = fv_params_int(p, "paths_per_pixel", 0, 0, 64, &o->paths, err)) || (s = fv_params_bool(p, "tpm", true, &o->tpm, err)))
            return s;
        if ((s = fv_params_choice(p, "eta_region", 0, k_regions, &o->eta_region, err))) return s;
        if ((s = fv_params_choice(p, "terms", 0, k_terms, &o->terms, err))) return s;
        if (o->fov_fraction >= 1.0)
            return fv_error_set(err, FV_ERR_INVALID, "parameter fov_fraction=%g: some light photons are needed (use < 1)", o->fov_fraction);
        /* Absolute counts (the paper's Fig. 6 b, c vary one at a fixed other) replace the split. */
        if (o->light_photons > 0 || o->fov_photons > 0) {
            if (o->light_photons <= 0)
                return fv_error_set(err, FV_ERR_INVALID, "parameter fov_photons needs light_photons too (light photons feed the foveated ones)");
            o->photons = o->light_photons + o->fov_photons;
            o->fov_fraction = (double)o->fov_photons / o->photons;
        }
    }
    return FV_OK;
}

static fv_status pm_create_mode(pm_mode mode, const fv_scene *scene, fv_params *params, const fv_log *log, void **state,
                                fv_error *err)
{
    pm_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->mode = mode;
    st->scene = scene;
    fv_photon_map_init(&st->all);
    fv_status s = read_opts(mode, params, &st->o, err);
    if (s == FV_OK && mode != MODE_PM) s = fv_pmt_maps_init(&st->tm, scene, err);
    if (s == FV_OK) s = fv_atrous_create(&st->atrous, err);
    if (s == FV_OK && !(st->room = fv_photon_room_create())) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (s != FV_OK) {
        fv_pmt_maps_free(&st->tm);
        fv_atrous_destroy(st->atrous);
        fv_photon_room_destroy(st->room);
        free(st);
        return s;
    }
    st->lights_move = mode != MODE_PM && fv_scene_lights_move(scene);
    if (st->lights_move)
        fv_log_warn(log, "%s: the scene's lights move, so its light photons are retraced every frame%s",
                    mode == MODE_PMT ? "pm-t" : "fpm", mode == MODE_FPM ? " and no foveated path is kept across frames" : "");
    *state = st;
    return FV_OK;
}

static void pm_destroy(void *state)
{
    pm_state *st = state;
    if (!st) return;
    fv_photon_map_free(&st->all);
    fv_pmt_maps_free(&st->tm);
    fv_foveated_destroy(st->fov);
    fv_atrous_destroy(st->atrous);
    fv_photon_room_destroy(st->room);
    free(st->nbuf);
    free(st->pbuf);
    free(st->rbuf);
    free(st->obuf);
    free(st->sums);
    free(st->eta_l);
    free(st->eta_f);
    free(st->eta_mask);
    fv_kit_counters_destroy(st->counters);
    free(st->left_color);
    free(st);
}

/* ---- per-pixel radiance ---- */

/* What an fpm or pm-t pixel gathered from each map (f_r-weighted, not yet divided by
 * pi gamma^2); fpm keeps them until eta (Eq. 1) is known. */
typedef struct px_sums {
    fv_vec3 ls, ld, fs, fd;
    float u_ls, u_ld, u_fs, u_fd;  /* Eq. 4's u sums */
    fv_vec3 emitted, weight;
    float b;                       /* Eq. 6: 0 fovea, 1 periphery */
    bool hit;
} px_sums;

typedef struct render_ctx {
    const pm_state *st;
    const fv_frame *frame;
    fv_camera_basis cam;
    const fv_eye_model *eye;
    fv_gaze gaze;
    float gamma, norm;       /* gather radius and 1 / (pi gamma^2) */
    double eta;
    int pass;
    fv_film_views out;       /* colour accumulates over passes */
    float *nbuf, *pbuf, *rbuf;
    int32_t *obuf;
    bool right;              /* shading the right eye: reproject from the left first */
    px_sums *sums;           /* fpm, left eye: gathered sums per pixel */
    const float *left_color;
    const fv_camera_basis *left_cam;
    fv_kit_counters *counters; /* rays, NaN, reprojected (USER0), shaded (USER1) */
    fv_kit_progress prog;
} render_ctx;

/* Plain photon mapping (pm): one map, no blending. */
static fv_vec3 estimate_plain(const render_ctx *c, const fv_pm_hit *x)
{
    return fv_scale(fv_pm_gather(c->st->scene, &c->st->all, x, c->gamma, NULL), c->norm);
}

/* Gathers what pixel x needs: the light maps, and in the focus region (b < 1) the foveated ones. */
static void gather_sums(const render_ctx *c, const fv_pm_hit *x, float b, px_sums *o)
{
    const pm_state *st = c->st;
    double u_ls = 0, u_ld = 0, u_fs = 0, u_fd = 0;
    memset(o, 0, sizeof *o);
    o->emitted = x->emitted;
    o->weight = x->weight;
    o->b = b;
    o->hit = x->hit;
    if (!x->hit) return;
    o->ls = fv_pm_gather(st->scene, &st->tm.ls, x, c->gamma, &u_ls);
    o->ld = fv_pm_gather(st->scene, &st->tm.ld, x, c->gamma, &u_ld);
    if (b < 1.0f) {
        o->fs = fv_pm_gather(st->scene, fv_foveated_static_map(st->fov), x, c->gamma, &u_fs);
        o->fd = fv_pm_gather(st->scene, fv_foveated_dynamic_map(st->fov), x, c->gamma, &u_fd);
    }
    o->u_ls = (float)u_ls, o->u_ld = (float)u_ld, o->u_fs = (float)u_fs, o->u_fd = (float)u_fd;
}

/* Eq. 2-6 from the sums: Eq. 5 (light photons, static/dynamic blend k of Eq. 4) in the periphery,
 * Eq. 3 (all four maps, times eta) in the fovea, linear in b between. */
static fv_vec3 estimate_sums(const render_ctx *c, const px_sums *o)
{
    /* terms=light|foveated: one map pair's share of the same estimate (same eta, same k), the
     * emission and the periphery's light-photon estimate going to the light term: the two add
     * up to terms=all. */
    const int terms = c->st->o.terms;
    fv_vec3 emitted = terms == 2 ? fv_v3s(0.0f) : o->emitted;
    if (!o->hit) return emitted;
    float kl = fv_pmt_blend_k(o->u_ld, o->u_ls);
    fv_vec3 g = terms == 2 ? fv_v3s(0.0f) : fv_scale(fv_madd(o->ls, o->ld, kl), c->norm);
    if (o->b < 1.0f) {
        float kf = fv_pmt_blend_k(o->u_ld + o->u_fd / c->eta, o->u_ls + o->u_fs);
        fv_vec3 zero = fv_v3s(0.0f), ls = terms == 2 ? zero : o->ls, ld = terms == 2 ? zero : o->ld;
        fv_vec3 fs = terms == 1 ? zero : o->fs, fd = terms == 1 ? zero : o->fd;
        fv_vec3 fov = fv_scale(fv_madd(fv_add(ls, fs), fv_add(ld, fd), kf), (float)c->eta * c->norm);
        g = fv_add(fv_scale(fov, 1.0f - o->b), fv_scale(g, o->b));
    }
    return fv_add(emitted, fv_mul(o->weight, g));
}

static fv_vec3 shade(const render_ctx *c, const fv_pm_hit *x, float px, float py)
{
    if (c->st->mode == MODE_PM) return x->hit ? fv_add(x->emitted, fv_mul(x->weight, estimate_plain(c, x))) : x->emitted;
    /* pm-t is fpm's periphery everywhere (b = 1). */
    px_sums o;
    gather_sums(c, x, c->st->mode == MODE_FPM ? (float)fv_eye_blend(c->eye, c->gaze, px, py) : 1.0f, &o);
    return estimate_sums(c, &o);
}

static void render_tile(void *ctx, const fv_tile *tile)
{
    render_ctx *c = ctx;
    const int w = c->cam.width;
    uint64_t rays = 0, reproj = 0, shaded = 0, bad = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++) {
            size_t pix = (size_t)y * w + x;
            fv_rng rng = fv_kit_rng(c->frame, pix, (uint64_t)c->pass);
            fv_vec3 d = fv_camera_dir(&c->cam, x + 0.5f, y + 0.5f);
            fv_pm_hit h;
            fv_pm_eye_path(c->st->scene, c->cam.pos, d, c->st->o.eye_depth, &rng, &h);
            rays++;
            fv_vec3 L;
            bool copied = false;
            if (c->right && h.first_obj >= 0) {
                /* Sec. 3.3: reuse the left eye's colour when its pixel shows the same surface. */
                float lx, ly;
                if (fv_camera_project(c->left_cam, h.first_p, &lx, &ly) && lx >= 0 && ly >= 0 && lx < w && ly < c->cam.height) {
                    size_t lp = (size_t)(int)ly * w + (int)lx;
                    fv_vec3 q = fv_v3(c->pbuf[3 * lp], c->pbuf[3 * lp + 1], c->pbuf[3 * lp + 2]);
                    if (c->obuf[lp] == h.first_obj && fv_length(fv_sub(q, h.first_p)) < 0.01f * h.first_t) {
                        L = fv_v3(c->left_color[3 * lp], c->left_color[3 * lp + 1], c->left_color[3 * lp + 2]);
                        copied = true;
                        reproj++;
                    }
                }
            }
            if (!copied && c->sums) {
                /* fpm, left eye: the colour waits for eta (finish_fpm). */
                gather_sums(c, &h, (float)fv_eye_blend(c->eye, c->gaze, x + 0.5, y + 0.5), &c->sums[pix]);
                L = fv_v3s(0.0f);
                shaded++;
            } else if (!copied) {
                L = shade(c, &h, x + 0.5f, y + 0.5f);
                shaded++;
            }
            L = fv_kit_guard(L, &bad);
            float *col = &c->out.color[3 * pix];
            float wgt = 1.0f / (float)(c->pass + 1); /* running mean over passes */
            col[0] += (L.x - col[0]) * wgt;
            col[1] += (L.y - col[1]) * wgt;
            col[2] += (L.z - col[2]) * wgt;
            if (c->pass > 0) continue;
            bool any = h.first_obj >= 0;
            fv_vec3 zero = fv_v3s(0.0f), n = any ? h.first_n : zero, p = any ? h.first_p : zero;
            fv_film_store_first_hit(&c->out, pix, any, h.first_t, h.first_p, h.first_n, h.albedo, h.first_obj);
            if (!c->right) {
                fv_vec3 r = any ? h.reflectance : zero;
                memcpy(&c->nbuf[3 * pix], &n, sizeof n);
                memcpy(&c->pbuf[3 * pix], &p, sizeof p);
                memcpy(&c->rbuf[3 * pix], &r, sizeof r);
                c->obuf[pix] = h.first_obj;
            }
        }
    fv_kit_count(c->counters, tile->thread, FV_KIT_RAYS, rays);
    fv_kit_count(c->counters, tile->thread, FV_KIT_NAN, bad);
    fv_kit_count(c->counters, tile->thread, FV_KIT_USER0, reproj);
    fv_kit_count(c->counters, tile->thread, FV_KIT_USER1, shaded);
}

/* ---- one frame ---- */

static fv_status ensure_buffers(pm_state *st, int w, int h, fv_error *err)
{
    size_t n = (size_t)w * h;
    if (st->bufn == n) return FV_OK;
    free(st->nbuf);
    free(st->pbuf);
    free(st->rbuf);
    free(st->obuf);
    free(st->sums);
    free(st->eta_l);
    free(st->eta_f);
    free(st->eta_mask);
    st->sums = NULL;
    st->eta_l = st->eta_f = NULL;
    st->eta_mask = NULL;
    st->nbuf = fv_alloc_array(n, 3 * sizeof(float));
    st->pbuf = fv_alloc_array(n, 3 * sizeof(float));
    st->rbuf = fv_alloc_array(n, 3 * sizeof(float));
    st->obuf = fv_alloc_array(n, sizeof(int32_t));
    bool ok = st->nbuf && st->pbuf && st->rbuf && st->obuf;
    if (st->mode == MODE_FPM) {
        st->sums = fv_alloc_array(n, sizeof *st->sums);
        st->eta_l = fv_alloc_array(n, sizeof(float));
        st->eta_f = fv_alloc_array(n, sizeof(float));
        st->eta_mask = fv_alloc_array(n, 1);
        ok = ok && st->sums && st->eta_l && st->eta_f && st->eta_mask;
    }
    st->bufn = ok ? n : 0;
    return st->bufn ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory for %dx%d photon mapping buffers", w, h);
}

/* Light photons of this frame (pm: the whole map; pm-t / fpm: M_ls once, M_ld every frame).
 * Progress goes to prog. */
static fv_status light_tracing(pm_state *st, const fv_frame *frame, float cell, int pass, double n_light, fv_kit_progress *prog,
                               fv_stats *stats, fv_error *err)
{
    const fv_scene *s = st->scene;
    uint64_t rays = 0;
    fv_status rc = FV_OK;
    fv_photon_job job = {s, 0, frame->seed, frame->index, st->o.max_depth, frame->threads, 0, prog, NULL, NULL, st->room};
    if (st->mode == MODE_PM) {
        fv_photon_map_clear(&st->all);
        job.count = (int64_t)n_light;
        job.stream = 100 + (uint64_t)pass;
        if ((rc = fv_photon_trace_lights(&job, FV_TRACE_ALL, &st->all, &rays, err)) == FV_OK) rc = fv_photon_map_build_mt(&st->all, cell, frame->threads, err);
        fv_stats_add_count(stats, "light_photons", st->all.n);
    } else {
        rc = fv_pmt_maps_update(&st->tm, &job, n_light, st->o.dyn_fraction, cell, stats, &rays, err);
    }
    fv_stats_add_count(stats, "rays", (double)rays);
    return rc;
}

/* N of Alg. 1 from the foveated photon budget: paths per focus pixel, assuming about 2.5 photons
 * per path (the first frame's paths keep that guess honest enough; N stays fixed afterwards). */
static int paths_per_pixel(const pm_state *st, const fv_eye_model *eye, fv_gaze g, int w, int h)
{
    if (st->o.paths > 0) return st->o.paths;
    double rt = fv_eye_transition_radius_px(eye);
    long focus = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) focus += fv_eye_gaze_dist_px(eye, g, x + 0.5, y + 0.5) <= rt;
    double n = st->o.photons * st->o.fov_fraction / (2.5 * (focus > 0 ? focus : 1));
    return n < 1.0 ? 1 : n > 64.0 ? 64 : (int)lround(n);
}

/* One pass over the eye's pixels; right: reproject from the left eye first (Sec. 3.3). */
static fv_status render_eye_pass(render_ctx *c, fv_film *film, bool right, fv_stats *stats, fv_error *err)
{
    const fv_camera *cam = c->frame->camera;
    fv_status rc = fv_frame_camera(cam, film, &c->cam, err);
    if (rc != FV_OK) return rc;
    c->gaze = c->frame->gaze;
    c->right = right;
    c->out = fv_film_views_of(film);
    memset(c->counters, 0, sizeof *c->counters);
    fv_stage_clock t0 = fv_stage_clock_now();
    bool done = fv_parallel_tiles(cam->width, cam->height, c->frame->threads, render_tile, c, fv_kit_progress_fn, &c->prog);
    fv_stage_stop(stats, "render", t0);
    fv_kit_report(c->counters, stats);
    if (right)
        fv_stats_add_count(stats, "reprojected_fraction", (double)fv_kit_sum(c->counters, FV_KIT_USER0) / ((double)cam->width * cam->height));
    return done ? FV_OK : fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
}

/* Eq. 1 over what the fovea's pixels gathered (eta_region=fovea) or the focus region's
 * (=focus), then every fpm pixel's colour. */
static fv_status finish_fpm(render_ctx *c, fv_film *film, fv_stats *stats, fv_error *err)
{
    (void)err;
    int w = fv_film_width(film), h = fv_film_height(film);
    size_t n = (size_t)w * h;
    float *l = c->st->eta_l, *f = c->st->eta_f; /* the state's, sized with the film (ensure_buffers) */
    uint8_t *mask = c->st->eta_mask;
    bool fovea_only = c->st->o.eta_region == 0;
    for (size_t i = 0; i < n; i++) {
        const px_sums *o = &c->sums[i];
        l[i] = fv_luminance(fv_add(o->ls, o->ld));
        f[i] = fv_luminance(fv_add(o->fs, o->fd));
        mask[i] = o->hit && (fovea_only ? o->b <= 0.0f : o->b < 1.0f);
    }
    c->eta = fv_foveated_eta(l, f, mask, n);
    float *col = fv_film_color(film);
    uint64_t bad = 0;
    fv_region_begin();
    #pragma omp parallel for schedule(static) reduction(+ : bad) num_threads(fv_thread_count(c->frame->threads))
    for (long long i = 0; i < (long long)n; i++) {
        fv_vec3 L = fv_kit_guard(estimate_sums(c, &c->sums[i]), &bad);
        col[3 * i] = L.x, col[3 * i + 1] = L.y, col[3 * i + 2] = L.z;
    }
    fv_region_end();
    fv_stats_add_count(stats, "nan_samples", (double)bad);
    return FV_OK;
}

static fv_status filter_film(pm_state *st, fv_film *film, float gamma, int threads, fv_stats *stats, fv_error *err)
{
    if (!st->o.filter) return FV_OK;
    fv_stage_clock t0 = fv_stage_clock_now();
    fv_atrous_opts ao;
    fv_atrous_opts_default(&ao);
    ao.sigma_position = 2.0f * gamma; /* surfaces further apart than the gather disc do not mix */
    /* Light is filtered, not colour: each pixel divided by what its first surface reflects and
     * multiplied back after (filter/demod.h, as SVGF does), so that a texture's cells keep their
     * colour instead of taking their neighbours' (issue 25). */
    ao.demod = st->rbuf;
    ao.threads = threads;
    ao.workspace = st->atrous;
    fv_status rc = fv_atrous_filter(fv_film_color(film), st->nbuf, st->pbuf, fv_film_width(film), fv_film_height(film), &ao, err);
    fv_stage_stop(stats, "filter", t0);
    return rc;
}

/* Alg. 1 lines 7-10: temporal photon management, then the foveated photons of this frame. */
static fv_status foveated_photons(pm_state *st, render_ctx *c, int w, int h, float cell, fv_stats *stats, fv_error *err)
{
    const fv_frame *frame = c->frame;
    const fv_scene *s = st->scene;
    fv_status rc = FV_OK;
    if (st->fov && (st->fov_w != w || st->fov_h != h)) {
        fv_foveated_destroy(st->fov);
        st->fov = NULL;
    }
    if (!st->fov) {
        rc = fv_foveated_create(w, h, paths_per_pixel(st, c->eye, frame->gaze, w, h), st->o.max_depth, &st->fov, err);
        st->fov_w = w;
        st->fov_h = h;
    }
    fv_fov_stats fs;
    memset(&fs, 0, sizeof fs);
    fv_stage_clock t0 = fv_stage_clock_now();
    /* No previous camera: Alg. 2 then deletes every old path, whose flux moving lights made stale. */
    const fv_camera *prev = st->o.tpm && !st->lights_move ? frame->prev_camera : NULL;
    if (rc == FV_OK) rc = fv_foveated_manage(st->fov, s, frame->camera, prev, c->eye, frame->gaze, frame->threads, &fs, err);
    fv_stage_stop(stats, "tpm", t0);
    t0 = fv_stage_clock_now();
    if (rc == FV_OK)
        rc = fv_foveated_trace(st->fov, s, frame->camera, &st->tm.ls, &st->tm.ld, c->gamma, cell, frame->seed, frame->index, frame->threads, &fs,
                               err);
    fv_stage_stop(stats, "foveated_tracing", t0);
    fv_stats_add_count(stats, "foveated_photons", fs.photons_static + fs.photons_dynamic);
    fv_stats_add_count(stats, "paths_traced", (double)fs.paths_traced);
    fv_stats_add_count(stats, "paths_reused", (double)fs.paths_reused);
    fv_stats_add_count(stats, "paths_deleted", (double)fs.paths_deleted);
    fv_stats_add_count(stats, "paths_stored", (double)fs.paths_stored_static);
    int live = 0, cap = 0;
    if (st->fov) fv_foveated_pool(st->fov, &live, &cap);
    fv_stats_add_count(stats, "paths_live", live);
    fv_stats_add_count(stats, "path_capacity", cap);
    long denom = fs.paths_reused + fs.paths_traced;
    fv_stats_add_count(stats, "reuse_rate", denom > 0 ? (double)fs.paths_reused / (double)denom : 0.0);
    return rc;
}

/* The right eye of a stereo frame whose left eye was just rendered: reproject, shade the rest. */
static fv_status render_right(pm_state *st, render_ctx *c, fv_film *film, fv_stats *stats, fv_error *err)
{
    fv_camera_basis left;
    fv_status rc = fv_camera_basis_make(c->frame->left_camera, &left, err);
    c->left_cam = &left;
    c->left_color = st->left_color;
    c->gamma = st->left_gamma;
    c->norm = 1.0f / (FV_PI * c->gamma * c->gamma);
    c->eta = st->left_eta;
    c->pass = 0;
    fv_kit_phase(&c->prog, c->frame, 0.0, 1.0);
    memset(fv_film_color(film), 0, (size_t)fv_film_width(film) * fv_film_height(film) * 3 * sizeof(float));
    if (rc == FV_OK) rc = render_eye_pass(c, film, true, stats, err);
    return rc;
}

/* The left (or only) eye: light photons, foveated photons (fpm), gathering, the filter. */
static fv_status render_left(pm_state *st, render_ctx *c, fv_film *film, fv_stats *stats, fv_error *err)
{
    const fv_frame *frame = c->frame;
    const fv_scene *s = st->scene;
    int w = fv_film_width(film), h = fv_film_height(film);
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    c->gamma = st->o.radius > 0.0 ? (float)st->o.radius : fv_photon_radius_eq8(lo, hi, w, h);
    c->norm = 1.0f / (FV_PI * c->gamma * c->gamma);
    c->eta = 1.0;
    float cell = c->gamma;
    double n_light = st->mode == MODE_FPM ? st->o.photons * (1.0 - st->o.fov_fraction) : st->o.photons;
    int passes = st->mode == MODE_PM ? st->o.passes : 1;
    fv_status rc = FV_OK;
    memset(fv_film_color(film), 0, (size_t)w * h * 3 * sizeof(float));
    for (int pass = 0; pass < passes && rc == FV_OK; pass++) {
        /* Progress: each pass an equal share; in it, tracing light the first 40%, pixels the rest. */
        double base = (double)pass / passes, span = 1.0 / passes;
        fv_kit_phase(&c->prog, frame, base, 0.4 * span);
        fv_stage_clock t0 = fv_stage_clock_now();
        rc = light_tracing(st, frame, cell, pass, n_light, &c->prog, stats, err);
        fv_stage_stop(stats, "light_tracing", t0);
        if (rc == FV_OK && st->mode == MODE_FPM) rc = foveated_photons(st, c, w, h, cell, stats, err);
        c->pass = pass;
        if (rc == FV_OK && st->mode == MODE_FPM) c->sums = st->sums;
        fv_kit_phase(&c->prog, frame, base + 0.4 * span, 0.6 * span);
        if (rc == FV_OK) rc = render_eye_pass(c, film, false, stats, err);
        if (rc == FV_OK && c->sums) {
            fv_stage_clock t1 = fv_stage_clock_now();
            rc = finish_fpm(c, film, stats, err);
            fv_stage_stop(stats, "render", t1);
            fv_stats_add_count(stats, "eta", c->eta);
        }
        c->sums = NULL;
    }
    if (rc == FV_OK) rc = filter_film(st, film, c->gamma, frame->threads, stats, err);
    return rc;
}

static fv_status pm_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    pm_state *st = state;
    int w = fv_film_width(film), h = fv_film_height(film);
    fv_eye_model def;
    render_ctx ctx, *c = &ctx; /* on the stack: a frame allocates nothing once warmed up */
    memset(c, 0, sizeof *c);
    fv_status rc = ensure_buffers(st, w, h, err);
    if (rc == FV_OK && !(c->counters = fv_kit_counters_reuse(&st->counters))) rc = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    c->st = st;
    c->frame = frame;
    c->eye = fv_frame_eye_model(frame, w, h, &def);
    c->nbuf = st->nbuf;
    c->pbuf = st->pbuf;
    c->rbuf = st->rbuf;
    c->obuf = st->obuf;
    bool reuse_left = frame->eye == 1 && frame->left_camera && st->left_valid && st->left_index == frame->index;
    if (rc == FV_OK) rc = reuse_left ? render_right(st, c, film, stats, err) : render_left(st, c, film, stats, err);
    /* The left eye of a stereo pair keeps what the right eye will reuse. */
    st->left_valid = false;
    if (rc == FV_OK && frame->eye == 0 && frame->eye_count == 2) {
        size_t n = (size_t)w * h * 3;
        if (!st->left_color && !(st->left_color = fv_alloc_array(n, sizeof(float))))
            rc = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        if (rc == FV_OK) {
            memcpy(st->left_color, fv_film_color_const(film), n * sizeof(float));
            st->left_valid = true;
            st->left_index = frame->index;
            st->left_gamma = c->gamma;
            st->left_eta = c->eta;
        }
    }
    return rc;
}

static fv_status pm_create(const fv_scene *s, fv_params *p, const fv_log *log, void **state, fv_error *err)
{
    return pm_create_mode(MODE_PM, s, p, log, state, err);
}
static fv_status pmt_create(const fv_scene *s, fv_params *p, const fv_log *log, void **state, fv_error *err)
{
    return pm_create_mode(MODE_PMT, s, p, log, state, err);
}
static fv_status fpm_create(const fv_scene *s, fv_params *p, const fv_log *log, void **state, fv_error *err)
{
    return pm_create_mode(MODE_FPM, s, p, log, state, err);
}

/* The parameters all three read (read_opts), then each one's own. */
#define COMMON_PARAMS                                                                                                    \
    FV_PARAM_INT("photons", "300000", 1, 500000000, "photons per frame"), FV_PHOTON_RADIUS_PARAM("gather radius gamma in scene units"), \
        FV_PARAM_INT("max_depth", "8", 1, FV_FOV_MAX_DEPTH, "photon bounces"),                                            \
        FV_PARAM_INT("eye_depth", "8", 1, 64, "mirror/glass bounces of eye rays"),                                        \
        FV_PARAM_BOOL("filter", "true", "edge-avoiding A-Trous filter afterwards")

static const fv_param_info k_pm_params[] = {
    COMMON_PARAMS,
    FV_PARAM_INT("passes", "1", 1, 100000, "independent passes averaged (for references)"),
};

static const fv_param_info k_pmt_params[] = {
    COMMON_PARAMS,
    FV_PARAM_FLOAT("dyn_fraction", "0.2", 0.0, 0.95, "share of photons sent towards dynamic objects each frame"),
};

static const fv_param_info k_fpm_params[] = {
    COMMON_PARAMS,
    FV_PARAM_FLOAT("dyn_fraction", "0.2", 0.0, 0.95, "share of light photons sent towards dynamic objects each frame"),
    {.key = "fov_fraction", .type = FV_PARAM_FLOAT, .def = "0.4", .min = 0.0, .max = 1.0, .max_open = true,
     .help = "share of foveated photons in the total (some light photons are needed)"},
    FV_PARAM_INT("light_photons", "0", 0, 500000000, "absolute count of light photons instead of photons and fov_fraction (0: not used)"),
    FV_PARAM_INT("fov_photons", "0", 0, 500000000, "absolute count of foveated photons, with light_photons"),
    {.key = "paths_per_pixel", .type = FV_PARAM_INT, .def = "0", .def_note = "from the budget", .min = 0, .max = 64,
     .help = "N foveated paths per focus pixel"},
    FV_PARAM_BOOL("tpm", "true", "temporal photon management (false: retrace all foveated paths)"),
    FV_PARAM_CHOICE("eta_region", "fovea", k_regions, "the pixels whose gathered flux Eq. 1 sums (r_i)"),
    FV_PARAM_CHOICE("terms", "all", k_terms, "the focus region's estimate, or only one map pair's share of it (analysis)"),
};

/* The viewer's steps: the paper's 3M photons scaled to a CPU, a decade around the default. */
#define PHOTON_STEPS {"photons", {"10000", "30000", "100000", "300000", "1000000"}, false}

/* The furnace, with a gather radius fixed at r = 0.25: emission 0.5 seen directly, plus what the
 * photons of up to 8 bounces bring, 0.5 (1 - 0.5^8) = 0.498047, as the density estimate on the
 * unit sphere keeps it whole: the photons within chord r lie on a cap of area pi r^2
 * (Archimedes), so the pi r^2 of the estimate is right, and all of them are gathered (the normal
 * test rejects none while r < 1). So 0.998047, as pt's 1 - 0.5^9. Eq. 8 would give a 40x32 film
 * r = 1.11 here, where the gather's 60-degree normal test bounds the cap (area pi, 0.5 + 0.498 *
 * 0.812 = 0.904), hence the fixed radius in the furnace (the other checks keep Eq. 8's).
 * docs/photon-mapping.md, "The normal test", has the furnace at Eq. 8's radius at 128x128. */
#define FURNACE_TEST                                                                                \
    .test_params = "photons=40000", .furnace_params = "radius=0.25", .furnace_radiance = 0.998046875, \
    .furnace_tolerance = 0.04,                                                                       \
    .gathers_photons = true, .bench_scene = FV_PHOTON_BENCH_SCENE,                                   \
    .spp_instead = "one eye path per pixel centre gathers the photon maps: use --param photons=N, or passes=N to average N passes with pm; ppm takes --spp as its passes"

const fv_technique_class fv_technique_pm = {
    .name = "pm",
    .summary = "photon mapping, all photons retraced every frame (the paper's PM baseline)",
    .family = FV_FAMILY_PHOTON,
    .baseline = "pt", /* the truth its gather's bias is measured against (docs/photon-mapping.md) */
    FV_CLASS_PARAMS(k_pm_params),
    .main = PHOTON_STEPS,
    .create = pm_create,
    .render = pm_render,
    .destroy = pm_destroy,
    FURNACE_TEST,
    /* its passes are a float running mean, then filtered (and a stereo right eye reuses the left
     * eye's mean): not a sum of passes that MPI ranks could each take a part of */
    .unsplit = {"passes", "averaged and filtered in one process"},
};

const fv_technique_class fv_technique_pm_t = {
    .name = "pm-t",
    .summary = "photon mapping with the temporal strategy: static photons once, dynamic ones every frame (PM^t)",
    .family = FV_FAMILY_PHOTON,
    /* PM^t only changes which photons are retraced: measured against pm at the same photon count
     * (the fpm-* benchmarks' Table 1) */
    .baseline = "pm",
    FV_CLASS_PARAMS(k_pmt_params),
    .main = PHOTON_STEPS,
    .create = pmt_create,
    .render = pm_render,
    .destroy = pm_destroy,
    FURNACE_TEST,
};

const fv_technique_class fv_technique_fpm = {
    .name = "fpm",
    .summary = "foveated photon mapping: foveated photons in the focus region, temporal photon management",
    .family = FV_FAMILY_PHOTON,
    .baseline = "pm", /* the paper's PM_3M, at the same photon count (Table 1) */
    FV_CLASS_PARAMS(k_fpm_params),
    .main = PHOTON_STEPS,
    .create = fpm_create,
    .render = pm_render,
    .destroy = pm_destroy,
    FURNACE_TEST,
    .foveated = true,
    /* Temporal photon management keeps foveated paths while they stay valid, with no bound on
     * their age: a block of an MPI-split sequence rebuilds most of that pool in 8 frames (the
     * difference that remains is measured in docs/distributed.md). */
    .warmup_frames = 8,
};
