/* fovea — eye-tracker recordings into fovea's gaze trace format (docs/gaze.md, "Importing").
 *
 * EyeLink ASC (the text edf2asc writes): the screen size comes from the DISPLAY_COORDS message
 * ("MSG <t> DISPLAY_COORDS left top right bottom", pixels inclusive), which eyes were recorded from
 * the START and SAMPLES lines (LEFT, RIGHT), per recording block; sample lines are
 * "<ms> <x> <y> <pupil>" per eye, "." for a value the tracker lost. A sample is missing when its x
 * or y is "." or lies off the screen, or while that eye is in a blink (between its SBLINK and
 * EBLINK events). The sample rate (SAMPLES ... RATE r, MSG ... RECCFG <mode> r, !MODE RECORD
 * <mode> r) times samples that share a whole-millisecond stamp (2000 Hz written as whole ms: two
 * samples per stamp, 0.5 ms apart). Between recording blocks (END ... START, a trial's break) the
 * tracker records nothing: one missing sample at the block's end keeps the trace from
 * interpolating across the break.
 *
 * Pupil Labs gaze_positions.csv (Pupil Player's export): columns gaze_timestamp (s; `timestamp` in
 * older versions), confidence, norm_pos_x and norm_pos_y, found by name in the header (blank lines
 * before it are skipped), and base_data, which says which eye a row comes from ("<t>-0" eye 0, the
 * right eye; "<t>-1" eye 1, the left; both for a row Pupil mapped from both eyes). norm_pos has its
 * origin at the bottom left, fovea's at the top left, so y is flipped. A sample whose confidence is
 * below the threshold (0.6 by default, the value Pupil's own tools use) or whose position is off
 * [0,1] is missing. A binocular export interleaves one row per eye a fraction of a millisecond
 * apart, and the two eyes' estimates differ by a few percent of the screen: read in turn they make
 * the trace zigzag, so rows of the two eyes closer than 5 ms are paired first.
 *
 * Which eye (fv_gaze_eyes): left or right alone, both (the mean of the two eyes' known gaze, or the
 * one known), or each (a five-column trace, each eye its own gaze for stereo renders).
 *
 * Times are written in seconds from the first sample. Samples whose time does not increase are
 * dropped and counted. The output goes through the atomic writer: on any error no file is left.
 *
 * Other tables (a column mapping) and Tobii Pro Lab exports are read by gaze_table.c, through the
 * writer, line reader and field splitter here (import.h).
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>
#include <zlib.h>
#include "core/alloc.h"
#include "core/fileio.h"
#include "fovea/gaze.h"
#include "gaze/import.h"

/* Pupil: rows of the two eyes at most this far apart (s) are one binocular sample. Pupil's eye
 * cameras run at 120-200 Hz (5-8 ms apart), and the two eyes' rows of one moment are well under a
 * millisecond apart. */
#define PUPIL_PAIR_S 0.005
#define DEFAULT_MAX_INFLATED ((uint64_t)1 << 30)

void fv_gaze_import_opts_init(fv_gaze_import_opts *o)
{
    memset(o, 0, sizeof *o);
    o->format = FV_GAZE_FORMAT_AUTO;
    o->min_confidence = 0.6;
    o->eyes = FV_GAZE_EYES_DEFAULT;
    o->max_inflated = DEFAULT_MAX_INFLATED;
}


bool fv_gaze_read_line(FILE *in, const fv_gaze_writer *w, char **line, size_t *cap, int lineno, fv_status *st, fv_error *err)
{
    long n = fv_file_getline(in, line, cap, FV_LINE_MAX);
    if (n == -1) *st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: line longer than %d bytes", w->in, lineno, FV_LINE_MAX);
    else if (n < 0) *st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
    if (n > 0 && lineno == 1) fv_file_strip_bom(*line, n); /* every format's first line (also on a second pass) */
    return n > 0;
}

bool fv_gaze_on_screen(double x, double y) { return x >= 0.0 && x <= 1.0 && y >= 0.0 && y <= 1.0; }

/* One line of the trace (time in seconds; a pair of coordinates is missing when NaN or off the
 * screen; xr, yr only in a five-column trace). Returns false when dropped (time not increasing). */
