/* fovea CLI — the progress line (see cli.h): `fovea render`'s bar, and `fovea bench`'s within each
 * of its steps. What is shown, and when, is decided by two pure functions (fv_cli_progress_due,
 * fv_cli_progress_format) so that tests/unit/test_cli_progress.c can check them with made-up
 * clocks; the rest only reads the clock and writes stderr. */
#include <stdio.h>
#include <string.h>
#include <unistd.h>
#include "cli.h"

/* A terminal's line is redrawn at least this often while its percentage stands still, so the
 * elapsed time and the ETA keep moving. */
#define REDRAW_MS 1000.0
#define BAR_WIDTH 30

void fv_cli_duration(double seconds, char *buf, size_t n)
{
    if (!(seconds >= 0.0)) seconds = 0.0;
    if (seconds > 3.6e8) seconds = 3.6e8; /* 100000 h: an early ETA's nonsense stays short */
    long s = (long)(seconds + 0.5);
    if (s < 60) snprintf(buf, n, "%lds", s);
    else if (s < 3600) snprintf(buf, n, "%ldm%02lds", s / 60, s % 60);
    else snprintf(buf, n, "%ldh%02ldm", s / 3600, s % 3600 / 60);
}

static void reset(fv_cli_progress *p, int frames)
{
    p->t0 = p->last_ms = fv_time_ms();
    p->frame = 0;
    p->frames = frames > 0 ? frames : 1;
    p->last_percent = -1;
}

void fv_cli_progress_init(fv_cli_progress *p, bool quiet, int frames)
{
    memset(p, 0, sizeof *p);
    p->tty = isatty(STDERR_FILENO);
    p->enabled = !quiet && p->tty;
    p->every_ms = -1.0;
    reset(p, frames);
}

void fv_cli_progress_init_steps(fv_cli_progress *p, bool quiet, double every_s)
{
    fv_cli_progress_init(p, quiet, 1);
    p->every_ms = every_s >= 0.0 ? every_s * 1000.0 : -1.0;
    p->enabled = !quiet && (p->tty || p->every_ms >= 0.0);
}

void fv_cli_progress_step(fv_cli_progress *p, const char *label, int frames)
{
    fv_cli_progress_done(p);
    snprintf(p->label, sizeof p->label, "%s", label ? label : "");
    reset(p, frames);
}

bool fv_cli_progress_due(const fv_cli_progress *p, int percent, double now_ms)
{
    if (!p->enabled) return false;
    if (p->tty) return percent != p->last_percent || now_ms - p->last_ms >= REDRAW_MS;
    /* a log: a line only for news, and no sooner than every_ms after the step began or after the
     * last line, so a step shorter than that adds nothing to it */
    return p->every_ms >= 0.0 && percent != p->last_percent && now_ms - p->last_ms >= p->every_ms;
}

int fv_cli_progress_format(const fv_cli_progress *p, double total, double now_ms, char *buf, size_t n)
{
    if (total < 0.0) total = 0.0;
    if (total > 1.0) total = 1.0;
    const int percent = (int)(total * 100.0);
    const double el = (now_ms - p->t0) / 1000.0;
    char els[32], etas[48] = "";
    fv_cli_duration(el, els, sizeof els);
    /* an ETA once there is something to extrapolate from: a thousandth of the work, some time */
    if (total >= 0.001 && total < 1.0 && el > 0.0) {
        char d[32];
        fv_cli_duration(el * (1.0 - total) / total, d, sizeof d);
        snprintf(etas, sizeof etas, ", ETA %s", d);
    }
    /* the frame under way (the last one once all are done) */
    const int frame = p->frame + 1 < p->frames ? p->frame + 1 : p->frames;
    if (!p->tty)
        return snprintf(buf, n, "%s%s%d%%, frame %d/%d, %s elapsed%s\n", p->label, p->label[0] ? ": " : "", percent, frame, p->frames, els,
                        etas);
    char bar[BAR_WIDTH + 1];
    const int filled = (int)(total * BAR_WIDTH);
    for (int i = 0; i < BAR_WIDTH; i++) bar[i] = i < filled ? '#' : '.';
    bar[BAR_WIDTH] = '\0';
    return snprintf(buf, n, "\r[%s] %3d%%  frame %d/%d  %s elapsed%s ", bar, percent, frame, p->frames, els, etas);
}

bool fv_cli_progress_frame(void *user, double fraction)
{
    fv_cli_progress *p = user;
    if (fv_cli_interrupted()) return false;
    if (!p->enabled) return true;
    double total = (p->frame + fraction) / p->frames;
    int percent = (int)((total < 0.0 ? 0.0 : total > 1.0 ? 1.0 : total) * 100.0);
    double now = fv_time_ms();
    if (!fv_cli_progress_due(p, percent, now)) return true;
    char line[sizeof p->label + 160];
    int len = fv_cli_progress_format(p, total, now, line, sizeof line);
    if (len <= 0) return true;
    /* a line shorter than the one it replaces leaves no tail of it behind */
    if (p->tty && len < p->shown) fprintf(stderr, "%s%*s", line, p->shown - len, "");
    else fputs(line, stderr);
    fflush(stderr);
    if (p->tty && len > p->shown) p->shown = len;
    p->last_percent = percent;
    p->last_ms = now;
    return true;
}

void fv_cli_progress_done(fv_cli_progress *p)
{
    if (p->tty && p->shown > 0) {
        fprintf(stderr, "\r%*s\r", p->shown, "");
        fflush(stderr);
    }
    p->shown = 0;
}
