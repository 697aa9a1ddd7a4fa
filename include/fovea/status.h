/* fovea — status codes and the per-call error report.
 *
 * Every fallible library call returns an fv_status and fills an fv_error that the caller owns
 * (no hidden global "last error": two threads or two scenes never overwrite each other's message).
 * The message is one line meant for the user: it names the file, field or value at fault. Only the
 * tools decide how a status becomes an exit code (FV_ERR_INVALID/FV_ERR_IO -> 2, the rest -> 1).
 */
#ifndef FOVEA_STATUS_H
#define FOVEA_STATUS_H

#include "fovea/export.h"
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum fv_status {
    FV_OK = 0,
    FV_ERR_INVALID,  /* bad input from the user: value, name, size, file contents */
    FV_ERR_IO,       /* file missing, unreadable or unwritable */
    FV_ERR_NOMEM,    /* an allocation failed or a requested size overflows */
    FV_ERR_INTERNAL, /* a bug or an unexpected failure of a library we use */
    FV_ERR_CANCELLED /* the caller's progress callback asked to stop */
} fv_status;

#define FV_ERROR_MSG_MAX 512

typedef struct fv_error {
    fv_status status;
    char msg[FV_ERROR_MSG_MAX];
} fv_error;

/* Records status and a printf-style message in err (err may be NULL) and returns status, so a
 * failure path reads `return fv_error_set(err, FV_ERR_INVALID, "...", ...);`. */
FV_API fv_status fv_error_set(fv_error *err, fv_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Clears err to FV_OK with an empty message. */
FV_API void fv_error_clear(fv_error *err);

/* Prefixes the existing message with a context string ("scene.json: "), keeping the status. */
FV_API void fv_error_prefix(fv_error *err, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Short stable name of a status ("invalid input", "i/o error", ...). */
FV_API const char *fv_status_name(fv_status status);

/* Warnings (dropped NaN triangles, default light added, ...) go through a sink the caller sets;
 * the default sink of the tools prints "fovea: warning: ..." on stderr. */
typedef void (*fv_warn_fn)(void *user, const char *msg);
typedef struct fv_log {
    fv_warn_fn warn;
    void *user;
} fv_log;

FV_API void fv_log_warn(const fv_log *log, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#ifdef __cplusplus
}
#endif
#endif
