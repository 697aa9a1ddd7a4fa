/* fovea — the one bitmap font (5x7 glyphs, ASCII 32..126; characters outside draw as '?'): the
 * viewer's on-screen text and the tick labels of heat-map colour bars. Library-internal. */
#ifndef FV_FILM_FONT_H
#define FV_FILM_FONT_H

#include <stdbool.h>

enum {
    FV_FONT_W = 5,       /* glyph columns */
    FV_FONT_H = 7,       /* glyph rows */
    FV_FONT_ADVANCE = 6  /* columns from one character to the next: one blank column between */
};

/* Whether pixel (gx, gy) of character ch's glyph is lit; false outside the 5x7 cell. */
bool fv_font_lit(int ch, int gx, int gy);
/* Width in pixels that s takes at integer scale (no blank column after the last character). */
int fv_font_text_width(const char *s, int scale);
/* Draws s into a linear RGB float image (w x h, 3 floats per pixel) with its top-left at (x, y),
 * every glyph pixel a scale x scale block of `color`, clipped to the image; returns the advance. */
int fv_font_draw_rgb(float *rgb, int w, int h, int x, int y, int scale, const float color[3], const char *s);

#endif
