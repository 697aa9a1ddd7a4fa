/* fovea — delimited tables of gaze samples into fovea's gaze trace (docs/gaze.md, "Other tables"
 * and "Tobii Pro Lab").
 *
 * A generic table (FV_GAZE_FORMAT_TABLE): CSV, TSV or semicolon-separated, one sample per row,
 * read under a column mapping the user gives (fv_gaze_table_opts): a time column, and x/y of one
 * gaze or of each eye, in normalised units or pixels of a given screen, with the origin at the top
 * left or the bottom left, and optionally a validity column. The delimiter is the header line's:
 * a tab if it has one, else a semicolon if it has one, else a comma (a semicolon file is what a
 * spreadsheet in a decimal-comma locale writes, so in a file not delimited by commas a number
 * "0,25" is read as 0.25). Columns are found by header text (exact, any case) or by 1-based number.
 *
 * Tobii Pro Lab's data export (FV_GAZE_FORMAT_TOBII) is the same reader with Tobii's columns
 * found by name: "Recording timestamp" (microseconds unless its header brackets another unit:
 * "Recording timestamp [ms]"), "Gaze point X/Y" (Tobii's own combination of the two eyes, in
 * pixels of "Recording resolution width/height"), "Gaze point left X" ... per eye, and "Validity
 * left/right" ("Valid"/"Invalid"). A Pro Lab export interleaves rows that carry no eye-tracker
 * data with the samples: events (the "Event" field names one) and, in a Glasses recording, other
 * sensors ("Sensor" not "Eye Tracker"). A row with no gaze and no validity that is one of those is
 * skipped; any other row without a valid gaze (the tracker marked it invalid, or left it empty) is
 * a missing sample, so a blink is never interpolated across. Other columns (eye movement type,
 * pupil diameter, AOI hits, ...) are ignored.
 *
 * Rows must come in time order: a row earlier than the one before it is refused (naming its
 * line), not sorted, since in a table of one row per moment that means a wrong time column or
 * recordings pasted together, which a sort would hide. A row at the same time as the last one is
 * dropped and counted, as in the other readers (the writer, gaze_import.c).
 *
 * Limits: one line per row (a quoted field may hold the delimiter, not a line break); lines of at
 * most FV_LINE_MAX bytes.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "core/alloc.h"
#include "core/fileio.h"
#include "gaze/import.h"

/* The gazes a row can carry: one (for both eyes), the left eye's, the right eye's. */
enum { G_ONE = 0, G_LEFT = 1, G_RIGHT = 2, G_COUNT = 3 };

typedef struct table {
    fv_gaze_writer *w;
    char delim;
    bool header;
    int ncols;    /* the header's fields (or the first row's) */
    char **names; /* the header's fields (NULL without one) */
    int time;
    int x[G_COUNT], y[G_COUNT]; /* -1: the mapping has no such gaze */
    bool px[G_COUNT];           /* in pixels (else normalised) */
    int valid;                  /* a row's validity (-1: none) */
    int valid_eye[2];           /* Tobii: each eye's validity, left and right (-1: none) */
    int res_w, res_h;           /* Tobii: the recording resolution (-1: none) */
    int event, sensor;          /* Tobii: what a row without gaze is (-1: none) */
    double scale;               /* seconds per unit of time */
    /* The first row's time, which the others are taken relative to before scaling: an integer
     * time (a count of ns or µs since an epoch, some 1.7e18 ns) is subtracted as an integer, as a
     * double holds such a count only to a few hundred ns. */
    bool have_origin, origin_is_int;
    long long origin_i;
    double origin_d;
    bool bottom_left;
    bool tobii;
} table;

static void names_free(char **names, int n)
{
    if (!names) return;
    for (int k = 0; k < n; k++) free(names[k]);
    free(names);
}

static const char *field(const fv_gaze_fields *fs, int k) { return k >= 0 && k < fs->n ? fs->f[k] : ""; }

/* A column's name in a message: its header text, or its number. */
static const char *col_name(const table *t, int k, char *buf, size_t n)
{
    if (t->names && k >= 0 && k < t->ncols) snprintf(buf, n, "'%s'", t->names[k]);
    else snprintf(buf, n, "%d", k + 1);
    return buf;
}

