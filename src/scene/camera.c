/* fovea — pinhole camera basis, projection, stereo pairs and camera paths (include/fovea/camera.h). */
#include "fovea/camera.h"
#include "fovea/limits.h"

fv_status fv_camera_basis_make(const fv_camera *c, fv_camera_basis *b, fv_error *err)
{
    /* Bounded first: beyond the ray kernels' range Embree aborts, and nearer FLT_MAX the length
     * of the view direction overflows and would be reported as a parallel up vector. */
    fv_status s;
    if ((s = fv_limit_vec3("camera: position", c->pos, err)) != FV_OK ||
        (s = fv_limit_vec3("camera: look-at point", c->look, err)) != FV_OK ||
        (s = fv_limit_vec3("camera: up vector", c->up, err)) != FV_OK)
        return s;
    if (!(c->fov_y > 0.0f && c->fov_y < 180.0f))
        return fv_error_set(err, FV_ERR_INVALID, "camera: field of view %g is outside (0, 180) degrees", c->fov_y);
    if (c->width <= 0 || c->height <= 0)
        return fv_error_set(err, FV_ERR_INVALID, "camera: image size %dx%d must be positive", c->width, c->height);
    fv_vec3 f = fv_sub(c->look, c->pos);
    if (fv_length(f) <= 0.0f) return fv_error_set(err, FV_ERR_INVALID, "camera: look-at point equals the position");
    if (!(fv_length(c->up) > 0.0f)) return fv_error_set(err, FV_ERR_INVALID, "camera: up vector is zero");
    f = fv_normalize(f);
    fv_vec3 r = fv_cross(f, fv_normalize(c->up));
    if (fv_length(r) < 1e-6f) return fv_error_set(err, FV_ERR_INVALID, "camera: up vector is parallel to the view direction");
    r = fv_normalize(r);
    b->pos = c->pos;
    b->forward = f;
    b->right = r;
    b->up = fv_cross(r, f);
    b->tan_half_y = tanf(fv_radians(c->fov_y) * 0.5f);
    b->tan_half_x = b->tan_half_y * (float)c->width / (float)c->height;
    b->width = c->width;
    b->height = c->height;
    return FV_OK;
}

bool fv_camera_project(const fv_camera_basis *b, fv_vec3 p, float *px, float *py) { return fv_camera_project_point(b, p, px, py); }

void fv_camera_stereo(const fv_camera *center, float eye_sep, fv_camera *left, fv_camera *right)
{
    fv_vec3 f = fv_normalize(fv_sub(center->look, center->pos));
    fv_vec3 r = fv_normalize(fv_cross(f, fv_normalize(center->up)));
    fv_vec3 off = fv_scale(r, 0.5f * eye_sep);
    *left = *center;
    *right = *center;
    left->pos = fv_sub(center->pos, off);
    left->look = fv_sub(center->look, off);
    right->pos = fv_add(center->pos, off);
    right->look = fv_add(center->look, off);
}

void fv_camera_path_eval(const fv_camera_path *path, double t, const fv_camera *base, fv_camera *out)
{
    *out = *base;
    const fv_camera_key *k = path->keys;
    int n = path->count, i = 0;
    if (n <= 0) return;
    if (t <= k[0].time || n == 1) {
        i = 0;
    } else if (t >= k[n - 1].time) {
        i = n - 1;
    } else {
        while (i + 1 < n && k[i + 1].time <= t) i++;
        float a = (float)((t - k[i].time) / (k[i + 1].time - k[i].time));
        out->pos = fv_lerp3(k[i].pos, k[i + 1].pos, a);
        out->look = fv_lerp3(k[i].look, k[i + 1].look, a);
        out->up = fv_normalize(fv_lerp3(k[i].up, k[i + 1].up, a));
        out->fov_y = k[i].fov_y + (k[i + 1].fov_y - k[i].fov_y) * a;
        return;
    }
    out->pos = k[i].pos;
    out->look = k[i].look;
    out->up = k[i].up;
    out->fov_y = k[i].fov_y;
}
