/* fovea — how a result was made: the build (version, git commit and dirty flag recorded at build
 * time, build type, compiler, Embree) and the machine (CPU model, cores, threads used, date).
 * Bench reports, `fovea render --stats-json` and image metadata carry these so a figure can be
 * traced to the code and the machine that produced it.
 *
 * Everything here is plain data filled by the library; nothing to free.
 */
#ifndef FOVEA_PROVENANCE_H
#define FOVEA_PROVENANCE_H

#include <stdbool.h>
#include "fovea/export.h"

/* The library's version (also in the build info below, and in every report). */
#define FOVEA_VERSION_MAJOR 0
#define FOVEA_VERSION_MINOR 1
#define FOVEA_VERSION_PATCH 0
#define FOVEA_VERSION_STRING "0.1.0"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_build_info {
    const char *version;    /* FOVEA_VERSION_STRING */
    const char *commit;     /* full git hash of the source tree at build time, or "unknown" (no .git) */
    int dirty;              /* 1: tracked files differed from the commit; 0: clean; -1: unknown */
    const char *build_type; /* CMAKE_BUILD_TYPE: Release, RelWithDebInfo, ... */
    const char *compiler;   /* C compiler id and version, e.g. "GNU 12.2.0" */
    const char *embree;     /* the Embree version libfovea was built against */
    bool sanitize;          /* built with AddressSanitizer and UBSan (timings are not comparable) */
} fv_build_info;

/* The build this library is. The strings are static. */
FV_API void fv_build_info_get(fv_build_info *out);

typedef struct fv_host_info {
    char cpu[128];  /* the CPU model (/proc/cpuinfo "model name"), or "unknown" */
    int cores;      /* logical CPUs online */
    char os[128];   /* kernel name and release (uname), or "unknown" */
} fv_host_info;

FV_API void fv_host_info_get(fv_host_info *out);

/* The number of worker threads a render with `requested` threads (0: all) actually uses. */
FV_API int fv_threads_used(int requested);

/* The current UTC time as ISO 8601 ("2026-11-27T01:02:03Z") into out (at least 21 bytes). */
FV_API void fv_utc_now(char *out, int n);

#ifdef __cplusplus
}
#endif
#endif
