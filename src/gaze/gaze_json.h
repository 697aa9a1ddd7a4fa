/* fovea — JSON blocks for the eye model ("eye"/"display") and gaze paths ("gaze"). */
#ifndef FV_GAZE_JSON_H
#define FV_GAZE_JSON_H

#include <cjson/cJSON.h>
#include "fovea/gaze.h"

/* Overrides fields of *eye from object o: ppi, eye_dist_mm, fov_x_deg, mode ("angle"|"width"),
 * fovea_deg, transition_deg, fovea_frac, transition_frac; then validates. */
fv_status fv_gaze_json_eye(const cJSON *o, const char *file, const char *where, fv_eye_model *eye, fv_error *err);
/* One of {"fixed": [x, y]}, {"keys": [[t, x, y], ...]}, {"trace": "file.csv"} (relative to dir). */
fv_status fv_gaze_json_path(const cJSON *o, const char *file, const char *where, const char *dir, fv_gaze_path **out,
                            fv_error *err);

#endif
