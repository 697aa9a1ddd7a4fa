/* fovea-view — what is drawn over the render: the eye model's fovea and transition circles and
 * a gaze cursor (key O), and the text lines (method, ms per frame and per stage, counters,
 * gaze). The circles come from the driver's eye model, so they are the regions the technique
 * was given, scaled from film pixels to the panel; their shapes and colours are the library's
 * (gaze/overlay.h), the ones `fovea render --overlay` draws. */
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include "view.h"
#include "gaze/overlay.h"

/* The library's shapes (gaze/overlay.h: the rings and cross `fovea render --overlay` draws), on
 * the panel's pixel grid: the film scaled to the panel, pixels judged one by one inside the box
 * the shapes can reach, clipped to the panel. */
void fv_vw_overlay_gaze(fv_vw_canvas *c, fv_vw_rect panel, const fv_eye_model *m, int film_w, fv_gaze g)
{
    fv_overlay_shape sh;
    fv_overlay_shape_of(m, g, panel.x, panel.y, (double)panel.w / (double)film_w, 1, &sh);
    uint32_t color[FV_MARK_COUNT];
    for (int k = 0; k < FV_MARK_COUNT; k++) {
        uint8_t b[3];
        fv_overlay_color(FV_OVERLAY_ON_IMAGE, (fv_overlay_mark)k, b);
        color[k] = fv_vw_rgb(b[0], b[1], b[2]);
    }
    int x0, y0, x1, y1;
    fv_overlay_bounds(&sh, &x0, &y0, &x1, &y1);
    if (x0 < panel.x) x0 = panel.x;
    if (y0 < panel.y) y0 = panel.y;
    if (x1 > panel.x + panel.w - 1) x1 = panel.x + panel.w - 1;
    if (y1 > panel.y + panel.h - 1) y1 = panel.y + panel.h - 1;
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > c->w - 1) x1 = c->w - 1;
    if (y1 > c->h - 1) y1 = c->h - 1;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            fv_overlay_mark k = fv_overlay_mark_at(&sh, x, y);
            if (k != FV_MARK_NONE) c->px[(size_t)y * c->w + x] = color[k];
        }
}

/* Appends "fmt" to a line, wrapping to the next one when the panel would be too narrow. */
typedef struct text_lines {
    char line[8][256];
    int n, cols;
} text_lines;

static void add(text_lines *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void add(text_lines *t, const char *fmt, ...)
{
    char item[128];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(item, sizeof item, fmt, ap);
    va_end(ap);
    if (t->n == 0) t->n = 1;
    char *l = t->line[t->n - 1];
    size_t len = strlen(l), il = strlen(item);
    if (len > 0 && (int)(len + il) > t->cols && t->n < 8) {
        l = t->line[t->n++];
        len = 0;
    }
    snprintf(l + len, sizeof t->line[0] - len, "%s", item);
}

static void newline(text_lines *t)
{
    if (t->n < 8) t->line[t->n++][0] = '\0';
}

void fv_vw_hud(fv_vw_canvas *c, fv_vw_app *app, const fv_vw_panel *p, int np)
{
    const uint32_t white = fv_vw_rgb(255, 255, 255), green = fv_vw_rgb(140, 255, 140);
    /* per panel: which method (and eye) and what it cost */
    for (int i = 0; i < np; i++) {
        const fv_vw_slot *s = p[i].slot;
        char label[64], line[160];
        fv_vw_slot_param_label(s, label, sizeof label);
        const char *eye = app->args.stereo > 0 ? (p[i].eye ? " right eye" : " left eye") : "";
        snprintf(line, sizeof line, "%s %s%s  %.1f ms", s->method >= 0 ? fv_technique_name(s->method) : "-", label, eye, s->ms);
        if (s->accum_n > 1) snprintf(line + strlen(line), sizeof line - strlen(line), "  accum %d", s->accum_n);
        fv_vw_text(c, p[i].r.x + 4, p[i].r.y + 4, green, line);
    }
    /* bottom: the main technique's frame, and the gaze it was given (the trace's, with --gaze-trace) */
    text_lines t;
    memset(&t, 0, sizeof t);
    t.cols = c->w / FV_VW_CELL_W - 1;
    const fv_stats *st = &app->main.stats;
    add(&t, "%.1f fps  frame %.1f ms  t %.2f s%s%s  gaze %.3f,%.3f", app->frame_ms > 0 ? 1000.0 / app->frame_ms : 0.0, app->frame_ms,
        app->anim_time, app->paused ? " PAUSED" : "", app->rec.gaze ? " REC" : "", app->main.gaze[0].x, app->main.gaze[0].y);
    newline(&t);
    for (int i = 0; i < st->n_stages; i++) add(&t, "%s %.1f  ", st->stage[i].name, st->stage[i].value);
    if (st->n_stages) add(&t, "(ms)");
    newline(&t);
    for (int i = 0; i < st->n_counters; i++) {
        double v = st->counter[i].value;
        if (v >= 1e6) add(&t, "%s %.2fM  ", st->counter[i].name, v / 1e6);
        else if (v >= 1e4) add(&t, "%s %.1fk  ", st->counter[i].name, v / 1e3);
        else add(&t, "%s %.4g  ", st->counter[i].name, v);
    }
    if (app->message[0] && fv_time_ms() < app->message_until) {
        newline(&t);
        add(&t, "%s", app->message);
    }
    int y = c->h - t.n * FV_VW_CELL_H - 3;
    for (int i = 0; i < t.n; i++, y += FV_VW_CELL_H) fv_vw_text(c, 4, y, white, t.line[i]);
}

fv_status fv_vw_screenshot(const fv_vw_canvas *c, const char *path, fv_error *err)
{
    /* the canvas is sRGB bytes; fv_image_write wants linear floats and encodes them again, which
     * gives back the same bytes */
    float lut[256];
    for (int i = 0; i < 256; i++) lut[i] = fv_srgb_decode((float)i / 255.0f);
    size_t n = (size_t)c->w * c->h;
    float *rgb = malloc(n * 3 * sizeof *rgb);
    if (!rgb) return fv_error_set(err, FV_ERR_NOMEM, "screenshot: out of memory");
    for (size_t i = 0; i < n; i++) {
        uint32_t v = c->px[i];
        rgb[3 * i] = lut[(v >> 16) & 255];
        rgb[3 * i + 1] = lut[(v >> 8) & 255];
        rgb[3 * i + 2] = lut[v & 255];
    }
    fv_status s = fv_image_write(path, rgb, c->w, c->h, 1.0f, err);
    free(rgb);
    return s;
}
