/* fovea — reading a benchmark scenario (docs/bench.md). Strict: unknown fields, wrong types and
 * absurd values are refused with the file and field named, before anything is rendered.
 * A "quick" or "full" block holds overrides merged over the top level for that mode.
 */
#include <ctype.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench/scenario.h"
#include "core/alloc.h"
#include "core/json_util.h"
#include "fovea/limits.h"
#include "gaze/gaze_json.h"
#include "scene/anim.h"
#include "scene/anim_json.h"

/* Objects merge key by key, recursively; any other value replaces. */
static bool json_merge(cJSON *dst, const cJSON *src)
{
    for (const cJSON *it = src->child; it; it = it->next) {
        cJSON *d = cJSON_GetObjectItemCaseSensitive(dst, it->string);
        if (d && cJSON_IsObject(d) && cJSON_IsObject(it)) {
            if (!json_merge(d, it)) return false;
            continue;
        }
        cJSON *copy = cJSON_Duplicate(it, 1);
        if (!copy) return false;
        if (d) cJSON_ReplaceItemInObjectCaseSensitive(dst, it->string, copy);
        else cJSON_AddItemToObject(dst, it->string, copy);
    }
    return true;
}

static bool label_ok(const char *s)
{
    if (!s[0] || strlen(s) >= FV_BENCH_LABEL_MAX) return false;
    for (; *s; s++)
        if (!isalnum((unsigned char)*s) && *s != '-' && *s != '_' && *s != '.' && *s != '=') return false;
    return true;
}

/* A method's "params" into a new bag in *out; on failure *out is NULL (nothing to release). */
static fv_status parse_params(const cJSON *obj, const char *file, const char *where, fv_params **out, fv_error *err)
{
    fv_status st = fv_params_create(out, err);
    if (st != FV_OK || !obj) return st;
    if (!cJSON_IsObject(obj)) st = fv_error_set(err, FV_ERR_INVALID, "%s: %s.params: expected an object", file, where);
    for (const cJSON *it = st == FV_OK ? obj->child : NULL; it; it = it->next) {
        char text[128];
        if (!fv_json_scalar_text(it, text, sizeof text)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s: %s.params.%s: expected a number, string or boolean", file, where, it->string);
            break;
        }
        if ((st = fv_params_set(*out, it->string, text, err)) != FV_OK) {
            fv_error_prefix(err, "%s: %s.params: ", file, where);
            break;
        }
    }
    if (st != FV_OK) {
        fv_params_destroy(*out);
        *out = NULL;
    }
    return st;
}

static fv_status parse_method(const cJSON *obj, const char *file, const char *where, bool need_label, fv_bench_method *m,
                              fv_error *err)
{
    static const char *const keys[] = {"label", "method", "params", NULL};
    fv_status st;
    const char *label = NULL, *method = NULL;
    if ((st = fv_json_check_keys(obj, keys, file, where, err)) != FV_OK || (st = fv_json_require(obj, "method", file, where, err)) != FV_OK ||
        (st = fv_json_string(obj, "method", file, where, &method, err)) != FV_OK ||
        (st = fv_json_string(obj, "label", file, where, &label, err)) != FV_OK)
        return st;
    if (fv_technique_index(method) < 0) {
        char known[256] = "";
        size_t len = 0;
        for (int i = 0; i < fv_technique_count(); i++) {
            int w = snprintf(known + len, sizeof known - len, "%s%s", i ? ", " : "", fv_technique_name(i));
            if (w < 0 || (size_t)w >= sizeof known - len) break;
            len += (size_t)w;
        }
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.method: unknown method '%s' (known: %s)", file, where, method, known);
    }
    if (!label) label = method;
    if (need_label && !label_ok(label))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.label: '%s' must be 1-63 characters of [A-Za-z0-9._=-]", file, where, label);
    snprintf(m->label, sizeof m->label, "%s", label);
    snprintf(m->method, sizeof m->method, "%s", method);
    return parse_params(cJSON_GetObjectItemCaseSensitive(obj, "params"), file, where, &m->params, err);
}

