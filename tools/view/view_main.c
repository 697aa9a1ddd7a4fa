/* fovea-view — the interactive viewer (`fovea view`): any registered technique, live, with the
 * gaze on the mouse (or a trace, or fixed) and a flying camera. Everything up to the window is
 * `fovea render`'s path (the same parsers, scene loading, method check and messages); then one
 * loop on the main thread: events and script -> camera, gaze, clock -> render through the
 * sequence driver -> window. Rendering on the main thread keeps SDL's event queue in one thread;
 * the progress callback looks at it so closing the window cancels a long frame. */
#include <SDL.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "view.h"

static const char *k_cmd = "view";

void fv_vw_say(fv_vw_app *app, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(app->message, sizeof app->message, fmt, ap);
    va_end(ap);
    app->message_until = fv_time_ms() + 4000.0;
}

/* Everything the user typed and everything loaded before a window opens, so bad input fails the
 * same way with or without a display. Returns 0 or the exit code. */
static int prepare(fv_vw_app *app, fv_vw_script *script)
{
    fv_vw_args *a = &app->args;
    fv_error err;
    fv_error_clear(&err);
    fv_status s;
    if ((s = fv_film_check_size(a->width, a->height, &err)) != FV_OK) return fv_cli_fail(k_cmd, s, err.msg);
    int rc;
    if ((rc = fv_cli_check_method(k_cmd, a->method)) != 0) return rc;
    fv_device dev;
    if (a->device && (s = fv_device_check(a->method, a->device, &dev, &err)) != FV_OK) return fv_cli_fail(k_cmd, s, err.msg);
    if (a->script && (s = fv_vw_script_load(a->script, script, &err)) != FV_OK) return fv_cli_fail(k_cmd, s, err.msg);
    if (a->gaze_trace && (s = fv_gaze_path_load_csv(a->gaze_trace, &app->gaze_trace, &err)) != FV_OK) return fv_cli_fail(k_cmd, s, err.msg);
    if ((rc = fv_cli_open_scene(k_cmd, a->scene, &app->log, &a->scene_opts, &app->scene, &app->view)) != 0) return rc;
    app->user_method = fv_technique_index(a->method);
    if ((s = fv_vw_slot_create(&app->main, app->scene, app->user_method, -1, a->params, a->device, &app->log, &err)) != FV_OK)
        return fv_cli_fail(k_cmd, s, err.msg);
    if (a->fps_log) {
        if (!(app->fps_log = fopen(a->fps_log, "w"))) return fv_cli_usage_error(k_cmd, "--fps-log %s: cannot write there", a->fps_log);
        fprintf(app->fps_log, "frame,method,render_ms,frame_ms,display_ms,baseline,baseline_ms,stages_ms\n");
    }
    fv_camera c;
    fv_view_camera(app->view, app->scene, 0.0, a->width, a->height, &c);
    fv_vw_fly_init(&app->fly, &c);
    fv_vec3 lo, hi;
    fv_scene_bounds(app->scene, &lo, &hi);
    float diag = fv_length(fv_sub(hi, lo));
    app->fly_speed = isfinite(diag) && diag > 0.0f ? 0.25f * diag : 1.0f;
    app->gaze = a->has_gaze ? (fv_gaze){a->gaze[0], a->gaze[1]} : (fv_gaze){0.5f, 0.5f};
    app->script_gaze = a->script != NULL;
    for (int i = 0; i <= FV_VW_LUT; i++) app->srgb[i] = (uint8_t)lrintf(fv_srgb_encode((float)i / FV_VW_LUT) * 255.0f);
    return 0;
}

typedef struct sdl_out {
    SDL_Window *win;
    SDL_Renderer *ren;
    SDL_Texture *tex;
} sdl_out;

