/* fovea — small helpers over cJSON for our strict file formats (scene files, bench scenarios):
 * parse with a line number on error, refuse unknown keys, read typed values with one-line errors
 * that name the file and the field path ("pt-cornell.json: methods[2].params: ...").
 */
#ifndef FV_CORE_JSON_UTIL_H
#define FV_CORE_JSON_UTIL_H

#include <cjson/cJSON.h>
#include <stdbool.h>
#include "fovea/status.h"

/* Reads and parses a whole file (at most 64 MiB). Missing file -> FV_ERR_IO; malformed ->
 * FV_ERR_INVALID "file:LINE: malformed JSON near '...'". */
fv_status fv_json_parse_file(const char *path, cJSON **out, fv_error *err);
/* Same for text already in memory; `name` is used in messages. */
fv_status fv_json_parse_text(const char *name, const char *text, cJSON **out, fv_error *err);

/* Every key of object `obj` must be in the NULL-terminated `allowed` list. `where` names the
 * object in messages (e.g. "methods[1]"). */
fv_status fv_json_check_keys(const cJSON *obj, const char *const *allowed, const char *file, const char *where,
                             fv_error *err);

/* Typed readers: when the key is absent, *out keeps its value and FV_OK is returned (required
 * fields use fv_json_require first). Wrong type or range -> FV_ERR_INVALID naming file/where.key. */
fv_status fv_json_require(const cJSON *obj, const char *key, const char *file, const char *where, fv_error *err);
fv_status fv_json_number(const cJSON *obj, const char *key, double lo, double hi, const char *file, const char *where,
                         double *out, fv_error *err);
fv_status fv_json_int(const cJSON *obj, const char *key, int lo, int hi, const char *file, const char *where, int *out,
                      fv_error *err);
fv_status fv_json_bool(const cJSON *obj, const char *key, const char *file, const char *where, bool *out, fv_error *err);
/* *out points into the cJSON tree. */
fv_status fv_json_string(const cJSON *obj, const char *key, const char *file, const char *where, const char **out,
                         fv_error *err);
/* An array of exactly n numbers, each in [lo, hi]. */
fv_status fv_json_numbers(const cJSON *obj, const char *key, int n, double lo, double hi, const char *file,
                          const char *where, double *out, fv_error *err);

/* An array of exactly n finite numbers, then `check` (fv_limit_coords or fv_limit_intensity of
 * fovea/limits.h: the range every reader of coordinates and intensities shares), with the
 * message naming file and where.key. */
typedef fv_status (*fv_json_limit_fn)(const char *what, const double *v, int n, fv_error *err);
fv_status fv_json_limited(const cJSON *obj, const char *key, int n, fv_json_limit_fn check, const char *file, const char *where,
                          double *out, fv_error *err);

/* A scalar (string, number, bool) rendered as text for a parameter bag: numbers print in the
 * shortest form that reads back exactly. False for objects, arrays and null. */
bool fv_json_scalar_text(const cJSON *item, char *buf, size_t n);

#endif
