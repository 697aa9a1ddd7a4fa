/* fovea — what the library's modules share about views beyond fovea/view.h. */
#ifndef FV_SCENE_VIEW_IMPL_H
#define FV_SCENE_VIEW_IMPL_H

#include "fovea/view.h"

/* The view's camera when it has one, else its framing of box [lo, hi] (fv_camera_frame with the
 * view's up axis and frame); v may be NULL. The scene need not be committed (the default
 * lighting places its key light with it before the commit). */
void fv_view_frame_bounds(const fv_view *v, fv_vec3 lo, fv_vec3 hi, int width, int height, fv_camera *out);

#endif
