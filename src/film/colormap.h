/* fovea — the colour map of error heat maps: one perceptual ramp, and the colour bar that states
 * its scale (film/colormap.c). Library-internal: metrics/heatmap.c draws heat maps with it, and
 * the tests read the bar's layout to find its ends. */
#ifndef FV_FILM_COLORMAP_H
#define FV_FILM_COLORMAP_H

/* The ramp at t in [0,1] (clamped; NaN is 0) as display (sRGB-encoded) values in [0,1]: near
 * black at 0, through purple, red and orange, to pale yellow at 1. */
void fv_colormap_ramp(float t, float srgb[3]);

/* Where a colour bar's parts lie: the ramp runs from column x0 (value 0: the ramp's first colour)
 * to column x1 (vmax: its last colour), both inclusive, over rows bar_y0..bar_y1 inclusive; the
 * strip is `height` rows from the row it starts at. */
typedef struct fv_colorbar_layout {
    int x0, x1, bar_y0, bar_y1, height, scale;
} fv_colorbar_layout;

/* The text's integer magnification for a map map_h rows high (1 up to 539 rows, then one more
 * per 540): the labels stay readable on a large image. */
int fv_colorbar_scale(int map_h);
/* Rows the strip takes at that scale. */
int fv_colorbar_height(int scale);
/* The narrowest image that holds the strip's label, tick labels and a ramp of at least 32 x scale
 * columns; a narrower map is drawn on a canvas this wide (heatmap.c pads its right side). */
int fv_colorbar_min_width(int scale, float vmax, const char *label);
/* The layout in an image w >= fv_colorbar_min_width pixels wide, the strip from row y0. */
void fv_colorbar_layout_of(int w, int y0, int scale, float vmax, const char *label, fv_colorbar_layout *out);
/* Draws the strip into rows y0 .. y0 + height - 1 of a linear RGB float image w x h (what the
 * PNG writer takes at exposure 1): white, with label (the metric's name, may be NULL) left of
 * the ramp, the ramp from 0 to vmax left to right in a grey frame, and tick marks with labels
 * at 0, vmax (and vmax / 2 where it fits) below it. */
void fv_colorbar_draw(float *rgb, int w, int h, int y0, int scale, float vmax, const char *label);

#endif
