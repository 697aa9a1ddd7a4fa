/* fovea-view — the techniques on screen: which parameter +/- steps for each method, which
 * baseline the split view puts beside it, and (re)creating a slot's technique through
 * fv_technique_create exactly as `fovea render` does. */
#include <stdlib.h>
#include <string.h>
#include "view.h"

/* The parameter that sets each method's cost, and the values +/- offer (the papers' settings
 * around each default). The vpolar sample spaces have no spp: their cost is the share of pixels
 * not sampled (vpolar, cartesian) or the bounce count (the full-resolution launches). */
static const struct {
    const char *method;
    fv_vw_main_param p;
} k_main[] = {
    {"pt", {"spp", {"1", "2", "4", "8", "16", "32", "64"}, 7, 4, true}},
    {"pm", {"photons", {"10000", "30000", "100000", "300000", "1000000"}, 5, 3, false}},
    {"pm-t", {"photons", {"10000", "30000", "100000", "300000", "1000000"}, 5, 3, false}},
    {"fpm", {"photons", {"10000", "30000", "100000", "300000", "1000000"}, 5, 3, false}},
    {"ir", {"vpls", {"250", "500", "1000", "2000", "4000", "8000"}, 6, 3, false}},
    {"ir-low", {"vpls", {"250", "500", "1000", "2000", "4000", "8000"}, 6, 3, false}},
    {"fir", {"vpls", {"250", "500", "1000", "2000", "4000"}, 5, 2, false}},
    {"sdf-gt", {"spp", {"1", "4", "16"}, 3, 0, false}},
    {"sdf-relaxed", {"spp", {"1", "4", "16"}, 3, 0, false}},
    {"ipr", {"spp", {"1", "4", "16"}, 3, 0, false}},
    {"fipr", {"spp", {"1", "4", "16"}, 3, 0, false}},
    {"vpolar", {"reduction", {"0.61", "0.71", "0.88"}, 3, 0, false}},
    {"cartesian", {"reduction", {"0.61", "0.71", "0.88"}, 3, 0, false}},
    {"cartesian-full", {"bounces", {"1", "2", "3"}, 3, 0, false}},
    {"linear-falloff", {"bounces", {"1", "2", "3"}, 3, 0, false}},
    {"log-polar", {"bounces", {"1", "2", "3"}, 3, 0, false}},
};

const fv_vw_main_param *fv_vw_main_param_of(const char *method)
{
    for (size_t i = 0; i < sizeof k_main / sizeof k_main[0]; i++)
        if (!strcmp(k_main[i].method, method)) return &k_main[i].p;
    return NULL;
}

const char *fv_vw_baseline_of(const char *method)
{
    static const char *const pairs[][2] = {
        {"fpm", "pm"}, {"fir", "ir"}, {"fipr", "sdf-gt"}, {"ipr", "sdf-gt"}, {"vpolar", "cartesian-full"},
    };
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++)
        if (!strcmp(pairs[i][0], method)) return pairs[i][1];
    return "pt";
}

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
    const fv_vw_main_param *mp = fv_vw_main_param_of(name);
    fv_params *p = NULL;
    fv_status st = user_params ? fv_params_clone(user_params, &p, err) : fv_params_create(&p, err);
    if (st == FV_OK && mp && value >= 0) st = fv_params_set(p, mp->key, mp->values[value], err);
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
    if (mp) {
        const char *v = value >= 0 ? mp->values[value] : "default";
        for (int i = 0; value < 0 && user_params && i < fv_params_count(user_params); i++)
            if (!strcmp(fv_params_key(user_params, i), mp->key)) v = fv_params_value(user_params, i);
        snprintf(s->label, sizeof s->label, "%s=%s", mp->key, v);
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
        const fv_vw_main_param *mp = fv_vw_main_param_of(fv_technique_name(m));
        /* pt starts at 1 spp here: the viewer averages its frames while nothing moves */
        int value = mp && !strcmp(fv_technique_name(m), "pt") ? 0 : -1;
        const fv_params *user = m == app->user_method ? app->args.params : NULL;
        if (m == app->user_method) value = -1;
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
    const char *name = fv_technique_name(s->method);
    const fv_vw_main_param *mp = fv_vw_main_param_of(name);
    if (!mp) {
        fv_vw_say(app, "%s has no main parameter to step", name);
        return;
    }
    int v = s->value;
    if (v < 0) {
        /* from --param's value when it is one of the list, else from the method's default */
        v = mp->dflt;
        for (int i = 0; i < mp->count; i++)
            if (!strcmp(s->label + strlen(mp->key) + 1, mp->values[i])) v = i;
    }
    v += dir;
    if (v < 0 || v >= mp->count) {
        fv_vw_say(app, "%s: %s is at the end of its range", name, mp->key);
        return;
    }
    fv_error err;
    fv_error_clear(&err);
    const fv_params *user = s->method == app->user_method ? app->args.params : NULL;
    if (fv_vw_slot_create(s, app->scene, s->method, v, user, app->args.device, &app->log, &err) != FV_OK) fv_vw_say(app, "%s", err.msg);
    else fv_vw_say(app, "%s %s=%s", name, mp->key, mp->values[v]);
}

void fv_vw_update_baseline(fv_vw_app *app)
{
    if (!app->split || app->main.method < 0) {
        fv_technique_destroy(app->base.tech);
        app->base.tech = NULL;
        app->base.method = -1;
        return;
    }
    int m = fv_technique_index(fv_vw_baseline_of(fv_technique_name(app->main.method)));
    if (m < 0 || (app->base.tech && app->base.method == m)) return;
    fv_error err;
    fv_error_clear(&err);
    int value = !strcmp(fv_technique_name(m), "pt") ? 0 : -1;
    if (fv_vw_slot_create(&app->base, app->scene, m, value, NULL, app->args.device, &app->log, &err) != FV_OK) {
        fv_vw_say(app, "baseline %s: %s", fv_technique_name(m), err.msg);
        app->split = false;
    }
}
