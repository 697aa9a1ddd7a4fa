/* fovea — `vpolar` (Foveated Real-Time Path Tracing in Visual-Polar Space) and the sample
 * distributions it is compared with (Sec. 4.3), each a technique of its own on one pipeline
 * (vp_pipeline.h): they differ only in the sample space and the launch.
 *
 *   vpolar          Visual-Polar space, 61% fewer samples than pixels, foveated blur
 *   cartesian       a uniform screen grid with the same sample count, bilinear upscaling
 *   cartesian-full  1 sample per pixel at full resolution: the cost reference of Fig. 12
 *   linear-falloff  full-resolution launch, paths killed at random outside a 10-degree fovea,
 *                   20% survive from 20 degrees on (Weier et al. 2016), foveated blur
 *   log-polar       kernel log-polar space (Meng et al. 2018), sigma 1.8, alpha 4
 * All share the 1-sample path tracing of Sec. 3.1 and the same SVGF settings.
 *
 * `show=space` puts the sample-space image itself in the film's top-left corner (Fig. 1, left;
 * the clipped part of Visual-Polar space white, as in Fig. 3); `show=density` writes the samples
 * per screen pixel (Fig. 1, right, and Fig. 8), averaged over a 13x13 window.
 */
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include "core/alloc.h"
#include "technique/class.h"
#include "technique/vpolar/vp_pipeline.h"

typedef enum vp_show { SHOW_SCREEN = 0, SHOW_SPACE, SHOW_DENSITY } vp_show;

typedef enum vp_kind { K_VPOLAR, K_CARTESIAN, K_CARTESIAN_FULL, K_LINEAR_FALLOFF, K_LOGPOLAR } vp_kind;

typedef struct vp_state {
    const char *name;
    const fv_scene *scene;
    vp_kind kind;
    fv_vp_opts o;
    vp_show show;
    fv_vp_device *dev;       /* portable and cuda: the backend every pipeline below runs on */
    fv_vp_pipeline *eye[2];
    /* The foveated kinds (vpolar, linear-falloff, log-polar) while the frame's fovea covers the whole
     * screen (a missing gaze under `widen`, docs/gaze.md): cartesian-full's pipeline with this
     * method's path tracing and denoiser settings, made at the first such frame. in_full: which of
     * the two rendered this eye's last frame (a switch starts the other's history afresh). */
    fv_vp_pipeline *full[2];
    bool in_full[2];
    /* The frames submitted (vp_submit), oldest first from head: the pipelines each eye went to,
     * and whether the device still has it in flight (else it was rendered in its submit). */
    struct vp_flight {
        int eyes;
        fv_vp_pipeline *p[2];
        bool in_flight;
    } flight[2];
    int head, in_flight;
} vp_state;

#define VP_PERIPHERY_PASSES 3 /* vpolar's periphery_passes default */
#define VP_PERIPHERY_DEG 20.0 /* and where they start (at most blur_ramp_deg) */

static const char *const k_orders[] = {"grid", "random", NULL};
static const char *const k_offscreen[] = {"skip", "trace", NULL}; /* skip first: the default */
static const char *const k_show[] = {"screen", "space", "density", NULL};

/* A float parameter that must lie strictly inside (lo, hi). */
static fv_status open_range(fv_params *p, const char *key, double def, double lo, double hi, double *out, fv_error *err)
{
    fv_status s = fv_params_float(p, key, def, lo, hi, out, err);
    if (s == FV_OK && !(*out > lo && *out < hi))
        s = fv_error_set(err, FV_ERR_INVALID, "parameter %s=%g must be in (%g, %g)", key, *out, lo, hi);
    return s;
}

