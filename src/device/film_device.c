/* fovea — a film's buffers on a device backend (device/film_device.h). */
#include <string.h>
#include "device/film_device.h"

/* The host film's buffers in a fixed order, with their bytes per pixel. */
static void slots(const fv_film_views *v, void *p[FV_FILM_DEVICE_BUFFERS], size_t per[FV_FILM_DEVICE_BUFFERS])
{
    p[0] = v->color, p[1] = v->depth, p[2] = v->normal, p[3] = v->albedo, p[4] = v->position, p[5] = v->id;
    per[0] = 3 * sizeof(float), per[1] = sizeof(float), per[2] = per[3] = per[4] = 3 * sizeof(float), per[5] = sizeof(uint32_t);
}

static bool shares_host(const fv_backend *b) { return fv_backend_device(b) == FV_DEVICE_PORTABLE; }

fv_status fv_film_device_views(fv_backend *b, fv_film_device *f, const fv_film_views *host, size_t n, fv_film_views *dev, fv_error *err)
{
    if (shares_host(b)) {
        *dev = *host;
        return FV_OK;
    }
    void *hp[FV_FILM_DEVICE_BUFFERS], *dp[FV_FILM_DEVICE_BUFFERS];
    size_t per[FV_FILM_DEVICE_BUFFERS];
    slots(host, hp, per);
    for (int i = 0; i < FV_FILM_DEVICE_BUFFERS; i++) {
        dp[i] = NULL;
        if (!hp[i]) continue;
        fv_status s = fv_buffer_ensure(b, &f->dev[i], n * per[i], "the film", err);
        if (s != FV_OK) return s;
        dp[i] = f->dev[i].p;
    }
    dev->color = dp[0], dev->depth = dp[1], dev->normal = dp[2], dev->albedo = dp[3], dev->position = dp[4], dev->id = dp[5];
    return FV_OK;
}

fv_status fv_film_device_download(fv_backend *b, fv_film_device *f, int slot, const fv_film_views *host, size_t n, fv_error *err)
{
    if (shares_host(b)) return FV_OK;
    if (slot < 0 || slot >= FV_FILM_DEVICE_SLOTS) return fv_error_set(err, FV_ERR_INTERNAL, "the film's read-back: slot %d", slot);
    void *hp[FV_FILM_DEVICE_BUFFERS];
    size_t per[FV_FILM_DEVICE_BUFFERS];
    slots(host, hp, per);
    for (int i = 0; i < FV_FILM_DEVICE_BUFFERS; i++) {
        if (!hp[i]) continue;
        /* both slots now, so that the next frame, in the other slot, allocates nothing */
        for (int k = 0; k < FV_FILM_DEVICE_SLOTS; k++) {
            fv_status s = fv_pinned_ensure(b, &f->stage[k][i], n * per[i], "the film's read-back", err);
            if (s != FV_OK) return s;
        }
        fv_status s = fv_backend_download(b, f->stage[slot][i].p, f->dev[i].p, n * per[i], "the film", err);
        if (s != FV_OK) return s;
    }
    return FV_OK;
}

void fv_film_device_deliver(fv_backend *b, const fv_film_device *f, int slot, const fv_film_views *host, size_t n)
{
    if (shares_host(b) || slot < 0 || slot >= FV_FILM_DEVICE_SLOTS) return;
    void *hp[FV_FILM_DEVICE_BUFFERS];
    size_t per[FV_FILM_DEVICE_BUFFERS];
    slots(host, hp, per);
    for (int i = 0; i < FV_FILM_DEVICE_BUFFERS; i++)
        if (hp[i] && f->stage[slot][i].p) memcpy(hp[i], f->stage[slot][i].p, n * per[i]);
}

void fv_film_device_release(fv_backend *b, fv_film_device *f)
{
    for (int i = 0; i < FV_FILM_DEVICE_BUFFERS; i++) {
        fv_buffer_release(b, &f->dev[i]);
        for (int k = 0; k < FV_FILM_DEVICE_SLOTS; k++) fv_pinned_release(b, &f->stage[k][i]);
    }
}