static bool put_sample(fv_gaze_writer *w, double t, double xl, double yl, double xr, double yr)
{
    /* The time as written (9 digits) must increase too: a jump to 1e19 s would print equal. */
    char tt[40];
    snprintf(tt, sizeof tt, "%.9g", w->any ? t - w->t0 : 0.0);
    double shown = strtod(tt, NULL);
    if (!isfinite(t) || !isfinite(shown) || (w->any && !(shown > w->prev))) {
        w->info->dropped++;
        return false;
    }
    if (!w->any) w->t0 = t;
    w->any = true;
    w->prev = shown;
    bool ml = !fv_gaze_on_screen(xl, yl), mr = !fv_gaze_on_screen(xr, yr);
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
    return true;
}

bool fv_gaze_emit(fv_gaze_writer *w, double t, double xl, double yl, double xr, double yr)
{
    bool kl = fv_gaze_on_screen(xl, yl), kr = fv_gaze_on_screen(xr, yr);
    switch (w->eyes) {
    case FV_GAZE_EYES_LEFT: return put_sample(w, t, xl, yl, NAN, NAN);
    case FV_GAZE_EYES_RIGHT: return put_sample(w, t, xr, yr, NAN, NAN);
    case FV_GAZE_EYES_BOTH:
        if (kl && kr) return put_sample(w, t, 0.5 * (xl + xr), 0.5 * (yl + yr), NAN, NAN);
        return kr ? put_sample(w, t, xr, yr, NAN, NAN) : put_sample(w, t, xl, yl, NAN, NAN);
    default: return put_sample(w, t, xl, yl, xr, yr);
    }
}

/* ---- gzip-compressed recordings ----
 *
 * A recording that starts with gzip's magic bytes (an EyeLink .asc.gz: a long recording is
 * hundreds of MB of text and usually kept compressed) is inflated with zlib into an anonymous
 * temporary file, which the readers then read like the plain file (two passes, fseek; bounded
 * lines). zlib rather than `gzip -dc` in a sandbox child (core/sandbox.h): inflating is zlib's own
 * code, which reports a corrupt or truncated stream as an error and never aborts or allocates
 * without bound, so a child process would buy no safety, while it would add a gzip binary on the
 * PATH, a pipe protocol and a second channel for errors; and zlib is in every build anyway
 * (libpng needs it; CMakeLists.txt links it directly). The inflated size is bounded (opts.max_inflated, 1 GiB by default; a one-hour
 * binocular 2000 Hz recording is about half that): a gzip bomb is refused, not written out. */
