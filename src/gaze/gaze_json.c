/* fovea — reading the eye model and a gaze path from JSON (scene files and bench scenarios share
 * the same blocks, documented in docs/scene-format.md and docs/bench.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/json_util.h"
#include "gaze/gaze_json.h"

fv_status fv_gaze_json_eye(const cJSON *o, const char *file, const char *where, fv_eye_model *eye, fv_error *err)
{
    static const char *const keys[] = {"ppi", "eye_dist_mm", "fov_x_deg", "mode", "fovea_deg", "transition_deg", "fovea_frac",
                                       "transition_frac", NULL};
    fv_status st = fv_json_check_keys(o, keys, file, where, err);
    double v;
    const char *mode = NULL;
#define EYE_NUM(k, lo, hi)                                                                                \
    do {                                                                                                  \
        v = eye->k;                                                                                       \
        if (st == FV_OK && (st = fv_json_number(o, #k, lo, hi, file, where, &v, err)) == FV_OK) eye->k = (float)v; \
    } while (0)
    EYE_NUM(ppi, 1, 1e5);
    EYE_NUM(eye_dist_mm, 1e-3, 1e5);
    EYE_NUM(fov_x_deg, 0, 179.9);
    EYE_NUM(fovea_deg, 0.01, 89.9);
    EYE_NUM(transition_deg, 0.01, 89.9);
    EYE_NUM(fovea_frac, 1e-4, 4);
    EYE_NUM(transition_frac, 1e-4, 4);
#undef EYE_NUM
    if (st == FV_OK && (st = fv_json_string(o, "mode", file, where, &mode, err)) == FV_OK && mode) {
        if (strcmp(mode, "angle") == 0) eye->mode = FV_FOVEA_ANGLE;
        else if (strcmp(mode, "width") == 0) eye->mode = FV_FOVEA_WIDTH;
        else st = fv_error_set(err, FV_ERR_INVALID, "%s: %s.mode: '%s' is not 'angle' or 'width'", file, where, mode);
    }
    if (st == FV_OK && (st = fv_eye_model_validate(eye, err)) != FV_OK) fv_error_prefix(err, "%s: ", file);
    return st;
}

static fv_status gaze_json_path(const cJSON *o, const char *file, const char *where, const char *dir, fv_gaze_path **out, fv_error *err);

fv_status fv_gaze_json_path(const cJSON *o, const char *file, const char *where, const char *dir, fv_gaze_path **out, fv_error *err)
{
    static const char *const keys[] = {"fixed", "keys", "trace", "missing", NULL};
    fv_status st = fv_json_check_keys(o, keys, file, where, err);
    if (st != FV_OK) return st;
    const char *missing = NULL;
    if ((st = fv_json_string(o, "missing", file, where, &missing, err)) != FV_OK) return st;
    fv_gaze_missing policy = FV_GAZE_MISSING_HOLD;
    if (missing && !fv_gaze_missing_from_name(missing, &policy))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.missing: '%s' is not 'hold' or 'widen'", file, where, missing);
    st = gaze_json_path(o, file, where, dir, out, err);
    if (st == FV_OK) fv_gaze_path_set_missing(*out, policy);
    return st;
}

static fv_status gaze_json_path(const cJSON *o, const char *file, const char *where, const char *dir, fv_gaze_path **out, fv_error *err)
{
    fv_status st;
    const cJSON *fixed = cJSON_GetObjectItemCaseSensitive(o, "fixed"), *keys_ = cJSON_GetObjectItemCaseSensitive(o, "keys"),
                *trace = cJSON_GetObjectItemCaseSensitive(o, "trace");
    if (!!fixed + !!keys_ + !!trace != 1)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s: give exactly one of 'fixed', 'keys' or 'trace'", file, where);
    if (fixed) {
        double g[2];
        if ((st = fv_json_numbers(o, "fixed", 2, 0.0, 1.0, file, where, g, err)) != FV_OK) return st;
        return fv_gaze_path_create_fixed((fv_gaze){(float)g[0], (float)g[1]}, out, err);
    }
    if (trace) {
        const char *p = NULL;
        if ((st = fv_json_string(o, "trace", file, where, &p, err)) != FV_OK) return st;
        char full[4096];
        snprintf(full, sizeof full, "%s%s%s", p[0] == '/' ? "" : dir, p[0] == '/' ? "" : "/", p);
        st = fv_gaze_path_load_csv(full, out, err);
        if (st != FV_OK) fv_error_prefix(err, "%s: %s.trace: ", file, where);
        return st;
    }
    int n = cJSON_GetArraySize(keys_);
    if (!cJSON_IsArray(keys_) || n < 1)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.keys: expected a non-empty array of [time, x, y]", file, where);
    fv_gaze_key *k = fv_alloc_array((size_t)n, sizeof *k);
    if (!k) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    int i = 0;
    for (const cJSON *e = keys_->child; e; e = e->next, i++) {
        double v[3] = {0, 0, 0};
        int c = cJSON_GetArraySize(e);
        bool ok = cJSON_IsArray(e) && c == 3;
        const cJSON *x = ok ? e->child : NULL;
        for (int j = 0; ok && j < 3; j++, x = x->next) {
            ok = cJSON_IsNumber(x) && isfinite(x->valuedouble);
            v[j] = ok ? x->valuedouble : 0.0;
        }
        if (!ok) {
            free(k);
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s.keys[%d]: expected [time, x, y] numbers", file, where, i);
        }
        k[i].time = v[0];
        k[i].left = k[i].right = (fv_gaze){(float)v[1], (float)v[2]};
    }
    st = fv_gaze_path_create_keys(k, n, out, err);
    if (st != FV_OK) fv_error_prefix(err, "%s: ", file);
    free(k);
    return st;
}