static int open_window(const fv_vw_args *a, sdl_out *o)
{
    /* one line naming the problem, as for any bad input: no display is the user's setting. Asked
     * first, as SDL's probing would print the Wayland library's own complaints on stderr. */
    const char *asked = SDL_getenv("SDL_VIDEODRIVER");
    if (!asked && !SDL_getenv("DISPLAY") && !SDL_getenv("WAYLAND_DISPLAY"))
        return fv_cli_usage_error(k_cmd, "no display: DISPLAY and WAYLAND_DISPLAY are unset (run under X or Wayland, or xvfb-run)");
    if (SDL_Init(SDL_INIT_VIDEO) != 0) return fv_cli_usage_error(k_cmd, "no display (SDL: %s)", SDL_GetError());
    /* Without a display SDL falls back on its invisible "offscreen" driver; that is only wanted
     * when asked for by name (SDL_VIDEODRIVER=offscreen, e.g. to time methods headless). */
    const char *drv = SDL_GetCurrentVideoDriver();
    if (drv && (!strcmp(drv, "offscreen") || !strcmp(drv, "dummy")) && !(asked && strstr(asked, drv))) {
        const char *x = SDL_getenv("DISPLAY"), *w = SDL_getenv("WAYLAND_DISPLAY");
        return fv_cli_usage_error(k_cmd, "no display: cannot connect to DISPLAY '%s' or WAYLAND_DISPLAY '%s'", x ? x : "", w ? w : "");
    }
    o->win = SDL_CreateWindow("fovea view", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, a->width, a->height, 0);
    if (!o->win) return fv_cli_usage_error(k_cmd, "cannot open a window (SDL: %s)", SDL_GetError());
    o->ren = SDL_CreateRenderer(o->win, -1, 0);
    if (!o->ren) return fv_cli_usage_error(k_cmd, "cannot draw into the window (SDL: %s)", SDL_GetError());
    o->tex = SDL_CreateTexture(o->ren, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_STREAMING, a->width, a->height);
    if (!o->tex) return fv_cli_usage_error(k_cmd, "cannot draw into the window (SDL: %s)", SDL_GetError());
    return 0;
}

static void gaze_from_mouse(fv_vw_app *app, const fv_vw_panel *p, int np, int mx, int my)
{
    if (app->script_gaze || app->args.has_gaze || app->gaze_trace) return;
    for (int i = 0; i < np; i++) {
        const fv_vw_rect *r = &p[i].r;
        if (mx < r->x || mx >= r->x + r->w || my < r->y || my >= r->y + r->h) continue;
        app->gaze.x = fv_clampf(((float)(mx - r->x) + 0.5f) / (float)r->w, 0.0f, 1.0f);
        app->gaze.y = fv_clampf(((float)(my - r->y) + 0.5f) / (float)r->h, 0.0f, 1.0f);
    }
}

/* Held movement keys, once per frame: dt seconds at the fly speed. */
static void fly_keys(fv_vw_app *app, double dt)
{
    const Uint8 *k = SDL_GetKeyboardState(NULL);
    float step = app->fly_speed * (float)dt;
    float r = (float)(k[SDL_SCANCODE_D] - k[SDL_SCANCODE_A]), u = (float)(k[SDL_SCANCODE_E] - k[SDL_SCANCODE_Q]),
          f = (float)(k[SDL_SCANCODE_W] - k[SDL_SCANCODE_S]);
    if (r != 0.0f || u != 0.0f || f != 0.0f) fv_vw_fly_move(&app->fly, r * step, u * step, f * step);
}

