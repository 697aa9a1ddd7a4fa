/* fovea — rigid keyframe animation (see anim.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "scene/anim.h"

fv_status fv_anim_check(const char *who, const fv_anim_key *keys, int count, fv_error *err)
{
    if (count < 1 || !keys) return fv_error_set(err, FV_ERR_INVALID, "animation of %s: no keys", who);
    for (int i = 0; i < count; i++) {
        const fv_anim_key *k = &keys[i];
        float ql = sqrtf(k->rotate.x * k->rotate.x + k->rotate.y * k->rotate.y + k->rotate.z * k->rotate.z + k->rotate.w * k->rotate.w);
        if (!isfinite(k->time) || !fv_is_finite3(k->translate) || !fv_is_finite3(k->scale) || !(ql > 1e-6f) || !isfinite(ql))
            return fv_error_set(err, FV_ERR_INVALID, "animation of %s: key %d has non-finite values or a zero rotation", who, i);
        if (fv_min3(k->scale) <= 0.0f) return fv_error_set(err, FV_ERR_INVALID, "animation of %s: key %d has a scale <= 0", who, i);
        if (i > 0 && !(k->time > keys[i - 1].time))
            return fv_error_set(err, FV_ERR_INVALID, "animation of %s: key times must increase (key %d)", who, i);
    }
    return FV_OK;
}

fv_status fv_anim_set(fv_anim *a, const char *who, const fv_anim_key *keys, int count, fv_error *err)
{
    fv_status st = fv_anim_check(who, keys, count, err);
    if (st != FV_OK) return st;
    fv_anim_key *copy = fv_alloc_array((size_t)count, sizeof *copy);
    if (!copy) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    memcpy(copy, keys, (size_t)count * sizeof *copy);
    /* Unit rotations once here, so interpolation never rescales a shape. */
    for (int i = 0; i < count; i++) {
        fv_quat q = copy[i].rotate;
        float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
        copy[i].rotate = (fv_quat){q.x / l, q.y / l, q.z / l, q.w / l};
    }
    free(a->keys);
    a->keys = copy;
    a->nkeys = count;
    return FV_OK;
}

void fv_anim_free(fv_anim *a)
{
    free(a->keys);
    a->keys = NULL;
    a->nkeys = 0;
}

fv_anim_key fv_anim_at(const fv_anim *a, double t)
{
    const fv_anim_key *k = a->keys;
    int n = a->nkeys;
    fv_anim_key r;
    if (n == 1 || t <= k[0].time) {
        r = k[0];
    } else if (t >= k[n - 1].time) {
        r = k[n - 1];
    } else {
        int i = 0;
        while (i + 1 < n && k[i + 1].time <= t) i++;
        float u = (float)((t - k[i].time) / (k[i + 1].time - k[i].time));
        r.translate = fv_lerp3(k[i].translate, k[i + 1].translate, u);
        r.rotate = fv_quat_slerp(k[i].rotate, k[i + 1].rotate, u);
        r.scale = fv_lerp3(k[i].scale, k[i + 1].scale, u);
    }
    r.time = t;
    return r;
}
