/* fovea — numeric CSV lines (see csv.h). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/csv.h"
#include "core/fileio.h"

fv_csv_kind fv_csv_line(const char *line, bool before_rows, double *v, int max, int *n)
{
    const char *s = line;
    while (*s == ' ' || *s == '\t') s++;
    if (*s == '#' || *s == '\n' || *s == '\r' || *s == '\0') return FV_CSV_SKIP;
    *n = 0;
    bool ok = true;
    for (;;) {
        while (*s == ' ' || *s == '\t') s++;
        if (*n == max) {
            ok = false;
            break;
        }
        if (*s == ',' || *s == '\0' || *s == '\n' || *s == '\r') {
            v[(*n)++] = NAN; /* an empty field: a value the file does not know */
        } else {
            char *end;
            double x = strtod(s, &end);
            if (end == s) {
                ok = false;
                break;
            }
            v[(*n)++] = x;
            s = end;
            while (*s == ' ' || *s == '\t') s++;
        }
        if (*s == ',') {
            s++;
            continue;
        }
        while (*s == '\r' || *s == '\n') s++;
        ok = *s == '\0';
        break;
    }
    if (ok) return FV_CSV_ROW;
    /* Not a row of numbers: a header is allowed once, before the samples, and has no digits. */
    return before_rows && !strpbrk(line, "0123456789") ? FV_CSV_HEADER : FV_CSV_BAD;
}

fv_status fv_csv_read(const char *path, const char *what, int max, const char *expect, fv_csv_row_fn row, void *ctx, fv_error *err)
{
    FILE *f;
    fv_status st = fv_file_open_read(path, what, &f, err);
    if (st != FV_OK) return st;
    char *line = NULL;
    size_t cap = 0;
    int lineno = 0, rows = 0;
    bool before = true;
    double prev = 0.0, v[32];
    if (max > 32) max = 32;
    long len;
    while (st == FV_OK && (len = fv_file_getline(f, &line, &cap, FV_LINE_MAX)) != 0) {
        lineno++;
        if (len < 0) {
            st = len == -1 ? fv_error_set(err, FV_ERR_INVALID, "%s:%d: line longer than %d bytes", path, lineno, FV_LINE_MAX)
                           : fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
            break;
        }
        if (lineno == 1) fv_file_strip_bom(line, len);
        int n = 0;
        fv_csv_kind kind = fv_csv_line(line, before, v, max, &n);
        if (kind == FV_CSV_SKIP) continue;
        before = false;
        if (kind == FV_CSV_HEADER) continue;
        if (kind == FV_CSV_BAD) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected %s", path, lineno, expect);
        } else if (!isfinite(v[0])) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: time must be finite", path, lineno);
        } else if (rows > 0 && !(v[0] > prev)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: time %g does not increase (previous %g)", path, lineno, v[0], prev);
        } else {
            st = row(ctx, v, n, path, lineno, err);
            prev = v[0];
            rows++;
        }
    }
    if (st == FV_OK && ferror(f)) st = fv_error_set(err, FV_ERR_IO, "cannot read %s '%s': %s", what, path, strerror(errno));
    if (st == FV_OK && rows == 0) st = fv_error_set(err, FV_ERR_INVALID, "%s: the %s has no samples", path, what);
    free(line);
    fclose(f);
    return st;
}
