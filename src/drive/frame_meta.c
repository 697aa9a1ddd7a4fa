/* fovea — the metadata of a rendered frame (frame_meta.h): the method and its typed parameters,
 * the scene, this eye's camera and gaze, the scene time, the seed, the render time and the build
 * (version, commit), so `fovea compare` can take the gaze from the file and a figure can be traced
 * to its code (issue 27).
 */
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include "core/provenance_json.h"
#include "drive/frame_meta.h"
#include "drive/params_json.h"
#include "fovea/technique.h"

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

fv_status fv_frame_meta(const fv_frame_meta_run *run, int frame, const fv_frame_views *v, int eye, double render_ms,
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
     * for different gazes only when both do. */
    SET("foveated", "%s", fv_technique_foveated(fv_technique_index(run->method)) ? "true" : "false");
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
    SET("warmup_frames", "%d", run->warmup);
    SET("size", "%dx%d", run->width, run->height);
    SET("exposure", "%.9g", run->exposure);
    SET("threads", "%d", fv_threads_used(run->threads));
    if (render_ms >= 0) SET("render_ms", "%.3f", render_ms);
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

fv_status fv_frame_meta_overlay(fv_params *meta, fv_error *err) { return fv_params_set(meta, "overlay", "rings,gaze", err); }
