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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pupil_blank_first), cmocka_unit_test(test_pupil_old_header), cmocka_unit_test(test_pupil_binocular),
        cmocka_unit_test(test_eyelink_2000hz),    cmocka_unit_test(test_eyelink_gz),       cmocka_unit_test(test_eyelink_trials),
        cmocka_unit_test(test_eyelink_eyes),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
