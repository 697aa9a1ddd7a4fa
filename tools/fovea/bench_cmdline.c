/* fovea CLI — a bench scenario from the command line (bench_cmdline.h). The scenario is built as
 * the JSON a user would write (docs/bench.md) and handed to fv_bench_run_text, so a command-line
 * comparison and the same scenario file give the same numbers: one parser, one harness, one cache
 * key. `--save-scenario F` writes that JSON, to rerun or edit.
 */
#include <cjson/cJSON.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include "bench_cmdline.h"

#define DEFAULT_REFERENCE "pt:spp=1024"

/* A value typed as the scenario format reads it: whole numbers as numbers, the rest as text. */
static cJSON *value_json(const char *v)
{
    size_t n = strlen(v), d = v[0] == '-' ? 1 : 0;
    bool integer = n > d && n - d <= 15 && strspn(v + d, "0123456789") == n - d && (v[d] != '0' || n - d == 1);
    return integer ? cJSON_CreateNumber(strtod(v, NULL)) : cJSON_CreateString(v);
}

/* "METHOD[:KEY=VALUE...]" -> {"label", "method", "params"}; the label is the method's name, made
 * unique among those before it with -2, -3, ... */
static int method_json(const char *cmd, const char *opt, const char *spec, size_t len, cJSON *list, cJSON **out)
{
    char buf[512];
    if (len == 0 || len >= sizeof buf) return fv_cli_usage_error(cmd, "%s: expected METHOD[:KEY=VALUE...], got '%.*s'", opt, (int)len, spec);
    memcpy(buf, spec, len);
    buf[len] = 0;
    char *save = NULL, *name = strtok_r(buf, ":", &save);
    if (!name || fv_technique_index(name) < 0)
        return fv_cli_usage_error(cmd, "%s: unknown method '%s' (fovea methods lists them)", opt, name ? name : "");
    cJSON *m = cJSON_CreateObject(), *params = cJSON_CreateObject();
    if (!m || !params) {
        cJSON_Delete(m);
        cJSON_Delete(params);
        return fv_cli_fail(cmd, FV_ERR_NOMEM, "out of memory");
    }
    /* label, method, params: the order a person writes them */
    cJSON_AddItemToObject(m, "params", params);
    for (char *kv = strtok_r(NULL, ":", &save); kv; kv = strtok_r(NULL, ":", &save)) {
        char *eq = strchr(kv, '=');
        if (!eq || eq == kv || !eq[1]) {
            cJSON_Delete(m);
            return fv_cli_usage_error(cmd, "%s: '%s' of method %s: expected KEY=VALUE", opt, kv, name);
        }
        *eq = 0;
        if (cJSON_GetObjectItemCaseSensitive(params, kv)) {
            cJSON_Delete(m);
            return fv_cli_usage_error(cmd, "%s: method %s sets '%s' twice", opt, name, kv);
        }
        cJSON_AddItemToObject(params, kv, value_json(eq + 1));
    }
    char label[64];
    snprintf(label, sizeof label, "%s", name);
    for (int k = 2; list; k++) {
        bool taken = false;
        for (const cJSON *e = list->child; e && !taken; e = e->next)
            taken = strcmp(cJSON_GetObjectItemCaseSensitive(e, "label")->valuestring, label) == 0;
        if (!taken) break;
        snprintf(label, sizeof label, "%.50s-%d", name, k);
    }
    cJSON_DetachItemViaPointer(m, params);
    cJSON_AddStringToObject(m, "label", label);
    cJSON_AddStringToObject(m, "method", name);
    cJSON_AddItemToObject(m, "params", params);
    *out = m;
    return 0;
}

/* A path the scenario can hold wherever it is saved: absolute when the file exists. */
static void absolute(const char *p, char *out, size_t n)
{
    char real[PATH_MAX];
    snprintf(out, n, "%s", realpath(p, real) ? real : p);
}

/* The scene's stem in the report's name, cut to the characters names allow. */
static void name_part(const char *s, char *out, size_t n)
{
    const char *slash = strrchr(s, '/');
    if (slash) s = slash + 1;
    size_t k = 0;
    for (; *s && *s != '.' && k + 1 < n; s++) out[k++] = strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-", *s) ? *s : '-';
    out[k] = 0;
}

