/* fovea — the view: how a scene is looked at, kept apart from what the scene is. A view holds an
 * optional camera, an optional keyframed camera path, an optional display (eye model) and an
 * optional gaze path: the "camera", "camera_path", "display" and "gaze" blocks of a scene file
 * (docs/scene-format.md), which the loaders return beside the scene.
 *
 * Ownership: fv_view_create returns a view the caller destroys with fv_view_destroy. Setters copy
 * what they are given, except fv_view_set_gaze_path, which takes the path over. A view is plain
 * data: concurrent reads are safe, a write must not overlap any other call on the same view.
 */
#ifndef FOVEA_VIEW_H
#define FOVEA_VIEW_H

#include <stdbool.h>
#include "fovea/export.h"
#include "fovea/camera.h"
#include "fovea/gaze.h"
#include "fovea/scene.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_view fv_view;

/* A view with nothing set; destroy it with fv_view_destroy. */
FV_API fv_status fv_view_create(fv_view **out, fv_error *err);
/* Frees the view and the gaze path it owns; NULL is a no-op. */
FV_API void fv_view_destroy(fv_view *v);

/* Sets the base camera (copied); its width/height are replaced by fv_view_camera's. */
FV_API void fv_view_set_camera(fv_view *v, const fv_camera *camera);
FV_API bool fv_view_has_camera(const fv_view *v);
/* Copies keys (count >= 1, times strictly increasing, finite, fov in (0,180)); on error the view
 * keeps its earlier path. */
FV_API fv_status fv_view_set_camera_path(fv_view *v, const fv_camera_key *keys, int count, fv_error *err);
FV_API bool fv_view_has_camera_path(const fv_view *v);
/* The model's up axis (unit; a zero or non-finite vector is ignored): the loaders set it (glTF +y,
 * other mesh files fv_up_axis_guess) and the default camera keeps it up. +y when never set. */
FV_API void fv_view_set_up_axis(fv_view *v, fv_vec3 up);
FV_API fv_vec3 fv_view_up_axis(const fv_view *v);
/* Frames the scene from `frame` (fv_camera_frame): drops the view's camera, so fv_view_camera
 * gives that framing (a camera path still moves it). Without this call the framing is
 * three-quarter. */
FV_API void fv_view_set_frame(fv_view *v, fv_frame_view frame);
/* The camera at time t with the given size: the view's camera (when it has none and scene is a
 * committed scene: fv_camera_frame of the scene's bounds with the view's up axis and frame, by
 * default three-quarter; else all zero but the size), moved along the camera path when there is one. v and scene may each be NULL; v == NULL
 * gives the scene's framing camera. Reads only: safe from several threads at once. */
FV_API void fv_view_camera(const fv_view *v, const fv_scene *scene, double t, int width, int height, fv_camera *out);

/* Sets the display/eye model (copied). */
FV_API void fv_view_set_display(fv_view *v, const fv_eye_model *eye);
/* Copies the display into *out; false (and *out untouched) when the view has none. */
FV_API bool fv_view_display(const fv_view *v, fv_eye_model *out);
/* Takes ownership of path (NULL allowed); an earlier path is destroyed. */
FV_API void fv_view_set_gaze_path(fv_view *v, fv_gaze_path *path);
/* The view's gaze path or NULL; it lives until the view is destroyed or gets another path. */
FV_API const fv_gaze_path *fv_view_gaze_path(const fv_view *v);

#ifdef __cplusplus
}
#endif
#endif
