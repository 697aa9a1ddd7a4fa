/* fovea — the eye model's regions drawn over an image (overlay.h): so a reader sees where a
 * foveated method was told the viewer looks, at the radii the technique and the metrics use
 * (fv_eye_fovea_radius_px, fv_eye_transition_radius_px: Foveated Photon Mapping Eq. 7).
 */
#include <math.h>
#include "fovea/film.h"
#include "gaze/overlay.h"

static const uint8_t k_palette[2][FV_MARK_COUNT][3] = {
    {{0, 0, 0}, {0, 255, 255}, {255, 0, 255}, {255, 255, 0}},  /* on an image: cyan r_t, magenta r_f, yellow gaze */
    {{0, 0, 0}, {64, 224, 64}, {0, 255, 255}, {0, 255, 255}}, /* on a heat map: green r_t, cyan r_f and gaze */
};

void fv_overlay_color(fv_overlay_palette p, fv_overlay_mark m, uint8_t out[3])
{
    if ((int)p < 0 || p > FV_OVERLAY_ON_HEATMAP) p = FV_OVERLAY_ON_IMAGE;
    if ((int)m < 0 || m >= FV_MARK_COUNT) m = FV_MARK_NONE;
    for (int c = 0; c < 3; c++) out[c] = k_palette[p][m][c];
}

int fv_overlay_line_width(int width, int height)
{
    (void)width;
    return 1 + (height > 0 ? height / 540 : 0);
}

void fv_overlay_shape_of(const fv_eye_model *m, fv_gaze g, double ox, double oy, double scale, int line, fv_overlay_shape *out)
{
    out->cx = ox + (double)g.x * m->width * scale;
    out->cy = oy + (double)g.y * m->height * scale;
    out->r_fovea = fv_eye_fovea_radius_px(m) * scale;
    out->r_transition = fv_eye_transition_radius_px(m) * scale;
    out->line = line > 0 ? line : 1;
}

fv_overlay_mark fv_overlay_mark_at(const fv_overlay_shape *s, int x, int y)
{
    /* The cross: the pixel holding the gaze point, arms along its row and column. */
    const int L = s->line;
    const int gx = (int)floor(s->cx), gy = (int)floor(s->cy), dx = x - gx, dy = y - gy;
    const int adx = dx < 0 ? -dx : dx, ady = dy < 0 ? -dy : dy;
    if ((ady < L && adx >= 2 * L && adx <= 6 * L) || (adx < L && ady >= 2 * L && ady <= 6 * L)) return FV_MARK_GAZE;
    /* The rings: pixel centres within L pixels of the radius, a band 2 L wide: closed at any
     * radius (no gaps on the diagonals) and visible over a noisy render. */
    const double d = hypot(x + 0.5 - s->cx, y + 0.5 - s->cy);
    if (fabs(d - s->r_fovea) <= L) return FV_MARK_FOVEA;
    if (fabs(d - s->r_transition) <= L) return FV_MARK_TRANSITION;
    return FV_MARK_NONE;
}

void fv_overlay_bounds(const fv_overlay_shape *s, int *x0, int *y0, int *x1, int *y1)
{
    double r = fmax(fmax(s->r_fovea, s->r_transition), 6.0 * s->line) + s->line + 1.0;
    /* beyond the int range nothing is on a target anyway */
    double lo_x = fmax(s->cx - r, -1e9), hi_x = fmin(s->cx + r, 1e9), lo_y = fmax(s->cy - r, -1e9), hi_y = fmin(s->cy + r, 1e9);
    *x0 = (int)floor(lo_x), *x1 = (int)ceil(hi_x), *y0 = (int)floor(lo_y), *y1 = (int)ceil(hi_y);
}

void fv_overlay_draw_rgb(float *rgb, int stride, const fv_eye_model *m, fv_gaze g, fv_overlay_palette p, float exposure)
{
    const int w = m->width, h = m->height;
    fv_overlay_shape s;
    fv_overlay_shape_of(m, g, 0.0, 0.0, 1.0, fv_overlay_line_width(w, h), &s);
    float lin[FV_MARK_COUNT][3];
    for (int k = 0; k < FV_MARK_COUNT; k++) {
        uint8_t c[3];
        fv_overlay_color(p, (fv_overlay_mark)k, c);
        /* the PNG writer multiplies by the exposure and sRGB-encodes: undo both */
        for (int q = 0; q < 3; q++) lin[k][q] = fv_srgb_decode(c[q] / 255.0f) / (exposure > 0.0f ? exposure : 1.0f);
    }
    int x0, y0, x1, y1;
    fv_overlay_bounds(&s, &x0, &y0, &x1, &y1);
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > w - 1) x1 = w - 1;
    if (x1 > stride - 1) x1 = stride - 1;
    if (y1 > h - 1) y1 = h - 1;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            fv_overlay_mark k = fv_overlay_mark_at(&s, x, y);
            if (k == FV_MARK_NONE) continue;
            float *px = rgb + 3 * ((size_t)y * stride + x);
            px[0] = lin[k][0], px[1] = lin[k][1], px[2] = lin[k][2];
        }
}
