/* fovea — reading the numeric CSV files of gaze and camera traces: one sample per line, numbers
 * separated by commas, '#' comments, blank lines, and one optional header line (without digits)
 * before the first sample. */
#ifndef FV_CORE_CSV_H
#define FV_CORE_CSV_H

#include <stdbool.h>

typedef enum fv_csv_kind { FV_CSV_SKIP = 0, FV_CSV_HEADER, FV_CSV_ROW, FV_CSV_BAD } fv_csv_kind;

/* Classifies one line; for a row, the numbers go to v (at most max) and their count to *n.
 * `before_rows` says no sample or header has been seen yet (only then is a header accepted). */
fv_csv_kind fv_csv_line(const char *line, bool before_rows, double *v, int max, int *n);

#endif
