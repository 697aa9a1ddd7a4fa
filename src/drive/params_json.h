/* fovea — a method's parameters as typed JSON for reports and metadata: numbers as numbers,
 * switches as true/false, names as strings. */
#ifndef FV_DRIVE_PARAMS_JSON_H
#define FV_DRIVE_PARAMS_JSON_H

#include <cjson/cJSON.h>
#include "fovea/params.h"

/* An object {key: value} of `params` for method `method` (NULL or unknown: types guessed from the
 * values). NULL when out of memory. */
cJSON *fv_params_typed_json(const char *method, const fv_params *params);

#endif
