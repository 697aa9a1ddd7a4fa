/* fovea — framing a model: the default camera of a scene without one, and the named views of
 * `fovea render --frame-view` (include/fovea/camera.h).
 */
#include <string.h>
#include "fovea/camera.h"
#include "fovea/limits.h"

static const char *const k_names[] = {"three-quarter", "front", "back", "left", "right", "top"};

bool fv_frame_view_from_name(const char *name, fv_frame_view *out)
{
    for (int i = 0; name && i < (int)(sizeof k_names / sizeof k_names[0]); i++)
        if (strcmp(name, k_names[i]) == 0) {
            *out = (fv_frame_view)i;
            return true;
        }
    return false;
}

const char *fv_frame_view_name(fv_frame_view v)
{
    return (int)v >= 0 && (int)v < (int)(sizeof k_names / sizeof k_names[0]) ? k_names[v] : NULL;
}

fv_vec3 fv_up_axis_guess(fv_vec3 lo, fv_vec3 hi)
{
    float e[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
    int a = 0, b = 1, c = 2; /* sorted by extent: e[a] <= e[b] <= e[c] */
    int t;
    if (e[b] < e[a]) t = a, a = b, b = t;
    if (e[c] < e[b]) t = b, b = c, c = t;
    if (e[b] < e[a]) t = a, a = b, b = t;
    (void)c;
    if (!(e[a] < 0.5f * e[b])) return fv_v3(0, 1, 0);
    return fv_v3(a == 0 ? 1.0f : 0.0f, a == 1 ? 1.0f : 0.0f, a == 2 ? 1.0f : 0.0f);
}

/* The model's front: +z for a y-up (or x-up) model, -y for a z-up one, made orthogonal to up. */
static fv_vec3 front_of(fv_vec3 up)
{
    fv_vec3 f = fabsf(up.z) > fabsf(up.y) && fabsf(up.z) > fabsf(up.x) ? fv_v3(0, up.z > 0.0f ? -1.0f : 1.0f, 0) : fv_v3(0, 0, 1);
    f = fv_sub(f, fv_scale(up, fv_dot(f, up)));
    if (fv_length(f) < 1e-3f) f = fv_v3(1, 0, 0); /* up along z's axis with a y front: cannot happen, but stay defined */
    return fv_normalize(f);
}

static inline float comp(fv_vec3 v, int k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; }

void fv_camera_frame(fv_vec3 lo, fv_vec3 hi, fv_vec3 up, fv_frame_view view, int width, int height, fv_camera *out)
{
    up = fv_length(up) > 0.0f ? fv_normalize(up) : fv_v3(0, 1, 0);
    fv_vec3 front = front_of(up), right = fv_normalize(fv_cross(fv_neg(front), up));
    fv_vec3 dir, cam_up = up; /* dir: from the centre towards the camera */
    const float az = fv_radians(35.0f), el = fv_radians(25.0f);
    switch (view) {
    case FV_FRAME_FRONT: dir = front; break;
    case FV_FRAME_BACK: dir = fv_neg(front); break;
    case FV_FRAME_LEFT: dir = fv_neg(right); break;
    case FV_FRAME_RIGHT: dir = right; break;
    case FV_FRAME_TOP:
        dir = up;
        cam_up = fv_neg(front);
        break;
    default:
        dir = fv_add(fv_scale(front, cosf(el) * cosf(az)), fv_add(fv_scale(right, cosf(el) * sinf(az)), fv_scale(up, sinf(el))));
        break;
    }
    dir = fv_normalize(dir);
    fv_vec3 c = fv_scale(fv_add(lo, hi), 0.5f);
    const float fov = 45.0f;
    float ty = tanf(fv_radians(fov) * 0.5f), tx = ty * (width > 0 && height > 0 ? (float)width / (float)height : 1.0f);
    /* The camera's basis as fv_camera_basis_make builds it: forward -dir. */
    fv_vec3 f = fv_neg(dir), r = fv_normalize(fv_cross(f, cam_up)), u = fv_cross(r, f);
    /* Each corner k at offset (x, y, z) from the centre in that basis is inside the frame with a
     * 5% margin when |x| <= 0.95 tx (D + z) and |y| <= 0.95 ty (D + z), D the camera's distance
     * to the centre: the smallest D that keeps all eight. */
    float dist = 0.0f, rad = 0.5f * fv_length(fv_sub(hi, lo));
    for (int k = 0; k < 8; k++) {
        fv_vec3 p = fv_sub(fv_v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z), c);
        float x = fabsf(fv_dot(p, r)), y = fabsf(fv_dot(p, u)), z = fv_dot(p, f);
        dist = fv_maxf(dist, fv_maxf(x / (0.95f * tx), y / (0.95f * ty)) - z);
        dist = fv_maxf(dist, 0.05f * rad - z); /* in front of the nearest corner */
    }
    if (!(dist > 0.0f)) dist = 1.0f;
    /* A scene reaching the edge of the coordinate range would put the camera beyond it
     * (fovea/limits.h): it moves to the other side on an axis that has room there, else stops at
     * the edge on its way out from the centre. */
    float dv[3] = {dir.x, dir.y, dir.z};
    for (int k = 0; k < 3; k++) {
        /* beyond the range on this axis: look from the other side along it when that side has room */
        const float ck = comp(c, k), far = ck + dv[k] * dist, mirrored = ck - dv[k] * dist;
        if (fabsf(far) > (float)FV_COORD_MAX && fabsf(mirrored) <= (float)FV_COORD_MAX) dv[k] = -dv[k];
    }
    dir = fv_v3(dv[0], dv[1], dv[2]); /* a mirrored axis keeps dir apart from cam_up */
    dist = fv_limit_reach(c, dir, dist);
    fv_camera cam = {fv_madd(c, dir, dist), c, cam_up, fov, width, height};
    *out = cam;
}
