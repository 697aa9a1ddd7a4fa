/* fovea-view — the flying camera: WASD/QE move it, a right-drag turns it. It starts as the
 * camera the driver gave the first frame and, once moved, replaces it through
 * fv_driver_set_camera. Yaw turns about the scene's up vector so the horizon stays level. */
#include <math.h>
#include "view.h"

void fv_vw_fly_init(fv_vw_fly *f, const fv_camera *c)
{
    f->active = false;
    f->pos = c->pos;
    fv_vec3 d = fv_sub(c->look, c->pos);
    f->dist = fv_length(d);
    if (!(f->dist > 0.0f)) f->dist = 1.0f;
    f->fwd = fv_normalize(d);
    f->up = fv_normalize(c->up);
    f->fov_y = c->fov_y;
}

static fv_vec3 right_of(const fv_vw_fly *f) { return fv_normalize(fv_cross(f->fwd, f->up)); }

void fv_vw_fly_move(fv_vw_fly *f, float right, float up, float forward)
{
    f->pos = fv_madd(f->pos, right_of(f), right);
    f->pos = fv_madd(f->pos, f->up, up);
    f->pos = fv_madd(f->pos, f->fwd, forward);
    f->active = true;
}

/* Rotation of v about unit axis k by angle a (Rodrigues). */
static fv_vec3 rotate(fv_vec3 v, fv_vec3 k, float a)
{
    float c = cosf(a), s = sinf(a);
    return fv_add(fv_add(fv_scale(v, c), fv_scale(fv_cross(k, v), s)), fv_scale(k, fv_dot(k, v) * (1.0f - c)));
}

void fv_vw_fly_look(fv_vw_fly *f, float yaw, float pitch)
{
    fv_vec3 r = right_of(f);
    fv_vec3 fwd = fv_normalize(rotate(f->fwd, f->up, -yaw));
    fv_vec3 pitched = fv_normalize(rotate(fwd, r, -pitch));
    /* stop short of looking straight up or down: the camera's basis needs up and forward apart */
    if (fabsf(fv_dot(pitched, f->up)) < 0.98f) fwd = pitched;
    f->fwd = fwd;
    f->active = true;
}

void fv_vw_fly_camera(const fv_vw_fly *f, fv_camera *out)
{
    out->pos = f->pos;
    out->look = fv_madd(f->pos, f->fwd, f->dist);
    out->up = f->up;
    out->fov_y = f->fov_y;
}