static fv_status read_opts(vp_kind kind, fv_params *p, fv_vp_opts *o, vp_show *show, fv_error *err)
{
    memset(o, 0, sizeof *o);
    o->periphery_passes = 10; /* off: every column gets every pass */
    fv_space_kind sk = kind == K_VPOLAR ? FV_SPACE_VPOLAR : (kind == K_LOGPOLAR ? FV_SPACE_LOGPOLAR : FV_SPACE_CARTESIAN);
    fv_space_opts_default(sk, &o->space);
    fv_svgf_opts_default(&o->svgf);
    fv_status s;
    int bounces, order, offscreen, sh;
    double blur_fovea_def = kind == K_LINEAR_FALLOFF ? 10.0 : 5.79;
    bool blur_def = kind == K_VPOLAR || kind == K_LINEAR_FALLOFF;
    if ((s = fv_params_int(p, "bounces", 1, 0, 64, &bounces, err)) || (s = fv_params_int(p, "spp", 1, 1, 1 << 16, &o->pt.spp, err)) ||
        (s = fv_params_choice(p, "order", 0, k_orders, &order, err)) ||
        (s = fv_params_choice(p, "offscreen", 0, k_offscreen, &offscreen, err)) ||
        (s = fv_params_choice(p, "show", 0, k_show, &sh, err)) || (s = fv_params_bool(p, "denoise", true, &o->denoise, err)) ||
        (s = fv_params_int(p, "svgf_iterations", o->svgf.iterations, 0, 10, &o->svgf.iterations, err)))
        return s;
    double v;
    /* Each refused here by its own name: SVGF's validation would name its fields instead
     * ("alpha_color"), which no user typed. */
    if ((s = fv_params_float(p, "svgf_alpha", o->svgf.alpha_color, 0.0, 1.0, &v, err))) return s;
    if (!(v > 0.0)) return fv_error_set(err, FV_ERR_INVALID, "parameter svgf_alpha=%g must be in (0, 1]", v);
    o->svgf.alpha_color = o->svgf.alpha_moments = (float)v;
    float *sigmas[3] = {&o->svgf.sigma_lum, &o->svgf.sigma_normal, &o->svgf.sigma_depth};
    static const char *const sigma_keys[3] = {"sigma_lum", "sigma_normal", "sigma_depth"};
    for (int i = 0; i < 3; i++) {
        if ((s = fv_params_float(p, sigma_keys[i], *sigmas[i], 0.0, 1e6, &v, err))) return s;
        if (!(v > 0.0)) return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%g must be > 0", sigma_keys[i], v);
        *sigmas[i] = (float)v;
    }
    if ((s = fv_params_bool(p, "blur", blur_def, &o->blur, err)) ||
        (s = fv_params_float(p, "blur_sigma", 6.8, 0.0, 100.0, &o->blur_sigma, err)) ||
        (s = fv_params_float(p, "blur_fovea_deg", blur_fovea_def, 0.0, 180.0, &o->blur_fovea_deg, err)) ||
        (s = fv_params_float(p, "blur_ramp_deg", 30.0, 0.0, 180.0, &o->blur_ramp_deg, err)))
        return s;
    if (!(o->blur_ramp_deg > o->blur_fovea_deg))
        return fv_error_set(err, FV_ERR_INVALID, "parameter blur_ramp_deg=%g must be greater than blur_fovea_deg=%g", o->blur_ramp_deg,
                            o->blur_fovea_deg);
    switch (kind) {
    case K_VPOLAR:
        if ((s = open_range(p, "reduction", 0.61, 0.0, 1.0, &o->space.reduction, err)) ||
            (s = fv_params_float(p, "fovea_deg", 5.79, 0.01, 90.0, &o->space.fovea_deg, err)) ||
            (s = fv_params_int(p, "fit_degree", 6, 2, 10, &o->space.fit_degree, err)))
            return s;
        o->blur_follows_space = true;
        /* Issue 16: three passes beyond 20 degrees, where the blur already has 60% of its sigma,
         * lose nothing in the fovea and the transition and change the periphery's FLIP and
         * flicker by under 1% on cornell and the city (vp-periphery, docs/results.md); beyond
         * 15 degrees the transition starts to lose. So on by default. */
        if ((s = fv_params_int(p, "periphery_passes", VP_PERIPHERY_PASSES, 0, 10, &o->periphery_passes, err)) ||
            (s = fv_params_float(p, "periphery_deg", fmin(VP_PERIPHERY_DEG, o->blur_ramp_deg), 0.0, 180.0, &o->periphery_deg, err)))
            return s;
        break;
    case K_CARTESIAN:
        if ((s = open_range(p, "reduction", 0.61, 0.0, 1.0, &o->space.reduction, err))) return s;
        break;
    case K_LOGPOLAR:
        if ((s = fv_params_float(p, "sigma", 1.8, 1.0, 100.0, &o->space.lp_sigma, err)) ||
            (s = fv_params_float(p, "alpha", 4.0, 0.0, 100.0, &o->space.lp_alpha, err)))
            return s;
        if (!(o->space.lp_sigma > 1.0))
            return fv_error_set(err, FV_ERR_INVALID, "parameter sigma=%g must be greater than 1 (the grid is the screen / sigma)",
                                o->space.lp_sigma);
        if (!(o->space.lp_alpha > 0.0))
            return fv_error_set(err, FV_ERR_INVALID, "parameter alpha=%g must be positive", o->space.lp_alpha);
        break;
    case K_LINEAR_FALLOFF:
        o->kill = true;
        if ((s = fv_params_float(p, "falloff_fovea_deg", 10.0, 0.0, 180.0, &o->kill_e0, err)) ||
            (s = fv_params_float(p, "falloff_periphery_deg", 20.0, 0.0, 180.0, &o->kill_e1, err)) ||
            (s = fv_params_float(p, "falloff_probability", 0.2, 0.0, 1.0, &o->kill_p, err)))
            return s;
        if (!(o->kill_e1 > o->kill_e0))
            return fv_error_set(err, FV_ERR_INVALID, "parameter falloff_periphery_deg=%g must be greater than falloff_fovea_deg=%g",
                                o->kill_e1, o->kill_e0);
        if (!(o->kill_p > 0.0))
            return fv_error_set(err, FV_ERR_INVALID, "parameter falloff_probability=%g must be positive", o->kill_p);
        break;
    case K_CARTESIAN_FULL:
        break;
    }
    o->pt.max_depth = 1 + bounces;
    o->pt.rr_depth = 1 << 20; /* Sec. 3.1: a fixed path length, no Russian roulette */
    o->order = (fv_vp_order)order;
    o->skip_offscreen = offscreen == 0;
    *show = (vp_show)sh;
    return FV_OK;
}