/* A number, or in a file not delimited by commas, a number with a decimal comma ("0,25"). */
static bool number(const table *t, const char *s, double *v)
{
    size_t len = strlen(s);
    if (fv_gaze_field_number(s, len, v)) return true;
    const char *c = strchr(s, ',');
    if (t->delim == ',' || !c || strchr(c + 1, ',') || strchr(s, '.') || len > 63) return false;
    char tmp[64];
    memcpy(tmp, s, len + 1);
    tmp[c - s] = '.';
    return fv_gaze_field_number(tmp, len, v);
}

/* A whole number that a long long holds (a sign, digits, nothing else): *v gets it. */
static bool integer(const char *s, long long *v)
{
    const char *d = *s == '-' || *s == '+' ? s + 1 : s;
    size_t n = strspn(d, "0123456789");
    if (n == 0 || n > 19 || d[n] != '\0') return false;
    errno = 0;
    *v = strtoll(s, NULL, 10);
    return errno == 0;
}

/* A row's time relative to the first row's, in the table's unit (t->origin*: set by the first). */
static bool row_time(table *t, const char *s, double *v)
{
    long long i = 0;
    const bool is_int = integer(s, &i);
    double d = 0.0;
    if (!is_int && !number(t, s, &d)) return false;
    if (!is_int && !isfinite(d)) {
        *v = d; /* dropped by the caller; not an origin */
        return true;
    }
    if (!t->have_origin) {
        t->have_origin = true;
        t->origin_is_int = is_int;
        t->origin_i = i;
        t->origin_d = d;
    }
    long long diff;
    if (is_int && t->origin_is_int && !__builtin_sub_overflow(i, t->origin_i, &diff)) *v = (double)diff;
    else *v = (is_int ? (double)i : d) - (t->origin_is_int ? (double)t->origin_i : t->origin_d);
    return true;
}

/* A coordinate: a number, NaN for a missing marker (empty, nan, -, .), false for anything else. */
static bool coordinate(const table *t, const char *s, double *v)
{
    if (!*s || !strcasecmp(s, "nan") || !strcmp(s, "-") || !strcmp(s, ".")) {
        *v = NAN;
        return true;
    }
    return number(t, s, v);
}

/* A validity field that says the sample is good. */
static bool truthy(const char *s) { return !strcmp(s, "1") || !strcasecmp(s, "true") || !strcasecmp(s, "valid") || !strcasecmp(s, "yes"); }

static bool all_digits(const char *s)
{
    size_t n = strspn(s, "0123456789");
    return n > 0 && n <= 9 && s[n] == '\0';
}

/* The column a mapping option names (opt: the option, for messages). */
static fv_status resolve(const table *t, const char *spec, const char *opt, int *col, fv_error *err)
{
    for (int k = 0; t->names && k < t->ncols; k++)
        if (!strcasecmp(t->names[k], spec)) {
            *col = k;
            return FV_OK;
        }
    if (all_digits(spec)) {
        long n = strtol(spec, NULL, 10);
        if (n >= 1 && n <= t->ncols) {
            *col = (int)n - 1;
            return FV_OK;
        }
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s %s: the %s has %d column%s", t->w->in, opt, spec, t->header ? "header" : "first row",
                            t->ncols, t->ncols == 1 ? "" : "s");
    }
    if (!t->names)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s %s: the file has no header line, so its columns are named by number (1 to %d)", t->w->in,
                            opt, spec, t->ncols);
    /* The header's columns, as many as the message holds. */
    char list[320];
    size_t used = 0;
    list[0] = '\0';
    for (int k = 0; k < t->ncols; k++) {
        int n = snprintf(list + used, sizeof list - used, "%s'%s'", k ? ", " : "", t->names[k]);
        if (n < 0 || (size_t)n >= sizeof list - used - 6) {
            memcpy(list + used, ", ...", 6); /* room kept for it */
            break;
        }
        used += (size_t)n;
    }
    /* A first line of numbers is a row, not a header: the file has none. */
    bool numbers = true;
    double v;
    for (int k = 0; k < t->ncols; k++) numbers = numbers && (!t->names[k][0] || fv_gaze_field_number(t->names[k], strlen(t->names[k]), &v));
    if (numbers)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s %s: the file has no header line, so its columns are named by number (1 to %d)", t->w->in, opt,
                            spec, t->ncols);
    return fv_error_set(err, FV_ERR_INVALID, "%s: %s %s: no such column; the header has %s", t->w->in, opt, spec, list);
}

