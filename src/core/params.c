/* fovea — the parameter bag (include/fovea/params.h) and its readers (core/params_read.h).
 *
 * Values are kept as strings and parsed when a technique reads them, so the message for a bad
 * value can name both the key and the text the user typed. Reads mark keys as used; a key no
 * technique read is reported as unknown, which catches typos such as "sp=64".
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include "core/alloc.h"
#include "core/params_read.h"

typedef struct fv_param_entry {
    char *key, *value;
    bool used;
} fv_param_entry;

struct fv_params {
    fv_param_entry *e;
    int n, cap;
    fv_params_watch_fn watch; /* told every key a reader asks for (fv_params_watch) */
    void *watch_user;
};

fv_status fv_params_create(fv_params **out, fv_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory creating parameters");
}

void fv_params_destroy(fv_params *p)
{
    if (!p) return;
    for (int i = 0; i < p->n; i++) {
        free(p->e[i].key);
        free(p->e[i].value);
    }
    free(p->e);
    free(p);
}

static fv_param_entry *find(const fv_params *p, const char *key)
{
    for (int i = 0; i < p->n; i++)
        if (strcmp(p->e[i].key, key) == 0) return &p->e[i];
    return NULL;
}

void fv_params_watch(fv_params *p, fv_params_watch_fn fn, void *user)
{
    p->watch = fn;
    p->watch_user = user;
}

/* The entry of r->key, after telling the watcher what a reader asked for. */
static fv_param_entry *ask(const fv_params *p, const fv_params_read *r)
{
    if (!p) return NULL;
    if (p->watch) p->watch(p->watch_user, r);
    return find(p, r->key);
}

static bool valid_key(const char *k)
{
    if (!*k) return false;
    for (; *k; k++)
        if (!(islower((unsigned char)*k) || isdigit((unsigned char)*k) || *k == '_' || *k == '-')) return false;
    return true;
}

fv_status fv_params_set(fv_params *p, const char *key, const char *value, fv_error *err)
{
    if (!valid_key(key))
        return fv_error_set(err, FV_ERR_INVALID, "bad parameter name '%s' (use lower-case letters, digits, '_' or '-')", key);
    char *v = strdup(value);
    if (!v) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_param_entry *e = find(p, key);
    if (e) {
        free(e->value);
        e->value = v;
        return FV_OK;
    }
    char *k = strdup(key);
    if (!k || fv_grow((void **)&p->e, &p->cap, p->n + 1, sizeof *p->e)) {
        free(k);
        free(v);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    p->e[p->n++] = (fv_param_entry){k, v, false};
    return FV_OK;
}

fv_status fv_params_parse(fv_params *p, const char *kv, fv_error *err)
{
    const char *eq = strchr(kv, '=');
    if (!eq || eq == kv || !eq[1])
        return fv_error_set(err, FV_ERR_INVALID, "bad parameter '%s' (expected key=value)", kv);
    char key[64];
    size_t n = (size_t)(eq - kv);
    if (n >= sizeof key) return fv_error_set(err, FV_ERR_INVALID, "parameter name too long in '%s'", kv);
    memcpy(key, kv, n);
    key[n] = '\0';
    return fv_params_set(p, key, eq + 1, err);
}

int fv_params_count(const fv_params *p) { return p ? p->n : 0; }
const char *fv_params_key(const fv_params *p, int i) { return p->e[i].key; }
const char *fv_params_value(const fv_params *p, int i) { return p->e[i].value; }

fv_status fv_params_clone(const fv_params *p, fv_params **out, fv_error *err)
{
    fv_status s = fv_params_create(out, err);
    for (int i = 0; s == FV_OK && p && i < p->n; i++) s = fv_params_set(*out, p->e[i].key, p->e[i].value, err);
    if (s != FV_OK) {
        fv_params_destroy(*out);
        *out = NULL;
    }
    return s;
}

fv_status fv_params_int(fv_params *p, const char *key, int def, int lo, int hi, int *out, fv_error *err)
{
    const fv_params_read r = {key, FV_READ_INT, def, lo, hi, NULL};
    fv_param_entry *e = ask(p, &r);
    if (!e) {
        *out = def;
        return FV_OK;
    }
    e->used = true;
    errno = 0;
    char *end;
    long long v = strtoll(e->value, &end, 10);
    if (errno || end == e->value || *end)
        return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%s: not an integer", key, e->value);
    if (v < lo || v > hi)
        return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%s: out of range [%d, %d]", key, e->value, lo, hi);
    *out = (int)v;
    return FV_OK;
}

fv_status fv_params_float(fv_params *p, const char *key, double def, double lo, double hi, double *out,
                          fv_error *err)
{
    const fv_params_read r = {key, FV_READ_FLOAT, def, lo, hi, NULL};
    fv_param_entry *e = ask(p, &r);
    if (!e) {
        *out = def;
        return FV_OK;
    }
    e->used = true;
    errno = 0;
    char *end;
    double v = strtod(e->value, &end);
    if (errno || end == e->value || *end || !isfinite(v))
        return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%s: not a finite number", key, e->value);
    if (v < lo || v > hi)
        return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%s: out of range [%g, %g]", key, e->value, lo, hi);
    *out = v;
    return FV_OK;
}

fv_status fv_params_bool(fv_params *p, const char *key, bool def, bool *out, fv_error *err)
{
    const fv_params_read r = {key, FV_READ_BOOL, def, 0, 1, NULL};
    fv_param_entry *e = ask(p, &r);
    if (!e) {
        *out = def;
        return FV_OK;
    }
    e->used = true;
    static const char *const yes[] = {"1", "true", "yes", "on"}, *const no[] = {"0", "false", "no", "off"};
    for (int i = 0; i < 4; i++) {
        if (strcasecmp(e->value, yes[i]) == 0) { *out = true; return FV_OK; }
        if (strcasecmp(e->value, no[i]) == 0) { *out = false; return FV_OK; }
    }
    return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%s: expected on/off, true/false, 1/0", key, e->value);
}

fv_status fv_params_choice(fv_params *p, const char *key, int def, const char *const *choices, int *out,
                           fv_error *err)
{
    const fv_params_read r = {key, FV_READ_CHOICE, def, 0, 0, choices};
    fv_param_entry *e = ask(p, &r);
    if (!e) {
        *out = def;
        return FV_OK;
    }
    e->used = true;
    char list[256] = "";
    for (int i = 0; choices[i]; i++) {
        if (strcmp(e->value, choices[i]) == 0) {
            *out = i;
            return FV_OK;
        }
        size_t l = strlen(list);
        snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", choices[i]);
    }
    return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%s: expected one of %s", key, e->value, list);
}

bool fv_params_has(const fv_params *p, const char *key)
{
    const fv_params_read r = {key, FV_READ_HAS, 0, 0, 0, NULL};
    return ask(p, &r) != NULL;
}

fv_status fv_params_check_used(const fv_params *p, const char *technique, fv_error *err)
{
    for (int i = 0; p && i < p->n; i++)
        if (!p->e[i].used)
            return fv_error_set(err, FV_ERR_INVALID, "unknown parameter '%s' for method '%s' (see fovea methods)",
                                p->e[i].key, technique);
    return FV_OK;
}