static fv_status create_kind(vp_kind kind, const char *name, const fv_scene *scene, fv_params *params, fv_device device, void **state,
                             fv_error *err)
{
    vp_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->name = name;
    st->kind = kind;
    st->scene = scene;
    fv_status s = read_opts(kind, params, &st->o, &st->show, err);
    st->o.device = device;
    /* On cuda the sample grid stays on the GPU: the diagnostics that draw it need its host copy. */
    if (s == FV_OK && device == FV_DEVICE_CUDA && st->show != SHOW_SCREEN)
        s = fv_error_set(err, FV_ERR_INVALID, "parameter show=%s: device cuda renders the image only (devices cpu and portable draw diagnostics)",
                         k_show[st->show]);

    if (s == FV_OK && device != FV_DEVICE_CPU) s = fv_vp_device_create(scene, device, &st->dev, err);
    for (int e = 0; s == FV_OK && e < 2; e++) s = fv_vp_pipeline_create(scene, &st->o, st->dev, &st->eye[e], err);
    if (s != FV_OK) {
        fv_vp_pipeline_destroy(st->eye[0]);
        fv_vp_pipeline_destroy(st->eye[1]);
        fv_vp_device_destroy(st->dev);
        free(st);
        return s;
    }
    *state = st;
    return FV_OK;
}

/* show=space: the sample-space image in the top-left corner, clipped rows white. */
static void show_space(const fv_vp_pipeline *p, fv_film *film)
{
    fv_space_view view;
    const float *img;
    double ppd;
    const fv_space *sp = fv_vp_pipeline_space(p, &view, &img, &ppd);
    float *out = fv_film_color(film);
    int w = fv_film_width(film), h = fv_film_height(film);
    memset(out, 0, sizeof(float) * 3 * (size_t)w * h);
    if (!sp) return;
    const fv_grid *g = fv_space_grid(sp);
    for (int y = 0; y < g->h && y < h; y++)
        for (int x = 0; x < g->w && x < w; x++) {
            float *o = &out[3 * ((size_t)y * w + x)];
            if (!fv_grid_valid(g, x, y)) {
                o[0] = o[1] = o[2] = 1e3f;
                continue;
            }
            memcpy(o, &img[3 * ((size_t)y * g->w + x)], 3 * sizeof(float));
        }
}

/* show=density: samples per screen pixel, from the positions of the grid's samples in the frame
 * just rendered (linear fall-off: their expected survival). */
