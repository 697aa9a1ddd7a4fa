/* fovea — reading the numeric CSV files of gaze and camera traces: one sample per line, numbers
 * separated by commas, '#' comments, blank lines, and one optional header line (without digits)
 * before the first sample. */
#ifndef FV_CORE_CSV_H
#define FV_CORE_CSV_H

#include <stdbool.h>
#include "fovea/status.h"

typedef enum fv_csv_kind { FV_CSV_SKIP = 0, FV_CSV_HEADER, FV_CSV_ROW, FV_CSV_BAD } fv_csv_kind;

/* Classifies one line; for a row, the numbers go to v (at most max) and their count to *n. An
 * empty field reads as NaN, as does "nan" (strtod): a value the file marks as unknown, which each
 * reader accepts (a gaze trace's missing sample) or refuses (a camera trace's coordinates).
 * `before_rows` says no sample or header has been seen yet (only then is a header accepted). */
fv_csv_kind fv_csv_line(const char *line, bool before_rows, double *v, int max, int *n);

/* Called for each sample line with its numbers (v[0] is the time, finite and increasing: the
 * reader checks it); returns FV_OK or an error naming path:line. */
typedef fv_status (*fv_csv_row_fn)(void *ctx, const double *v, int n, const char *path, int line, fv_error *err);

/* Reads a trace file line by line: comments, blank lines and one header are skipped; a line that is
 * not a row of at most `max` numbers fails with "path:line: expected <expect>"; a time that is not
 * finite or does not increase fails too; so does a file without samples, a line longer than
 * FV_LINE_MAX bytes ("path:line: line longer than 65536 bytes") and anything but a regular file
 * (fv_file_open_read: /dev/zero would read forever, a FIFO block). `what` names the file in
 * messages ("gaze trace"). */
fv_status fv_csv_read(const char *path, const char *what, int max, const char *expect, fv_csv_row_fn row, void *ctx, fv_error *err);

#endif