static fv_status parse_camera_path(const cJSON *arr, const char *file, fv_scenario *s, fv_error *err)
{
    static const char *const keys[] = {"time", "pos", "look", "up", "fov", NULL};
    int n = cJSON_GetArraySize(arr);
    if (!cJSON_IsArray(arr) || n < 1) return fv_error_set(err, FV_ERR_INVALID, "%s: camera_path: expected a non-empty array", file);
    if (!(s->cam_keys = fv_calloc_array((size_t)n, sizeof *s->cam_keys))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    s->ncam_keys = n;
    int i = 0;
    fv_status st = FV_OK;
    for (const cJSON *e = arr->child; e && st == FV_OK; e = e->next, i++) {
        char where[32];
        snprintf(where, sizeof where, "camera_path[%d]", i);
        double t = 0, pos[3], look[3], up[3] = {0, 1, 0}, fov = 40;
        if ((st = fv_json_check_keys(e, keys, file, where, err)) != FV_OK || (st = fv_json_require(e, "time", file, where, err)) ||
            (st = fv_json_require(e, "pos", file, where, err)) || (st = fv_json_require(e, "look", file, where, err)) ||
            (st = fv_json_number(e, "time", -1e9, 1e9, file, where, &t, err)) ||
            (st = fv_json_limited(e, "pos", 3, fv_limit_coords, file, where, pos, err)) ||
            (st = fv_json_limited(e, "look", 3, fv_limit_coords, file, where, look, err)) ||
            (st = fv_json_limited(e, "up", 3, fv_limit_coords, file, where, up, err)) ||
            (st = fv_json_number(e, "fov", 0.1, 179.9, file, where, &fov, err)))
            break;
        fv_camera_key *k = &s->cam_keys[i];
        k->time = t;
        k->pos = fv_v3((float)pos[0], (float)pos[1], (float)pos[2]);
        k->look = fv_v3((float)look[0], (float)look[1], (float)look[2]);
        k->up = fv_v3((float)up[0], (float)up[1], (float)up[2]);
        k->fov_y = (float)fov;
        if (i > 0 && !(t > s->cam_keys[i - 1].time))
            st = fv_error_set(err, FV_ERR_INVALID, "%s: %s.time: times must increase", file, where);
    }
    return st;
}

static fv_status add_method(fv_scenario *s, int *cap, fv_bench_method *m, const char *file, fv_error *err)
{
    for (int i = 0; i < s->nmethods; i++)
        if (strcmp(s->methods[i].label, m->label) == 0) {
            fv_params_destroy(m->params);
            m->params = NULL;
            return fv_error_set(err, FV_ERR_INVALID, "%s: two methods share the label '%s' (labels name the outputs)", file, m->label);
        }
    if (fv_grow((void **)&s->methods, cap, s->nmethods + 1, sizeof *s->methods)) {
        fv_params_destroy(m->params);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    s->methods[s->nmethods++] = *m;
    return FV_OK;
}

/* One sweep object; where is "sweep" for the single-object form, "sweep[i]" in an array. */
static fv_status parse_sweep(const cJSON *o, const char *file, const char *where, fv_scenario *s, int *cap, fv_error *err)
{
    static const char *const keys[] = {"label", "method", "params", "param", "values", NULL};
    fv_status st;
    const char *param = NULL;
    if (!cJSON_IsObject(o)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an object {label, method, params, param, values}", file, where);
    if ((st = fv_json_check_keys(o, keys, file, where, err)) || (st = fv_json_require(o, "param", file, where, err)) ||
        (st = fv_json_require(o, "values", file, where, err)) || (st = fv_json_string(o, "param", file, where, &param, err)))
        return st;
    if (s->sweep_array) {
        /* The parameter names the sweep's CSV and plot, so it must make a file name and be unique. */
        if (!label_ok(param))
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s.param: '%s' must be 1-63 characters of [A-Za-z0-9._=-] (it names %s-sweep-%s.csv)",
                                file, where, param, s->name, param);
        for (int k = 0; k < s->nsweeps; k++)
            if (!strcmp(s->sweeps[k].param, param))
                return fv_error_set(err, FV_ERR_INVALID, "%s: %s.param: another sweep already varies '%s' (each writes %s-sweep-%s.csv)", file,
                                    where, param, s->name, param);
    }
    /* Reuse the method parser on a copy without the sweep-only keys. */
    cJSON *mo = cJSON_CreateObject();
    if (!mo) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (const cJSON *it = o->child; it; it = it->next)
        if (strcmp(it->string, "param") != 0 && strcmp(it->string, "values") != 0) cJSON_AddItemToObject(mo, it->string, cJSON_Duplicate(it, 1));
    fv_bench_method base;
    memset(&base, 0, sizeof base);
    st = parse_method(mo, file, where, true, &base, err);
    cJSON_Delete(mo);
    if (st != FV_OK) {
        fv_params_destroy(base.params);
        return st;
    }
    const cJSON *vals = cJSON_GetObjectItemCaseSensitive(o, "values");
    int n = cJSON_GetArraySize(vals);
    if (!cJSON_IsArray(vals) || n < 2 || n > 64) {
        fv_params_destroy(base.params);
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.values: expected an array of 2 to 64 numbers", file, where);
    }
    fv_bench_sweep *sw = &s->sweeps[s->nsweeps];
    snprintf(sw->param, sizeof sw->param, "%s", param);
    snprintf(sw->method, sizeof sw->method, "%s", base.method);
    sw->first = s->nmethods;
    sw->count = 0;
    int i = 0;
    for (const cJSON *v = vals->child; v && st == FV_OK; v = v->next, i++) {
        char text[64];
        if (!cJSON_IsNumber(v) || !fv_json_scalar_text(v, text, sizeof text)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s: %s.values[%d]: expected a finite number", file, where, i);
            break;
        }
        /* the label shows the shortest text that reads back as the value (0.35, not
         * 0.34999999999999998; 50, not 5e+01); the parameter keeps the exact text */
        char shown[64];
        snprintf(shown, sizeof shown, "%s", text);
        if (v->valuedouble == floor(v->valuedouble) && fabs(v->valuedouble) < 1e15)
            snprintf(shown, sizeof shown, "%.0f", v->valuedouble);
        else
            for (int prec = 1; prec <= 17; prec++) {
                snprintf(shown, sizeof shown, "%.*g", prec, v->valuedouble);
                if (strtod(shown, NULL) == v->valuedouble) break;
            }
        fv_bench_method m;
        memset(&m, 0, sizeof m);
        snprintf(m.method, sizeof m.method, "%s", base.method);
        int w = snprintf(m.label, sizeof m.label, "%s-%s=%s", base.label, param, shown);
        if (w < 0 || w >= (int)sizeof m.label) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s: %s: label '%s-%s=%s' is too long", file, where, base.label, param, shown);
            break;
        }
        m.from_sweep = true;
        m.sweep = s->nsweeps;
        m.sweep_value = v->valuedouble;
        if ((st = fv_params_clone(base.params, &m.params, err)) != FV_OK) break;
        if ((st = fv_params_set(m.params, param, text, err)) != FV_OK) {
            fv_params_destroy(m.params);
            fv_error_prefix(err, "%s: %s.param: ", file, where);
            break;
        }
        if ((st = add_method(s, cap, &m, file, err)) == FV_OK) sw->count++;
    }
    s->nsweeps++;
    fv_params_destroy(base.params);
    return st;
}

/* "sweep": one sweep object, or an array of them. */
static fv_status parse_sweeps(const cJSON *o, const char *file, fv_scenario *s, int *cap, fv_error *err)
{
    if (!cJSON_IsArray(o)) return parse_sweep(o, file, "sweep", s, cap, err);
    int n = cJSON_GetArraySize(o);
    if (n < 1 || n > FV_BENCH_MAX_SWEEPS)
        return fv_error_set(err, FV_ERR_INVALID, "%s: sweep: expected a sweep object or an array of 1 to %d of them", file, FV_BENCH_MAX_SWEEPS);
    s->sweep_array = true;
    int i = 0;
    fv_status st = FV_OK;
    for (const cJSON *e = o->child; e && st == FV_OK; e = e->next, i++) {
        char where[32];
        snprintf(where, sizeof where, "sweep[%d]", i);
        st = parse_sweep(e, file, where, s, cap, err);
    }
    return st;
}

/* "animate": [{"light": INDEX | "object": NAME, "animation": [keys]}]. The keys are read by the
 * scene format's own parser and checked with the scene's rules here, so a bad list is refused
 * before anything is loaded; whether the light or object exists is known only once the scene is
 * open (run.c). */
static fv_status parse_animate(const cJSON *arr, const char *file, fv_scenario *s, fv_error *err)
{
    static const char *const keys[] = {"light", "object", "animation", NULL};
    int n = cJSON_GetArraySize(arr);
    if (!cJSON_IsArray(arr) || n < 1 || n > FV_BENCH_MAX_ANIMATE)
        return fv_error_set(err, FV_ERR_INVALID, "%s: animate: expected an array of 1 to %d {light or object, animation} entries", file,
                            FV_BENCH_MAX_ANIMATE);
    if (!(s->animate = fv_calloc_array((size_t)n, sizeof *s->animate))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    int i = 0;
    fv_status st = FV_OK;
    for (const cJSON *e = arr->child; e && st == FV_OK; e = e->next, i++) {
        char where[32];
        snprintf(where, sizeof where, "animate[%d]", i);
        fv_bench_animate *a = &s->animate[i];
        const char *obj = NULL;
        a->light = -1;
        if (!cJSON_IsObject(e)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an object {light or object, animation}", file, where);
        bool has_light = cJSON_GetObjectItemCaseSensitive(e, "light") != NULL, has_obj = cJSON_GetObjectItemCaseSensitive(e, "object") != NULL;
        if ((st = fv_json_check_keys(e, keys, file, where, err)) || (st = fv_json_require(e, "animation", file, where, err)))
            return st;
        if (has_light == has_obj) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: give exactly one of 'light' (an index) and 'object' (a name)", file, where);
        if ((st = fv_json_int(e, "light", 0, 1000000, file, where, &a->light, err)) || (st = fv_json_string(e, "object", file, where, &obj, err)))
            return st;
        if (obj) {
            if (!obj[0] || strlen(obj) >= FV_NAME_MAX)
                return fv_error_set(err, FV_ERR_INVALID, "%s: %s.object: expected an object name of 1 to %d characters", file, where, FV_NAME_MAX - 1);
            snprintf(a->object, sizeof a->object, "%s", obj);
        }
        s->nanimate = i + 1;
        if ((st = fv_load_json_anim_keys(cJSON_GetObjectItemCaseSensitive(e, "animation"), file, where, &a->keys, &a->nkeys, err)) != FV_OK)
            return st;
        /* Reads "FILE: animation of animate[i]: key times must increase (key 1)". */
        if ((st = fv_anim_check(where, a->keys, a->nkeys, err)) != FV_OK) fv_error_prefix(err, "%s: ", file);
    }
    return st;
}

static fv_status parse_match(const cJSON *o, const char *file, int index, fv_scenario *s, fv_error *err)
{
    static const char *const keys[] = {"label", "method", "params", "param", "values", "target", "metric", "region", NULL};
    char where[32];
    snprintf(where, sizeof where, "match[%d]", index);
    fv_status st;
    const char *param = NULL, *target = NULL, *metric = "mse", *region = "fovea";
    if ((st = fv_json_check_keys(o, keys, file, where, err)) || (st = fv_json_require(o, "param", file, where, err)) ||
        (st = fv_json_require(o, "values", file, where, err)) || (st = fv_json_require(o, "target", file, where, err)) ||
        (st = fv_json_string(o, "param", file, where, &param, err)) || (st = fv_json_string(o, "target", file, where, &target, err)) ||
        (st = fv_json_string(o, "metric", file, where, &metric, err)) || (st = fv_json_string(o, "region", file, where, &region, err)))
        return st;
    fv_bench_match *m = &s->matches[index];
    memset(m, 0, sizeof *m);
    cJSON *mo = cJSON_CreateObject();
    if (!mo) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (const cJSON *it = o->child; it; it = it->next)
        if (!strcmp(it->string, "label") || !strcmp(it->string, "method") || !strcmp(it->string, "params"))
            cJSON_AddItemToObject(mo, it->string, cJSON_Duplicate(it, 1));
    st = parse_method(mo, file, where, true, &m->base, err);
    cJSON_Delete(mo);
    if (st != FV_OK) return st;
    snprintf(m->param, sizeof m->param, "%s", param);
    snprintf(m->target, sizeof m->target, "%s", target);
    if (strcmp(metric, "mse") && strcmp(metric, "flip") && strcmp(metric, "e"))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.metric: '%s' is not mse, flip or e", file, where, metric);
    snprintf(m->metric, sizeof m->metric, "%s", metric);
    int r;
    for (r = 0; r < FV_REGION_COUNT; r++)
        if (!strcmp(region, fv_region_name((fv_region)r))) break;
    if (r == FV_REGION_COUNT)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.region: '%s' is not fovea, transition, periphery or all", file, where, region);
    m->region = (fv_region)r;
    const cJSON *vals = cJSON_GetObjectItemCaseSensitive(o, "values");
    int n = cJSON_GetArraySize(vals);
    if (!cJSON_IsArray(vals) || n < 1 || n > 64)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.values: expected 1 to 64 increasing numbers", file, where);
    int i = 0;
    for (const cJSON *v = vals->child; v; v = v->next, i++) {
        if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || (i > 0 && !(v->valuedouble > m->values[i - 1])))
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s.values[%d]: expected increasing finite numbers", file, where, i);
        m->values[i] = v->valuedouble;
    }
    m->nvalues = n;
    bool found = false;
    for (int k = 0; k < s->nmethods && !found; k++) found = !strcmp(s->methods[k].label, target);
    if (!found) return fv_error_set(err, FV_ERR_INVALID, "%s: %s.target: no method is labelled '%s'", file, where, target);
    return FV_OK;
}

static fv_status parse_root(cJSON *root, const char *file, const char *dir, fv_scenario *s, fv_error *err)
{
    static const char *const keys[] = {"name", "description", "scene", "size", "frames", "measure_from", "fps", "start_time", "repeats",
                                       "exposure", "seed", "eye", "gaze", "camera_path", "reference", "baseline", "methods",
                                       "sweep", "match", "extra_references", "diffuse", "animate", "stereo", "quick", "full", NULL};
    fv_status st = fv_json_check_keys(root, keys, file, "", err);
    if (st != FV_OK) return st;
    const char *name = NULL, *desc = NULL, *scene = NULL, *baseline = NULL;
    double size[2] = {256, 256}, exposure = 1.0, seed = 1, stereo = 0.0;
    if ((st = fv_json_require(root, "scene", file, "", err)) || (st = fv_json_require(root, "reference", file, "", err)) ||
        (st = fv_json_string(root, "name", file, "", &name, err)) || (st = fv_json_string(root, "description", file, "", &desc, err)) ||
        (st = fv_json_string(root, "scene", file, "", &scene, err)) || (st = fv_json_string(root, "baseline", file, "", &baseline, err)) ||
        (st = fv_json_numbers(root, "size", 2, 1, FV_FILM_MAX_DIM, file, "", size, err)) ||
        (st = fv_json_int(root, "frames", 1, 100000, file, "", &s->frames, err)) ||
        (st = fv_json_int(root, "measure_from", 0, 100000, file, "", &s->measure_from, err)) ||
        (st = fv_json_number(root, "fps", 1e-3, 1e4, file, "", &s->fps, err)) ||
        (st = fv_json_number(root, "start_time", -1e9, 1e9, file, "", &s->start_time, err)) ||
        (st = fv_json_int(root, "repeats", 1, 1000, file, "", &s->repeats, err)) ||
        (st = fv_json_number(root, "exposure", 0, 1e9, file, "", &exposure, err)) ||
        (st = fv_json_number(root, "seed", 0, 9007199254740992.0, file, "", &seed, err)) ||
        (st = fv_json_bool(root, "diffuse", file, "", &s->diffuse, err)) ||
        (st = fv_json_number(root, "stereo", 0, FV_COORD_MAX, file, "", &stereo, err)))
        return st;
    s->stereo = (float)stereo;
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(root, "animate");
    if (an && (st = parse_animate(an, file, s, err)) != FV_OK) return st;
    if (s->measure_from >= s->frames)
        return fv_error_set(err, FV_ERR_INVALID, "%s: measure_from %d must be below frames (%d)", file, s->measure_from, s->frames);
    if (size[0] != floor(size[0]) || size[1] != floor(size[1]))
        return fv_error_set(err, FV_ERR_INVALID, "%s: size: expected two integers [width, height]", file);
    s->width = (int)size[0];
    s->height = (int)size[1];
    if ((st = fv_film_check_size(s->width, s->height, err)) != FV_OK) {
        fv_error_prefix(err, "%s: size: ", file);
        return st;
    }
    s->exposure = (float)exposure;
    s->seed = (unsigned long long)seed;
    if (name) {
        if (!label_ok(name)) return fv_error_set(err, FV_ERR_INVALID, "%s: name: '%s' must be 1-63 characters of [A-Za-z0-9._=-]", file, name);
        snprintf(s->name, sizeof s->name, "%s", name);
    }
    if (desc && !(s->description = strdup(desc))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    /* A scene that names a file is found relative to the scenario; a built-in name stays as is. */
    bool is_file = strchr(scene, '/') || strchr(scene, '.');
    size_t need = strlen(dir) + strlen(scene) + 2;
    if (!(s->scene = malloc(need))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (is_file && scene[0] != '/') snprintf(s->scene, need, "%s/%s", dir, scene);
    else snprintf(s->scene, need, "%s", scene);

    /* Without "eye" or "gaze" blocks the sequence driver takes the scene file's display and gaze
     * path, as `fovea render` does (fovea/drive.h). */
    fv_eye_model_default(s->width, s->height, &s->eye);
    const cJSON *o;
    if ((o = cJSON_GetObjectItemCaseSensitive(root, "eye"))) {
        if ((st = fv_gaze_json_eye(o, file, "eye", &s->eye, err))) return st;
        s->has_eye = true;
    }
    if ((o = cJSON_GetObjectItemCaseSensitive(root, "gaze")) && (st = fv_gaze_json_path(o, file, "gaze", dir, &s->gaze, err)) != FV_OK)
        return st;
    if ((o = cJSON_GetObjectItemCaseSensitive(root, "camera_path")) && cJSON_IsString(o)) {
        char full[8192];
        snprintf(full, sizeof full, "%s%s%s", o->valuestring[0] == '/' ? "" : dir, o->valuestring[0] == '/' ? "" : "/", o->valuestring);
        fv_camera base = {{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 45.0f, s->width, s->height};
        if ((st = fv_camera_path_load_csv(full, &base, &s->cam_keys, &s->ncam_keys, err)) != FV_OK) {
            fv_error_prefix(err, "%s: camera_path: ", file);
            return st;
        }
    } else if (o && (st = parse_camera_path(o, file, s, err))) {
        return st;
    }
    if ((st = parse_method(cJSON_GetObjectItemCaseSensitive(root, "reference"), file, "reference", false, &s->reference, err)))
        return st;
    snprintf(s->reference.label, sizeof s->reference.label, "reference");
    const cJSON *ex = cJSON_GetObjectItemCaseSensitive(root, "extra_references");
    if (ex) {
        int n = cJSON_GetArraySize(ex);
        if (!cJSON_IsArray(ex) || n > FV_BENCH_MAX_EXTRA)
            return fv_error_set(err, FV_ERR_INVALID, "%s: extra_references: expected an array of at most %d references", file, FV_BENCH_MAX_EXTRA);
        int k = 0;
        for (const cJSON *e = ex->child; e; e = e->next, k++) {
            char where[40];
            snprintf(where, sizeof where, "extra_references[%d]", k);
            if ((st = parse_method(e, file, where, true, &s->extra[k], err)) != FV_OK) return st;
            s->nextra++;
            if (!strcmp(s->extra[k].label, "reference"))
                return fv_error_set(err, FV_ERR_INVALID, "%s: %s.label: 'reference' is taken", file, where);
        }
    }

    int cap = 0;
    const cJSON *methods = cJSON_GetObjectItemCaseSensitive(root, "methods");
    if (methods && !cJSON_IsArray(methods)) return fv_error_set(err, FV_ERR_INVALID, "%s: methods: expected an array", file);
    int i = 0;
    for (const cJSON *m = methods ? methods->child : NULL; m; m = m->next, i++) {
        char where[32];
        snprintf(where, sizeof where, "methods[%d]", i);
        fv_bench_method bm;
        memset(&bm, 0, sizeof bm);
        if ((st = parse_method(m, file, where, true, &bm, err)) != FV_OK) {
            fv_params_destroy(bm.params);
            return st;
        }
        if ((st = add_method(s, &cap, &bm, file, err)) != FV_OK) return st;
    }
    if ((o = cJSON_GetObjectItemCaseSensitive(root, "sweep")) && (st = parse_sweeps(o, file, s, &cap, err))) return st;
    if (s->nmethods == 0) return fv_error_set(err, FV_ERR_INVALID, "%s: no methods to compare (give 'methods' or 'sweep')", file);
    const cJSON *ma = cJSON_GetObjectItemCaseSensitive(root, "match");
    if (ma) {
        int n = cJSON_GetArraySize(ma);
        if (!cJSON_IsArray(ma) || n < 1 || n > 16) return fv_error_set(err, FV_ERR_INVALID, "%s: match: expected an array of 1 to 16 searches", file);
        if (!(s->matches = fv_calloc_array((size_t)n, sizeof *s->matches))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        s->nmatches = n;
        int k = 0;
        for (const cJSON *m = ma->child; m; m = m->next, k++)
            if ((st = parse_match(m, file, k, s, err)) != FV_OK) return st;
    }
    if (baseline) {
        bool found = false;
        for (int k = 0; k < s->nmethods && !found; k++) found = strcmp(s->methods[k].label, baseline) == 0;
        if (!found) return fv_error_set(err, FV_ERR_INVALID, "%s: baseline: no method is labelled '%s'", file, baseline);
        snprintf(s->baseline, sizeof s->baseline, "%s", baseline);
    } else {
        snprintf(s->baseline, sizeof s->baseline, "%s", s->methods[0].label);
    }
    return FV_OK;
}

/* The scenario in `root` (taken: freed here); `label` names it in messages and gives the default
 * name (its base name without extension), relative paths resolve against `dir`. */
static fv_status load_root(cJSON *root, const char *label, const char *dir, fv_bench_mode mode, fv_scenario **out, fv_error *err)
{
    fv_status st = FV_OK;
    fv_scenario *s = calloc(1, sizeof *s);
    char *labelcopy = strdup(label);
    if (!s || !labelcopy) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        goto done;
    }
    s->frames = 1;
    s->fps = 30.0;
    s->repeats = 3;
    /* Default name: the file name without .json. */
    const char *base = basename(labelcopy);
    snprintf(s->name, sizeof s->name, "%.*s", (int)(strcspn(base, ".")), base);
    const char *key = mode == FV_BENCH_QUICK ? "quick" : mode == FV_BENCH_FULL ? "full" : NULL;
    const cJSON *over = key ? cJSON_GetObjectItemCaseSensitive(root, key) : NULL;
    for (int k = 0; k < 2; k++) {
        const cJSON *blk = cJSON_GetObjectItemCaseSensitive(root, k ? "full" : "quick");
        if (blk && !cJSON_IsObject(blk)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an object of overrides", label, k ? "full" : "quick");
            goto done;
        }
    }
    if (over) {
        cJSON *copy = cJSON_Duplicate(over, 1);
        bool ok = copy && json_merge(root, copy);
        cJSON_Delete(copy);
        if (!ok) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
    st = parse_root(root, label, dir, s, err);
done:
    cJSON_Delete(root);
    free(labelcopy);
    if (st != FV_OK) {
        fv_scenario_destroy(s);
        return st;
    }
    *out = s;
    return FV_OK;
}

fv_status fv_scenario_load(const char *path, fv_bench_mode mode, fv_scenario **out, fv_error *err)
{
    cJSON *root = NULL;
    fv_status st = fv_json_parse_file(path, &root, err);
    if (st != FV_OK) return st;
    char *pathcopy = strdup(path);
    if (!pathcopy) {
        cJSON_Delete(root);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    st = load_root(root, path, dirname(pathcopy), mode, out, err);
    free(pathcopy);
    return st;
}

fv_status fv_scenario_load_text(const char *text, const char *label, const char *dir, fv_bench_mode mode, fv_scenario **out, fv_error *err)
{
    cJSON *root = NULL;
    fv_status st = fv_json_parse_text(label, text, &root, err);
    if (st != FV_OK) return st;
    return load_root(root, label, dir, mode, out, err);
}

void fv_scenario_destroy(fv_scenario *s)
{
    if (!s) return;
    for (int i = 0; i < s->nmethods; i++) fv_params_destroy(s->methods[i].params);
    for (int i = 0; i < s->nmatches; i++) fv_params_destroy(s->matches[i].base.params);
    free(s->matches);
    for (int i = 0; i < s->nanimate; i++) free(s->animate[i].keys);
    free(s->animate);
    fv_params_destroy(s->reference.params);
    for (int i = 0; i < s->nextra; i++) fv_params_destroy(s->extra[i].params);
    fv_gaze_path_destroy(s->gaze);
    free(s->methods);
    free(s->cam_keys);
    free(s->scene);
    free(s->description);
    free(s);
}