static fv_status show_density(const vp_state *st, const fv_vp_pipeline *p, fv_film *film, fv_error *err)
{
    int w = fv_film_width(film), h = fv_film_height(film);
    fv_space_view view;
    const float *img;
    double ppd;
    const fv_space *sp = fv_vp_pipeline_space(p, &view, &img, &ppd);
    if (!sp) return fv_error_set(err, FV_ERR_INTERNAL, "show=density before a frame was rendered");
    const fv_grid *g = fv_space_grid(sp);
    double *count = fv_calloc_array((size_t)(w + 1) * (h + 1), sizeof(double));
    if (!count) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (int y = 0; y < g->h; y++)
        for (int x = 0; x < g->w; x++) {
            if (!fv_grid_valid(g, x, y)) continue;
            float px, py, X, V;
            fv_grid_centre(g, x, y, &X, &V);
            fv_space_to_screen(&view, X, V, &px, &py);
            if (px < 0.0f || py < 0.0f || px >= (float)w || py >= (float)h) continue;
            double weight = st->o.kill ? fv_vp_survival(&view, px, py, ppd, st->o.kill_e0, st->o.kill_e1, st->o.kill_p) : 1.0;
            count[(size_t)((int)py + 1) * (w + 1) + (int)px + 1] += weight;
        }
    /* Summed-area table, then the mean over a 13x13 window. */
    for (int y = 1; y <= h; y++)
        for (int x = 1; x <= w; x++)
            count[(size_t)y * (w + 1) + x] +=
                count[(size_t)(y - 1) * (w + 1) + x] + count[(size_t)y * (w + 1) + x - 1] - count[(size_t)(y - 1) * (w + 1) + x - 1];
    float *out = fv_film_color(film);
    const int r = 6;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int x0 = x - r < 0 ? 0 : x - r, x1 = x + r + 1 > w ? w : x + r + 1;
            int y0 = y - r < 0 ? 0 : y - r, y1 = y + r + 1 > h ? h : y + r + 1;
            double sum = count[(size_t)y1 * (w + 1) + x1] - count[(size_t)y0 * (w + 1) + x1] - count[(size_t)y1 * (w + 1) + x0] +
                         count[(size_t)y0 * (w + 1) + x0];
            float d = (float)(sum / ((double)(x1 - x0) * (y1 - y0)));
            out[3 * ((size_t)y * w + x)] = out[3 * ((size_t)y * w + x) + 1] = out[3 * ((size_t)y * w + x) + 2] = d;
        }
    free(count);
    return FV_OK;
}

/* Whether the frame's fovea covers the whole screen for a method whose samples follow the gaze: it
 * then renders as cartesian-full does, every pixel sampled and nothing blurred. */
static bool whole_fovea(const vp_state *st, const fv_frame *frame)
{
    if (st->kind != K_VPOLAR && st->kind != K_LINEAR_FALLOFF && st->kind != K_LOGPOLAR) return false;
    const fv_camera *cam = frame->camera;
    fv_eye_model def;
    return fv_frame_fovea_covers(frame, fv_frame_eye_model(frame, cam->width, cam->height, &def), cam->width, cam->height);
}

/* cartesian-full's options with this method's launch, path tracing and denoiser settings. */
static fv_vp_opts full_opts(const fv_vp_opts *o)
{
    fv_vp_opts f = *o;
    fv_space_opts_default(FV_SPACE_CARTESIAN, &f.space);
    f.kill = false;
    f.blur = false;
    f.blur_follows_space = false;
    f.periphery_passes = 10;
    return f;
}

/* Each eye has its own pipeline: its history follows that eye's camera. The pipeline for the
 * frame's eye (*full: cartesian-full's, made here at its first frame) and the frame it renders. */
static fv_status eye_pipeline(vp_state *st, const fv_frame *frame, fv_vp_pipeline **p, fv_frame *f, bool *full, fv_error *err)
{
    const int e = frame->eye;
    *full = whole_fovea(st, frame);
    if (*full && !st->full[e]) {
        const fv_vp_opts fo = full_opts(&st->o);
        fv_status s = fv_vp_pipeline_create(st->scene, &fo, st->dev, &st->full[e], err);
        if (s != FV_OK) return s;
    }
    *p = *full ? st->full[e] : st->eye[e];
    /* The pipeline that did not render this eye's last frame holds an older history: not reused. */
    *f = *frame;
    if (*full != st->in_full[e]) f->prev_camera = NULL;
    return FV_OK;
}