/* Tobii: the column whose header is name, alone or followed by a bracketed unit ("Recording
 * timestamp [μs]"); *unit gets the bracket's text (empty when none). Where an export has the
 * same gaze in two units, pixels are taken before normalised units (MCS norm). */
static int tobii_col(const table *t, const char *name, char *unit, size_t unit_n)
{
    int best = -1;
    bool best_norm = false;
    size_t n = strlen(name);
    for (int k = 0; k < t->ncols; k++) {
        const char *h = t->names[k];
        if (strncasecmp(h, name, n) != 0) continue;
        const char *r = h + n;
        while (*r == ' ') r++;
        const char *close = *r == '[' ? strchr(r, ']') : NULL;
        if (*r && !(close && close[1 + strspn(close + 1, " ")] == '\0')) continue;
        bool norm = *r && strstr(r, "norm");
        if (best < 0 || (best_norm && !norm)) {
            best = k, best_norm = norm;
            if (unit) {
                size_t u = *r ? (size_t)(close - r - 1) : 0;
                if (u >= unit_n) u = unit_n - 1;
                memcpy(unit, r + (*r ? 1 : 0), u);
                unit[u] = '\0';
            }
        }
    }
    return best;
}

/* Seconds per unit of a bracketed time unit, or 0 for one not known. */
static double unit_scale(const char *u)
{
    while (*u == ' ') u++;
    size_t n = strlen(u);
    while (n && u[n - 1] == ' ') n--;
    if ((n == 3 && (!strncmp(u, "\xCE\xBCs", 3) || !strncmp(u, "\xC2\xB5s", 3))) || (n == 2 && !strncasecmp(u, "us", 2))) return 1e-6;
    if (n == 2 && !strncasecmp(u, "ms", 2)) return 1e-3;
    if (n == 2 && !strncasecmp(u, "ns", 2)) return 1e-9;
    if (n == 1 && (u[0] == 's' || u[0] == 'S')) return 1.0;
    return 0.0;
}