int fv_bench_cmdline_json(const char *cmd, const fv_bench_cmdline *c, char **json, char *label, size_t label_n)
{
    *json = NULL;
    if (!c->methods || !c->methods[0]) return fv_cli_usage_error(cmd, "--scene needs --methods M1,M2,... (fovea methods lists them)");
    if (c->has_gaze && c->gaze_trace) return fv_cli_usage_error(cmd, "--gaze and --gaze-trace exclude each other");
    cJSON *root = cJSON_CreateObject();
    cJSON *methods = root ? cJSON_CreateArray() : NULL;
    if (!methods) {
        cJSON_Delete(root);
        return fv_cli_fail(cmd, FV_ERR_NOMEM, "out of memory");
    }
    int rc = 0;
    char scene[PATH_MAX], name[64], part[64];
    bool is_file = strchr(c->scene, '/') || strchr(c->scene, '.');
    if (is_file) absolute(c->scene, scene, sizeof scene);
    else snprintf(scene, sizeof scene, "%s", c->scene);
    name_part(c->scene, part, sizeof part);
    snprintf(name, sizeof name, "%s", part[0] ? part : "scene");
    for (const char *p = c->methods; rc == 0;) {
        size_t len = strcspn(p, ",");
        cJSON *m = NULL;
        rc = method_json(cmd, "--methods", p, len, methods, &m);
        if (rc == 0) {
            cJSON_AddItemToArray(methods, m);
            size_t nl = strlen(name);
            snprintf(name + nl, sizeof name - nl, "-%s", cJSON_GetObjectItemCaseSensitive(m, "label")->valuestring);
        }
        if (!p[len]) break;
        p += len + 1;
    }
    cJSON *ref = NULL;
    const char *rs = c->reference ? c->reference : DEFAULT_REFERENCE;
    if (rc == 0) rc = method_json(cmd, "--reference", rs, strlen(rs), NULL, &ref);
    if (rc != 0) {
        cJSON_Delete(root);
        cJSON_Delete(methods);
        return rc;
    }
    cJSON_DeleteItemFromObject(ref, "label");
    cJSON_AddStringToObject(root, "name", name);
    char desc[PATH_MAX + 1024];
    snprintf(desc, sizeof desc, "Built from the command line: fovea bench --scene %s --methods %s --reference %s.", c->scene, c->methods, rs);
    cJSON_AddStringToObject(root, "description", desc);
    cJSON_AddStringToObject(root, "scene", scene);
    if (c->width > 0) {
        cJSON *size = cJSON_AddArrayToObject(root, "size");
        cJSON_AddItemToArray(size, cJSON_CreateNumber(c->width));
        cJSON_AddItemToArray(size, cJSON_CreateNumber(c->height));
    }
    if (c->frames > 0) {
        cJSON_AddNumberToObject(root, "frames", c->frames);
    } else {
        /* One measured frame, converged: a temporal method's still warm-up frames (SVGF's history,
         * fovea methods NAME) come first, timed like the others but not measured, as `fovea render`
         * runs them before a still. */
        int warm = 0;
        cJSON *m;
        cJSON_ArrayForEach(m, methods)
        {
            int w = fv_technique_still_warmup(fv_technique_index(cJSON_GetObjectItemCaseSensitive(m, "method")->valuestring));
            if (w > warm) warm = w;
        }
        if (warm > 0) {
            cJSON_AddNumberToObject(root, "frames", warm + 1);
            cJSON_AddNumberToObject(root, "measure_from", warm);
        }
    }
    if (c->has_gaze || c->gaze_trace) {
        cJSON *g = cJSON_AddObjectToObject(root, "gaze");
        if (c->gaze_trace) {
            char trace[PATH_MAX];
            absolute(c->gaze_trace, trace, sizeof trace);
            cJSON_AddStringToObject(g, "trace", trace);
        } else {
            /* As typed (%g of a float would print 0.300000012): the same text a user would write. */
            cJSON *xy = cJSON_AddArrayToObject(g, "fixed");
            char t[32];
            for (int k = 0; k < 2; k++) {
                snprintf(t, sizeof t, "%.6g", c->gaze[k]);
                cJSON_AddItemToArray(xy, cJSON_CreateNumber(strtod(t, NULL)));
            }
        }
    }
    cJSON_AddItemToObject(root, "reference", ref);
    cJSON_AddItemToObject(root, "methods", methods);
    *json = cJSON_Print(root);
    cJSON_Delete(root);
    if (!*json) return fv_cli_fail(cmd, FV_ERR_NOMEM, "out of memory");
    snprintf(label, label_n, "%s.json", name);
    return 0;
}
