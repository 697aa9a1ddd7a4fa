/* fovea CLI — image metadata and the --stats-json log of `fovea render` (render_record.h).
 *
 * Both say how a result was made (issue 27): the method and its typed parameters, the scene, the
 * camera and gaze of each eye, the scene time, the seed, the render time, and the build
 * (version, commit) — so `fovea compare` can take the gaze from the file, and a figure can be
 * traced to its code.
 */
#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>
#include "core/fileio.h"
#include "core/provenance.h"
#include "render_record.h"
#include "technique/class.h"
#include "technique/params_json.h"

/* A cJSON tree as compact text into the bag under key; takes the tree. */
static fv_status set_json(fv_params *p, const char *key, cJSON *j, fv_error *err)
{
    char *t = j ? cJSON_PrintUnformatted(j) : NULL;
    cJSON_Delete(j);
    if (!t) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_status st = fv_params_set(p, key, t, err);
    free(t);
    return st;
}

static cJSON *vec3(fv_vec3 v)
{
    double a[3] = {v.x, v.y, v.z};
    return cJSON_CreateDoubleArray(a, 3);
}

static cJSON *camera_json(const fv_camera *c)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON_AddItemToObject(o, "pos", vec3(c->pos));
    cJSON_AddItemToObject(o, "look", vec3(c->look));
    cJSON_AddItemToObject(o, "up", vec3(c->up));
    cJSON_AddNumberToObject(o, "fov_y", c->fov_y);
    return o;
}

fv_status fv_render_meta(const fv_render_record_run *run, int frame, const fv_frame_views *v, int eye, double render_ms,
                         fv_params **out, fv_error *err)
{
    fv_params *p;
    fv_status st = fv_params_create(&p, err);
    if (st != FV_OK) return st;
    fv_build_info b;
    fv_build_info_get(&b);
    char buf[128], date[32];
    fv_utc_now(date, sizeof date);
#define SET(k, ...) (st == FV_OK ? (snprintf(buf, sizeof buf, __VA_ARGS__), st = fv_params_set(p, k, buf, err)) : st)
    st = fv_params_set(p, "method", run->method, err);
    if (st == FV_OK) st = set_json(p, "params", fv_params_typed_json(run->method, run->params), err);
    /* Whether the image depends on the gaze at all: `fovea compare` refuses two images rendered
     * for different gazes only when one of them does. */
    const fv_technique_class *tc = fv_technique_class_find(run->method);
    SET("foveated", "%s", tc && tc->foveated ? "true" : "false");
    if (st == FV_OK) st = fv_params_set(p, "scene", run->scene, err);
    if (st == FV_OK) st = set_json(p, "camera", camera_json(&v->camera[eye]), err);
    /* The gaze of this image's eye, in normalised screen coordinates (what `fovea compare`
     * reads); a stereo pair says which eye each file is. */
    SET("gaze", "%.7g,%.7g", v->gaze[eye].x, v->gaze[eye].y);
    SET("gaze_known", "%s", v->gaze_known ? "true" : "false");
    SET("eye", "%s", v->eye_count == 2 ? (eye ? "right" : "left") : "mono");
    SET("frame", "%d", frame);
    SET("frame_time", "%.9g", v->time);
    SET("seed", "%llu", run->seed);
    SET("size", "%dx%d", run->width, run->height);
    SET("exposure", "%.9g", run->exposure);
    SET("threads", "%d", fv_threads_used(run->threads));
    SET("render_ms", "%.3f", render_ms);
    SET("version", "%s", b.version);
    SET("commit", "%s%s", b.commit, b.dirty > 0 ? "-dirty" : "");
    SET("date", "%s", date);
#undef SET
    if (st != FV_OK) {
        fv_params_destroy(p);
        return st;
    }
    *out = p;
    return FV_OK;
}

struct fv_stats_log {
    cJSON *root, *frames;
};

fv_status fv_stats_log_create(const fv_render_record_run *run, fv_stats_log **out, fv_error *err)
{
    fv_stats_log *l = calloc(1, sizeof *l);
    if (!l || !(l->root = cJSON_CreateObject())) {
        free(l);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    cJSON_AddItemToObject(l->root, "provenance", fv_provenance_json(run->threads));
    cJSON_AddStringToObject(l->root, "method", run->method);
    cJSON_AddItemToObject(l->root, "params", fv_params_typed_json(run->method, run->params));
    cJSON_AddStringToObject(l->root, "scene", run->scene);
    cJSON *size = cJSON_AddArrayToObject(l->root, "size");
    cJSON_AddItemToArray(size, cJSON_CreateNumber(run->width));
    cJSON_AddItemToArray(size, cJSON_CreateNumber(run->height));
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", run->seed);
    cJSON_AddStringToObject(l->root, "seed", seed);
    l->frames = cJSON_AddArrayToObject(l->root, "frames");
    if (!l->frames) {
        fv_stats_log_destroy(l);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    *out = l;
    return FV_OK;
}

void fv_stats_log_destroy(fv_stats_log *log)
{
    if (!log) return;
    cJSON_Delete(log->root);
    free(log);
}

fv_status fv_stats_log_add(fv_stats_log *log, int frame, const fv_frame_views *v, double ms, const fv_stats *stats, fv_error *err)
{
    cJSON *f = cJSON_CreateObject();
    if (!f || !cJSON_AddItemToArray(log->frames, f)) {
        cJSON_Delete(f);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    cJSON_AddNumberToObject(f, "frame", frame);
    cJSON_AddNumberToObject(f, "time", v->time);
    cJSON_AddNumberToObject(f, "ms", ms);
    cJSON *gz = cJSON_AddArrayToObject(f, "gaze");
    for (int e = 0; e < v->eye_count; e++) {
        double g[2] = {v->gaze[e].x, v->gaze[e].y};
        cJSON_AddItemToArray(gz, cJSON_CreateDoubleArray(g, 2));
    }
    cJSON *st = cJSON_AddObjectToObject(f, "stages_ms");
    for (int i = 0; i < stats->n_stages; i++) cJSON_AddNumberToObject(st, stats->stage[i].name, stats->stage[i].value);
    cJSON *co = cJSON_AddObjectToObject(f, "counters");
    for (int i = 0; i < stats->n_counters; i++) cJSON_AddNumberToObject(co, stats->counter[i].name, stats->counter[i].value);
    return co ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
}

fv_status fv_stats_log_write(fv_stats_log *log, const char *path, bool complete, fv_error *err)
{
    cJSON_DeleteItemFromObject(log->root, "complete");
    cJSON_AddBoolToObject(log->root, "complete", complete);
    char *t = cJSON_Print(log->root);
    if (!t) return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    fv_status st = fv_file_write_atomic(path, t, strlen(t), err);
    free(t);
    return st;
}
