/* fovea — what the recording readers of `fovea gaze import` share (docs/gaze.md, "Importing"):
 * the trace writer and its eye choice, bounded line reading, and splitting a delimited line into
 * fields. gaze_import.c holds these with the EyeLink and Pupil readers and the entry point;
 * gaze_table.c reads generic delimited tables and Tobii Pro Lab exports through them. */
#ifndef FV_GAZE_IMPORT_H
#define FV_GAZE_IMPORT_H

#include <stdbool.h>
#include <stdio.h>
#include "fovea/gaze.h"

/* The trace being written. */
typedef struct fv_gaze_writer {
    FILE *f;
    const char *in;
    fv_gaze_eyes eyes; /* resolved by the reader before its first sample: never DEFAULT */
    bool binocular;    /* five columns (eyes == EACH) */
    bool any;
    long known[2]; /* samples with a known gaze, per column pair */
    double t0, prev;
    fv_gaze_import_info *info;
} fv_gaze_writer;

/* The next line of the recording (at most FV_LINE_MAX bytes): true for a line; false at the end,
 * on a read error (ferror tells) or with *st set for a line too long. */
bool fv_gaze_read_line(FILE *in, const fv_gaze_writer *w, char **line, size_t *cap, int lineno, fv_status *st, fv_error *err);

/* Normalised coordinates on the screen ([0,1] both; NaN is not). */
bool fv_gaze_on_screen(double x, double y);

/* One moment's gaze of each eye (in seconds of the recording's clock; NaN, or off the screen:
 * missing or not recorded), written as w->eyes wants it. False when the sample was dropped (its
 * time, as written, does not increase; counted in info->dropped). */
bool fv_gaze_emit(fv_gaze_writer *w, double t, double xl, double yl, double xr, double yr);

/* The fields of one delimited line (CSV, TSV, semicolons): a field in double quotes may hold the
 * delimiter and "" for a quote; spaces around a field are left off (tabs too unless they
 * delimit). f[k] is the k-th field, NUL-terminated, len[k] its length. The storage is reused from
 * line to line; zero-initialise, release with fv_gaze_fields_free. */
typedef struct fv_gaze_fields {
    char *buf;
    size_t bufcap;
    const char **f;
    size_t *len;
    int n, cap, lencap;
    bool unterminated; /* a quoted field ran to the end of the line */
} fv_gaze_fields;

/* Splits line at delim; false when out of memory. */
bool fv_gaze_fields_split(fv_gaze_fields *fs, const char *line, char delim);
void fv_gaze_fields_free(fv_gaze_fields *fs);

/* The whole field is a number (strtod's syntax). */
bool fv_gaze_field_number(const char *s, size_t len, double *v);

/* gaze_table.c: a delimited table under the column mapping of opts->table
 * (FV_GAZE_FORMAT_TABLE), or a Tobii Pro Lab data export (FV_GAZE_FORMAT_TOBII, its columns found
 * by name). *format says which was asked for; FV_GAZE_FORMAT_AUTO (a .tsv named without a
 * mapping) reads a Tobii export when the header is one and refuses anything else; the format read
 * is left in *format. */
fv_status fv_gaze_import_table(FILE *in, fv_gaze_writer *w, const fv_gaze_import_opts *opts, fv_gaze_format *format, fv_error *err);

#endif
