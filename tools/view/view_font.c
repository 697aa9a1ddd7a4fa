/* fovea-view — text on the canvas, in the library's 5x7 bitmap font (film/font.h, which the heat
 * maps' colour bars use too). One pixel of dark outline around every lit pixel keeps the text
 * readable over a bright or noisy render at 640x360 without a box. */
#include "view.h"
#include "film/font.h"

static void put(fv_vw_canvas *c, int x, int y, uint32_t color)
{
    if (x >= 0 && y >= 0 && x < c->w && y < c->h) c->px[(size_t)y * c->w + x] = color;
}

int fv_vw_text(fv_vw_canvas *c, int x, int y, uint32_t color, const char *s)
{
    int x0 = x;
    for (; *s; s++, x += FV_VW_CELL_W) {
        int ch = (unsigned char)*s;
        /* outline first: every unlit pixel next to a lit one */
        for (int gy = -1; gy <= FV_FONT_H; gy++)
            for (int gx = -1; gx <= FV_FONT_W; gx++) {
                if (fv_font_lit(ch, gx, gy)) continue;
                bool edge = false;
                for (int dy = -1; dy <= 1 && !edge; dy++)
                    for (int dx = -1; dx <= 1 && !edge; dx++) edge = fv_font_lit(ch, gx + dx, gy + dy);
                if (edge) put(c, x + gx, y + gy, 0xFF000000u);
            }
        for (int gy = 0; gy < FV_FONT_H; gy++)
            for (int gx = 0; gx < FV_FONT_W; gx++)
                if (fv_font_lit(ch, gx, gy)) put(c, x + gx, y + gy, color);
    }
    return x - x0;
}
