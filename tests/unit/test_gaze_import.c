/* fovea gaze import against hand-made recordings (tests/data, made for these tests; the formats
 * are public): Pupil Labs exports with a leading blank line, the old `timestamp` header and one row
 * per eye; EyeLink at 2000 Hz with whole-millisecond stamps, gzip-compressed, and with a break
 * between trials (issue 25, items 4 and 5). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include <zlib.h>
#include "fovea/gaze.h"

#define DATA FOVEA_TEST_DATA "/"

typedef struct trace {
    int n, columns;
    double t[512], v[512][4]; /* NaN: missing */
} trace;

static char tmpdir[64];

static int setup(void **st)
{
    (void)st;
    strcpy(tmpdir, "/tmp/fovea-gaze-import-XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void **st)
{
    (void)st;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *tmp_path(const char *name)
{
    static char buf[4][256];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
    return buf[k];
}

/* Reads a trace fovea wrote: '#' comments, then "t,x,y" or "t,xl,yl,xr,yr" with empty fields. */
static void read_trace(const char *path, trace *tr)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[512];
    memset(tr, 0, sizeof *tr);
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#') continue;
        assert_true(tr->n < 512);
        int c = 0;
        char *s = line;
        double vals[5];
        for (;;) {
            char *end;
            double v = strtod(s, &end);
            vals[c++] = end == s ? NAN : v;
            s = end + strcspn(end, ",\n");
            if (*s != ',' || c == 5) break;
            s++;
        }
        if (tr->columns == 0) tr->columns = c;
        assert_int_equal(c, tr->columns);
        tr->t[tr->n] = vals[0];
        for (int i = 1; i < c; i++) tr->v[tr->n][i - 1] = vals[i];
        tr->n++;
    }
    fclose(f);
}

static fv_status import(const char *in, const fv_gaze_import_opts *o, fv_gaze_import_info *info, trace *tr, fv_error *err)
{
    const char *out = tmp_path("trace.csv");
    unlink(out);
    fv_error_clear(err);
    fv_status st = fv_gaze_import(in, out, o, info, err);
    if (st == FV_OK) read_trace(out, tr);
    else assert_int_equal(access(out, F_OK), -1); /* nothing half-written */
    return st;
}

/* Mean |dx| between consecutive known samples (column 0) among the first `count`. */
static double mean_step(const trace *tr, int count)
{
    double sum = 0;
    int n = 0;
    for (int i = 1; i < count && i < tr->n; i++)
        if (!isnan(tr->v[i][0]) && !isnan(tr->v[i - 1][0])) sum += fabs(tr->v[i][0] - tr->v[i - 1][0]), n++;
    return n ? sum / n : 0;
}

static void write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
}

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char *buf = malloc(1 << 20);
    *n = fread(buf, 1, (1 << 20) - 1, f);
    buf[*n] = '\0';
    fclose(f);
    return buf;
}

/* Pupil: an export that starts with blank lines (and has CRLF line ends) is read; rows 0.008 s
 * apart; row 7 has confidence 0.2 (missing). x = 0.40 + 0.005 k, y = 1 - (0.70 - 0.005 k). */
