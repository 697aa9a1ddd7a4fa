/* fovea-view — one frame: the panels the window shows, each slot rendered through the sequence
 * driver exactly as `fovea render` renders (same options, same policy), and the films scaled into
 * the window.
 *
 * A driver is created for every render rather than kept: it is only its options, and the
 * viewer's options change from frame to frame (the render size with the split view, the seed
 * while frames accumulate). Frame index i is at time i / FV_VW_FPS, the animation clock in
 * milliseconds; `continues` holds while a slot keeps its technique and size, so temporal methods
 * reuse their history as in a rendered sequence. */
#include <SDL.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include "view.h"

int fv_vw_panels(fv_vw_app *app, int win_w, int win_h, fv_vw_panel out[2])
{
    int half = win_w / 2;
    if (app->args.stereo > 0) {
        out[0] = (fv_vw_panel){{0, 0, half, win_h}, &app->main, 0};
        out[1] = (fv_vw_panel){{half, 0, win_w - half, win_h}, &app->main, 1};
        return 2;
    }
    if (app->split && app->base.tech) {
        out[0] = (fv_vw_panel){{0, 0, half, win_h}, &app->main, 0};
        out[1] = (fv_vw_panel){{half, 0, win_w - half, win_h}, &app->base, 0};
        return 2;
    }
    out[0] = (fv_vw_panel){{0, 0, win_w, win_h}, &app->main, 0};
    return 1;
}

/* The window may close while a frame renders: the progress callback looks at SDL's queue (only
 * from the main thread, where SDL allows it, and at most every 20 ms) and cancels the frame. */
typedef struct cancel_poll {
    fv_vw_app *app;
    pthread_t main;
    double last;
} cancel_poll;

static bool on_progress(void *user, double fraction)
{
    cancel_poll *p = user;
    if (p->app->cancelled) return false;
    if (!pthread_equal(pthread_self(), p->main)) return true;
    double now = fv_time_ms();
    if (now - p->last < 20.0) return true;
    p->last = now;
    SDL_PumpEvents();
    if (SDL_QuitRequested()) p->app->cancelled = true;
    return !p->app->cancelled;
}

static uint64_t mix(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001b3ULL; /* FNV-1a */
    return h;
}

static fv_status render_slot(fv_vw_app *app, fv_vw_slot *s, int w, int h, fv_error *err)
{
    int eyes = app->args.stereo > 0 ? 2 : 1;
    fv_status st = fv_vw_slot_films(s, w, h, eyes, err);
    if (st != FV_OK) return st;
    int index = (int)llround(app->anim_time * FV_VW_FPS);
    fv_camera cam;
    memset(&cam, 0, sizeof cam);
    if (app->fly.active) fv_vw_fly_camera(&app->fly, &cam);
    /* what the frame depends on: while it stays the same, a progressive method averages frames */
    uint64_t key = 0xcbf29ce484222325ULL;
    key = mix(key, &index, sizeof index);
    key = mix(key, &cam, sizeof cam);
    key = mix(key, &app->gaze, sizeof app->gaze);
    key = mix(key, &s->method, sizeof s->method);
    key = mix(key, &s->value, sizeof s->value);
    bool accumulate = fv_technique_progressive(s->method) && s->accum[0] && s->accum_key == key;

    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = w;
    o.height = h;
    o.time0 = 0.0;
    o.fps = FV_VW_FPS;
    o.seed = app->base_seed + (accumulate ? (uint64_t)s->accum_n : 0);
    o.threads = app->args.threads;
    o.eye_separation = (float)app->args.stereo;
    o.gaze_path = app->gaze_trace;
    fv_driver *d = NULL;
    if ((st = fv_driver_create(app->scene, app->view, &o, &d, err)) != FV_OK) return st;
    if (!app->gaze_trace) fv_driver_set_gaze(d, app->gaze);
    if (app->fly.active) fv_driver_set_camera(d, &cam);
    fv_frame_views v;
    fv_driver_views(d, index, &v);
    s->eye = *fv_driver_eye_model(d);
    s->gaze[0] = v.gaze[0];
    s->gaze[1] = v.gaze[1];

    cancel_poll poll = {app, pthread_self(), fv_time_ms()};
    fv_stats_clear(&s->stats);
    double t0 = fv_time_ms();
    st = fv_driver_render(d, s->tech, index, s->rendered, s->film, &s->stats, on_progress, &poll, err);
    s->ms = fv_time_ms() - t0;
    fv_driver_destroy(d);
    if (st != FV_OK) return st;
    s->rendered = true;

    if (s == &app->main && app->rec.gaze) {
        fv_camera c = v.camera[0];
        if (eyes == 2) {
            c.pos = fv_scale(fv_add(v.camera[0].pos, v.camera[1].pos), 0.5f);
            c.look = fv_scale(fv_add(v.camera[0].look, v.camera[1].look), 0.5f);
        }
        fv_vw_record_sample(&app->rec, v.time, v.gaze[0], &c);
    }
    if (!fv_technique_progressive(s->method)) return FV_OK;
    size_t n = (size_t)w * h * 3;
    for (int e = 0; e < eyes; e++) {
        if (!s->accum[e] && !(s->accum[e] = malloc(n * sizeof(float)))) return fv_error_set(err, FV_ERR_NOMEM, "viewer: out of memory");
        const float *src = fv_film_color_const(s->film[e]);
        if (accumulate) for (size_t i = 0; i < n; i++) s->accum[e][i] += src[i];
        else memcpy(s->accum[e], src, n * sizeof(float));
    }
    s->accum_n = accumulate ? s->accum_n + 1 : 1;
    s->accum_key = key;
    return FV_OK;
}

fv_status fv_vw_render(fv_vw_app *app, const fv_vw_panel *p, int np, fv_error *err)
{
    for (int i = 0; i < np; i++) {
        if (i > 0 && p[i].slot == p[i - 1].slot) continue; /* the right eye came with the left */
        int w = (int)lround(p[i].r.w * app->args.scale), h = (int)lround(p[i].r.h * app->args.scale);
        fv_status st = render_slot(app, p[i].slot, w < 1 ? 1 : w, h < 1 ? 1 : h, err);
        if (st != FV_OK) return st;
    }
    return FV_OK;
}

void fv_vw_blit(fv_vw_canvas *c, const fv_vw_panel *p, const uint8_t *lut)
{
    const fv_vw_slot *s = p->slot;
    const float *src = s->accum_n > 0 && s->accum[p->eye] ? s->accum[p->eye] : fv_film_color_const(s->film[p->eye]);
    float k = (s->accum_n > 0 && s->accum[p->eye] ? 1.0f / (float)s->accum_n : 1.0f) * (float)FV_VW_LUT;
    for (int y = 0; y < p->r.h; y++) {
        int sy = (int)((long long)y * s->fh / p->r.h);
        uint32_t *row = c->px + (size_t)(p->r.y + y) * c->w + p->r.x;
        for (int x = 0; x < p->r.w; x++) {
            int sx = (int)((long long)x * s->fw / p->r.w);
            const float *q = src + 3 * ((size_t)sy * s->fw + sx);
            unsigned rgb[3];
            for (int ch = 0; ch < 3; ch++) {
                float v = q[ch] * k;
                int i = v > 0.0f ? (v < (float)FV_VW_LUT ? (int)v : FV_VW_LUT) : 0; /* NaN lands on 0 */
                rgb[ch] = lut[i];
            }
            row[x] = fv_vw_rgb(rgb[0], rgb[1], rgb[2]);
        }
    }
}