static fv_status vp_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    vp_state *st = state;
    fv_vp_pipeline *p;
    fv_frame f;
    bool full;
    fv_status s = eye_pipeline(st, frame, &p, &f, &full, err);
    if (s != FV_OK) return s;
    s = fv_vp_pipeline_render(p, &f, film, stats, err);
    if (s != FV_OK) return s;
    st->in_full[frame->eye] = full;
    if (st->show == SHOW_SPACE) show_space(p, film);
    if (st->show == SHOW_DENSITY) s = show_density(st, p, film, err);
    return s;
}

/* A stereo frame: on a device both eyes' frames are queued before one host wait
 * (fv_vp_pipeline_render_pair, docs/gpu.md), each eye on its own pipeline as vp_render renders it;
 * on the CPU, and for the diagnostics (show=space, density: drawn per eye), the two per-eye calls. */
static fv_status vp_render_pair(void *state, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    vp_state *st = state;
    fv_status s;
    if (st->o.device == FV_DEVICE_CPU || st->show != SHOW_SCREEN) {
        s = vp_render(state, &frames[0], films[0], stats, err);
        return s == FV_OK ? vp_render(state, &frames[1], films[1], stats, err) : s;
    }
    fv_vp_pipeline *p[2];
    fv_frame f[2];
    bool full[2];
    for (int e = 0; e < 2; e++)
        if ((s = eye_pipeline(st, &frames[e], &p[e], &f[e], &full[e], err)) != FV_OK) return s;
    if ((s = fv_vp_pipeline_render_pair(p, f, films, stats, err)) != FV_OK) return s;
    for (int e = 0; e < 2; e++) st->in_full[e] = full[e];
    return FV_OK;
}

/* A frame queued (docs/gpu.md, "Frames in flight"): on a device, with the diagnostics off, every
 * eye on its pipeline as vp_render_pair and vp_render choose it, without a host wait; otherwise
 * rendered now, and collect only hands it over. */
static fv_status vp_submit(void *state, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    vp_state *st = state;
    if (st->in_flight >= 2) return fv_error_set(err, FV_ERR_INTERNAL, "%s: %d frames in flight already", st->name, st->in_flight);
    struct vp_flight *fl = &st->flight[(st->head + st->in_flight) % 2];
    fv_status s;
    memset(fl, 0, sizeof *fl);
    if (st->o.device == FV_DEVICE_CPU || st->show != SHOW_SCREEN) {
        s = eyes == 2 ? vp_render_pair(state, frames, films, stats, err) : vp_render(state, frames, films[0], stats, err);
        if (s == FV_OK) st->in_flight++;
        return s;
    }
    fv_frame f[2];
    bool full[2] = {false, false};
    memset(f, 0, sizeof f);
    for (int e = 0; e < eyes; e++)
        if ((s = eye_pipeline(st, &frames[e], &fl->p[e], &f[e], &full[e], err)) != FV_OK) return s;
    if ((s = fv_vp_pipeline_submit(fl->p, eyes, f, films, stats, &fl->in_flight, err)) != FV_OK) return s;
    for (int e = 0; e < eyes; e++) st->in_full[frames[e].eye] = full[e];
    fl->eyes = eyes;
    st->in_flight++;
    return FV_OK;
}

static fv_status vp_collect(void *state, fv_error *err)
{
    vp_state *st = state;
    if (!st->in_flight) return fv_error_set(err, FV_ERR_INTERNAL, "%s: no frame in flight", st->name);
    const struct vp_flight fl = st->flight[st->head];
    st->head = (st->head + 1) % 2;
    st->in_flight--;
    return fl.in_flight ? fv_vp_pipeline_collect(fl.p, fl.eyes, err) : FV_OK;
}

static void vp_destroy(void *state)
{
    vp_state *st = state;
    if (!st) return;
    fv_vp_pipeline_destroy(st->eye[0]);
    fv_vp_pipeline_destroy(st->eye[1]);
    fv_vp_pipeline_destroy(st->full[0]);
    fv_vp_pipeline_destroy(st->full[1]);
    fv_vp_device_destroy(st->dev); /* after its pipelines */
    free(st);
}