/* Tobii: the columns, found by name, and the eye choice. */
static fv_status map_tobii(table *t, const fv_gaze_import_opts *o, fv_error *err)
{
    const char *in = t->w->in;
    char unit[64], ux[64];
    t->time = tobii_col(t, "Recording timestamp", unit, sizeof unit);
    if (t->time < 0)
        return fv_error_set(err, FV_ERR_INVALID, "%s: no 'Recording timestamp' column (is it a Tobii Pro Lab data export?)", in);
    if (o->table.time_unit > 0) t->scale = o->table.time_unit;
    else if (!unit[0]) t->scale = 1e-6; /* Pro Lab's default */
    else if (!(t->scale = unit_scale(unit)))
        return fv_error_set(err, FV_ERR_INVALID, "%s: the header gives the recording timestamp in [%s], a unit fovea does not know (give --time-unit)",
                            in, unit);
    static const char *const xs[G_COUNT] = {"Gaze point X", "Gaze point left X", "Gaze point right X"};
    static const char *const ys[G_COUNT] = {"Gaze point Y", "Gaze point left Y", "Gaze point right Y"};
    for (int g = 0; g < G_COUNT; g++) {
        ux[0] = '\0';
        t->x[g] = tobii_col(t, xs[g], ux, sizeof ux);
        t->y[g] = tobii_col(t, ys[g], NULL, 0);
        t->px[g] = !strstr(ux, "norm");
        if (t->x[g] < 0 || t->y[g] < 0) t->x[g] = t->y[g] = -1;
    }
    t->valid_eye[0] = tobii_col(t, "Validity left", NULL, 0);
    t->valid_eye[1] = tobii_col(t, "Validity right", NULL, 0);
    t->res_w = tobii_col(t, "Recording resolution width", NULL, 0);
    t->res_h = tobii_col(t, "Recording resolution height", NULL, 0);
    t->event = tobii_col(t, "Event", NULL, 0);
    t->sensor = tobii_col(t, "Sensor", NULL, 0);
    bool eyes = t->x[G_LEFT] >= 0 || t->x[G_RIGHT] >= 0;
    fv_gaze_eyes want = o->eyes;
    if ((want == FV_GAZE_EYES_DEFAULT || want == FV_GAZE_EYES_BOTH) && t->x[G_ONE] >= 0) {
        /* Tobii's own gaze point: the eyes combined as Pro Lab's gaze filter combines them. */
        t->x[G_LEFT] = t->y[G_LEFT] = t->x[G_RIGHT] = t->y[G_RIGHT] = -1;
        t->w->eyes = FV_GAZE_EYES_BOTH;
        return FV_OK;
    }
    if (!eyes) {
        if (t->x[G_ONE] < 0)
            return fv_error_set(err, FV_ERR_INVALID, "%s: no 'Gaze point X'/'Gaze point Y' columns, nor per eye (is it a Tobii Pro Lab data export?)",
                                in);
        return fv_error_set(err, FV_ERR_INVALID, "%s: --eye %s needs the per-eye columns ('Gaze point left X' ...), which the export lacks", in,
                            want == FV_GAZE_EYES_LEFT ? "left" : want == FV_GAZE_EYES_RIGHT ? "right" : "each");
    }
    t->x[G_ONE] = t->y[G_ONE] = -1;
    return FV_OK;
}

/* A generic table: the user's mapping, checked. */
static fv_status map_table(table *t, const fv_gaze_import_opts *o, fv_error *err)
{
    const fv_gaze_table_opts *m = &o->table;
    const char *in = t->w->in;
    if (!m->time) return fv_error_set(err, FV_ERR_INVALID, "%s: a table needs its time column (--time COL)", in);
    const char *xs[G_COUNT] = {m->x, m->left_x, m->right_x}, *ys[G_COUNT] = {m->y, m->left_y, m->right_y};
    static const char *const xo[G_COUNT] = {"--x", "--left-x", "--right-x"}, *const yo[G_COUNT] = {"--y", "--left-y", "--right-y"};
    for (int g = 0; g < G_COUNT; g++)
        if (!xs[g] != !ys[g]) return fv_error_set(err, FV_ERR_INVALID, "%s: %s needs %s", in, xs[g] ? xo[g] : yo[g], xs[g] ? yo[g] : xo[g]);
    if (!m->x && !m->left_x && !m->right_x)
        return fv_error_set(err, FV_ERR_INVALID, "%s: a table needs its gaze columns (--x COL --y COL, or --left-x/--left-y and --right-x/--right-y)",
                            in);
    if (m->x && (m->left_x || m->right_x))
        return fv_error_set(err, FV_ERR_INVALID, "%s: --x/--y give one gaze: not with the per-eye columns (--left-x ...)", in);
    if (!m->pixels && (o->width > 0 || o->height > 0))
        return fv_error_set(err, FV_ERR_INVALID, "%s: --screen is for a table in pixels (--coords px); this one is normalised (--coords norm)", in);
    if (m->pixels && !(o->width > 0 && o->height > 0))
        return fv_error_set(err, FV_ERR_INVALID, "%s: --coords px needs the screen the pixels are of (--screen WxH)", in);
    fv_status st = resolve(t, m->time, "--time", &t->time, err);
    for (int g = 0; g < G_COUNT && st == FV_OK; g++) {
        t->x[g] = t->y[g] = -1;
        t->px[g] = m->pixels;
        if (xs[g] && (st = resolve(t, xs[g], xo[g], &t->x[g], err)) == FV_OK) st = resolve(t, ys[g], yo[g], &t->y[g], err);
    }
    if (st == FV_OK && m->valid) st = resolve(t, m->valid, "--valid", &t->valid, err);
    if (st != FV_OK) return st;
    /* Two options naming one column is a slip (x twice for y, the time as a coordinate). */
    const int cols[8] = {t->time, t->x[0], t->y[0], t->x[1], t->y[1], t->x[2], t->y[2], t->valid};
    static const char *const opts[8] = {"--time", "--x", "--y", "--left-x", "--left-y", "--right-x", "--right-y", "--valid"};
    for (int a = 0; a < 8; a++)
        for (int b = a + 1; b < 8; b++)
            if (cols[a] >= 0 && cols[a] == cols[b]) {
                char nb[300];
                return fv_error_set(err, FV_ERR_INVALID, "%s: %s and %s both name column %s", in, opts[a], opts[b], col_name(t, cols[a], nb, sizeof nb));
            }
    t->scale = m->time_unit > 0 ? m->time_unit : 1.0;
    t->bottom_left = m->bottom_left;
    /* The eye choice: one gaze serves both eyes; per-eye columns as for EyeLink (default each). */
    fv_gaze_eyes want = o->eyes;
    if (m->x) {
        if (want != FV_GAZE_EYES_DEFAULT && want != FV_GAZE_EYES_BOTH)
            return fv_error_set(err, FV_ERR_INVALID, "%s: --x/--y give one gaze; --eye %s needs per-eye columns (--left-x ... --right-y)", in,
                                want == FV_GAZE_EYES_LEFT ? "left" : want == FV_GAZE_EYES_RIGHT ? "right" : "each");
        t->w->eyes = FV_GAZE_EYES_BOTH;
    }
    return FV_OK;
}

