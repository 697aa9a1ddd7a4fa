/* fovea — provenance as JSON and as one line, for reports (bench, render --stats-json); the data
 * itself is public (fovea/provenance.h). */
#ifndef FV_CORE_PROVENANCE_JSON_H
#define FV_CORE_PROVENANCE_JSON_H

#include <cjson/cJSON.h>
#include <stddef.h>
#include "fovea/provenance.h"

/* {"fovea_version", "commit", "dirty" (true/false/null), "build_type", "sanitize", "compiler",
 * "embree", "cpu", "cores", "os", "threads_requested", "threads" (used), "date"}; NULL when out
 * of memory. */
cJSON *fv_provenance_json(int threads_requested);
/* "fovea 0.1.0, commit 0123456789ab (dirty), Release, GNU 12.2.0, Embree 3.13.5" */
void fv_provenance_line(char *out, size_t n);

#endif
