/* fovea — pinhole camera, stereo pairs and keyframed camera paths.
 *
 * Screen convention used everywhere in fovea: pixel (0,0) is the top-left corner, x grows right,
 * y grows down; normalised screen coordinates are (x + 0.5)/width, (y + 0.5)/height in [0,1].
 * Cameras and keys are plain structs; the functions are pure (thread-safe) except the CSV reader,
 * whose keys the caller releases with fv_camera_keys_free.
 */
#ifndef FOVEA_CAMERA_H
#define FOVEA_CAMERA_H

#include <stdbool.h>
#include "fovea/export.h"
#include "fovea/math.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_camera {
    fv_vec3 pos;    /* eye position */
    fv_vec3 look;   /* a point the camera looks at */
    fv_vec3 up;     /* up hint, need not be orthogonal to the view direction */
    float fov_y;    /* vertical field of view in degrees, (0, 180) */
    int width, height;
} fv_camera;

/* Derived, per-frame constant data for generating rays and projecting points. */
typedef struct fv_camera_basis {
    fv_vec3 pos, right, up, forward; /* orthonormal; right-handed with forward = -z in view space */
    float tan_half_y, tan_half_x;
    int width, height;
} fv_camera_basis;

/* Checks fields (finite vectors, look != pos, up not parallel to view, fov in (0,180), sizes > 0)
 * and builds the basis. */
FV_API fv_status fv_camera_basis_make(const fv_camera *cam, fv_camera_basis *out, fv_error *err);

/* Direction (unit) of the ray through film position (px, py) in pixels, e.g. (x + 0.5, y + 0.5). */
FV_HD static inline fv_vec3 fv_camera_dir(const fv_camera_basis *b, float px, float py)
{
    float sx = (2.0f * px / (float)b->width - 1.0f) * b->tan_half_x;
    float sy = (1.0f - 2.0f * py / (float)b->height) * b->tan_half_y;
    return fv_normalize(fv_add(b->forward, fv_add(fv_scale(b->right, sx), fv_scale(b->up, sy))));
}

/* Projects a world point to film coordinates in pixels; false when behind the camera.
 * Inverse of fv_camera_dir: used by reprojection between two cameras. */
FV_API bool fv_camera_project(const fv_camera_basis *b, fv_vec3 p, float *px, float *py);
/* The same inline, for the device kernels (fv_camera_project calls it). */
FV_HD static inline bool fv_camera_project_point(const fv_camera_basis *b, fv_vec3 p, float *px, float *py)
{
    fv_vec3 d = fv_sub(p, b->pos);
    float z = fv_dot(d, b->forward);
    if (z <= 1e-8f) return false;
    float sx = fv_dot(d, b->right) / (z * b->tan_half_x);
    float sy = fv_dot(d, b->up) / (z * b->tan_half_y);
    *px = (sx + 1.0f) * 0.5f * (float)b->width;
    *py = (1.0f - sy) * 0.5f * (float)b->height;
    return true;
}

/* Left and right eye cameras of a stereo pair: each offset by half of eye_sep along the camera's
 * right vector, looking in parallel (look point offset by the same amount). */
FV_API void fv_camera_stereo(const fv_camera *center, float eye_sep, fv_camera *left, fv_camera *right);

/* A keyframed camera path: position, look-at point and fov interpolated linearly in time;
 * times strictly increasing. Before the first / after the last key the end key holds. */
typedef struct fv_camera_key {
    double time;
    fv_vec3 pos, look, up;
    float fov_y;
} fv_camera_key;

typedef struct fv_camera_path {
    fv_camera_key *keys; /* owned by whoever filled the struct */
    int count;
} fv_camera_path;

/* Reads a camera path from a CSV trace (docs/gaze.md): lines "time,px,py,pz,lx,ly,lz", optionally
 * followed by "ux,uy,uz" and then "fov"; missing up and fov come from base. Release *keys with
 * fv_camera_keys_free. Errors name the file and line; on error *keys is NULL. */
FV_API fv_status fv_camera_path_load_csv(const char *path, const fv_camera *base, fv_camera_key **keys, int *count, fv_error *err);
/* Releases keys from fv_camera_path_load_csv (NULL is ignored). */
FV_API void fv_camera_keys_free(fv_camera_key *keys);

/* Camera at time t along path (count >= 1); width/height are taken from base. */
FV_API void fv_camera_path_eval(const fv_camera_path *path, double t, const fv_camera *base, fv_camera *out);

/* ---- framing a model (src/scene/framing.c, docs/scene-format.md "Default view and light") ----
 * A model's front is +z when its up axis is +y or x (glTF's convention) and -y when its up axis is
 * z (the convention of z-up tools). The views look at the centre of the bounding box: front, back,
 * left and right from the horizon, top from above (the front at the bottom of the image), and
 * three-quarter, the default, from the front 35 degrees to the right and 25 degrees above. */
typedef enum fv_frame_view {
    FV_FRAME_THREE_QUARTER = 0,
    FV_FRAME_FRONT,
    FV_FRAME_BACK,
    FV_FRAME_LEFT,
    FV_FRAME_RIGHT,
    FV_FRAME_TOP
} fv_frame_view;

/* "three-quarter" | "front" | "back" | "left" | "right" | "top" <-> view; false when unknown. */
FV_API bool fv_frame_view_from_name(const char *name, fv_frame_view *out);
FV_API const char *fv_frame_view_name(fv_frame_view view);
/* The unit axis (+x, +y or +z) taken as the up of a model with bounds [lo, hi] whose file does
 * not say: the axis of the smallest extent when the model is flat (that extent under half of the
 * middle one: a relief, a plan, a terrain lies on it), else +y. */
FV_API fv_vec3 fv_up_axis_guess(fv_vec3 lo, fv_vec3 hi);
/* A camera (fov 45 degrees, width x height) that sees box [lo, hi] from `view`, with `up` the
 * model's up axis (unit), as close as keeps all eight corners inside the frame with a 5% margin. */
FV_API void fv_camera_frame(fv_vec3 lo, fv_vec3 hi, fv_vec3 up, fv_frame_view view, int width, int height, fv_camera *out);

#ifdef __cplusplus
}
#endif
#endif
