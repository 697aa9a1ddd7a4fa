/* fovea — strict JSON reading helpers (see json_util.h). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/json_util.h"

#define FV_JSON_MAX_BYTES (64L << 20)

static int cmp_key(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* cJSON keeps every member of an object and lookups return the first: a key given twice would
 * silently lose its second value. Every object of the tree is checked (its keys sorted), with
 * the path of the object in the message. cJSON's nesting limit bounds the recursion. */
static fv_status check_duplicates(const cJSON *node, const char *file, const char *path, int depth, fv_error *err)
{
    if (!cJSON_IsObject(node) && !cJSON_IsArray(node)) return FV_OK;
    int n = 0;
    for (const cJSON *it = node->child; it; it = it->next) n++;
    if (cJSON_IsObject(node) && n > 1) {
        const char **keys = malloc((size_t)n * sizeof *keys);
        if (!keys) return fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", file);
        int k = 0;
        for (const cJSON *it = node->child; it; it = it->next) keys[k++] = it->string ? it->string : "";
        qsort(keys, (size_t)n, sizeof *keys, cmp_key);
        const char *dup = NULL;
        for (int i = 1; i < n && !dup; i++)
            if (strcmp(keys[i - 1], keys[i]) == 0) dup = keys[i];
        fv_status st = FV_OK;
        if (dup)
            st = fv_error_set(err, FV_ERR_INVALID, "%s: %s%sfield '%s' is given twice", file, path[0] ? path : "",
                              path[0] ? ": " : "", dup);
        free(keys);
        if (st != FV_OK) return st;
    }
    int i = 0;
    for (const cJSON *it = node->child; it; it = it->next, i++) {
        if (!cJSON_IsObject(it) && !cJSON_IsArray(it)) continue;
        char sub[256];
        if (cJSON_IsObject(node)) snprintf(sub, sizeof sub, "%s%s%.64s", path, path[0] ? "." : "", it->string ? it->string : "");
        else snprintf(sub, sizeof sub, "%s[%d]", path, i);
        fv_status st = check_duplicates(it, file, sub, depth + 1, err);
        if (st != FV_OK) return st;
    }
    return FV_OK;
}

/* The line where objects and arrays first nest deeper than limit, 0 when they never do (strings
 * skipped): cJSON refuses such text without saying why or where. */
static int nesting_beyond(const char *text, int limit)
{
    int depth = 0, line = 1;
    bool in_string = false;
    for (const char *c = text; *c; c++) {
        if (*c == '\n') line++;
        if (in_string) {
            if (*c == '\\' && c[1]) c++;
            else if (*c == '"') in_string = false;
        } else if (*c == '"') {
            in_string = true;
        } else if (*c == '{' || *c == '[') {
            if (++depth > limit) return line;
        } else if (*c == '}' || *c == ']') {
            depth--;
        }
    }
    return 0;
}

fv_status fv_json_parse_text(const char *name, const char *text, cJSON **out, fv_error *err)
{
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithOpts(text, &end, 1);
    if (!root) {
        int deep = nesting_beyond(text, CJSON_NESTING_LIMIT);
        if (deep)
            return fv_error_set(err, FV_ERR_INVALID, "%s:%d: objects and arrays nested deeper than %d levels", name, deep, CJSON_NESTING_LIMIT);
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
    fv_status st = check_duplicates(root, name, "", 0, err);
    if (st != FV_OK) {
        cJSON_Delete(root);
        return st;
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

fv_status fv_json_limited(const cJSON *obj, const char *key, int n, fv_json_limit_fn check, const char *file, const char *where,
                          double *out, fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FV_OK;
    double tmp[16];
    int i = 0;
    if (cJSON_IsArray(it) && cJSON_GetArraySize(it) == n && n <= 16)
        for (const cJSON *e = it->child; e && cJSON_IsNumber(e) && isfinite(e->valuedouble); e = e->next) tmp[i++] = e->valuedouble;
    if (i != n || n > 16)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s%s%s: expected an array of %d finite numbers", file, w0(where), dot(where), key, n);
    char what[512];
    snprintf(what, sizeof what, "%s: %s%s%s", file, w0(where), dot(where), key);
    fv_status st = check(what, tmp, n, err);
    if (st == FV_OK) memcpy(out, tmp, (size_t)n * sizeof *out);
    return st;
}

bool fv_json_scalar_text(const cJSON *item, char *buf, size_t n)
{
    if (cJSON_IsString(item)) return snprintf(buf, n, "%s", item->valuestring) < (int)n;
    if (cJSON_IsBool(item)) return snprintf(buf, n, "%s", cJSON_IsTrue(item) ? "true" : "false") < (int)n;
    if (cJSON_IsNumber(item) && isfinite(item->valuedouble)) {
        double v = item->valuedouble;
        if (v == floor(v) && fabs(v) < 1e15) return snprintf(buf, n, "%.0f", v) < (int)n;
        /* The shortest text that reads back as v: 9.7 stays "9.7" in reports, not 9.6999999999999993. */
        for (int prec = 15; prec < 17; prec++) {
            if (snprintf(buf, n, "%.*g", prec, v) >= (int)n) return false;
            if (strtod(buf, NULL) == v) return true;
        }
        return snprintf(buf, n, "%.17g", v) < (int)n;
    }
    return false;
}
