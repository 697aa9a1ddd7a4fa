/* fovea — eye-tracker recordings into fovea's gaze trace format (docs/gaze.md, "Importing").
 *
 * EyeLink ASC (the text edf2asc writes): the screen size comes from the DISPLAY_COORDS message
 * ("MSG <t> DISPLAY_COORDS left top right bottom", pixels inclusive), which eyes were recorded from
 * the START or SAMPLES line (LEFT, RIGHT); sample lines are "<ms> <x> <y> <pupil>" per eye, "."
 * for a value the tracker lost. A sample is missing when its x or y is "." or lies off the screen,
 * or while that eye is in a blink (between its SBLINK and EBLINK events).
 *
 * Pupil Labs gaze_positions.csv (Pupil Player's export): columns gaze_timestamp (s), confidence,
 * norm_pos_x and norm_pos_y, found by name in the header; norm_pos has its origin at the bottom
 * left, fovea's at the top left, so y is flipped. A sample whose confidence is below the threshold
 * (0.6 by default, the value Pupil's own tools use) or whose position is off [0,1] is missing.
 *
 * Times are written in seconds from the first sample. Samples whose time does not increase (a
 * Pupil export interleaves the two eyes' gaze) are dropped and counted. The output goes through
 * the atomic writer: on any error no file is left.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "core/fileio.h"
#include "fovea/gaze.h"

void fv_gaze_import_opts_init(fv_gaze_import_opts *o)
{
    memset(o, 0, sizeof *o);
    o->format = FV_GAZE_FORMAT_AUTO;
    o->min_confidence = 0.6;
}

typedef struct writer {
    FILE *f;
    const char *in;
    bool any, binocular;
    long known[2]; /* samples with a known gaze, per eye */
    double t0, prev;
    fv_gaze_import_info *info;
} writer;

/* The next line of the recording (at most FV_LINE_MAX bytes): true for a line; false at the end,
 * on a read error (ferror tells) or with *st set for a line too long. */
static bool next_line(FILE *in, const writer *w, char **line, size_t *cap, int lineno, fv_status *st, fv_error *err)
{
    long n = fv_file_getline(in, line, cap, FV_LINE_MAX);
    if (n == -1) *st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: line longer than %d bytes", w->in, lineno, FV_LINE_MAX);
    else if (n < 0) *st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
    return n > 0;
}

static bool on_screen(double x, double y) { return x >= 0.0 && x <= 1.0 && y >= 0.0 && y <= 1.0; }

/* One sample (time in seconds; an eye is missing when its coordinates are NaN). */
static void put_sample(writer *w, double t, double xl, double yl, double xr, double yr)
{
    /* The time as written (9 digits) must increase too: a jump to 1e19 s would print equal. */
    char tt[40];
    snprintf(tt, sizeof tt, "%.9g", w->any ? t - w->t0 : 0.0);
    double shown = strtod(tt, NULL);
    if (!isfinite(t) || !isfinite(shown) || (w->any && !(shown > w->prev))) {
        w->info->dropped++;
        return;
    }
    if (!w->any) w->t0 = t;
    w->any = true;
    w->prev = shown;
    bool ml = !on_screen(xl, yl), mr = !on_screen(xr, yr);
    w->info->samples++;
    if (ml || (w->binocular && mr)) w->info->missing++;
    fputs(tt, w->f);
    if (ml) fputs(",,", w->f);
    else fprintf(w->f, ",%.6f,%.6f", xl, yl);
    if (w->binocular) {
        if (mr) fputs(",,", w->f);
        else fprintf(w->f, ",%.6f,%.6f", xr, yr);
    }
    fputc('\n', w->f);
    w->known[0] += !ml;
    w->known[1] += w->binocular && !mr;
}

/* ---- EyeLink ASC ---- */

static bool starts_with(const char *s, const char *p) { return strncmp(s, p, strlen(p)) == 0; }

/* A value of a sample line: a number, or "." for one the tracker lost (NaN). */
static bool asc_value(const char **s, double *v)
{
    while (**s == ' ' || **s == '\t') (*s)++;
    if (**s == '.' && !isdigit((unsigned char)(*s)[1])) {
        (*s)++;
        *v = NAN;
        return true;
    }
    char *end;
    *v = strtod(*s, &end);
    if (end == *s) return false;
    *s = end;
    return true;
}