/* Per-eye columns: which eyes the mapping has, and the choice (shared by table and Tobii). */
static fv_status choose_eyes(table *t, fv_gaze_eyes want, fv_error *err)
{
    if (t->x[G_ONE] >= 0) return FV_OK;
    int have = (t->x[G_LEFT] >= 0) | (t->x[G_RIGHT] >= 0) << 1;
    if ((want == FV_GAZE_EYES_LEFT && !(have & 1)) || (want == FV_GAZE_EYES_RIGHT && !(have & 2)))
        return fv_error_set(err, FV_ERR_INVALID, "%s: no %s-eye columns (the %s eye's alone)", t->w->in, want == FV_GAZE_EYES_LEFT ? "left" : "right",
                            want == FV_GAZE_EYES_LEFT ? "right" : "left");
    if (have != 3) t->w->eyes = have == 1 ? FV_GAZE_EYES_LEFT : FV_GAZE_EYES_RIGHT;
    else if (want == FV_GAZE_EYES_DEFAULT) t->w->eyes = t->tobii ? FV_GAZE_EYES_BOTH : FV_GAZE_EYES_EACH;
    else t->w->eyes = want;
    t->w->binocular = t->w->eyes == FV_GAZE_EYES_EACH;
    return FV_OK;
}

/* The delimiter of a header line: a tab, else a semicolon, else a comma (outside quotes). */
static char detect_delim(const char *s)
{
    bool quoted = false, semi = false;
    for (; *s; s++) {
        if (*s == '"') quoted = !quoted;
        else if (!quoted && *s == '\t') return '\t';
        else if (!quoted && *s == ';') semi = true;
    }
    return semi ? ';' : ',';
}

