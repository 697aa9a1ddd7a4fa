/* fovea-view — the techniques on screen: (re)creating a slot's technique through
 * fv_technique_create exactly as `fovea render` does, stepping its main parameter and choosing the
 * baseline the split view puts beside it. Which parameter, its steps and the baseline are the
 * registry's (fovea/technique.h): no method is named here. */
#include <stdlib.h>
#include <string.h>
#include "view.h"

/* The step a slot of method m starts at: a progressive method at its first step (frames are
 * averaged while nothing moves, so it converges on screen), any other at its default (-1). */
static int first_step(int m) { return fv_technique_main_param(m) && fv_technique_progressive(m) ? 0 : -1; }

static void drop_accum(fv_vw_slot *s)
{
    free(s->accum[0]);
    free(s->accum[1]);
    s->accum[0] = s->accum[1] = NULL;
    s->accum_n = 0;
}

fv_status fv_vw_slot_create(fv_vw_slot *s, const fv_scene *scene, int m, int value, const fv_params *user_params, const char *device,
                            const fv_log *log, fv_error *err)
{
    const char *name = fv_technique_name(m);
    const char *key = fv_technique_main_param(m);
    fv_params *p = NULL;
    fv_status st = user_params ? fv_params_clone(user_params, &p, err) : fv_params_create(&p, err);
    if (st == FV_OK && key && value >= 0) st = fv_params_set(p, key, fv_technique_main_step(m, value), err);
    fv_device d;
    fv_error ignored;
    if (st == FV_OK && device && fv_device_parse(device, name, &d, &ignored) == FV_OK && d != FV_DEVICE_CPU && fv_technique_has_device(m, d))
        st = fv_params_set(p, "device", device, err);
    fv_technique *t = NULL;
    if (st == FV_OK) st = fv_technique_create(name, scene, p, log, &t, err);
    fv_params_destroy(p);
    if (st != FV_OK) return st;
    fv_technique_destroy(s->tech);
    s->tech = t;
    s->label[0] = '\0';
    if (key) {
        const char *v = value >= 0 ? fv_technique_main_step(m, value) : "default";
        for (int i = 0; value < 0 && user_params && i < fv_params_count(user_params); i++)
            if (!strcmp(fv_params_key(user_params, i), key)) v = fv_params_value(user_params, i);
        snprintf(s->label, sizeof s->label, "%s=%s", key, v);
    }
    s->method = m;
    s->value = value;
    s->rendered = false;
    s->ms = 0.0;
    fv_stats_clear(&s->stats);
    drop_accum(s);
    return FV_OK;
}

void fv_vw_slot_destroy(fv_vw_slot *s)
{
    fv_technique_destroy(s->tech);
    fv_film_destroy(s->film[0]);
    fv_film_destroy(s->film[1]);
    drop_accum(s);
    memset(s, 0, sizeof *s);
    s->method = -1;
    s->value = -1;
}

fv_status fv_vw_slot_films(fv_vw_slot *s, int w, int h, int eyes, fv_error *err)
{
    if (s->film[0] && s->fw == w && s->fh == h && s->eyes == eyes) return FV_OK;
    fv_film_destroy(s->film[0]);
    fv_film_destroy(s->film[1]);
    s->film[0] = s->film[1] = NULL;
    drop_accum(s);
    /* a technique's history is at the old size: start its sequence again */
    s->rendered = false;
    for (int e = 0; e < eyes; e++) {
        fv_status st = fv_film_create(w, h, 0, &s->film[e], err);
        if (st != FV_OK) return st;
    }
    s->fw = w, s->fh = h, s->eyes = eyes;
    return FV_OK;
}

void fv_vw_slot_param_label(const fv_vw_slot *s, char *out, size_t n) { snprintf(out, n, "%s", s->method >= 0 ? s->label : ""); }

void fv_vw_cycle(fv_vw_app *app, int dir)
{
    int n = fv_technique_count();
    fv_error err;
    for (int k = 1; k < n; k++) {
        int m = ((app->main.method + dir * k) % n + n) % n;
        /* the method named on the command line keeps its --param values */
        int value = m == app->user_method ? -1 : first_step(m);
        const fv_params *user = m == app->user_method ? app->args.params : NULL;
        fv_error_clear(&err);
        /* a method that refuses the scene (the sdf family without fields) is skipped silently */
        if (fv_vw_slot_create(&app->main, app->scene, m, value, user, app->args.device, &app->log, &err) == FV_OK) {
            fv_vw_say(app, "method %s", fv_technique_name(m));
            fv_vw_update_baseline(app);
            return;
        }
    }
}

void fv_vw_step_param(fv_vw_app *app, int dir)
{
    fv_vw_slot *s = &app->main;
    if (s->method < 0) return;
    const int m = s->method;
    const char *name = fv_technique_name(m), *key = fv_technique_main_param(m);
    if (!key) {
        fv_vw_say(app, "%s has no main parameter to step", name);
        return;
    }
    const int count = fv_technique_main_step_count(m);
    int v = s->value;
    if (v < 0) {
        /* from --param's value when it is one of the steps, else from the method's default */
        v = fv_technique_main_default_step(m);
        for (int i = 0; i < count; i++)
            if (!strcmp(s->label + strlen(key) + 1, fv_technique_main_step(m, i))) v = i;
    }
    v += dir;
    if (v < 0 || v >= count) {
        fv_vw_say(app, "%s: %s is at the end of its range", name, key);
        return;
    }
    fv_error err;
    fv_error_clear(&err);
    const fv_params *user = s->method == app->user_method ? app->args.params : NULL;
    if (fv_vw_slot_create(s, app->scene, s->method, v, user, app->args.device, &app->log, &err) != FV_OK) fv_vw_say(app, "%s", err.msg);
    else fv_vw_say(app, "%s %s=%s", name, key, fv_technique_main_step(m, v));
}

void fv_vw_update_baseline(fv_vw_app *app)
{
    if (!app->split || app->main.method < 0) {
        fv_technique_destroy(app->base.tech);
        app->base.tech = NULL;
        app->base.method = -1;
        return;
    }
    const char *baseline = fv_technique_baseline(app->main.method);
    int m = fv_technique_index(baseline);
    if (m < 0) {
        /* the reference has nothing to be measured against: the split view is left */
        fv_vw_say(app, "%s is the reference: it has no baseline", fv_technique_name(app->main.method));
        fv_vw_slot_destroy(&app->base);
        app->split = false;
        return;
    }
    if (app->base.tech && app->base.method == m) return;
    fv_error err;
    fv_error_clear(&err);
    if (fv_vw_slot_create(&app->base, app->scene, m, first_step(m), NULL, app->args.device, &app->log, &err) != FV_OK) {
        fv_vw_say(app, "baseline %s: %s", fv_technique_name(m), err.msg);
        app->split = false;
    }
}