static void test_pupil_blank_first(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    assert_int_equal(import(DATA "pupil_blank_first.csv", NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 20);
    assert_int_equal(tr.columns, 3);
    assert_int_equal(info.missing, 1);
    assert_int_equal(info.eyes, FV_GAZE_EYES_RIGHT); /* eye 0 rows only */
    assert_true(isnan(tr.v[7][0]));
    for (int k = 0; k < 20; k++) {
        assert_float_equal(tr.t[k], 0.008 * k, 1e-9);
        if (k != 7) assert_float_equal(tr.v[k][0], 0.40 + 0.005 * k, 1e-6), assert_float_equal(tr.v[k][1], 0.30 + 0.005 * k, 1e-6);
    }
    /* A bad row names the file and its line: two blank lines, the header, then row 1 at line 4. */
    const char *bad = tmp_path("bad.csv");
    const char text[] = "\n\ngaze_timestamp,confidence,norm_pos_x,norm_pos_y\n1,x,0.5,0.5\n";
    write_file(bad, text, sizeof text - 1);
    assert_int_equal(import(bad, NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.csv:4: expected numbers in gaze_timestamp and confidence"));
    /* Only blank lines: no header. */
    write_file(bad, "\n \n", 3);
    assert_int_equal(import(bad, NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "the header lacks gaze_timestamp (or timestamp)"));
}

/* Pupil before v1: the time column is `timestamp`. x = 0.20 + 0.01 k, rows 0.01 s apart. */
static void test_pupil_old_header(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    assert_int_equal(import(DATA "pupil_old_header.csv", NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 20);
    assert_int_equal(info.missing, 0);
    assert_float_equal(tr.t[19], 0.19, 1e-9);
    assert_float_equal(tr.v[19][0], 0.39, 1e-6);
    assert_float_equal(tr.v[19][1], 0.75, 1e-6);
    /* Every row is eye 0's (base_data "...-0"): there is no left eye to choose. */
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    o.eyes = FV_GAZE_EYES_LEFT;
    assert_int_equal(import(DATA "pupil_old_header.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "pupil_old_header.csv: no row is from the left eye"));
    const char *bad = tmp_path("old.csv");
    const char text[] = "timestamp,index,confidence,norm_pos_x,norm_pos_y\n1,0,0.9,0.5,0.5\nnope,1,0.9,0.5,0.5\n";
    write_file(bad, text, sizeof text - 1);
    assert_int_equal(import(bad, NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "old.csv:3: expected numbers in timestamp and confidence"));
}

/* Pupil, one row per eye: 40 moments 1/120 s apart, the right eye's (eye 0) and the left eye's (eye
 * 1) rows 0.13 ms apart (the left's first in moments 3, 8, 13, ...), x = 0.30 + 0.002 k - 0.045 (right) and
 * + 0.045 (left), norm y = 0.60 - 0.001 k + 0.01 (right) and - 0.01 (left); moment 10's left row
 * and both of moment 20's are below the confidence threshold; two rows mapped from both eyes end
 * the file (x = 0.38, 0.382). */
static void test_pupil_binocular(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    /* The file read row by row zigzags between the eyes (the issue: mean |dx| 0.09). */
    size_t n;
    char *text = slurp(DATA "pupil_binocular.csv", &n);
    double prev = NAN, sum = 0;
    int steps = 0;
    for (char *s = strchr(text, '\n') + 1; *s; s = strchr(s, '\n') + 1) {
        double t, c, x, y;
        assert_int_equal(sscanf(s, "%lf,%*d,%lf,%lf,%lf", &t, &c, &x, &y), 4);
        if (!isnan(prev)) sum += fabs(x - prev), steps++;
        prev = x;
    }
    free(text);
    assert_true(sum / steps > 0.06);

    /* Both (the default): one sample per moment, the mean of the two eyes. */
    assert_int_equal(import(DATA "pupil_binocular.csv", NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(info.eyes, FV_GAZE_EYES_BOTH);
    assert_int_equal(tr.columns, 3);
    assert_int_equal(tr.n, 42);
    assert_int_equal(info.paired, 40);
    assert_int_equal(info.missing, 1);
    assert_int_equal(info.dropped, 0);
    for (int k = 0; k < 40; k++) {
        assert_float_equal(tr.t[k], k / 120.0, 1e-6);
        if (k == 20) {
            assert_true(isnan(tr.v[k][0]));
            continue;
        }
        double dx = k == 10 ? -0.045 : 0.0, dy = k == 10 ? 0.01 : 0.0; /* moment 10: the right eye alone */
        assert_float_equal(tr.v[k][0], 0.30 + 0.002 * k + dx, 1e-6);
        assert_float_equal(tr.v[k][1], 1.0 - (0.60 - 0.001 * k + dy), 1e-6);
    }
    assert_float_equal(tr.v[41][0], 0.382, 1e-6);
    double both = mean_step(&tr, 40);
    assert_true(both < 0.006);

    /* Left: eye 1's rows (and the two combined ones). */
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    o.eyes = FV_GAZE_EYES_LEFT;
    assert_int_equal(import(DATA "pupil_binocular.csv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 42);
    assert_int_equal(info.missing, 2);
    for (int k = 0; k < 40; k++)
        if (k != 10 && k != 20) assert_float_equal(tr.v[k][0], 0.345 + 0.002 * k, 1e-6), assert_float_equal(tr.v[k][1], 0.41 + 0.001 * k, 1e-6);
    assert_true(isnan(tr.v[10][0]) && isnan(tr.v[20][0]));
    double left = mean_step(&tr, 40);
    assert_true(left < 0.003); /* a monocular trace's steps: 0.002 */
    assert_true(both < 2 * left + 0.002);

    o.eyes = FV_GAZE_EYES_RIGHT;
    assert_int_equal(import(DATA "pupil_binocular.csv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 42);
    assert_int_equal(info.missing, 1);
    assert_float_equal(tr.v[10][0], 0.255 + 0.020, 1e-6);
    assert_float_equal(tr.v[10][1], 1.0 - (0.60 - 0.010 + 0.01), 1e-6);

    /* Each: a five-column trace a stereo render takes each eye's gaze from. */
    o.eyes = FV_GAZE_EYES_EACH;
    assert_int_equal(import(DATA "pupil_binocular.csv", &o, &info, &tr, &err), FV_OK);
    assert_true(info.binocular);
    assert_int_equal(tr.columns, 5);
    assert_float_equal(tr.v[5][0], 0.355, 1e-6);
    assert_float_equal(tr.v[5][2], 0.265, 1e-6);
    fv_gaze_path *p;
    assert_int_equal(fv_gaze_path_load_csv(tmp_path("trace.csv"), &p, &err), FV_OK);
    fv_gaze l, r;
    assert_true(fv_gaze_path_eval(p, 5.0 / 120.0, &l, &r));
    assert_float_equal(l.x, 0.355, 1e-5);
    assert_float_equal(r.x, 0.265, 1e-5);
    fv_gaze_path_destroy(p);
}

/* EyeLink at 2000 Hz, stamps in whole milliseconds (two samples per stamp): all 40 samples are
 * kept, 0.5 ms apart; x = (640 + 0.5 i) / 1280. */
static void test_eyelink_2000hz(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    assert_int_equal(import(DATA "eyelink_2000hz.asc", NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 40);
    assert_int_equal(info.dropped, 0);
    assert_int_equal(info.eyes, FV_GAZE_EYES_RIGHT);
    assert_float_equal(info.rate, 2000.0, 0.0);
    for (int i = 0; i < 40; i++) {
        assert_float_equal(tr.t[i], 0.0005 * i, 1e-9);
        assert_float_equal(tr.v[i][0], (640.0 + 0.5 * i) / 1280.0, 1e-6);
    }
    /* The rate from the RECCFG message alone; and without any rate the repeated stamps cannot be
     * timed (the old behaviour: half the samples dropped). */
    size_t n;
    char *text = slurp(DATA "eyelink_2000hz.asc", &n);
    char *reccfg = malloc(n + 1), *none = malloc(n + 1);
    size_t a = 0, b = 0;
    for (char *s = text; *s;) {
        size_t len = strcspn(s, "\n") + 1;
        s[len - 1] = '\0';
        bool rate_line = !strncmp(s, "SAMPLES", 7) || !strncmp(s, "EVENTS", 6), reccfg_line = strstr(s, "RECCFG") != NULL;
        s[len - 1] = '\n';
        if (!rate_line) memcpy(reccfg + a, s, len), a += len;
        if (!rate_line && !reccfg_line) memcpy(none + b, s, len), b += len;
        s += len;
    }
    write_file(tmp_path("reccfg.asc"), reccfg, a);
    write_file(tmp_path("norate.asc"), none, b);
    assert_int_equal(import(tmp_path("reccfg.asc"), NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 40);
    assert_float_equal(tr.t[39], 0.0195, 1e-9);
    assert_int_equal(import(tmp_path("norate.asc"), NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 20);
    assert_int_equal(info.dropped, 20);
    free(text);
    free(reccfg);
    free(none);
}

/* A gzip-compressed recording reads as the plain one; truncated, corrupt or inflating past the
 * limit, it is refused with one line naming it, and nothing is written. */
static void test_eyelink_gz(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace plain, tr;
    assert_int_equal(import(DATA "eyelink_2000hz.asc", NULL, &info, &plain, &err), FV_OK);
    assert_false(info.compressed);
    assert_int_equal(import(DATA "eyelink_2000hz.asc.gz", NULL, &info, &tr, &err), FV_OK);
    assert_true(info.compressed);
    assert_int_equal(tr.n, plain.n);
    assert_memory_equal(tr.t, plain.t, sizeof tr.t[0] * (size_t)tr.n);
    assert_memory_equal(tr.v, plain.v, sizeof tr.v[0] * (size_t)tr.n);
    /* The trials file compressed here with zlib, under a name without .asc: --format says. */
    size_t n;
    char *text = slurp(DATA "eyelink_trials.asc", &n);
    gzFile gz = gzopen(tmp_path("trials.gz"), "wb");
    assert_non_null(gz);
    assert_int_equal(gzwrite(gz, text, (unsigned)n), (int)n);
    assert_int_equal(gzclose(gz), Z_OK);
    free(text);
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    assert_int_equal(import(tmp_path("trials.gz"), &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "unknown recording format"));
    o.format = FV_GAZE_FORMAT_EYELINK_ASC;
    assert_int_equal(import(tmp_path("trials.gz"), &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 21);
    assert_int_equal(info.gaps, 1);

    char *gzdata = slurp(DATA "eyelink_2000hz.asc.gz", &n);
    write_file(tmp_path("cut.asc.gz"), gzdata, n / 2);
    assert_int_equal(import(tmp_path("cut.asc.gz"), NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "cut.asc.gz: the compressed data ends early"));
    for (size_t i = 20; i < 60; i++) gzdata[i] ^= 0x5a;
    write_file(tmp_path("bad.asc.gz"), gzdata, n);
    assert_int_equal(import(tmp_path("bad.asc.gz"), NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.asc.gz: "));
    assert_null(strchr(err.msg, '\n'));
    free(gzdata);
    o.format = FV_GAZE_FORMAT_AUTO;
    o.max_inflated = 1000; /* the file inflates to 1740 bytes */
    assert_int_equal(import(DATA "eyelink_2000hz.asc.gz", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "eyelink_2000hz.asc.gz: inflates to more than 1000 bytes"));
}

/* Two trials (500 Hz, left eye, x 100 px then 900 px of 1000) with a 1 s break between them: the
 * break is one missing sample at the first trial's END (20 ms), not an interpolation from x = 0.1
 * to 0.9. */
static void test_eyelink_trials(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    assert_int_equal(import(DATA "eyelink_trials.asc", NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 21);
    assert_int_equal(info.gaps, 1);
    assert_int_equal(info.missing, 1);
    assert_float_equal(tr.t[9], 0.018, 1e-9);
    assert_float_equal(tr.t[10], 0.020, 1e-9);
    assert_true(isnan(tr.v[10][0]));
    assert_float_equal(tr.t[11], 1.020, 1e-9);
    fv_gaze_path *p;
    assert_int_equal(fv_gaze_path_load_csv(tmp_path("trace.csv"), &p, &err), FV_OK);
    fv_gaze g;
    assert_true(fv_gaze_path_eval(p, 0.010, &g, NULL));
    assert_false(fv_gaze_path_eval(p, 0.5, &g, NULL)); /* unknown during the break */
    assert_float_equal(g.x, 0.1, 1e-6);                  /* held, not 0.5 */
    assert_true(fv_gaze_path_eval(p, 1.03, &g, NULL));
    assert_float_equal(g.x, 0.9, 1e-6);
    fv_gaze_path_destroy(p);
}

/* The eye choice on a binocular EyeLink recording (tests/data/eyelink_bino.asc, 800x600: at 20 ms
 * left (400,300), right (410,300); at 24 ms the left lost; at 28 ms the right in a blink). */
static void test_eyelink_eyes(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    assert_int_equal(import(DATA "eyelink_bino.asc", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(info.eyes, FV_GAZE_EYES_EACH);
    assert_int_equal(tr.columns, 5);
    o.eyes = FV_GAZE_EYES_BOTH;
    assert_int_equal(import(DATA "eyelink_bino.asc", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.columns, 3);
    assert_float_equal(tr.v[0][0], 0.50625, 1e-6);
    assert_float_equal(tr.v[1][0], 0.5125, 1e-6); /* the right eye alone */
    assert_float_equal(tr.v[2][0], 0.25, 1e-6);   /* the left eye alone */
    o.eyes = FV_GAZE_EYES_RIGHT;
    assert_int_equal(import(DATA "eyelink_bino.asc", &o, &info, &tr, &err), FV_OK);
    assert_float_equal(tr.v[0][0], 0.5125, 1e-6);
    assert_true(isnan(tr.v[2][0]));
    assert_int_equal(info.missing, 1);
    /* A left-eye recording has no right eye. */
    assert_int_equal(import(DATA "eyelink_mono.asc", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "eyelink_mono.asc: the recording has no right-eye samples"));
    /* A sample line short of a value for each eye names its line. */
    const char text[] = "MSG\t1 DISPLAY_COORDS 0 0 99 99\nSTART\t1 \tLEFT\tRIGHT\tSAMPLES\n1\t1.0\t2.0\t3.0\t4.0\t5.0\t6.0\n2\t1.0\t2.0\t3.0\t...\n";
    write_file(tmp_path("short.asc"), text, sizeof text - 1);
    assert_int_equal(import(tmp_path("short.asc"), NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "short.asc:4: expected a sample"));
}

/* ---- tables (--format table) and Tobii Pro Lab exports (src/gaze/gaze_table.c) ---- */

/* A mapping for one gaze: --time time --x x --y y. */
/* The first n samples of a three-column trace: times within t_tol of t[], gazes within 1e-6 of
 * (x[], y[]), a NaN x meaning a missing sample (both fields empty). */
static void expect_samples(const trace *tr, int n, const double *t, double t_tol, const double *x, const double *y)
{
    for (int k = 0; k < n; k++) {
        assert_float_equal(tr->t[k], t[k], t_tol);
        if (isnan(x[k])) assert_true(isnan(tr->v[k][0]) && isnan(tr->v[k][1]));
        else assert_float_equal(tr->v[k][0], x[k], 1e-6), assert_float_equal(tr->v[k][1], y[k], 1e-6);
    }
}

static fv_gaze_import_opts table_opts(const char *t, const char *x, const char *y)
{
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    o.table.time = t;
    o.table.x = x;
    o.table.y = y;
    return o;
}

/* table_norm.csv: normalised, seconds, a note column first whose quoted fields hold commas (and
 * ""), found by name in any case (GX as gx). Rows at 10.000 ... 10.060 s: times from the first,
 * 0 ... 0.06; (0.5,0.5), (0.25,0.75); three missing by each marker (empty, nan/NaN, - and .);
 * (0.8,0.2); a second row at 10.050 s (dropped); x = 1.2, off the screen (missing). */
static void test_table_norm(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    fv_gaze_import_opts o = table_opts("TIME", "gx", "gy");
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(info.format, FV_GAZE_FORMAT_TABLE); /* a .csv with a mapping is a table */
    assert_int_equal(tr.n, 7);
    assert_int_equal(tr.columns, 3);
    assert_int_equal(info.missing, 4);
    assert_int_equal(info.dropped, 1);
    assert_int_equal(info.eyes, FV_GAZE_EYES_BOTH);
    static const double t[7] = {0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06}, x[7] = {0.5, 0.25, NAN, NAN, NAN, 0.8, NAN},
                        y[7] = {0.5, 0.75, NAN, NAN, NAN, 0.2, NAN};
    expect_samples(&tr, 7, t, 1e-9, x, y);
    /* The same y with the origin at the bottom left: 1 - 0.75 = 0.25, 1 - 0.2 = 0.8. */
    o.table.bottom_left = true;
    o.format = FV_GAZE_FORMAT_TABLE;
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_OK);
    assert_float_equal(tr.v[1][1], 0.25, 1e-6);
    assert_float_equal(tr.v[5][1], 0.8, 1e-6);
    /* Milliseconds: the 10 ms steps become 10 us. */
    o.table.time_unit = 1e-3;
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_OK);
    assert_float_equal(tr.t[1], 1e-5, 1e-12);
    /* The trace reads back: a blink from 0.02 s to 0.04 s is unknown gaze. */
    o = table_opts("time", "gx", "gy");
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_OK);
    fv_gaze_path *p;
    assert_int_equal(fv_gaze_path_load_csv(tmp_path("trace.csv"), &p, &err), FV_OK);
    fv_gaze g;
    assert_true(fv_gaze_path_eval(p, 0.005, &g, NULL));
    assert_float_equal(g.x, 0.375, 1e-6); /* halfway from 0.5 to 0.25 */
    assert_false(fv_gaze_path_eval(p, 0.03, &g, NULL));
    fv_gaze_path_destroy(p);
}

/* table_px_bottomleft.tsv: tab-separated, ms, pixels of 1920x1080 with the origin at the bottom
 * left, both eyes, and a validity column (1, true, 0, YES). Left eye at 1000 ms (960,540):
 * 960/1920 = 0.5, 1 - 540/1080 = 0.5; right (980,560): 0.5104167, 1 - 0.5185185 = 0.4814815.
 * At 1004 ms left (480,270): 0.25, 0.75; right (500,250): 0.2604167, 0.7685185. At 1008 ms
 * invalid. At 1012 ms left (1920,0): 1, 1 (the screen's corner); right (1900,20): 0.9895833,
 * 0.9814815. */
static void test_table_px_two_eyes(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    o.table = (fv_gaze_table_opts){.time = "time (ms)", .left_x = "LX", .left_y = "LY", .right_x = "RX", .right_y = "RY", .valid = "valid",
                                   .time_unit = 1e-3, .pixels = true, .bottom_left = true};
    /* Pixels need their screen. */
    assert_int_equal(import(DATA "table_px_bottomleft.tsv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--coords px needs the screen the pixels are of (--screen WxH)"));
    o.width = 1920, o.height = 1080;
    assert_int_equal(import(DATA "table_px_bottomleft.tsv", &o, &info, &tr, &err), FV_OK);
    /* Per-eye columns of one row are one instant: each eye its own gaze by default, as EyeLink. */
    assert_int_equal(info.eyes, FV_GAZE_EYES_EACH);
    assert_int_equal(tr.columns, 5);
    assert_int_equal(tr.n, 4);
    assert_int_equal(info.missing, 1);
    assert_float_equal(info.width, 1920, 0);
    static const double t[4] = {0, 0.004, 0.008, 0.012};
    static const double v[4][4] = {{0.5, 0.5, 0.5104167, 0.4814815},
                                   {0.25, 0.75, 0.2604167, 0.7685185},
                                   {NAN, NAN, NAN, NAN},
                                   {1.0, 1.0, 0.9895833, 0.9814815}};
    for (int k = 0; k < 4; k++) {
        assert_float_equal(tr.t[k], t[k], 1e-9);
        for (int c = 0; c < 4; c++)
            if (isnan(v[k][c])) assert_true(isnan(tr.v[k][c]));
            else assert_float_equal(tr.v[k][c], v[k][c], 1e-6);
    }
    /* both: the mean, (0.5 + 0.5104167)/2 = 0.5052083, (0.5 + 0.4814815)/2 = 0.4907407. */
    o.eyes = FV_GAZE_EYES_BOTH;
    assert_int_equal(import(DATA "table_px_bottomleft.tsv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.columns, 3);
    assert_float_equal(tr.v[0][0], 0.5052083, 1e-6);
    assert_float_equal(tr.v[0][1], 0.4907407, 1e-6);
    o.eyes = FV_GAZE_EYES_RIGHT;
    assert_int_equal(import(DATA "table_px_bottomleft.tsv", &o, &info, &tr, &err), FV_OK);
    assert_float_equal(tr.v[3][0], 0.9895833, 1e-6);
    assert_float_equal(tr.v[3][1], 0.9814815, 1e-6);
    /* Only the left eye mapped: its trace, and no right eye to ask for. */
    o.table.right_x = o.table.right_y = NULL;
    o.eyes = FV_GAZE_EYES_DEFAULT;
    assert_int_equal(import(DATA "table_px_bottomleft.tsv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(info.eyes, FV_GAZE_EYES_LEFT);
    assert_float_equal(tr.v[1][0], 0.25, 1e-6);
    o.eyes = FV_GAZE_EYES_RIGHT;
    assert_int_equal(import(DATA "table_px_bottomleft.tsv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "table_px_bottomleft.tsv: no right-eye columns"));
}

/* table_semicolon.csv: semicolons, decimal commas, CRLF: 5,000 s (0,5; 0,25), 5,020 s (0,75;
 * 0,125), 5,040 s missing. table_noheader.csv: no header, columns by number (2: time, 3 and 4:
 * x, y) at 2.000 ... 2.012 s: (0.1,0.2), (0.3,0.4), missing, (0.5,0.6). */
static void test_table_delimiters_and_numbers(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    fv_gaze_import_opts o = table_opts("t", "x", "y");
    assert_int_equal(import(DATA "table_semicolon.csv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 3);
    assert_float_equal(tr.t[1], 0.02, 1e-9);
    assert_float_equal(tr.v[0][0], 0.5, 1e-9);
    assert_float_equal(tr.v[0][1], 0.25, 1e-9);
    assert_float_equal(tr.v[1][0], 0.75, 1e-9);
    assert_float_equal(tr.v[1][1], 0.125, 1e-9);
    assert_true(isnan(tr.v[2][0]));
    o = table_opts("2", "3", "4");
    assert_int_equal(import(DATA "table_noheader.csv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 4); /* the first line is a row */
    static const double t[4] = {0, 0.004, 0.008, 0.012}, x[4] = {0.1, 0.3, NAN, 0.5}, y[4] = {0.2, 0.4, NAN, 0.6};
    expect_samples(&tr, 4, t, 1e-9, x, y);
    /* Without a header, names mean nothing; numbers past the row do not exist. */
    o = table_opts("2", "3", "y");
    assert_int_equal(import(DATA "table_noheader.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--y y: the file has no header line, so its columns are named by number (1 to 4)"));
    o = table_opts("2", "3", "5");
    assert_int_equal(import(DATA "table_noheader.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--y 5: the first row has 4 columns"));
    /* A header and numbers: the time's column 2 holds "time", so the first line is a header. */
    o = table_opts("2", "3", "4");
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 7);
    assert_float_equal(tr.v[1][0], 0.25, 1e-6);
}

/* Refusals: one line naming the file (and line and column for a row), nothing written. */
/* Nanoseconds since 1970 (Pupil Cloud's gaze.csv: some 1.7e18, beyond what a double holds to the
 * nanosecond; its ulp there is 256 ns): rows 5 ms apart must come out 0.005 s apart, not 0.005 s
 * give or take a few hundred ns. Pixels of a 1600x1200 scene camera: 800/1600 = 0.5,
 * 816/1600 = 0.51, 612/1200 = 0.51, 400/1600 = 0.25, 300/1200 = 0.25; `worn` 0 is missing. */
static void test_table_ns_epoch(void **st)
{
    (void)st;
    const char *path = tmp_path("neon.csv");
    const char neon[] = "section id,timestamp [ns],gaze x [px],gaze y [px],worn\n"
                        "a,1700000000000000000,800.0,600.0,1\n"
                        "a,1700000000005000000,816.0,612.0,1\n"
                        "a,1700000000010000000,,,0\n"
                        "a,1700000000015000000,400.0,300.0,1\n";
    write_file(path, neon, sizeof neon - 1);
    fv_gaze_import_opts o = table_opts("timestamp [ns]", "gaze x [px]", "gaze y [px]");
    o.table.time_unit = 1e-9;
    o.table.pixels = true;
    o.table.valid = "worn";
    o.width = 1600, o.height = 1200;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    assert_int_equal(import(path, &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 4);
    assert_int_equal(info.missing, 1);
    static const double t[4] = {0, 0.005, 0.01, 0.015}, x[4] = {0.5, 0.51, NAN, 0.25}, y[4] = {0.5, 0.51, NAN, 0.25};
    expect_samples(&tr, 4, t, 1e-12, x, y);
}

static void test_table_refusals(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    fv_gaze_import_opts o = table_opts("time", "gz", "gy");
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "table_norm.csv: --x gz: no such column; the header has 'note', 'time', 'GX', 'gy'"));
    o = table_opts("time", "gx", "GX");
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "table_norm.csv: --x and --y both name column 'GX'"));
    o = table_opts("gy", "gx", "gy");
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--time and --y both name column 'gy'"));
    o = table_opts("time", "gx", NULL);
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--x needs --y"));
    o = table_opts("time", "gx", "gy");
    o.eyes = FV_GAZE_EYES_EACH;
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--x/--y give one gaze; --eye each needs per-eye columns"));
    o = table_opts("time", "gx", "gy");
    o.width = 640, o.height = 480; /* a screen for normalised coordinates: a forgotten --coords px */
    assert_int_equal(import(DATA "table_norm.csv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--screen is for a table in pixels"));
    o = table_opts("time", "gx", "gy");
    o.format = FV_GAZE_FORMAT_EYELINK_ASC;
    assert_int_equal(import(DATA "eyelink_mono.asc", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "the column options (--time, --x, --coords, ...) are for --format table"));

    o = table_opts("t", "x", "y");
    char bad[256]; /* tmp_path's buffers are reused by import() */
    snprintf(bad, sizeof bad, "%s", tmp_path("bad.csv"));
    write_file(bad, "", 0);
    assert_int_equal(import(bad, &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.csv: the file is empty"));
    const char malformed[] = "t,x,y\n0,0.1,0.2\n\n0.01,0.3,0.4e\n";
    write_file(bad, malformed, sizeof malformed - 1);
    assert_int_equal(import(bad, &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.csv:4: column 'y': '0.4e' is not a number"));
    const char time[] = "t,x,y\n0,0.1,0.2\nsoon,0.3,0.4\n";
    write_file(bad, time, sizeof time - 1);
    assert_int_equal(import(bad, &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.csv:3: column 't' (the time): 'soon' is not a number"));
    /* Out of order: refused, not sorted (a table of one row per moment out of order has a wrong
     * time column or two recordings pasted together). */
    const char order[] = "t,x,y\n0,0.1,0.2\n0.02,0.3,0.4\n0.01,0.5,0.6\n";
    write_file(bad, order, sizeof order - 1);
    assert_int_equal(import(bad, &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.csv:4: time 0.01 s is before the previous row's 0.02 s"));
    const char quote[] = "t,x,y,note\n0,0.1,0.2,\"open\n";
    write_file(bad, quote, sizeof quote - 1);
    assert_int_equal(import(bad, &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.csv:2: a quoted field is not closed on its line"));
    /* A .csv that is not Pupil's, named without a mapping: the message says how to map it. */
    assert_int_equal(import(DATA "table_norm.csv", NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "not Pupil's gaze_positions.csv (for another table: --format table --time COL --x COL --y COL)"));
    /* A .tsv that is not Tobii's, likewise. */
    assert_int_equal(import(DATA "table_px_bottomleft.tsv", NULL, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "not a Tobii Pro Lab export"));
    assert_non_null(strstr(err.msg, "--format table --time COL --x COL --y COL"));
}

/* tobii_prolab.tsv (Pro Lab's columns, 1920x1080, "Recording timestamp [us]" with the micro
 * sign): an event row at 1.990 s (RecordingStart) before the first sample at 2.000 s, so times
 * count from 2.000 s; samples at 2.000000, 2.008333, 2.016667, 2.025000, 2.033333 s and an event
 * row at 2.010 s (both events skipped). Gaze point (960,540) -> (0.5,0.5); (480,270) -> (0.25,
 * 0.25); at 2.016667 s the left eye Invalid, the right Valid: Tobii's gaze (1440,810) -> (0.75,
 * 0.75); at 2.025 s both Invalid, no gaze: missing; (192,108) -> (0.1,0.1). Per eye at 2.000 s:
 * left (950,530) -> 0.4947917, 0.4907407; right (970,550) -> 0.5052083, 0.5092593. */
static void test_tobii(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    assert_int_equal(import(DATA "tobii_prolab.tsv", NULL, &info, &tr, &err), FV_OK);
    assert_int_equal(info.format, FV_GAZE_FORMAT_TOBII); /* from the .tsv's header */
    assert_int_equal(info.eyes, FV_GAZE_EYES_BOTH);
    assert_int_equal(info.skipped, 2);
    assert_int_equal(info.missing, 1);
    assert_int_equal(tr.n, 5);
    assert_int_equal(tr.columns, 3);
    assert_float_equal(info.width, 1920, 0);
    assert_float_equal(info.height, 1080, 0);
    static const double t[5] = {0, 0.008333, 0.016667, 0.025, 0.033333}, xy[5] = {0.5, 0.25, 0.75, NAN, 0.1};
    expect_samples(&tr, 5, t, 1e-9, xy, xy);
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    o.eyes = FV_GAZE_EYES_EACH;
    o.format = FV_GAZE_FORMAT_TOBII;
    assert_int_equal(import(DATA "tobii_prolab.tsv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.columns, 5);
    assert_int_equal(info.missing, 2); /* 2.016667 s (the left eye) and 2.025 s */
    assert_float_equal(tr.v[0][0], 0.4947917, 1e-6);
    assert_float_equal(tr.v[0][1], 0.4907407, 1e-6);
    assert_float_equal(tr.v[0][2], 0.5052083, 1e-6);
    assert_float_equal(tr.v[0][3], 0.5092593, 1e-6);
    assert_true(isnan(tr.v[2][0]));
    assert_float_equal(tr.v[2][2], 0.75, 1e-6);
    /* The five-column trace reads back as two eyes' gaze. */
    fv_gaze_path *p;
    assert_int_equal(fv_gaze_path_load_csv(tmp_path("trace.csv"), &p, &err), FV_OK);
    fv_gaze_path_destroy(p);
    /* A unit of the header's overridden: as if the stamps were ns, 8333 ns apart. */
    o.eyes = FV_GAZE_EYES_DEFAULT;
    o.table.time_unit = 1e-9;
    assert_int_equal(import(DATA "tobii_prolab.tsv", &o, &info, &tr, &err), FV_OK);
    assert_float_equal(tr.t[1], 8.333e-6, 1e-12);
    /* Tobii's columns are its own. */
    o.table.x = "Gaze point X";
    assert_int_equal(import(DATA "tobii_prolab.tsv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "are for --format table"));
}

/* tobii_ms.tsv: "Recording timestamp [ms]", Tobii's gaze alone, no validity and no recording
 * resolution (--screen 640x480): 100.0 ms (320,240) -> (0.5,0.5); 116.5 ms (640,480) -> (1,1);
 * an event row at 120.0 ms (skipped); 133.0 ms with no gaze and no event: a lost sample, missing;
 * 149.5 ms (0,0). */
static void test_tobii_ms(void **st)
{
    (void)st;
    fv_gaze_import_info info;
    fv_error err;
    trace tr;
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    assert_int_equal(import(DATA "tobii_ms.tsv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "tobii_ms.tsv:2: gaze in pixels, and no recording resolution in the row (give the screen with --screen WxH)"));
    o.width = 640, o.height = 480;
    assert_int_equal(import(DATA "tobii_ms.tsv", &o, &info, &tr, &err), FV_OK);
    assert_int_equal(tr.n, 4);
    assert_int_equal(info.skipped, 1);
    assert_int_equal(info.missing, 1);
    static const double t[4] = {0, 0.0165, 0.033, 0.0495}, xy[4] = {0.5, 1.0, NAN, 0.0};
    expect_samples(&tr, 4, t, 1e-9, xy, xy);
    /* No per-eye columns: no eye to choose. */
    o.eyes = FV_GAZE_EYES_LEFT;
    assert_int_equal(import(DATA "tobii_ms.tsv", &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "--eye left needs the per-eye columns"));
    /* A unit fovea does not know, and a .tsv without Tobii's time. */
    char bad[256];
    snprintf(bad, sizeof bad, "%s", tmp_path("bad.tsv"));
    const char minutes[] = "Recording timestamp [min]\tGaze point X\tGaze point Y\n1\t2\t3\n";
    write_file(bad, minutes, sizeof minutes - 1);
    o.eyes = FV_GAZE_EYES_DEFAULT;
    assert_int_equal(import(bad, &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.tsv: the header gives the recording timestamp in [min]"));
    const char notime[] = "Timestamp\tGaze point X\tGaze point Y\n1\t2\t3\n";
    write_file(bad, notime, sizeof notime - 1);
    o.format = FV_GAZE_FORMAT_TOBII;
    assert_int_equal(import(bad, &o, &info, &tr, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bad.tsv: no 'Recording timestamp' column"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pupil_blank_first), cmocka_unit_test(test_pupil_old_header), cmocka_unit_test(test_pupil_binocular),
        cmocka_unit_test(test_eyelink_2000hz),    cmocka_unit_test(test_eyelink_gz),       cmocka_unit_test(test_eyelink_trials),
        cmocka_unit_test(test_eyelink_eyes),      cmocka_unit_test(test_table_norm),       cmocka_unit_test(test_table_px_two_eyes),
        cmocka_unit_test(test_table_delimiters_and_numbers), cmocka_unit_test(test_table_refusals), cmocka_unit_test(test_table_ns_epoch), cmocka_unit_test(test_tobii),
        cmocka_unit_test(test_tobii_ms),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