static fv_status inflate_recording(const char *path, uint64_t max, FILE **io, bool *compressed, fv_error *err)
{
    FILE *f = *io;
    unsigned char magic[2];
    size_t n = fread(magic, 1, 2, f);
    if (ferror(f)) return fv_error_set(err, FV_ERR_IO, "cannot read '%s': %s", path, strerror(errno));
    if (n < 2 || magic[0] != 0x1f || magic[1] != 0x8b) {
        *compressed = false;
        if (fseek(f, 0, SEEK_SET) != 0) return fv_error_set(err, FV_ERR_IO, "cannot read '%s': %s", path, strerror(errno));
        return FV_OK;
    }
    *compressed = true;
    /* zlib reads the descriptor from the start (stdio has buffered past the magic). */
    int fd = dup(fileno(f));
    if (fd < 0 || lseek(fd, 0, SEEK_SET) != 0) {
        int e = errno;
        if (fd >= 0) close(fd);
        return fv_error_set(err, FV_ERR_IO, "cannot read '%s': %s", path, strerror(e));
    }
    gzFile gz = gzdopen(fd, "rb");
    if (!gz) {
        close(fd);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory inflating '%s'", path);
    }
    FILE *tmp = tmpfile();
    if (!tmp) {
        int e = errno;
        gzclose(gz);
        return fv_error_set(err, FV_ERR_IO, "cannot create a temporary file to inflate '%s': %s", path, strerror(e));
    }
    fv_status st = FV_OK;
    enum { CHUNK = 1 << 16 };
    char *buf = malloc(CHUNK);
    if (!buf) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory inflating '%s'", path);
    uint64_t total = 0;
    while (st == FV_OK) {
        int k = gzread(gz, buf, CHUNK);
        if (k <= 0) break;
        total += (uint64_t)k;
        if (total > max) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s: inflates to more than %llu bytes (the limit for a compressed recording)", path,
                              (unsigned long long)max);
            break;
        }
        if (fwrite(buf, 1, (size_t)k, tmp) != (size_t)k) {
            st = fv_error_set(err, FV_ERR_IO, "cannot inflate '%s' into a temporary file: %s", path, strerror(errno));
            break;
        }
    }
    if (st == FV_OK) {
        int zerr = Z_OK;
        const char *why = gzerror(gz, &zerr);
        if (zerr == Z_ERRNO) st = fv_error_set(err, FV_ERR_IO, "cannot read '%s': %s", path, strerror(errno));
        else if (zerr == Z_BUF_ERROR) st = fv_error_set(err, FV_ERR_INVALID, "%s: the compressed data ends early (a truncated .gz file)", path);
        else if (zerr != Z_OK) st = fv_error_set(err, FV_ERR_INVALID, "%s: not a readable gzip file (%s)", path, why && *why ? why : "corrupt data");
    }
    free(buf);
    gzclose(gz);
    if (st == FV_OK && (fflush(tmp) != 0 || fseek(tmp, 0, SEEK_SET) != 0))
        st = fv_error_set(err, FV_ERR_IO, "cannot inflate '%s' into a temporary file: %s", path, strerror(errno));
    if (st != FV_OK) {
        fclose(tmp);
        return st;
    }
    fclose(f);
    *io = tmp;
    return FV_OK;
}

/* ---- EyeLink ASC ---- */

static bool starts_with(const char *s, const char *p) { return strncmp(s, p, strlen(p)) == 0; }

/* A line that starts with the keyword word (followed by a blank or the end). */
static bool keyword(const char *s, const char *word)
{
    size_t n = strlen(word);
    return strncmp(s, word, n) == 0 && (s[n] == ' ' || s[n] == '\t' || s[n] == '\r' || s[n] == '\n' || s[n] == '\0');
}

/* The eyes a START or SAMPLES line names: bit 0 left, bit 1 right. */
static int line_eyes(const char *line) { return (strstr(line, "LEFT") != NULL) | (strstr(line, "RIGHT") != NULL) << 1; }

/* A value of a sample line: a number, or "." for one the tracker lost (NaN); not the flags
 * column ("...", "....."). */
