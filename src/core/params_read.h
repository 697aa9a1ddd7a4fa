/* fovea — reading the parameter bag inside the library (techniques, bench): typed readers that
 * mark each key they read, and the check that refuses keys nobody read. Not public: a caller only
 * fills a bag (fovea/params.h); fv_technique_create validates a private copy of it.
 */
#ifndef FV_CORE_PARAMS_READ_H
#define FV_CORE_PARAMS_READ_H

#include <stdbool.h>
#include "fovea/params.h"

/* Missing key -> def; present but malformed or outside [lo, hi] -> FV_ERR_INVALID naming the key
 * and value. Each read marks the key as used. */
fv_status fv_params_int(fv_params *p, const char *key, int def, int lo, int hi, int *out, fv_error *err);
fv_status fv_params_float(fv_params *p, const char *key, double def, double lo, double hi, double *out, fv_error *err);
fv_status fv_params_bool(fv_params *p, const char *key, bool def, bool *out, fv_error *err);
/* Value must be one of the NULL-terminated `choices`; *out gets its index. */
fv_status fv_params_choice(fv_params *p, const char *key, int def, const char *const *choices, int *out, fv_error *err);
/* True when the bag holds key (read or not). */
bool fv_params_has(const fv_params *p, const char *key);
/* Any key never read is an error "unknown parameter 'k' for method 'm'". */
fv_status fv_params_check_used(const fv_params *p, const char *technique, fv_error *err);
/* From now on every reader above (and fv_params_has) tells fn the key it asks for, present in the
 * bag or not, with what it accepts: how the conformance suite learns every key a method reads and
 * holds the method's parameter table to the readers (the same keys, defaults and ranges). fn NULL
 * stops it. Not copied by fv_params_clone. */
typedef enum fv_params_reader { FV_READ_INT, FV_READ_FLOAT, FV_READ_BOOL, FV_READ_CHOICE, FV_READ_HAS } fv_params_reader;
typedef struct fv_params_read {
    const char *key;
    fv_params_reader reader;
    double def, lo, hi;         /* int and float: the default and the accepted range; bool: def 0/1 */
    const char *const *choices; /* choice: the accepted values; def is the default's index */
} fv_params_read;
typedef void (*fv_params_watch_fn)(void *user, const fv_params_read *r);
void fv_params_watch(fv_params *p, fv_params_watch_fn fn, void *user);

#endif
