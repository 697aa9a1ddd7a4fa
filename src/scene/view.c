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

struct fv_view {
    bool has_camera;
    fv_camera camera;
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

/* Frames the bounding sphere from the +z side with a 45 degree view. The arithmetic is the one
 * fv_scene_commit used when the scene carried the camera, so images framed this way are unchanged. */
static fv_camera framing_camera(const fv_scene *s)
{
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    float diag = fv_length(fv_sub(hi, lo));
    fv_vec3 c = fv_scale(fv_add(lo, hi), 0.5f);
    float r = 0.5f * diag, fov = 45.0f;
    float dist = 1.05f * r / sinf(fv_radians(fov) * 0.5f);
    fv_camera cam = {fv_add(c, fv_v3(0, 0, dist)), c, fv_v3(0, 1, 0), fov, 512, 512};
    /* A scene reaching the edge of the coordinate range would put its framing camera beyond it
     * (fovea/limits.h): the camera stops at the edge, looking the same way. */
    cam.pos.z = fminf(cam.pos.z, (float)FV_COORD_MAX);
    if (!(cam.pos.z > c.z)) cam.pos.z = fmaxf(c.z - dist, -(float)FV_COORD_MAX); /* the centre is at the edge: from -z */
    return cam;
}

void fv_view_camera(const fv_view *v, const fv_scene *scene, double t, int width, int height, fv_camera *out)
{
    /* Without a camera or a committed scene to frame, the base is all zeros, as an uncommitted
     * scene's camera was: a CSV camera path then takes only what its lines give. */
    fv_camera base;
    memset(&base, 0, sizeof base);
    if (v && v->has_camera) base = v->camera;
    else if (scene && scene->committed) base = framing_camera(scene);
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