static bool asc_value(const char **s, double *v)
{
    while (**s == ' ' || **s == '\t') (*s)++;
    char after = (*s)[1];
    if (**s == '.' && (after == ' ' || after == '\t' || after == '\r' || after == '\n' || after == '\0')) {
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

/* The sample rate a SAMPLES line ("... RATE 2000.00 ...") or a RECCFG / !MODE RECORD message
 * ("RECCFG CR 2000 2 1 LR") gives, or 0. */
static double line_rate(const char *line)
{
    const char *p;
    double r = 0;
    char *end;
    if (starts_with(line, "SAMPLES") && (p = strstr(line, "RATE"))) r = strtod(p + 4, &end);
    else if (starts_with(line, "MSG") && ((p = strstr(line, "RECCFG")) || (p = strstr(line, "!MODE RECORD")))) {
        p += *p == 'R' ? 6 : 12;
        while (*p == ' ' || *p == '\t') p++;
        while (*p && *p != ' ' && *p != '\t') p++; /* the tracking mode (CR, P) */
        r = strtod(p, &end);
    }
    return isfinite(r) && r >= 1.0 && r <= 100000.0 ? r : 0.0;
}

static fv_status import_asc(FILE *in, fv_gaze_writer *w, fv_gaze_eyes want, fv_error *err)
{
    char *line = NULL;
    size_t cap = 0;
    double left = 0, top = 0, right = -1, bottom = -1;
    int eyes = 0;
    bool sized = false;
    fv_status st = FV_OK;
    int lineno = 0;
    /* First pass: the screen and the eyes. */
    while (fv_gaze_read_line(in, w, &line, &cap, ++lineno, &st, err)) {
        const char *d = strstr(line, "DISPLAY_COORDS");
        if (starts_with(line, "MSG") && d && sscanf(d + 14, "%lf %lf %lf %lf", &left, &top, &right, &bottom) == 4) sized = true;
        if (keyword(line, "START") || keyword(line, "SAMPLES")) eyes |= line_eyes(line);
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
    /* The eye choice. A file that names no eye has one, taken as whichever is asked for. */
    if (eyes == 0) eyes = want == FV_GAZE_EYES_RIGHT ? 2 : 1;
    if ((want == FV_GAZE_EYES_LEFT && !(eyes & 1)) || (want == FV_GAZE_EYES_RIGHT && !(eyes & 2))) {
        free(line);
        return fv_error_set(err, FV_ERR_INVALID, "%s: the recording has no %s-eye samples (it recorded the %s eye)", w->in,
                            want == FV_GAZE_EYES_LEFT ? "left" : "right", want == FV_GAZE_EYES_LEFT ? "right" : "left");
    }
    if (eyes != 3) w->eyes = eyes == 1 ? FV_GAZE_EYES_LEFT : FV_GAZE_EYES_RIGHT;
    else w->eyes = want == FV_GAZE_EYES_DEFAULT ? FV_GAZE_EYES_EACH : want;
    w->binocular = w->eyes == FV_GAZE_EYES_EACH;
    if (fseek(in, 0, SEEK_SET) != 0) {
        free(line);
        return fv_error_set(err, FV_ERR_IO, "cannot read '%s' twice: %s", w->in, strerror(errno));
    }
    /* Second pass: samples, per recording block (the eyes its START / SAMPLES lines name), with
     * each eye's blinks. */
    bool blink[2] = {false, false};
    int block = eyes;
    double rate = 0, last = NAN, end_ms = NAN;
    bool gap = false;
    lineno = 0;
    while (fv_gaze_read_line(in, w, &line, &cap, ++lineno, &st, err)) {
        if (!isdigit((unsigned char)line[0])) {
            char eye = 0;
            double r = line_rate(line);
            if (r > 0) rate = w->info->rate = r;
            if (keyword(line, "START")) {
                int e = line_eyes(line);
                block = e ? e : eyes;
                blink[0] = blink[1] = false;
                gap |= isfinite(last);
            } else if (keyword(line, "SAMPLES")) {
                int e = line_eyes(line);
                if (e) block = e;
            } else if (keyword(line, "END")) {
                char *end;
                double t = strtod(line + 3, &end);
                end_ms = end > line + 3 && isfinite(t) ? t : NAN;
                gap |= isfinite(last);
            } else if (sscanf(line, "SBLINK %c", &eye) == 1 || sscanf(line, "EBLINK %c", &eye) == 1) {
                /* In a recording of one eye (or naming none), a blink is that eye's. */
                int k = eyes == 1 ? 0 : eyes == 2 ? 1 : eye == 'R';
                if (eye == 'L' || eye == 'R') blink[k] = line[0] == 'S';
            }
            continue;
        }
        const char *s = line;
        double t, v[6];
        int n = 0, want_n = block == 3 ? 6 : 3;
        if (asc_value(&s, &t))
            while (n < want_n && asc_value(&s, &v[n])) n++;
        if (n < want_n || !isfinite(t)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected a sample '<time> <x> <y> <pupil>'%s", w->in, lineno,
                              block == 3 ? " for each eye (the block records both)" : "");
            break;
        }
        /* Times: a stamp not above the last one (2000 Hz written in whole milliseconds: two
         * samples per stamp) is the last time plus a sample period, as long as that stays within
         * the stamp's millisecond; otherwise the sample is dropped. */
        double period = rate > 0 ? 1000.0 / rate : 1.0;
        if (isfinite(last) && !(t > last)) {
            double c = last + period;
            if (!(rate > 0 && c < t + 1.0 - 1e-6)) {
                w->info->dropped++;
                continue;
            }
            t = c;
        }
        /* A break between recording blocks: the gaze is unknown from the block's END (or a sample
         * period after its last sample) until this sample. */
        if (gap && isfinite(last) && t - last > 1.5 * period) {
            double g = end_ms > last && end_ms < t ? end_ms : last + period;
            if (fv_gaze_emit(w, g / 1000.0, NAN, NAN, NAN, NAN)) w->info->gaps++;
        }
        gap = false;
        end_ms = NAN;
        last = t;
        double xl = NAN, yl = NAN, xr = NAN, yr = NAN;
        if (block == 3) xl = v[0], yl = v[1], xr = v[3], yr = v[4];
        else if (block == 2) xr = v[0], yr = v[1];
        else xl = v[0], yl = v[1];
        if (blink[0]) xl = yl = NAN;
        if (blink[1]) xr = yr = NAN;
        fv_gaze_emit(w, t / 1000.0, (xl - left) / sw, (yl - top) / sh, (xr - left) / sw, (yr - top) / sh);
    }
    free(line);
    return st;
}

/* ---- Pupil Labs gaze_positions.csv ---- */

void fv_gaze_fields_free(fv_gaze_fields *fs)
{
    free(fs->buf);
    free(fs->f);
    free(fs->len);
    memset(fs, 0, sizeof *fs);
}

/* Fields are copied into fs->buf (a quoted field's "" becomes one quote), so each is a C string;
 * a line of L bytes needs at most L + 1 bytes of copies and NULs. Whatever follows a quoted
 * field's closing quote up to the delimiter is left off, as is the end of line. */
bool fv_gaze_fields_split(fv_gaze_fields *fs, const char *line, char delim)
{
    size_t need = strlen(line) + 2;
    if (need > fs->bufcap) {
        char *b = realloc(fs->buf, need);
        if (!b) return false;
        fs->buf = b;
        fs->bufcap = need;
    }
    char *o = fs->buf;
    const char *s = line;
    fs->n = 0;
    fs->unterminated = false;
    for (;;) {
        if (fv_grow((void **)&fs->f, &fs->cap, fs->n + 1, sizeof *fs->f) || fv_grow((void **)&fs->len, &fs->lencap, fs->n + 1, sizeof *fs->len))
            return false;
        while (*s == ' ' || (*s == '\t' && delim != '\t')) s++;
        char *start = o;
        if (*s == '"') {
            s++;
            for (;;) {
                if (*s == '\0' || ((*s == '\r' || *s == '\n') && s[strspn(s, "\r\n")] == '\0')) {
                    fs->unterminated = true;
                    break;
                }
                if (*s == '"' && s[1] == '"') *o++ = '"', s += 2;
                else if (*s == '"') {
                    s++;
                    break;
                } else *o++ = *s++;
            }
            while (*s && *s != delim && *s != '\r' && *s != '\n') s++;
        } else {
            while (*s && *s != delim && *s != '\r' && *s != '\n') *o++ = *s++;
        }
        while (o > start && (o[-1] == ' ' || o[-1] == '\t')) o--;
        *o++ = '\0';
        fs->f[fs->n] = start;
        fs->len[fs->n] = (size_t)(o - 1 - start);
        fs->n++;
        if (*s != delim) return true;
        s++;
    }
}

bool fv_gaze_field_number(const char *s, size_t len, double *v)
{
    if (len == 0 || len > 63) return false;
    char tmp[64];
    memcpy(tmp, s, len);
    tmp[len] = '\0';
    char *end;
    *v = strtod(tmp, &end);
    return end != tmp && *end == '\0';
}

enum { EYE_COMBINED = 0, EYE_LEFT = 1, EYE_RIGHT = 2 };

/* The eye a row comes from: its base_data names the pupil data it was mapped from, "<t>-0" from
 * eye 0 (the right eye), "<t>-1" from eye 1 (the left); an eye_id column (0, 1) where there is no
 * base_data. Both, or neither: a combined row. */
static int row_eye(const char *base, size_t blen, const char *id, size_t ilen)
{
    int bits = 0;
    for (size_t i = 0; i + 1 < blen; i++) {
        if (base[i] != '-' || (base[i + 1] != '0' && base[i + 1] != '1')) continue;
        char after = i + 2 < blen ? base[i + 2] : ' ';
        if (isdigit((unsigned char)after) || after == '.') continue;
        bits |= base[i + 1] == '0' ? EYE_RIGHT : EYE_LEFT;
    }
    if (!bits && id && ilen == 1 && (id[0] == '0' || id[0] == '1')) bits = id[0] == '0' ? EYE_RIGHT : EYE_LEFT;
    return bits == 3 ? EYE_COMBINED : bits;
}

typedef struct pupil_row {
    double t, x, y; /* x, y NaN when missing */
    int eye, index; /* index: the order in the file, for a stable sort */
} pupil_row;

static int cmp_rows(const void *a, const void *b)
{
    const pupil_row *p = a, *q = b;
    if (p->t != q->t) return p->t < q->t ? -1 : 1;
    return (p->index > q->index) - (p->index < q->index);
}

static fv_status import_pupil(FILE *in, fv_gaze_writer *w, double min_conf, fv_gaze_eyes want, fv_error *err)
{
    char *line = NULL;
    size_t cap = 0;
    int col_t = -1, col_old_t = -1, col_c = -1, col_x = -1, col_y = -1, col_base = -1, col_id = -1;
    fv_status st = FV_OK;
    int lineno = 0;
    fv_gaze_fields fs = {0};
    const char **f = NULL;
    size_t *len = NULL;
    /* The header: the first line that is not blank (an export may start with one). */
    while (fv_gaze_read_line(in, w, &line, &cap, ++lineno, &st, err)) {
        char *h = line;
        if (!strncmp(h, "\xEF\xBB\xBF", 3)) h += 3; /* a byte order mark */
        if (h[strspn(h, " \t\r\n")] == '\0') continue;
        if (!fv_gaze_fields_split(&fs, h, ',')) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
            break;
        }
        int n = fs.n;
        f = fs.f, len = fs.len;
        for (int k = 0; k < n; k++) {
#define IS(name) (len[k] == strlen(name) && !strncmp(f[k], name, len[k]))
            if (IS("gaze_timestamp")) col_t = k;
            else if (IS("timestamp")) col_old_t = k; /* Pupil before v1.x */
            else if (IS("confidence")) col_c = k;
            else if (IS("norm_pos_x")) col_x = k;
            else if (IS("norm_pos_y")) col_y = k;
            else if (IS("base_data")) col_base = k;
            else if (IS("eye_id")) col_id = k;
#undef IS
        }
        break;
    }
    if (st != FV_OK) {
        free(line);
        fv_gaze_fields_free(&fs);
        return st;
    }
    if (col_t < 0) col_t = col_old_t;
    if (col_t < 0 || col_c < 0 || col_x < 0 || col_y < 0) {
        free(line);
        fv_gaze_fields_free(&fs);
        return fv_error_set(err, FV_ERR_INVALID,
                            "%s: the header lacks gaze_timestamp (or timestamp), confidence, norm_pos_x or norm_pos_y: not Pupil's "
                            "gaze_positions.csv (for another table: --format table --time COL --x COL --y COL)",
                            w->in);
    }
    const char *tname = col_t == col_old_t ? "timestamp" : "gaze_timestamp";
    pupil_row *rows = NULL;
    int count = 0, rcap = 0;
    long per_eye[3] = {0, 0, 0};
    while (st == FV_OK && fv_gaze_read_line(in, w, &line, &cap, ++lineno, &st, err)) {
        if (line[strspn(line, " \t\r\n")] == '\0') continue;
        if (!fv_gaze_fields_split(&fs, line, ',')) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
            break;
        }
        int n = fs.n;
        f = fs.f, len = fs.len;
        double t, c, x, y;
        if (col_t >= n || col_c >= n || !fv_gaze_field_number(f[col_t], len[col_t], &t) || !fv_gaze_field_number(f[col_c], len[col_c], &c)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected numbers in %s and confidence", w->in, lineno, tname);
            break;
        }
        if (!isfinite(t)) {
            w->info->dropped++;
            continue;
        }
        if (col_x >= n || col_y >= n || !fv_gaze_field_number(f[col_x], len[col_x], &x) || !fv_gaze_field_number(f[col_y], len[col_y], &y) || !(c >= min_conf) ||
            !fv_gaze_on_screen(x, y))
            x = y = NAN;
        int eye = row_eye(col_base >= 0 && col_base < n ? f[col_base] : NULL, col_base >= 0 && col_base < n ? len[col_base] : 0,
                          col_id >= 0 && col_id < n ? f[col_id] : NULL, col_id >= 0 && col_id < n ? len[col_id] : 0);
        if (count == INT32_MAX || fv_grow((void **)&rows, &rcap, count + 1, sizeof *rows)) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", w->in);
            break;
        }
        rows[count] = (pupil_row){t, x, 1.0 - y, eye, count};
        count++;
        per_eye[eye]++;
    }
    free(line);
    fv_gaze_fields_free(&fs);
    if (st != FV_OK) {
        free(rows);
        return st;
    }
    /* The eye choice. Rows Pupil mapped from both eyes (or that name no eye) count for either. */
    if ((want == FV_GAZE_EYES_LEFT || want == FV_GAZE_EYES_RIGHT) && per_eye[want == FV_GAZE_EYES_LEFT ? EYE_LEFT : EYE_RIGHT] + per_eye[EYE_COMBINED] == 0) {
        free(rows);
        return fv_error_set(err, FV_ERR_INVALID, "%s: no row is from the %s eye (base_data ending in -%d)", w->in,
                            want == FV_GAZE_EYES_LEFT ? "left" : "right", want == FV_GAZE_EYES_LEFT ? 1 : 0);
    }
    w->eyes = want == FV_GAZE_EYES_DEFAULT ? FV_GAZE_EYES_BOTH : want;
    if (w->eyes == FV_GAZE_EYES_BOTH || w->eyes == FV_GAZE_EYES_EACH) {
        /* An export of one eye's rows is that eye's; one of combined rows only has nothing to pair. */
        if (per_eye[EYE_COMBINED] == 0 && per_eye[EYE_RIGHT] == 0) w->eyes = FV_GAZE_EYES_LEFT;
        else if (per_eye[EYE_COMBINED] == 0 && per_eye[EYE_LEFT] == 0) w->eyes = FV_GAZE_EYES_RIGHT;
        else if (per_eye[EYE_LEFT] + per_eye[EYE_RIGHT] == 0) w->eyes = FV_GAZE_EYES_BOTH;
    }
    w->binocular = w->eyes == FV_GAZE_EYES_EACH;
    if (count > 1) qsort(rows, (size_t)count, sizeof *rows, cmp_rows); /* rows is NULL when there are none */
    bool pair = w->eyes == FV_GAZE_EYES_BOTH || w->eyes == FV_GAZE_EYES_EACH;
    for (int i = 0; i < count; i++) {
        const pupil_row *r = &rows[i];
        if ((w->eyes == FV_GAZE_EYES_LEFT && r->eye == EYE_RIGHT) || (w->eyes == FV_GAZE_EYES_RIGHT && r->eye == EYE_LEFT)) continue;
        double l[2] = {NAN, NAN}, rt[2] = {NAN, NAN}, t = r->t;
        if (r->eye != EYE_RIGHT) l[0] = r->x, l[1] = r->y;
        if (r->eye != EYE_LEFT) rt[0] = r->x, rt[1] = r->y;
        const pupil_row *o = i + 1 < count ? &rows[i + 1] : NULL;
        if (pair && r->eye != EYE_COMBINED && o && o->eye != EYE_COMBINED && o->eye != r->eye && o->t - r->t <= PUPIL_PAIR_S) {
            if (o->eye == EYE_LEFT) l[0] = o->x, l[1] = o->y;
            else rt[0] = o->x, rt[1] = o->y;
            t = 0.5 * (r->t + o->t);
            i++;
            w->info->paired++;
        }
        fv_gaze_emit(w, t, l[0], l[1], rt[0], rt[1]);
    }
    free(rows);
    return FV_OK;
}

