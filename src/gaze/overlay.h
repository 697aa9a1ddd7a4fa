/* fovea — the eye model drawn over an image: a ring at the foveal radius r_f, one at the
 * transition radius r_t around the gaze, and a cross at the gaze point (gaze/overlay.c). The
 * shapes are computed here once; `fovea render --overlay` and heat maps draw them into float
 * images (fv_overlay_draw_rgb), the viewer into its canvas (one pixel at a time through
 * fv_overlay_mark_at). Library-internal. */
#ifndef FV_GAZE_OVERLAY_H
#define FV_GAZE_OVERLAY_H

#include <stdint.h>
#include "fovea/gaze.h"

typedef enum fv_overlay_mark { FV_MARK_NONE = 0, FV_MARK_TRANSITION, FV_MARK_FOVEA, FV_MARK_GAZE, FV_MARK_COUNT } fv_overlay_mark;

/* Colours of the marks (sRGB bytes). ON_IMAGE over a render (the viewer's too): magenta fovea,
 * cyan transition, yellow gaze. ON_HEATMAP over the error ramp (film/colormap.h), which has no
 * green or cyan: cyan fovea and gaze, green transition, so no mark reads as an error value. */
typedef enum fv_overlay_palette { FV_OVERLAY_ON_IMAGE = 0, FV_OVERLAY_ON_HEATMAP } fv_overlay_palette;
void fv_overlay_color(fv_overlay_palette p, fv_overlay_mark m, uint8_t out[3]);

/* The shapes on a target's pixel grid: centre and radii in target pixels, and the line width. */
typedef struct fv_overlay_shape {
    double cx, cy, r_fovea, r_transition;
    int line;
} fv_overlay_shape;

/* The line width for an image of this size: 1 pixel up to 539 rows (then one more per 540), so
 * the rings stay visible on a large image. */
int fv_overlay_line_width(int width, int height);
/* Eye model m with gaze g drawn on a target where the film's (0,0) is at (ox, oy) and one film
 * pixel is `scale` target pixels (1: the image itself), lines `line` pixels wide. */
void fv_overlay_shape_of(const fv_eye_model *m, fv_gaze g, double ox, double oy, double scale, int line, fv_overlay_shape *out);
/* The mark of target pixel (x, y), judged at its centre: the gaze cross (four arms along the row
 * and column of the pixel holding the gaze point, from 2 x line to 6 x line pixels away, so the
 * gaze pixel itself stays visible), else the fovea ring (the centre within `line` pixels of r_f),
 * else the transition ring (within `line` of r_t), else none. */
fv_overlay_mark fv_overlay_mark_at(const fv_overlay_shape *s, int x, int y);
/* The pixels outside which no pixel is marked: x0..x1, y0..y1 inclusive (may exceed a target). */
void fv_overlay_bounds(const fv_overlay_shape *s, int *x0, int *y0, int *x1, int *y1);

/* Draws eye model m's rings and gaze cross for gaze g into a linear RGB float image `stride`
 * pixels wide whose top-left m->width x m->height pixels are the film (nothing is drawn outside
 * them: a heat map's colour bar below stays clean), in palette p, as values that a PNG written at
 * `exposure` shows as the palette's exact bytes. */
void fv_overlay_draw_rgb(float *rgb, int stride, const fv_eye_model *m, fv_gaze g, fv_overlay_palette p, float exposure);

#endif
