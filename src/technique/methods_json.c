/* fovea — the registry as one JSON document (fovea/technique.h, fv_methods_json): what `fovea
 * methods --json` prints and what a binding reads instead of parsing help text. Everything in it
 * comes from the classes (class.h): families, baselines, devices, warm-up frames, the main
 * parameter and every parameter with its type, default and range; values of numeric parameters
 * are JSON numbers, so a reader needs no second parser for them.
 */
#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>
#include "technique/class.h"

/* Adds item to obj under key (to an array when key is NULL); a failed allocation clears *ok and
 * frees the item. */
static void put(cJSON *obj, const char *key, cJSON *item, bool *ok)
{
    bool added = item && (key ? cJSON_AddItemToObject(obj, key, item) : cJSON_AddItemToArray(obj, item));
    if (!added) {
        cJSON_Delete(item);
        *ok = false;
    }
}

static cJSON *string_or_null(const char *s) { return s ? cJSON_CreateString(s) : cJSON_CreateNull(); }

/* A value of parameter p written as text ("16", "0.61", "true", "grid"), as JSON of p's type. */
static cJSON *typed_value(const fv_param_info *p, const char *text)
{
    switch (p->type) {
    case FV_PARAM_INT:
    case FV_PARAM_FLOAT: return cJSON_CreateNumber(strtod(text, NULL));
    case FV_PARAM_BOOL: return cJSON_CreateBool(strcmp(text, "true") == 0);
    case FV_PARAM_CHOICE:
    case FV_PARAM_STRING: break;
    }
    return cJSON_CreateString(text);
}

static cJSON *param_json(const fv_param_info *p, bool *ok)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    put(o, "key", cJSON_CreateString(p->key), ok);
    put(o, "type", cJSON_CreateString(fv_param_type_name(p->type)), ok);
    put(o, "default", p->def ? typed_value(p, p->def) : cJSON_CreateNull(), ok);
    if (p->def_note) put(o, "default_note", cJSON_CreateString(p->def_note), ok);
    if (p->type == FV_PARAM_INT || p->type == FV_PARAM_FLOAT) {
        put(o, "min", cJSON_CreateNumber(p->min), ok);
        put(o, "max", cJSON_CreateNumber(p->max), ok);
        put(o, "min_open", cJSON_CreateBool(p->min_open), ok);
        put(o, "max_open", cJSON_CreateBool(p->max_open), ok);
    }
    if (p->choices) {
        cJSON *c = cJSON_CreateArray();
        for (int i = 0; c && p->choices[i]; i++) put(c, NULL, typed_value(p, p->choices[i]), ok);
        put(o, "choices", c, ok);
    }
    put(o, "help", cJSON_CreateString(p->help ? p->help : ""), ok);
    return o;
}

static cJSON *main_json(int i, bool *ok)
{
    const fv_param_info *p = fv_technique_param_find(i, fv_technique_main_param(i));
    if (!p) return cJSON_CreateNull();
    cJSON *o = cJSON_CreateObject(), *steps = cJSON_CreateArray();
    if (!o || !steps) {
        cJSON_Delete(o);
        cJSON_Delete(steps);
        return NULL;
    }
    put(o, "key", cJSON_CreateString(p->key), ok);
    for (int k = 0; k < fv_technique_main_step_count(i); k++) put(steps, NULL, typed_value(p, fv_technique_main_step(i, k)), ok);
    put(o, "steps", steps, ok);
    int d = fv_technique_main_default_step(i);
    put(o, "default_step", d >= 0 ? cJSON_CreateNumber(d) : cJSON_CreateNull(), ok);
    put(o, "progressive", cJSON_CreateBool(fv_technique_progressive(i)), ok);
    return o;
}

static cJSON *method_json(int i, bool *ok)
{
    const fv_technique_class *c = fv_technique_class_at(i);
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    put(o, "name", cJSON_CreateString(c->name), ok);
    put(o, "summary", cJSON_CreateString(c->summary), ok);
    put(o, "family", cJSON_CreateString(c->family), ok);
    put(o, "foveated", cJSON_CreateBool(c->foveated), ok);
    put(o, "baseline", string_or_null(c->baseline), ok);
    cJSON *dev = cJSON_CreateArray();
    for (int d = FV_DEVICE_CPU; dev && d <= FV_DEVICE_CUDA; d++)
        if (fv_technique_has_device(i, (fv_device)d)) put(dev, NULL, cJSON_CreateString(fv_device_name((fv_device)d)), ok);
    put(o, "devices", dev, ok);
    put(o, "warmup_frames", cJSON_CreateNumber(c->warmup_frames), ok);
    put(o, "still_warmup_frames", cJSON_CreateNumber(c->still_warmup_frames), ok);
    put(o, "spp_param", string_or_null(c->spp_param), ok);
    put(o, "spp_instead", string_or_null(c->spp_instead), ok);
    put(o, "sdf_only", cJSON_CreateBool(c->sdf_only), ok);
    put(o, "main_parameter", main_json(i, ok), ok);
    cJSON *params = cJSON_CreateArray();
    for (int j = 0; params && j < c->param_count; j++) put(params, NULL, param_json(&c->params[j], ok), ok);
    put(o, "parameters", params, ok);
    return o;
}

/* The families of the methods `only` selects (-1: all), in the order of their first method. */
static cJSON *families_json(int only, bool *ok)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < fv_technique_count(); i++) {
        if (only >= 0 && i != only) continue;
        const char *fam = fv_technique_family(i);
        bool seen = false;
        for (int k = 0; only < 0 && k < i && !seen; k++) seen = strcmp(fv_technique_family(k), fam) == 0;
        if (seen) continue;
        cJSON *f = cJSON_CreateObject(), *names = cJSON_CreateArray();
        for (int k = i; names && k < fv_technique_count(); k++)
            if ((only < 0 || k == only) && strcmp(fv_technique_family(k), fam) == 0) put(names, NULL, cJSON_CreateString(fv_technique_name(k)), ok);
        if (f) put(f, "name", cJSON_CreateString(fam), ok);
        if (f) put(f, "methods", names, ok);
        else cJSON_Delete(names);
        put(a, NULL, f, ok);
    }
    return a;
}

char *fv_methods_json(const char *name, fv_error *err)
{
    int only = -1;
    if (name && (only = fv_technique_index(name)) < 0) {
        fv_technique_unknown(name, err);
        return NULL;
    }
    bool ok = true;
    cJSON *doc = cJSON_CreateObject();
    if (doc) {
        put(doc, "families", families_json(only, &ok), &ok);
        cJSON *common = cJSON_CreateArray();
        if (common) put(common, NULL, param_json(fv_technique_device_param(), &ok), &ok);
        put(doc, "common_parameters", common, &ok);
        cJSON *methods = cJSON_CreateArray();
        for (int i = 0; methods && i < fv_technique_count(); i++)
            if (only < 0 || i == only) put(methods, NULL, method_json(i, &ok), &ok);
        put(doc, "methods", methods, &ok);
    }
    char *text = doc && ok ? cJSON_Print(doc) : NULL;
    cJSON_Delete(doc);
    if (!text) fv_error_set(err, FV_ERR_NOMEM, "out of memory writing the methods as JSON");
    return text;
}

void fv_methods_json_free(char *json) { cJSON_free(json); }