/* The format from the name: .asc EyeLink, .csv Pupil (or a table when a column mapping is given),
 * .tsv Tobii Pro Lab (a table with a mapping; without one, read as Tobii's when its header is),
 * any of them with .gz after it. */
static fv_gaze_format guess_format(const char *path, bool mapping)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = strlen(base);
    if (n > 3 && strcasecmp(base + n - 3, ".gz") == 0) n -= 3;
    if (n > 4 && strncasecmp(base + n - 4, ".asc", 4) == 0) return FV_GAZE_FORMAT_EYELINK_ASC;
    if (mapping) return FV_GAZE_FORMAT_TABLE;
    if (n > 4 && strncasecmp(base + n - 4, ".csv", 4) == 0) return FV_GAZE_FORMAT_PUPIL_CSV;
    if (n > 4 && strncasecmp(base + n - 4, ".tsv", 4) == 0) return FV_GAZE_FORMAT_AUTO; /* gaze_table.c looks at the header */
    return (fv_gaze_format)-1;
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
    const fv_gaze_table_opts *m = &opts->table;
    bool mapping = m->time || m->x || m->y || m->left_x || m->left_y || m->right_x || m->right_y || m->valid;
    fv_gaze_format fmt = opts->format != FV_GAZE_FORMAT_AUTO ? opts->format : guess_format(in_path, mapping);
    if (!(opts->min_confidence >= 0.0 && opts->min_confidence <= 1.0))
        return fv_error_set(err, FV_ERR_INVALID, "gaze import: confidence threshold %g is outside [0, 1]", opts->min_confidence);
    if ((unsigned)opts->eyes > FV_GAZE_EYES_EACH) return fv_error_set(err, FV_ERR_INVALID, "gaze import: unknown eye choice %d", (int)opts->eyes);
    /* A regular file only, whatever its name (core/fileio.h: /dev/zero reads forever). */
    FILE *in;
    fv_status st = fv_file_open_read(in_path, "recording", &in, err);
    if (st != FV_OK) return st;
    if ((unsigned)fmt > FV_GAZE_FORMAT_TOBII) {
        fclose(in);
        return fv_error_set(err, FV_ERR_INVALID,
                            "%s: unknown recording format (an EyeLink .asc, a Pupil Labs gaze_positions .csv, a Tobii Pro Lab .tsv, any of them "
                            ".gz; another table: --format table --time COL --x COL --y COL)",
                            in_path);
    }
    /* A mapping belongs to a table; Tobii's columns are its own (only its time unit may be given). */
    bool table_opts = mapping || m->time_unit > 0 || m->pixels || m->bottom_left;
    if (fmt == FV_GAZE_FORMAT_TOBII ? mapping || m->pixels || m->bottom_left : table_opts && fmt != FV_GAZE_FORMAT_TABLE && fmt != FV_GAZE_FORMAT_AUTO) {
        fclose(in);
        return fv_error_set(err, FV_ERR_INVALID, "%s: the column options (--time, --x, --coords, ...) are for --format table%s", in_path,
                            fmt == FV_GAZE_FORMAT_TOBII ? " (Tobii's columns are found by name; --time-unit alone applies)" : "");
    }
    if ((st = inflate_recording(in_path, opts->max_inflated ? opts->max_inflated : DEFAULT_MAX_INFLATED, &in, &info->compressed, err)) != FV_OK) {
        fclose(in);
        return st;
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
    fv_gaze_writer w = {out, in_path, FV_GAZE_EYES_LEFT, false, false, {0, 0}, 0, 0, info};
    fprintf(out, "# gaze trace imported from %s by fovea gaze import (docs/gaze.md)\n", in_path);
    if (fmt == FV_GAZE_FORMAT_EYELINK_ASC) st = import_asc(in, &w, opts->eyes, err);
    else if (fmt == FV_GAZE_FORMAT_PUPIL_CSV) st = import_pupil(in, &w, opts->min_confidence, opts->eyes, err);
    else st = fv_gaze_import_table(in, &w, opts, &fmt, err);
    info->format = fmt;
    if (st == FV_OK && ferror(in)) st = fv_error_set(err, FV_ERR_IO, "cannot read '%s': %s", in_path, strerror(errno));
    fclose(in);
    info->eyes = w.eyes;
    info->binocular = w.binocular;
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
