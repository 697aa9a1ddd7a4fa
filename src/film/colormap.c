/* fovea — the colour map of error heat maps (colormap.h): a perceptual ramp like the error
 * figures of the papers, and a colour bar with tick labels so that a heat map says its own scale
 * and two heat maps can be compared by eye only when their bars agree.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "film/colormap.h"
#include "film/font.h"
#include "fovea/film.h"

/* Control points of the ramp (sRGB, 0..1), evenly spaced; chosen by hand to rise steadily in
 * lightness (CIE L* from 0.2 to 97, never falling: tests/unit/test_colormap.c) so that a larger
 * error always looks brighter, also in grey-scale print. */
static const float k_ramp[6][3] = {{0.00f, 0.00f, 0.02f}, {0.23f, 0.06f, 0.43f}, {0.55f, 0.13f, 0.50f},
                                   {0.87f, 0.29f, 0.35f}, {0.99f, 0.62f, 0.36f}, {0.99f, 0.98f, 0.75f}};

void fv_colormap_ramp(float t, float srgb[3])
{
    if (!(t > 0.0f)) t = 0.0f;
    if (t > 1.0f) t = 1.0f;
    float x = t * 5.0f;
    int i = (int)x;
    if (i >= 5) i = 4;
    float f = x - (float)i;
    for (int c = 0; c < 3; c++) srgb[c] = k_ramp[i][c] + f * (k_ramp[i + 1][c] - k_ramp[i][c]);
}

/* Strip geometry in units of the scale: 3 rows of margin, the ramp 8 rows, ticks 2 rows, a
 * blank row, labels 7 rows, 1 row of margin; 4 columns of margin at each side. */
enum { BAR_TOP = 3, BAR_H = 8, TICK_H = 2, LABEL_TOP = BAR_TOP + BAR_H + TICK_H + 1, STRIP_H = LABEL_TOP + FV_FONT_H + 1, MARGIN = 4,
       MIN_BAR = 32 };

int fv_colorbar_scale(int map_h) { return 1 + (map_h > 0 ? map_h / 540 : 0); }

int fv_colorbar_height(int scale) { return STRIP_H * scale; }

/* "0", "%.3g" of v otherwise: the tick labels. */
static void tick_text(float v, char *out, size_t n)
{
    if (v == 0.0f) snprintf(out, n, "0");
    else snprintf(out, n, "%.3g", v);
}

/* The columns before the ramp: the margin, then the label and a gap when there is one. */
static int ramp_start(int scale, const char *label)
{
    int lw = label && *label ? fv_font_text_width(label, scale) : 0;
    return MARGIN * scale + (lw > 0 ? lw + 2 * MARGIN * scale : 0);
}

int fv_colorbar_min_width(int scale, float vmax, const char *label)
{
    char hi[32];
    tick_text(vmax, hi, sizeof hi);
    /* the end labels side by side with a character's gap, or the ramp's least width */
    int need = fv_font_text_width("0", scale) + fv_font_text_width(hi, scale) + 2 * FV_FONT_ADVANCE * scale;
    if (need < MIN_BAR * scale) need = MIN_BAR * scale;
    return ramp_start(scale, label) + need + MARGIN * scale + 1;
}

void fv_colorbar_layout_of(int w, int y0, int scale, float vmax, const char *label, fv_colorbar_layout *out)
{
    (void)vmax;
    out->scale = scale;
    out->x0 = ramp_start(scale, label);
    out->x1 = w - 1 - MARGIN * scale;
    /* an odd number of columns puts a column exactly at vmax / 2, where the middle tick goes */
    if ((out->x1 - out->x0) % 2) out->x1--;
    out->bar_y0 = y0 + BAR_TOP * scale;
    out->bar_y1 = out->bar_y0 + BAR_H * scale - 1;
    out->height = STRIP_H * scale;
}

static void fill(float *rgb, int w, int h, int x0, int y0, int x1, int y1, const float c[3])
{
    for (int y = y0 < 0 ? 0 : y0; y <= y1 && y < h; y++)
        for (int x = x0 < 0 ? 0 : x0; x <= x1 && x < w; x++) {
            float *p = rgb + 3 * ((size_t)y * w + x);
            p[0] = c[0], p[1] = c[1], p[2] = c[2];
        }
}

void fv_colorbar_draw(float *rgb, int w, int h, int y0, int scale, float vmax, const char *label)
{
    const int s = scale;
    fv_colorbar_layout L;
    fv_colorbar_layout_of(w, y0, s, vmax, label, &L);
    const float white[3] = {1.0f, 1.0f, 1.0f}, black[3] = {0.0f, 0.0f, 0.0f};
    const float g = fv_srgb_decode(0.45f), grey[3] = {g, g, g};
    fill(rgb, w, h, 0, y0, w - 1, y0 + L.height - 1, white);
    /* a frame, so that the pale end stands out from the white */
    fill(rgb, w, h, L.x0 - 1, L.bar_y0 - 1, L.x1 + 1, L.bar_y1 + 1, grey);
    for (int x = L.x0; x <= L.x1; x++) {
        float c[3];
        fv_colormap_ramp((float)(x - L.x0) / (float)(L.x1 - L.x0), c);
        for (int k = 0; k < 3; k++) c[k] = fv_srgb_decode(c[k]); /* the PNG writer encodes again */
        fill(rgb, w, h, x, L.bar_y0, x, L.bar_y1, c);
    }
    if (label && *label) fv_font_draw_rgb(rgb, w, h, MARGIN * s, L.bar_y0 + (BAR_H - FV_FONT_H) * s / 2, s, black, label);
    /* ticks and their labels: 0 starts at x0, vmax ends at x1, vmax / 2 is centred on its column */
    /* the ticks hang from the frame's lower edge, a blank row above the labels */
    const int tick_y0 = L.bar_y1 + 1, tick_y1 = L.bar_y1 + TICK_H * s, text_y = y0 + LABEL_TOP * s;
    const int xm = (L.x0 + L.x1) / 2;
    char lo[32], hi[32], mid[32];
    tick_text(0.0f, lo, sizeof lo);
    tick_text(vmax, hi, sizeof hi);
    tick_text(0.5f * vmax, mid, sizeof mid);
    int wl = fv_font_text_width(lo, s), wh = fv_font_text_width(hi, s), wm = fv_font_text_width(mid, s);
    fill(rgb, w, h, L.x0, tick_y0, L.x0 + s - 1, tick_y1, black);
    fill(rgb, w, h, L.x1 - s + 1, tick_y0, L.x1, tick_y1, black);
    fv_font_draw_rgb(rgb, w, h, L.x0, text_y, s, black, lo);
    fv_font_draw_rgb(rgb, w, h, L.x1 - wh + 1, text_y, s, black, hi);
    int mx0 = xm - wm / 2, gap = FV_FONT_ADVANCE * s;
    if (mx0 >= L.x0 + wl + gap && mx0 + wm - 1 <= L.x1 - wh - gap) {
        fill(rgb, w, h, xm - (s - 1) / 2, tick_y0, xm + s / 2, tick_y1, black);
        fv_font_draw_rgb(rgb, w, h, mx0, text_y, s, black, mid);
    }
}