static int run(fv_vw_app *app, sdl_out *o, fv_vw_script *script)
{
    fv_vw_canvas canvas = {calloc((size_t)app->args.width * app->args.height, sizeof(uint32_t)), app->args.width, app->args.height};
    if (!canvas.px) return fv_cli_fail(k_cmd, FV_ERR_NOMEM, "out of memory");
    fv_vw_panel panels[2];
    int np = fv_vw_panels(app, canvas.w, canvas.h, panels);
    double dt = 0.0;
    int rc = FV_EXIT_OK;
    fv_error err;
    app->running = true;
    while (app->running) {
        double t0 = fv_time_ms();
        SDL_Event ev;
        while (SDL_PollEvent(&ev)) {
            if (ev.type == SDL_QUIT) app->running = false;
            else if (ev.type == SDL_KEYDOWN) fv_vw_on_key(app, ev.key.keysym.sym, ev.key.keysym.mod, NULL, &canvas);
            else if (ev.type == SDL_MOUSEMOTION) {
                if (ev.motion.state & SDL_BUTTON_RMASK) fv_vw_fly_look(&app->fly, 0.004f * (float)ev.motion.xrel, 0.004f * (float)ev.motion.yrel);
                else gaze_from_mouse(app, panels, np, ev.motion.x, ev.motion.y);
            }
        }
        /* a script's keys and gaze act before its frame renders; screenshots and quit after it is shown */
        for (int i = script->next; i < script->count && script->cmd[i].frame == app->frame; i++) {
            const fv_vw_cmd *c = &script->cmd[i];
            if (c->kind == FV_VW_CMD_KEY) fv_vw_on_key(app, c->key, c->mod, NULL, &canvas);
            else if (c->kind == FV_VW_CMD_MOUSE) app->gaze = (fv_gaze){c->x, c->y};
            else if (c->kind == FV_VW_CMD_MOVE) fv_vw_fly_move(&app->fly, c->v[0], c->v[1], c->v[2]);
            else if (c->kind == FV_VW_CMD_LOOK) fv_vw_fly_look(&app->fly, c->v[0], c->v[1]);
        }
        if (!app->running) break;
        fly_keys(app, dt);
        if (!app->paused) app->anim_time += dt;

        np = fv_vw_panels(app, canvas.w, canvas.h, panels);
        fv_error_clear(&err);
        fv_status s = fv_vw_render(app, panels, np, &err);
        if (s == FV_ERR_CANCELLED || app->cancelled) break; /* the window closed mid-frame: a normal exit */
        if (s != FV_OK) {
            rc = fv_cli_fail(k_cmd, s, err.msg);
            break;
        }
        /* display: from the rendered films to the presented window (tone map, overlay, the one texture
         * upload of the frame, present), logged apart from the render */
        const double t_shown = fv_time_ms();
        for (int i = 0; i < np; i++) fv_vw_blit(&canvas, &panels[i], app->srgb);
        if (app->overlay)
            for (int i = 0; i < np; i++)
                fv_vw_overlay_gaze(&canvas, panels[i].r, &panels[i].slot->eye, panels[i].slot->fw, panels[i].slot->gaze[panels[i].eye]);
        if (!app->hide_text) fv_vw_hud(&canvas, app, panels, np);
        SDL_UpdateTexture(o->tex, NULL, canvas.px, canvas.w * (int)sizeof(uint32_t));
        SDL_RenderClear(o->ren);
        SDL_RenderCopy(o->ren, o->tex, NULL, NULL);
        SDL_RenderPresent(o->ren);
        const double display_ms = fv_time_ms() - t_shown;

        for (; script->next < script->count && script->cmd[script->next].frame <= app->frame; script->next++) {
            const fv_vw_cmd *c = &script->cmd[script->next];
            fv_error_clear(&err);
            if (c->kind == FV_VW_CMD_SHOT && fv_vw_screenshot(&canvas, c->path, &err) != FV_OK) {
                rc = fv_cli_fail(k_cmd, err.status, err.msg);
                app->running = false;
            }
            if (c->kind == FV_VW_CMD_QUIT) app->running = false;
        }
        double ms = fv_time_ms() - t0;
        app->frame_ms = ms;
        dt = ms / 1000.0;
        if (dt > 0.25) dt = 0.25; /* a slow frame (or a method switch) must not throw the camera far */
        if (app->fps_log) {
            fprintf(app->fps_log, "%ld,%s,%.2f,%.2f,%.2f,%s,%.2f,", app->frame, fv_technique_name(app->main.method), app->main.ms, ms, display_ms,
                    app->split && app->base.tech ? fv_technique_name(app->base.method) : "", app->split && app->base.tech ? app->base.ms : 0.0);
            for (int i = 0; i < app->main.stats.n_stages; i++)
                fprintf(app->fps_log, "%s%s=%.2f", i ? " " : "", app->main.stats.stage[i].name, app->main.stats.stage[i].value);
            fputc('\n', app->fps_log);
        }
        app->frame++;
    }
    free(canvas.px);
    return rc;
}

int main(int argc, char **argv)
{
    /* The thread policy first: it may execute the viewer again (tools/fovea/cli_threads.c). */
    int prc = fv_cli_thread_policy(argc, argv, k_cmd);
    if (prc >= 0) return prc;
    fv_vw_app app;
    memset(&app, 0, sizeof app);
    app.main.method = app.base.method = -1;
    app.main.value = app.base.value = -1;
    app.base_seed = 1;
    fv_vw_args *a = &app.args;
    a->scene = "cornell";
    a->method = fv_technique_default_interactive();
    a->width = 640;
    a->height = 360;
    a->scale = 1.0;
    app.log = fv_cli_log(&app.quiet);
    fv_vw_script script;
    memset(&script, 0, sizeof script);
    sdl_out o;
    memset(&o, 0, sizeof o);
    fv_error err;
    fv_status s = fv_params_create(&a->params, &err);
    if (s != FV_OK) return fv_cli_fail(k_cmd, s, err.msg);
    int rc = fv_vw_args_parse(argc, argv, a);
    if (rc < 0) rc = FV_EXIT_OK;
    else if (rc == 0 && (rc = prepare(&app, &script)) == 0 && (rc = open_window(a, &o)) == 0) rc = run(&app, &o, &script);

    fv_vw_record_stop(&app.rec);
    if (app.fps_log) fclose(app.fps_log);
    if (o.tex) SDL_DestroyTexture(o.tex);
    if (o.ren) SDL_DestroyRenderer(o.ren);
    if (o.win) SDL_DestroyWindow(o.win);
    SDL_Quit();
    fv_vw_slot_destroy(&app.main);
    fv_vw_slot_destroy(&app.base);
    fv_vw_script_free(&script);
    fv_gaze_path_destroy(app.gaze_trace);
    fv_scene_destroy(app.scene);
    fv_view_destroy(app.view);
    fv_params_destroy(a->params);
    return rc;
}
