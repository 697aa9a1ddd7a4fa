/* fovea — small file helpers: whole-or-nothing writes and creating output folders. */
#ifndef FV_CORE_FILEIO_H
#define FV_CORE_FILEIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include "fovea/status.h"

/* A file written whole or not at all: the data goes to a temporary file next to the target (same
 * directory, so the final rename is atomic on POSIX) which is renamed over the target only when
 * complete. A failed or interrupted write never leaves a truncated file under the target's name.
 *
 * After a successful fv_atomic_file_begin the caller ends with fv_atomic_file_commit or
 * fv_atomic_file_abort, whatever happened in between; abort after a commit (successful or not) does
 * nothing, so one abort on every exit path is enough. Write through the descriptor `fd`, through
 * the stream of fv_atomic_file_stream, or let a library open fv_atomic_file_path by name. */
typedef struct fv_atomic_file {
    char target[4096]; /* the name the file gets on commit */
    char path[4096 + 16]; /* the temporary file */
    int fd;            /* open on path; -1 once a stream owns it */
    FILE *stream;      /* set by fv_atomic_file_stream */
    bool active;       /* between begin and commit/abort */
} fv_atomic_file;

/* Creates the temporary file for target (mode 0666 less the umask). Errors name target. */
fv_status fv_atomic_file_begin(const char *target, fv_atomic_file *out, fv_error *err);
/* The temporary file as a stdio stream (it takes over the descriptor; commit closes it). */
fv_status fv_atomic_file_stream(fv_atomic_file *af, FILE **out, fv_error *err);
/* The temporary file's name, for writers that open files themselves. */
const char *fv_atomic_file_path(const fv_atomic_file *af);
/* Closes the temporary file and renames it over the target; on any error (including an earlier
 * write error on the stream) removes it and fails with FV_ERR_IO naming the target. */
fv_status fv_atomic_file_commit(fv_atomic_file *af, fv_error *err);
/* Closes and removes the temporary file; the target is untouched. */
void fv_atomic_file_abort(fv_atomic_file *af);

/* Writes len bytes to path whole or not at all (an fv_atomic_file). */
fv_status fv_file_write_atomic(const char *path, const void *data, size_t len, fv_error *err);
/* mkdir -p. */
fv_status fv_mkdirs(const char *path, fv_error *err);
/* True when path names an existing regular file. */
bool fv_file_exists(const char *path);

#endif
