/* fovea — small file helpers: whole-or-nothing writes and creating output folders. */
#ifndef FV_CORE_FILEIO_H
#define FV_CORE_FILEIO_H

#include <stdbool.h>
#include <stddef.h>
#include "fovea/status.h"

/* Writes len bytes to a temporary file next to path, then renames it into place. */
fv_status fv_file_write_atomic(const char *path, const void *data, size_t len, fv_error *err);
/* mkdir -p. */
fv_status fv_mkdirs(const char *path, fv_error *err);
/* True when path names an existing regular file. */
bool fv_file_exists(const char *path);

#endif
