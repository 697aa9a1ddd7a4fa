/* fovea-view — what each key does. Keyboard presses and a script's `key` lines both come here,
 * so a script exercises exactly the code a user does. Movement keys (WASD/QE) are read as held
 * keys once per frame in view_main.c; here are the one-shot actions. */
#include <SDL.h>
#include <stdio.h>
#include "view.h"

void fv_vw_on_key(fv_vw_app *app, int key, unsigned mod, const char *shot_path, fv_vw_canvas *c)
{
    fv_error err;
    fv_error_clear(&err);
    switch (key) {
    case SDLK_TAB: fv_vw_cycle(app, (mod & KMOD_SHIFT) ? -1 : +1); break;
    case SDLK_PLUS:
    case SDLK_EQUALS:
    case SDLK_KP_PLUS: fv_vw_step_param(app, +1); break;
    case SDLK_MINUS:
    case SDLK_KP_MINUS: fv_vw_step_param(app, -1); break;
    case SDLK_o: app->overlay = !app->overlay; break;
    case SDLK_h: app->hide_text = !app->hide_text; break;
    case SDLK_p:
        app->paused = !app->paused;
        fv_vw_say(app, app->paused ? "animation paused" : "animation runs");
        break;
    case SDLK_v:
        if (app->args.stereo > 0) {
            fv_vw_say(app, "the split view is for mono: stereo already fills both halves");
            break;
        }
        app->split = !app->split;
        fv_vw_update_baseline(app);
        break;
    case SDLK_r:
        if (app->rec.gaze) {
            fv_vw_record_stop(&app->rec);
            fv_vw_say(app, "recording %03d stopped", app->rec.take);
        } else if (fv_vw_record_start(&app->rec, &err) != FV_OK) {
            fv_vw_say(app, "%s", err.msg);
        } else {
            fv_vw_say(app, "recording to fovea-view-gaze-%03d.csv and fovea-view-camera-%03d.csv", app->rec.take, app->rec.take);
        }
        break;
    case SDLK_F12: {
        char name[64];
        if (!shot_path) {
            snprintf(name, sizeof name, "fovea-view-%05ld.png", app->frame);
            shot_path = name;
        }
        if (fv_vw_screenshot(c, shot_path, &err) != FV_OK) fv_vw_say(app, "%s", err.msg);
        else fv_vw_say(app, "saved %s", shot_path);
        break;
    }
    case SDLK_ESCAPE: app->running = false; break;
    default: break;
    }
}