static fv_status create_vpolar_on(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    (void)l;
    return create_kind(K_VPOLAR, "vpolar", s, p, d, st, e);
}
static fv_status create_vpolar(const fv_scene *s, fv_params *p, const fv_log *l, void **st, fv_error *e)
{
    return create_vpolar_on(s, p, FV_DEVICE_CPU, l, st, e);
}
static fv_status create_cartesian_on(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    (void)l;
    return create_kind(K_CARTESIAN, "cartesian", s, p, d, st, e);
}
static fv_status create_cartesian(const fv_scene *s, fv_params *p, const fv_log *l, void **st, fv_error *e)
{
    return create_cartesian_on(s, p, FV_DEVICE_CPU, l, st, e);
}
static fv_status create_cartesian_full_on(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    (void)l;
    return create_kind(K_CARTESIAN_FULL, "cartesian-full", s, p, d, st, e);
}
static fv_status create_cartesian_full(const fv_scene *s, fv_params *p, const fv_log *l, void **st, fv_error *e)
{
    return create_cartesian_full_on(s, p, FV_DEVICE_CPU, l, st, e);
}
static fv_status create_linear_falloff_on(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    (void)l;
    return create_kind(K_LINEAR_FALLOFF, "linear-falloff", s, p, d, st, e);
}
static fv_status create_linear_falloff(const fv_scene *s, fv_params *p, const fv_log *l, void **st, fv_error *e)
{
    return create_linear_falloff_on(s, p, FV_DEVICE_CPU, l, st, e);
}
static fv_status create_logpolar_on(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    (void)l;
    return create_kind(K_LOGPOLAR, "log-polar", s, p, d, st, e);
}
static fv_status create_logpolar(const fv_scene *s, fv_params *p, const fv_log *l, void **st, fv_error *e)
{
    return create_logpolar_on(s, p, FV_DEVICE_CPU, l, st, e);
}

/* The devices beyond the CPU: the portable backend and CUDA (technique/vpolar/vp_device.h). */
#define VP_DEVICES ((1u << FV_DEVICE_PORTABLE) | (1u << FV_DEVICE_CUDA))

/* The furnace with one bounce (max_depth 2): emission 0.5 seen directly, plus 0.25 and 0.125
 * gathered at the two vertices; the denoiser and the blur preserve a constant image. */
#define FURNACE_TEST .test_params = "", .furnace_radiance = 0.875, .furnace_tolerance = 0.03

/* The parameters every kind reads (read_opts), with the kind's default for blur_fovea_deg. */
#define COMMON_PARAMS(blur_fovea_def)                                                                                    \
    FV_PARAM_INT("bounces", "1", 0, 64, "indirect bounces per path (Sec. 3.1: one)"),                                    \
        FV_PARAM_INT("spp", "1", 1, 1 << 16, "paths averaged per sample of the grid (Sec. 3.1: one)"),                  \
        FV_PARAM_BOOL("denoise", "true", "SVGF in the sample space"),                                                    \
        FV_PARAM_INT("svgf_iterations", "5", 0, 10, "SVGF's A-Trous passes"),                                            \
        {.key = "svgf_alpha", .type = FV_PARAM_FLOAT, .def = "0.2", .min = 0.0, .min_open = true, .max = 1.0,            \
         .help = "SVGF's temporal blend of colour and moments"},                                                         \
        {.key = "sigma_lum", .type = FV_PARAM_FLOAT, .def = "4", .min = 0.0, .min_open = true, .max = 1e6,               \
         .help = "SVGF's luminance edge-stopping"},                                                                      \
        {.key = "sigma_normal", .type = FV_PARAM_FLOAT, .def = "128", .min = 0.0, .min_open = true, .max = 1e6,          \
         .help = "SVGF's normal edge-stopping exponent"},                                                                \
        {.key = "sigma_depth", .type = FV_PARAM_FLOAT, .def = "1", .min = 0.0, .min_open = true, .max = 1e6,             \
         .help = "SVGF's depth edge-stopping"},                                                                          \
        FV_PARAM_FLOAT("blur_sigma", "6.8", 0.0, 100.0, "blur sigma in pixels at blur_ramp_deg, for 1280 pixels wide (scaled with the width)"), \
        FV_PARAM_FLOAT("blur_fovea_deg", blur_fovea_def, 0.0, 180.0, "the blur is 0 inside this eccentricity"),          \
        FV_PARAM_FLOAT("blur_ramp_deg", "30", 0.0, 180.0, "the blur rises linearly to blur_sigma here; greater than blur_fovea_deg"), \
        FV_PARAM_CHOICE("order", "grid", k_orders, "launch order of the samples (random: Sec. 6's incoherent launch)"),     \
        FV_PARAM_CHOICE("offscreen", "skip", k_offscreen, "trace the polar grids' cells no screen pixel sees, or not (same image either way)"), \
        FV_PARAM_CHOICE("show", "screen", k_show, "the image, the sample-space image, or samples per pixel")