/* One row: a sample emitted, or a Tobii row without eye-tracker data skipped. */
static fv_status row(table *t, const fv_gaze_fields *fs, const fv_gaze_import_opts *o, int lineno, double *prev, bool *any, fv_error *err)
{
    fv_gaze_writer *w = t->w;
    char nb[300];
    if (t->tobii) {
        /* No gaze and no validity, and the row says it is something else (an event, another
         * sensor): not a sample. An empty row that says nothing is a sample the tracker lost. */
        bool empty = true;
        for (int g = 0; g < G_COUNT; g++)
            if (t->x[g] >= 0) empty = empty && !*field(fs, t->x[g]) && !*field(fs, t->y[g]);
        for (int e = 0; e < 2; e++) empty = empty && !*field(fs, t->valid_eye[e]);
        const char *sensor = field(fs, t->sensor);
        if (empty && (*field(fs, t->event) || (*sensor && strcasecmp(sensor, "Eye Tracker") != 0))) {
            w->info->skipped++;
            return FV_OK;
        }
    }
    double tm;
    const char *ft = field(fs, t->time);
    if (!row_time(t, ft, &tm))
        return fv_error_set(err, FV_ERR_INVALID, "%s:%d: column %s (the time): '%s' is not a number", w->in, lineno, col_name(t, t->time, nb, sizeof nb),
                            ft);
    if (!isfinite(tm)) {
        w->info->dropped++;
        return FV_OK;
    }
    tm *= t->scale;
    if (*any && tm < *prev)
        return fv_error_set(err, FV_ERR_INVALID, "%s:%d: time %.9g s is before the previous row's %.9g s (rows must be in time order)", w->in, lineno,
                            tm, *prev);
    *any = true;
    *prev = tm;
    double v[G_COUNT][2];
    for (int g = 0; g < G_COUNT; g++) {
        v[g][0] = v[g][1] = NAN;
        if (t->x[g] < 0) continue;
        for (int c = 0; c < 2; c++) {
            int k = c ? t->y[g] : t->x[g];
            const char *s = field(fs, k);
            if (!coordinate(t, s, &v[g][c]))
                return fv_error_set(err, FV_ERR_INVALID, "%s:%d: column %s: '%s' is not a number (nor empty, nan, - or . for a missing sample)", w->in,
                                    lineno, col_name(t, k, nb, sizeof nb), s);
        }
        if (t->px[g]) {
            double sw = o->width, sh = o->height, rw, rh;
            if (t->res_w >= 0 && t->res_h >= 0 && number(t, field(fs, t->res_w), &rw) && number(t, field(fs, t->res_h), &rh) && rw >= 1 && rh >= 1 &&
                rw <= 1e6 && rh <= 1e6)
                sw = rw, sh = rh;
            if (!(sw > 0 && sh > 0))
                return fv_error_set(err, FV_ERR_INVALID, "%s:%d: gaze in pixels, and no recording resolution in the row (give the screen with --screen WxH)",
                                    w->in, lineno);
            w->info->width = sw;
            w->info->height = sh;
            v[g][0] /= sw;
            v[g][1] /= sh;
        }
        if (t->bottom_left) v[g][1] = 1.0 - v[g][1];
    }
    /* Validity: the row's (a table's --valid), or each eye's (Tobii); Tobii's combined gaze is
     * missing when no eye is valid. */
    bool ok = t->valid < 0 || truthy(field(fs, t->valid));
    bool okl = t->valid_eye[0] < 0 || truthy(field(fs, t->valid_eye[0]));
    bool okr = t->valid_eye[1] < 0 || truthy(field(fs, t->valid_eye[1]));
    bool any_eye = t->valid_eye[0] < 0 && t->valid_eye[1] < 0 ? true : (t->valid_eye[0] >= 0 && okl) || (t->valid_eye[1] >= 0 && okr);
    if (!ok || !any_eye) v[G_ONE][0] = NAN;
    if (!ok || !okl) v[G_LEFT][0] = NAN;
    if (!ok || !okr) v[G_RIGHT][0] = NAN;
    if (t->x[G_ONE] >= 0) fv_gaze_emit(w, tm, v[G_ONE][0], v[G_ONE][1], NAN, NAN);
    else fv_gaze_emit(w, tm, v[G_LEFT][0], v[G_LEFT][1], v[G_RIGHT][0], v[G_RIGHT][1]);
    return FV_OK;
}