static fv_status import_asc(FILE *in, writer *w, fv_error *err)
{
    char *line = NULL;
    size_t cap = 0;
    double left = 0, top = 0, right = -1, bottom = -1;
    bool has_left = false, has_right = false, sized = false;
    fv_status st = FV_OK;
    int lineno = 0;
    /* First pass: the screen and the eyes. */
    while (next_line(in, w, &line, &cap, ++lineno, &st, err)) {
        const char *d = strstr(line, "DISPLAY_COORDS");
        if (starts_with(line, "MSG") && d && sscanf(d + 14, "%lf %lf %lf %lf", &left, &top, &right, &bottom) == 4) sized = true;
        if (starts_with(line, "START") || starts_with(line, "SAMPLES")) {
            has_left |= strstr(line, "LEFT") != NULL;
            has_right |= strstr(line, "RIGHT") != NULL;
        }
    }
    if (st != FV_OK || ferror(in)) {
        free(line);
        return st != FV_OK ? st : fv_error_set(err, FV_ERR_IO, "cannot read '%s': %s", w->in, strerror(errno));
    }
    if (w->info->width > 0 && w->info->height > 0) {
        left = top = 0;
        right = w->info->width - 1;
        bottom = w->info->height - 1;
        sized = true;
    }
    double sw = right - left + 1, sh = bottom - top + 1;
    if (!sized || !(sw >= 1 && sh >= 1 && sw <= 1e6 && sh <= 1e6)) {
        free(line);
        return fv_error_set(err, FV_ERR_INVALID, "%s: no usable DISPLAY_COORDS message (give the screen size with --screen WxH)", w->in);
    }
    w->info->width = sw;
    w->info->height = sh;
    w->binocular = has_left && has_right;
    w->info->binocular = w->binocular;
    if (fseek(in, 0, SEEK_SET) != 0) {
        free(line);
        return fv_error_set(err, FV_ERR_IO, "cannot read '%s' twice: %s", w->in, strerror(errno));
    }
    /* Second pass: samples, with each eye's blinks. In a monocular recording the one eye's
     * samples come first whichever it is. */
    bool blink[2] = {false, false};
    lineno = 0;
    while (next_line(in, w, &line, &cap, ++lineno, &st, err)) {
        if (!isdigit((unsigned char)line[0])) {
            char eye = 0;
            if (sscanf(line, "SBLINK %c", &eye) == 1 || sscanf(line, "EBLINK %c", &eye) == 1) {
                bool start = line[0] == 'S';
                if (eye == 'L' || (!w->binocular && eye == 'R')) blink[0] = start;
                if (w->binocular && eye == 'R') blink[1] = start;
            }
            continue;
        }
        const char *s = line;
        double t, v[6];
        if (!asc_value(&s, &t)) continue;
        int n = 0, want = w->binocular ? 6 : 3;
        while (n < want && asc_value(&s, &v[n])) n++;
        if (n < want) continue; /* not a sample line we know (a velocity or resolution column layout is still read: extra columns are ignored) */
        double xl = v[0], yl = v[1], xr = NAN, yr = NAN;
        if (w->binocular) xr = v[3], yr = v[4];
        if (blink[0]) xl = yl = NAN;
        if (blink[1]) xr = yr = NAN;
        put_sample(w, t / 1000.0, (xl - left) / sw, (yl - top) / sh, (xr - left) / sw, (yr - top) / sh);
    }
    free(line);
    return st;
}

/* ---- Pupil Labs gaze_positions.csv ---- */

/* Field k (0-based) of a comma-separated line, or NULL; *len gets its length. */
static const char *csv_field(const char *line, int k, size_t *len)
{
    const char *s = line;
    for (int i = 0; i < k; i++) {
        s = strchr(s, ',');
        if (!s) return NULL;
        s++;
    }
    *len = strcspn(s, ",\r\n");
    return s;
}

static bool field_number(const char *line, int k, double *v)
{
    size_t len;
    const char *s = csv_field(line, k, &len);
    if (!s || len == 0 || len > 63) return false;
    char tmp[64];
    memcpy(tmp, s, len);
    tmp[len] = '\0';
    char *end;
    *v = strtod(tmp, &end);
    while (*end == ' ') end++;
    return end != tmp && *end == '\0';
}

