/* fovea — a film's buffers on a device backend (device/film_device.h). */
#include <string.h>
#include "device/display_kernels.h"
#include "device/film_device.h"
#include "film/film_display.h"

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

static size_t pixels_of(const fv_film *film) { return (size_t)fv_film_width(film) * (size_t)fv_film_height(film); }

fv_status fv_film_device_download_film(fv_backend *b, fv_film_device *f, int slot, fv_film *film, fv_error *err)
{
    fv_film_views host = fv_film_views_of(film);
    const size_t n = pixels_of(film);
    uint8_t *display = fv_film_display_buffer(film);
    if (!display) return fv_film_device_download(b, f, slot, &host, n, err);
    if (slot < 0 || slot >= FV_FILM_DEVICE_SLOTS) return fv_error_set(err, FV_ERR_INTERNAL, "the film's read-back: slot %d", slot);
    /* converted where the colour is: on portable into the film's own buffer, else on the device */
    fv_display_args a = {shares_host(b) ? host.color : f->dev[0].p, display, fv_film_display_exposure(film)};
    fv_status s = FV_OK;
    if (!shares_host(b)) {
        s = fv_buffer_ensure(b, &f->display, 4 * n, "the film's display output", err);
        for (int k = 0; k < FV_FILM_DEVICE_SLOTS && s == FV_OK; k++)
            s = fv_pinned_ensure(b, &f->display_stage[k], 4 * n, "the film's display read-back", err);
        a.rgba = f->display.p;
    }
    if (s == FV_OK) s = fv_backend_launch(b, &fv_display_kernel, (int)n, 1, &a, NULL, err);
    if (s == FV_OK && !shares_host(b)) s = fv_backend_download(b, f->display_stage[slot].p, f->display.p, 4 * n, "the film's display output", err);
    /* the rest of the film (its auxiliary buffers, if any) as ever; its float colour stays behind */
    host.color = NULL;
    return s == FV_OK ? fv_film_device_download(b, f, slot, &host, n, err) : s;
}

void fv_film_device_deliver_film(fv_backend *b, const fv_film_device *f, int slot, fv_film *film)
{
    fv_film_views host = fv_film_views_of(film);
    const size_t n = pixels_of(film);
    uint8_t *display = fv_film_display_buffer(film);
    if (display) {
        host.color = NULL;
        if (!shares_host(b) && slot >= 0 && slot < FV_FILM_DEVICE_SLOTS && f->display_stage[slot].p)
            memcpy(display, f->display_stage[slot].p, 4 * n);
    }
    fv_film_device_deliver(b, f, slot, &host, n);
    if (display) fv_film_display_filled(film);
}

void fv_film_device_release(fv_backend *b, fv_film_device *f)
{
    fv_buffer_release(b, &f->display);
    for (int k = 0; k < FV_FILM_DEVICE_SLOTS; k++) fv_pinned_release(b, &f->display_stage[k]);
    for (int i = 0; i < FV_FILM_DEVICE_BUFFERS; i++) {
        fv_buffer_release(b, &f->dev[i]);
        for (int k = 0; k < FV_FILM_DEVICE_SLOTS; k++) fv_pinned_release(b, &f->stage[k][i]);
    }
}
