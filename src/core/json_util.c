/* fovea — strict JSON reading helpers (see json_util.h). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/json_util.h"

#define FV_JSON_MAX_BYTES (64L << 20)

fv_status fv_json_parse_text(const char *name, const char *text, cJSON **out, fv_error *err)
{
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithOpts(text, &end, 1);
    if (!root) {
        /* cJSON reports where it stopped; turn the offset into a line number and a short excerpt. */
        const char *at = end ? end : cJSON_GetErrorPtr();
        if (!at || at < text) at = text;
        int line = 1;
        for (const char *c = text; c < at && *c; c++)
            if (*c == '\n') line++;
        char near[24];
        size_t k = 0;
        for (const char *c = at; *c && *c != '\n' && k + 1 < sizeof near; c++) near[k++] = *c;
        near[k] = '\0';
        if (k == 0) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: malformed JSON (unexpected end of file)", name, line);
        return fv_error_set(err, FV_ERR_INVALID, "%s:%d: malformed JSON near '%s'", name, line, near);
    }
    *out = root;
    return FV_OK;
}

fv_status fv_json_parse_file(const char *path, cJSON **out, fv_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return fv_error_set(err, FV_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    char *buf = NULL;
    long n = -1;
    if (fseek(f, 0, SEEK_END) == 0) n = ftell(f);
    if (n < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return fv_error_set(err, FV_ERR_IO, "cannot read '%s': not a regular file", path);
    }
    if (n > FV_JSON_MAX_BYTES) {
        fclose(f);
        return fv_error_set(err, FV_ERR_INVALID, "'%s' is too large for a JSON file (%ld bytes)", path, n);
    }
    buf = malloc((size_t)n + 1);
    if (!buf) {
        fclose(f);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
    }
    size_t got = fread(buf, 1, (size_t)n, f);
    bool bad = ferror(f);
    fclose(f);
    if (bad || got != (size_t)n) {
        free(buf);
        return fv_error_set(err, FV_ERR_IO, "cannot read '%s'", path);
    }
    buf[n] = '\0';
    if (strlen(buf) != (size_t)n) {
        free(buf);
        return fv_error_set(err, FV_ERR_INVALID, "%s: not a text file (contains NUL bytes)", path);
    }
    fv_status s = fv_json_parse_text(path, buf, out, err);
    free(buf);
    return s;
}

static const char *dot(const char *where) { return where && where[0] ? "." : ""; }
static const char *w0(const char *where) { return where ? where : ""; }

fv_status fv_json_check_keys(const cJSON *obj, const char *const *allowed, const char *file, const char *where, fv_error *err)
{
    if (!cJSON_IsObject(obj))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an object", file, where && where[0] ? where : "top level");
    for (const cJSON *it = obj->child; it; it = it->next) {
        bool ok = false;
        for (int i = 0; allowed[i] && !ok; i++) ok = strcmp(it->string, allowed[i]) == 0;
        if (!ok) {
            char list[256] = "";
            size_t len = 0;
            for (int i = 0; allowed[i]; i++) {
                int w = snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", allowed[i]);
                if (w < 0 || (size_t)w >= sizeof list - len) break;
                len += (size_t)w;
            }
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s%sunknown field '%s' (known: %s)", file, w0(where),
                                where && where[0] ? ": " : "", it->string, list);
        }
    }
    return FV_OK;
}

fv_status fv_json_require(const cJSON *obj, const char *key, const char *file, const char *where, fv_error *err)
{
    if (cJSON_GetObjectItemCaseSensitive(obj, key)) return FV_OK;
    return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: missing (required)", file, w0(where), dot(where), key);
}

fv_status fv_json_number(const cJSON *obj, const char *key, double lo, double hi, const char *file, const char *where,
                         double *out, fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FV_OK;
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: expected a finite number", file, w0(where), dot(where), key);
    if (it->valuedouble < lo || it->valuedouble > hi)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: %g is outside [%g, %g]", file, w0(where), dot(where), key,
                            it->valuedouble, lo, hi);
    *out = it->valuedouble;
    return FV_OK;
}

fv_status fv_json_int(const cJSON *obj, const char *key, int lo, int hi, const char *file, const char *where, int *out,
                      fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FV_OK;
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble) || it->valuedouble != floor(it->valuedouble))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: expected an integer", file, w0(where), dot(where), key);
    if (it->valuedouble < lo || it->valuedouble > hi)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: %g is outside [%d, %d]", file, w0(where), dot(where), key,
                            it->valuedouble, lo, hi);
    *out = (int)it->valuedouble;
    return FV_OK;
}

fv_status fv_json_bool(const cJSON *obj, const char *key, const char *file, const char *where, bool *out, fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FV_OK;
    if (!cJSON_IsBool(it))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: expected true or false", file, w0(where), dot(where), key);
    *out = cJSON_IsTrue(it);
    return FV_OK;
}

fv_status fv_json_string(const cJSON *obj, const char *key, const char *file, const char *where, const char **out,
                         fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FV_OK;
    if (!cJSON_IsString(it) || !it->valuestring[0])
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: expected a non-empty string", file, w0(where), dot(where), key);
    *out = it->valuestring;
    return FV_OK;
}

fv_status fv_json_numbers(const cJSON *obj, const char *key, int n, double lo, double hi, const char *file,
                          const char *where, double *out, fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FV_OK;
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != n)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: expected an array of %d numbers", file, w0(where), dot(where), key, n);
    int i = 0;
    double tmp[16];
    for (const cJSON *e = it->child; e && i < 16; e = e->next, i++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || e->valuedouble < lo || e->valuedouble > hi)
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: expected %d numbers in [%g, %g]", file, w0(where), dot(where),
                                key, n, lo, hi);
        tmp[i] = e->valuedouble;
    }
    for (i = 0; i < n && i < 16; i++) out[i] = tmp[i];
    return FV_OK;
}

bool fv_json_scalar_text(const cJSON *item, char *buf, size_t n)
{
    if (cJSON_IsString(item)) return snprintf(buf, n, "%s", item->valuestring) < (int)n;
    if (cJSON_IsBool(item)) return snprintf(buf, n, "%s", cJSON_IsTrue(item) ? "true" : "false") < (int)n;
    if (cJSON_IsNumber(item) && isfinite(item->valuedouble)) {
        double v = item->valuedouble;
        if (v == floor(v) && fabs(v) < 1e15) return snprintf(buf, n, "%.0f", v) < (int)n;
        return snprintf(buf, n, "%.17g", v) < (int)n;
    }
    return false;
}