fv_status fv_gaze_import_table(FILE *in, fv_gaze_writer *w, const fv_gaze_import_opts *opts, fv_gaze_format *format, fv_error *err)
{
    table t;
    memset(&t, 0, sizeof t);
    t.w = w;
    t.time = t.valid = t.res_w = t.res_h = t.event = t.sensor = -1;
    t.valid_eye[0] = t.valid_eye[1] = -1;
    for (int g = 0; g < G_COUNT; g++) t.x[g] = t.y[g] = -1;
    w->info->width = w->info->height = 0; /* set again for gaze in pixels */
    char *line = NULL;
    size_t cap = 0;
    fv_gaze_fields fs = {0};
    fv_status st = FV_OK;
    int lineno = 0;
    bool first = false;
    /* The first line that is not blank: the header, or a header-less file's first row. */
    while (fv_gaze_read_line(in, w, &line, &cap, ++lineno, &st, err)) {
        char *h = line;
        if (!strncmp(h, "\xEF\xBB\xBF", 3)) memmove(h, h + 3, strlen(h + 3) + 1); /* a byte order mark */
        if (h[strspn(h, " \t\r\n")] == '\0') continue;
        first = true;
        break;
    }
    if (st == FV_OK && !first) st = fv_error_set(err, FV_ERR_INVALID, "%s: the file is empty (no header line, no rows)", w->in);
    if (st == FV_OK) {
        t.delim = detect_delim(line);
        if (!fv_gaze_fields_split(&fs, line, t.delim)) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
        else if (fs.unterminated) st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: a quoted field is not closed on its line", w->in, lineno);
    }
    if (st == FV_OK) {
        t.ncols = fs.n;
        const fv_gaze_table_opts *m = &opts->table;
        bool named = false;
        const char *specs[8] = {m->time, m->x, m->y, m->left_x, m->left_y, m->right_x, m->right_y, m->valid};
        for (int k = 0; k < 8; k++) named |= specs[k] && !all_digits(specs[k]);
        double tv;
        /* Header-less: every column given by number and the first line's time a number. */
        t.header = *format != FV_GAZE_FORMAT_TABLE || named || !m->time || !number(&t, field(&fs, (int)strtol(m->time, NULL, 10) - 1), &tv);
        if (t.header) {
            t.names = fv_calloc_array((size_t)fs.n, sizeof *t.names);
            for (int k = 0; t.names && k < fs.n; k++)
                if (!(t.names[k] = strdup(fs.f[k]))) names_free(t.names, k), t.names = NULL;
            if (!t.names) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
        }
    }
    if (st == FV_OK && *format == FV_GAZE_FORMAT_AUTO) {
        /* A .tsv named without a mapping: Tobii's export, or a table that needs one. */
        if (tobii_col(&t, "Recording timestamp", NULL, 0) >= 0 && tobii_col(&t, "Gaze point X", NULL, 0) >= 0) *format = FV_GAZE_FORMAT_TOBII;
        else
            st = fv_error_set(err, FV_ERR_INVALID,
                              "%s: not a Tobii Pro Lab export (no 'Recording timestamp' and 'Gaze point X' columns); for another table: --format "
                              "table --time COL --x COL --y COL",
                              w->in);
    }
    if (st == FV_OK) {
        t.tobii = *format == FV_GAZE_FORMAT_TOBII;
        if (t.tobii && (opts->table.pixels || opts->table.bottom_left))
            st = fv_error_set(err, FV_ERR_INVALID, "%s: --coords and --origin are for --format table (Tobii's units come from its export)", w->in);
        else st = t.tobii ? map_tobii(&t, opts, err) : map_table(&t, opts, err);
    }
    if (st == FV_OK) st = choose_eyes(&t, opts->eyes, err);
    double prev = 0;
    bool any = false;
    if (st == FV_OK && !t.header) st = row(&t, &fs, opts, lineno, &prev, &any, err);
    while (st == FV_OK && fv_gaze_read_line(in, w, &line, &cap, ++lineno, &st, err)) {
        if (line[strspn(line, " \t\r\n")] == '\0') continue;
        if (!fv_gaze_fields_split(&fs, line, t.delim)) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
        else if (fs.unterminated) st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: a quoted field is not closed on its line", w->in, lineno);
        else st = row(&t, &fs, opts, lineno, &prev, &any, err);
    }
    free(line);
    fv_gaze_fields_free(&fs);
    names_free(t.names, t.ncols);
    return st;
}
