/* fovea CLI — the --stats-json log of `fovea render` (render_record.h): every frame's stage
 * timings and counters under the method, its typed parameters and the build (issue 27). */
#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>
#include "core/fileio.h"
#include "core/provenance_json.h"
#include "render_record.h"
#include "drive/params_json.h"

struct fv_stats_log {
    cJSON *root, *frames;
};

fv_status fv_stats_log_create(const fv_frame_meta_run *run, fv_stats_log **out, fv_error *err)
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
    /* the stages whose serial part was measured (docs/threads.md) */
    cJSON *se = cJSON_AddObjectToObject(f, "serial_ms");
    for (int i = 0; i < stats->n_serial; i++) cJSON_AddNumberToObject(se, stats->serial[i].name, stats->serial[i].value);
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
