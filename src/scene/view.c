/* fovea — the view (include/fovea/view.h): camera, camera path, display and gaze path, held apart
 * from the scene so a scene is only what is rendered and a view only how it is looked at.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "fovea/limits.h"
#include "fovea/view.h"
#include "scene/scene_impl.h"
#include "scene/view_impl.h"

struct fv_view {
    bool has_camera;
    fv_camera camera;
    bool has_up;               /* the model's up axis, when the loader knows or guessed it (else +y) */
    fv_vec3 up;
    fv_frame_view frame;       /* how the default camera frames the scene */
    fv_camera_key *cam_keys;
    int ncam_keys;

    bool has_eye;
    fv_eye_model eye;
    fv_gaze_path *gaze;        /* owned */
};

fv_status fv_view_create(fv_view **out, fv_error *err)
{
    fv_view *v = calloc(1, sizeof *v);
    if (!v) return fv_error_set(err, FV_ERR_NOMEM, "out of memory creating a view");
    *out = v;
    return FV_OK;
}

void fv_view_destroy(fv_view *v)
{
    if (!v) return;
    free(v->cam_keys);
    fv_gaze_path_destroy(v->gaze);
    free(v);
}

void fv_view_set_camera(fv_view *v, const fv_camera *c)
{
    v->camera = *c;
    v->has_camera = true;
}

bool fv_view_has_camera(const fv_view *v) { return v->has_camera; }

fv_status fv_view_set_camera_path(fv_view *v, const fv_camera_key *keys, int count, fv_error *err)
{
    if (count < 1) return fv_error_set(err, FV_ERR_INVALID, "camera path: no keys");
    for (int i = 0; i < count; i++) {
        char what[48];
        snprintf(what, sizeof what, "camera path: key %d", i);
        fv_status st;
        if ((st = fv_limit_vec3(what, keys[i].pos, err)) != FV_OK || (st = fv_limit_vec3(what, keys[i].look, err)) != FV_OK ||
            (st = fv_limit_vec3(what, keys[i].up, err)) != FV_OK)
            return st;
        if (!isfinite(keys[i].time) || !(keys[i].fov_y > 0.0f && keys[i].fov_y < 180.0f))
            return fv_error_set(err, FV_ERR_INVALID, "camera path: key %d has a non-finite time or a fov outside (0,180)", i);
        if (i > 0 && !(keys[i].time > keys[i - 1].time))
            return fv_error_set(err, FV_ERR_INVALID, "camera path: key times must increase (key %d)", i);
    }
    fv_camera_key *copy = fv_alloc_array((size_t)count, sizeof *copy);
    if (!copy) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    memcpy(copy, keys, (size_t)count * sizeof *copy);
    free(v->cam_keys);
    v->cam_keys = copy;
    v->ncam_keys = count;
    return FV_OK;
}

bool fv_view_has_camera_path(const fv_view *v) { return v->ncam_keys > 0; }

void fv_view_set_up_axis(fv_view *v, fv_vec3 up)
{
    if (!fv_is_finite3(up) || !(fv_length(up) > 0.0f)) return;
    v->up = fv_normalize(up);
    v->has_up = true;
}

fv_vec3 fv_view_up_axis(const fv_view *v) { return v && v->has_up ? v->up : fv_v3(0, 1, 0); }

void fv_view_set_frame(fv_view *v, fv_frame_view frame)
{
    v->frame = frame;
    v->has_camera = false;
}

void fv_view_frame_bounds(const fv_view *v, fv_vec3 lo, fv_vec3 hi, int width, int height, fv_camera *out)
{
    if (v && v->has_camera) {
        *out = v->camera;
        out->width = width;
        out->height = height;
        return;
    }
    fv_camera_frame(lo, hi, fv_view_up_axis(v), v ? v->frame : FV_FRAME_THREE_QUARTER, width, height, out);
}

void fv_view_camera(const fv_view *v, const fv_scene *scene, double t, int width, int height, fv_camera *out)
{
    /* Without a camera or a committed scene to frame, the base is all zeros, as an uncommitted
     * scene's camera was: a CSV camera path then takes only what its lines give. */
    fv_camera base;
    memset(&base, 0, sizeof base);
    if (v && v->has_camera) base = v->camera;
    else if (scene && scene->committed) fv_view_frame_bounds(v, scene->lo, scene->hi, width, height, &base);
    base.width = width;
    base.height = height;
    if (v && v->ncam_keys > 0) {
        fv_camera_path p = {v->cam_keys, v->ncam_keys};
        fv_camera_path_eval(&p, t, &base, out);
    } else {
        *out = base;
    }
}

void fv_view_set_display(fv_view *v, const fv_eye_model *eye)
{
    v->eye = *eye;
    v->has_eye = true;
}

bool fv_view_display(const fv_view *v, fv_eye_model *out)
{
    if (v->has_eye) *out = v->eye;
    return v->has_eye;
}

void fv_view_set_gaze_path(fv_view *v, fv_gaze_path *path)
{
    if (v->gaze != path) fv_gaze_path_destroy(v->gaze);
    v->gaze = path;
}

const fv_gaze_path *fv_view_gaze_path(const fv_view *v) { return v->gaze; }
