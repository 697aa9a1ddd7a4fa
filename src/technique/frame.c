/* fovea — frame helpers: the public starting point of a hand-built frame, and the two steps every
 * technique's render begins with (kit.h). */
#include <string.h>
#include "fovea/film.h"
#include "technique/kit.h"

void fv_frame_init(fv_frame *frame, const fv_camera *camera)
{
    memset(frame, 0, sizeof *frame);
    frame->seed = 1;
    frame->eye_count = 1;
    frame->camera = camera;
    frame->gaze.x = frame->gaze.y = 0.5f;
}

const fv_eye_model *fv_frame_eye_model(const fv_frame *frame, int width, int height, fv_eye_model *def)
{
    if (frame->eye_model) return frame->eye_model;
    fv_eye_model_default(width, height, def);
    return def;
}

bool fv_frame_fovea_covers(const fv_frame *frame, const fv_eye_model *eye, int width, int height)
{
    /* the farthest pixel centre from any point is one of the four corner pixels' centres */
    const double rf = fv_eye_fovea_radius_px(eye), xs[2] = {0.5, width - 0.5}, ys[2] = {0.5, height - 0.5};
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            if (!(fv_eye_gaze_dist_px(eye, frame->gaze, xs[i], ys[j]) <= rf)) return false;
    return true;
}

fv_status fv_frame_camera(const fv_camera *cam, const fv_film *film, fv_camera_basis *out, fv_error *err)
{
    fv_status s = fv_camera_basis_make(cam, out, err);
    if (s == FV_OK && (cam->width != fv_film_width(film) || cam->height != fv_film_height(film)))
        s = fv_error_set(err, FV_ERR_INVALID, "camera size %dx%d differs from the film's %dx%d", cam->width, cam->height,
                         fv_film_width(film), fv_film_height(film));
    return s;
}
