/* fovea — error heat maps as PNG, like the error figures of the papers: a perceptual ramp from
 * dark purple (no error) through red and orange to pale yellow (vmax), with optional thin rings
 * marking the fovea and the transition region around the gaze point.
 */
#include <math.h>
#include <stdlib.h>
#include "core/alloc.h"
#include "fovea/film.h"
#include "fovea/metrics.h"

/* Control points of the ramp (sRGB, 0..1), evenly spaced; chosen by hand to rise steadily in
 * lightness so that larger errors always look brighter, also in grey-scale print. */
static const float k_ramp[6][3] = {{0.00f, 0.00f, 0.02f}, {0.23f, 0.06f, 0.43f}, {0.55f, 0.13f, 0.50f},
                                   {0.87f, 0.29f, 0.35f}, {0.99f, 0.62f, 0.36f}, {0.99f, 0.98f, 0.75f}};

static void ramp(float t, float *rgb)
{
    if (!(t > 0.0f)) t = 0.0f;
    if (t > 1.0f) t = 1.0f;
    float x = t * 5.0f;
    int i = (int)x;
    if (i >= 5) i = 4;
    float f = x - i;
    for (int c = 0; c < 3; c++) rgb[c] = k_ramp[i][c] + f * (k_ramp[i + 1][c] - k_ramp[i][c]);
}

fv_status fv_heatmap_write(const char *path, const float *map, int w, int h, float vmax, const fv_eye_model *eye, fv_gaze g,
                           fv_error *err)
{
    fv_status st = fv_film_check_size(w, h, err);
    if (st != FV_OK) return st;
    if (!(vmax > 0.0f) || !isfinite(vmax)) {
        vmax = 0.0f;
        for (size_t i = 0; i < (size_t)w * h; i++)
            if (isfinite(map[i]) && map[i] > vmax) vmax = map[i];
        if (vmax <= 0.0f) vmax = 1.0f;
    }
    float *rgb = fv_alloc_array((size_t)w * h, 3 * sizeof(float));
    if (!rgb) return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    double rf = eye ? fv_eye_fovea_radius_px(eye) : 0.0, rt = eye ? fv_eye_transition_radius_px(eye) : 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            float c[3];
            ramp(map[i] / vmax, c);
            if (eye) {
                double d = hypot(x + 0.5 - (double)g.x * w, y + 0.5 - (double)g.y * h);
                if (fabs(d - rf) < 0.75 || fabs(d - rt) < 0.75) c[0] = c[1] = c[2] = 0.75f;
            }
            /* The PNG writer sRGB-encodes linear values: hand it the decoded ramp colour. */
            for (int k = 0; k < 3; k++) rgb[3 * i + k] = fv_srgb_decode(c[k]);
        }
    st = fv_image_write(path, rgb, w, h, 1.0f, err);
    free(rgb);
    return st;
}