#define REDUCTION_PARAM(h)                                                                                               \
    {.key = "reduction", .type = FV_PARAM_FLOAT, .def = "0.61", .min = 0.0, .max = 1.0, .min_open = true, .max_open = true, .help = (h)}
#define NO_BLUR_PARAM FV_PARAM_BOOL("blur", "false", "the foveated blur")

static const fv_param_info k_vpolar_params[] = {
    COMMON_PARAMS("5.79"),
    REDUCTION_PARAM("share of screen pixels not sampled (the paper: 0.61, 0.71, 0.88)"),
    FV_PARAM_FLOAT("fovea_deg", "5.79", 0.01, 90.0, "radius of the linear, clipped fovea in planar degrees"),
    FV_PARAM_INT("fit_degree", "6", 2, 10, "degree of the polynomial inverse of Eq. 2"),
    FV_PARAM_BOOL("blur", "true", "foveated blur (its fovea stretched with the space)"),
    FV_PARAM_INT("periphery_passes", "3", 0, 10, "SVGF passes for the columns beyond periphery_deg (svgf_iterations or more: all)"),
    {.key = "periphery_deg", .type = FV_PARAM_FLOAT, .def = "20", .def_note = "at most blur_ramp_deg", .min = 0.0, .max = 180.0,
     .help = "eccentricity where periphery_passes starts, on the blur's profile"},
};
static const fv_param_info k_cartesian_params[] = {
    COMMON_PARAMS("5.79"),
    REDUCTION_PARAM("share of screen pixels not sampled"),
    NO_BLUR_PARAM,
};
static const fv_param_info k_cartesian_full_params[] = {
    COMMON_PARAMS("5.79"),
    NO_BLUR_PARAM,
};
static const fv_param_info k_linear_falloff_params[] = {
    COMMON_PARAMS("10"),
    FV_PARAM_FLOAT("falloff_fovea_deg", "10", 0.0, 180.0, "survival 1 inside this eccentricity"),
    FV_PARAM_FLOAT("falloff_periphery_deg", "20", 0.0, 180.0, "survival falloff_probability beyond; greater than falloff_fovea_deg"),
    {.key = "falloff_probability", .type = FV_PARAM_FLOAT, .def = "0.2", .min = 0.0, .min_open = true, .max = 1.0,
     .help = "survival in the periphery"},
    FV_PARAM_BOOL("blur", "true", "foveated blur"),
};
static const fv_param_info k_logpolar_params[] = {
    COMMON_PARAMS("5.79"),
    {.key = "sigma", .type = FV_PARAM_FLOAT, .def = "1.8", .min = 1.0, .min_open = true, .max = 100.0,
     .help = "screen / grid size ratio per axis"},
    {.key = "alpha", .type = FV_PARAM_FLOAT, .def = "4", .min = 0.0, .min_open = true, .max = 100.0, .help = "kernel exponent"},
    NO_BLUR_PARAM,
};

/* The viewer's steps: the paper's three reductions; the bounce count of the full-resolution
 * launches, which have no share of pixels to step. */
#define REDUCTION_STEPS {"reduction", {"0.61", "0.71", "0.88"}, false}
#define BOUNCE_STEPS {"bounces", {"1", "2", "3"}, false}

/* Warm-up of a block of a sequence split over MPI ranks (class.h): SVGF's history blends each
 * frame in with weight 0.2 (Schied et al. 2017, Sec. 4.1), so after 16 frames a missing past
 * weighs 0.8^16 = 3% of the colour; the image converges to the one-process frame, not bit for bit.
 * A still needs as many (class.h's still_warmup_frames): its first frame has no history, so SVGF's
 * variance comes from the spatial estimate alone and the periphery's error is 1.6x the steady
 * state's (vpolar, cornell at 128x128, tests/cli/test_still_warmup.sh). */
