/* fovea — numeric CSV lines (see csv.h). */
#include <stdlib.h>
#include <string.h>
#include "core/csv.h"

fv_csv_kind fv_csv_line(const char *line, bool before_rows, double *v, int max, int *n)
{
    const char *s = line;
    while (*s == ' ' || *s == '\t') s++;
    if (*s == '#' || *s == '\n' || *s == '\r' || *s == '\0') return FV_CSV_SKIP;
    *n = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t') s++;
        if (*s == '\0' || *s == '\n' || *s == '\r') return *n > 0 ? FV_CSV_ROW : FV_CSV_BAD;
        char *end;
        double x = strtod(s, &end);
        if (end == s || *n == max) break;
        v[(*n)++] = x;
        s = end;
        while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n') s++;
        if (*s == ',') s++;
        else if (*s != '\0') break;
    }
    /* Not a row of numbers: a header is allowed once, before the samples, and has no digits. */
    return before_rows && !strpbrk(line, "0123456789") ? FV_CSV_HEADER : FV_CSV_BAD;
}
