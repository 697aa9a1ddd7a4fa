/* fovea — error heat maps as PNG, like the error figures of the papers: the per-pixel error
 * through the colour map's ramp (film/colormap.h), with the eye model's rings (gaze/overlay.h)
 * and a colour bar that states the scale, so two heat maps are compared by their bars, not
 * guessed at.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "core/alloc.h"
#include "film/colormap.h"
#include "fovea/film.h"
#include "fovea/metrics.h"
#include "gaze/overlay.h"

float fv_heatmap_scale(const float *map, int w, int h)
{
    float vmax = 0.0f;
    for (size_t i = 0; map && w > 0 && h > 0 && i < (size_t)w * h; i++)
        if (isfinite(map[i]) && map[i] > vmax) vmax = map[i];
    return vmax > 0.0f ? vmax : 1.0f;
}

fv_status fv_heatmap_write(const char *path, const float *map, int w, int h, const fv_heatmap_opts *o, fv_error *err)
{
    fv_status st = fv_film_check_size(w, h, err);
    if (st != FV_OK) return st;
    const fv_heatmap_opts none = {0};
    if (!o) o = &none;
    if (o->eye && (o->eye->width != w || o->eye->height != h))
        return fv_error_set(err, FV_ERR_INVALID, "heat map '%s': the eye model is %dx%d, the map %dx%d", path, o->eye->width, o->eye->height,
                            w, h);
    const float vmax = o->vmax > 0.0f && isfinite(o->vmax) ? o->vmax : fv_heatmap_scale(map, w, h);
    /* The canvas: the map at the top left, the colour bar's strip below it (as wide as the map,
     * or as the bar needs). */
    int cw = w, ch = h, scale = 0;
    if (o->label) {
        scale = fv_colorbar_scale(h);
        int need = fv_colorbar_min_width(scale, vmax, o->label);
        cw = w > need ? w : need;
        ch = h + fv_colorbar_height(scale);
    }
    float *rgb = fv_alloc_array((size_t)cw * ch, 3 * sizeof(float));
    if (!rgb) return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    for (size_t i = 0; i < (size_t)cw * ch * 3; i++) rgb[i] = 1.0f; /* padding: white, as the strip */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float c[3];
            fv_colormap_ramp(map[(size_t)y * w + x] / vmax, c);
            /* The PNG writer sRGB-encodes linear values: hand it the decoded ramp colour. */
            float *p = rgb + 3 * ((size_t)y * cw + x);
            for (int k = 0; k < 3; k++) p[k] = fv_srgb_decode(c[k]);
        }
    if (o->eye) fv_overlay_draw_rgb(rgb, cw, o->eye, o->gaze, FV_OVERLAY_ON_HEATMAP, 1.0f);
    if (o->label) fv_colorbar_draw(rgb, cw, ch, h, scale, vmax, o->label);
    fv_params *meta = NULL;
    char text[32];
    snprintf(text, sizeof text, "%.9g", vmax);
    if ((st = fv_params_create(&meta, err)) == FV_OK && (st = fv_params_set(meta, "heatmap", o->label ? o->label : "error", err)) == FV_OK &&
        (st = fv_params_set(meta, "heatmap_max", text, err)) == FV_OK && o->eye)
        st = fv_params_set(meta, "overlay", "rings,gaze", err);
    if (st == FV_OK) st = fv_image_write_meta(path, rgb, cw, ch, 1.0f, meta, err);
    fv_params_destroy(meta);
    free(rgb);
    return st;
}