#define SVGF_WARMUP 16

/* Baselines: cartesian-full, one sample per pixel at full resolution, is what the paper's sample
 * distributions are measured against (its cost reference, Fig. 12; the vp-* benchmarks); it is
 * itself measured against the converged path tracer. */
const fv_technique_class fv_technique_vpolar = {
    .name = "vpolar",
    .summary = "foveated path tracing in Visual-Polar space: 1 spp on the VP grid, SVGF in VP space, φ-mipmapped mapping, foveated blur",
    .family = FV_FAMILY_VPOLAR, .baseline = "cartesian-full", FV_CLASS_PARAMS(k_vpolar_params), .main = REDUCTION_STEPS,
    .create = create_vpolar, .create_on = create_vpolar_on, .devices = VP_DEVICES, .render = vp_render, .render_pair = vp_render_pair, .submit = vp_submit, .collect = vp_collect, .destroy = vp_destroy,
    FURNACE_TEST, .warmup_frames = SVGF_WARMUP, .still_warmup_frames = SVGF_WARMUP, .spp_param = "spp", .foveated = true,
};

const fv_technique_class fv_technique_cartesian = {
    .name = "cartesian",
    .summary = "uniform screen grid with vpolar's sample count, SVGF, bilinear upscaling (Visual-Polar Sec. 4.3 baseline)",
    .family = FV_FAMILY_VPOLAR, .baseline = "cartesian-full", FV_CLASS_PARAMS(k_cartesian_params), .main = REDUCTION_STEPS,
    .create = create_cartesian, .create_on = create_cartesian_on, .devices = VP_DEVICES, .render = vp_render, .render_pair = vp_render_pair, .submit = vp_submit, .collect = vp_collect, .destroy = vp_destroy,
    FURNACE_TEST, .warmup_frames = SVGF_WARMUP, .still_warmup_frames = SVGF_WARMUP, .spp_param = "spp",
};

const fv_technique_class fv_technique_cartesian_full = {
    .name = "cartesian-full",
    .summary = "1 spp at full resolution with SVGF: the cost reference of Visual-Polar Fig. 12",
    .family = FV_FAMILY_VPOLAR, .baseline = "pt", FV_CLASS_PARAMS(k_cartesian_full_params), .main = BOUNCE_STEPS,
    .create = create_cartesian_full, .create_on = create_cartesian_full_on, .devices = VP_DEVICES, .render = vp_render, .render_pair = vp_render_pair, .submit = vp_submit, .collect = vp_collect, .destroy = vp_destroy,
    FURNACE_TEST, .warmup_frames = SVGF_WARMUP, .still_warmup_frames = SVGF_WARMUP, .spp_param = "spp",
};

const fv_technique_class fv_technique_linear_falloff = {
    .name = "linear-falloff",
    .summary = "full-resolution launch, paths killed at random outside the fovea (Weier et al. 2016), SVGF, blur",
    .family = FV_FAMILY_VPOLAR, .baseline = "cartesian-full", FV_CLASS_PARAMS(k_linear_falloff_params), .main = BOUNCE_STEPS,
    .create = create_linear_falloff, .create_on = create_linear_falloff_on, .devices = VP_DEVICES, .render = vp_render, .render_pair = vp_render_pair, .submit = vp_submit, .collect = vp_collect, .destroy = vp_destroy,
    FURNACE_TEST, .warmup_frames = SVGF_WARMUP, .still_warmup_frames = SVGF_WARMUP, .spp_param = "spp", .foveated = true,
};

const fv_technique_class fv_technique_logpolar = {
    .name = "log-polar",
    .summary = "kernel log-polar space (Meng et al. 2018), SVGF in log-polar space, φ-mipmapped mapping",
    .family = FV_FAMILY_VPOLAR, .baseline = "cartesian-full", FV_CLASS_PARAMS(k_logpolar_params), .main = BOUNCE_STEPS,
    .create = create_logpolar, .create_on = create_logpolar_on, .devices = VP_DEVICES, .render = vp_render, .render_pair = vp_render_pair, .submit = vp_submit, .collect = vp_collect, .destroy = vp_destroy,
    FURNACE_TEST, .warmup_frames = SVGF_WARMUP, .still_warmup_frames = SVGF_WARMUP, .spp_param = "spp", .foveated = true,
};