static fv_status import_pupil(FILE *in, writer *w, double min_conf, fv_error *err)
{
    char *line = NULL;
    size_t cap = 0;
    int col_t = -1, col_c = -1, col_x = -1, col_y = -1;
    fv_status st = FV_OK;
    if (next_line(in, w, &line, &cap, 1, &st, err)) {
        for (int k = 0;; k++) {
            size_t len;
            const char *f = csv_field(line, k, &len);
            if (!f) break;
            while (len && (f[len - 1] == ' ' || f[len - 1] == '\r')) len--;
            if (len == 14 && !strncmp(f, "gaze_timestamp", 14)) col_t = k;
            else if (len == 10 && !strncmp(f, "confidence", 10)) col_c = k;
            else if (len == 10 && !strncmp(f, "norm_pos_x", 10)) col_x = k;
            else if (len == 10 && !strncmp(f, "norm_pos_y", 10)) col_y = k;
        }
    }
    if (st != FV_OK) {
        free(line);
        return st;
    }
    if (col_t < 0 || col_c < 0 || col_x < 0 || col_y < 0) {
        free(line);
        return fv_error_set(err, FV_ERR_INVALID, "%s: the header lacks gaze_timestamp, confidence, norm_pos_x or norm_pos_y (is it Pupil's gaze_positions.csv?)",
                            w->in);
    }
    w->binocular = false;
    int lineno = 1;
    while (st == FV_OK && next_line(in, w, &line, &cap, lineno + 1, &st, err)) {
        lineno++;
        if (line[strspn(line, " \t\r\n")] == '\0') continue;
        double t, c, x, y;
        if (!field_number(line, col_t, &t) || !field_number(line, col_c, &c)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected numbers in gaze_timestamp and confidence", w->in, lineno);
            break;
        }
        if (!field_number(line, col_x, &x) || !field_number(line, col_y, &y) || !(c >= min_conf)) x = y = NAN;
        put_sample(w, t, x, 1.0 - y, NAN, NAN);
    }
    free(line);
    return st;
}

static fv_gaze_format guess_format(const char *path)
{
    const char *dot = strrchr(path, '.');
    if (dot && strcasecmp(dot, ".asc") == 0) return FV_GAZE_FORMAT_EYELINK_ASC;
    if (dot && strcasecmp(dot, ".csv") == 0) return FV_GAZE_FORMAT_PUPIL_CSV;
    return FV_GAZE_FORMAT_AUTO;
}

fv_status fv_gaze_import(const char *in_path, const char *out_path, const fv_gaze_import_opts *opts, fv_gaze_import_info *info,
                         fv_error *err)
{
    fv_gaze_import_opts def;
    if (!opts) fv_gaze_import_opts_init(&def), opts = &def;
    fv_gaze_import_info local;
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    info->width = opts->width;
    info->height = opts->height;
    fv_gaze_format fmt = opts->format != FV_GAZE_FORMAT_AUTO ? opts->format : guess_format(in_path);
    if (!(opts->min_confidence >= 0.0 && opts->min_confidence <= 1.0))
        return fv_error_set(err, FV_ERR_INVALID, "gaze import: confidence threshold %g is outside [0, 1]", opts->min_confidence);
    /* A regular file only, whatever its name (core/fileio.h: /dev/zero reads forever). */
    FILE *in;
    fv_status st = fv_file_open_read(in_path, "recording", &in, err);
    if (st != FV_OK) return st;
    if (fmt != FV_GAZE_FORMAT_EYELINK_ASC && fmt != FV_GAZE_FORMAT_PUPIL_CSV) {
        fclose(in);
        return fv_error_set(err, FV_ERR_INVALID, "%s: unknown recording format (an EyeLink .asc or Pupil Labs gaze_positions .csv)", in_path);
    }
    fv_atomic_file af;
    FILE *out = NULL;
    st = fv_atomic_file_begin(out_path, &af, err);
    if (st != FV_OK) {
        fclose(in);
        return st;
    }
    if ((st = fv_atomic_file_stream(&af, &out, err)) != FV_OK) {
        fv_atomic_file_abort(&af);
        fclose(in);
        return st;
    }
    info->format = fmt;
    writer w = {out, in_path, false, false, {0, 0}, 0, 0, info};
    fprintf(out, "# gaze trace imported from %s by fovea gaze import (docs/gaze.md)\n", in_path);
    st = fmt == FV_GAZE_FORMAT_EYELINK_ASC ? import_asc(in, &w, err) : import_pupil(in, &w, opts->min_confidence, err);
    if (st == FV_OK && ferror(in)) st = fv_error_set(err, FV_ERR_IO, "cannot read '%s': %s", in_path, strerror(errno));
    fclose(in);
    /* A trace needs one known sample per eye (fv_gaze_path_load_csv). */
    if (st == FV_OK && (w.known[0] == 0 || (w.binocular && w.known[1] == 0)))
        st = fv_error_set(err, FV_ERR_INVALID, "%s: no usable gaze sample%s (%ld samples, all missing)", in_path,
                          w.binocular ? (w.known[0] ? " of the right eye" : " of the left eye") : "", info->samples);
    if (st != FV_OK) {
        fv_atomic_file_abort(&af);
        return st;
    }
    return fv_atomic_file_commit(&af, err);
}
