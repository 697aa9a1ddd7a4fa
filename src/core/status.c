/* fovea — error reports and warnings (see include/fovea/status.h). */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "fovea/status.h"

fv_status fv_error_set(fv_error *err, fv_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}

void fv_error_clear(fv_error *err)
{
    if (err) {
        err->status = FV_OK;
        err->msg[0] = '\0';
    }
}

void fv_error_prefix(fv_error *err, const char *fmt, ...)
{
    if (!err) return;
    char head[FV_ERROR_MSG_MAX], old[FV_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(head, sizeof head, fmt, ap);
    va_end(ap);
    memcpy(old, err->msg, sizeof old);
    size_t hl = strlen(head);
    if (hl >= sizeof err->msg) hl = sizeof err->msg - 1;
    memcpy(err->msg, head, hl);
    size_t ol = strlen(old);
    if (ol > sizeof err->msg - 1 - hl) ol = sizeof err->msg - 1 - hl;
    memcpy(err->msg + hl, old, ol);
    err->msg[hl + ol] = '\0';
}

const char *fv_status_name(fv_status status)
{
    switch (status) {
    case FV_OK: return "ok";
    case FV_ERR_INVALID: return "invalid input";
    case FV_ERR_IO: return "i/o error";
    case FV_ERR_NOMEM: return "out of memory";
    case FV_ERR_INTERNAL: return "internal error";
    case FV_ERR_CANCELLED: return "cancelled";
    }
    return "unknown status";
}

void fv_log_warn(const fv_log *log, const char *fmt, ...)
{
    if (!log || !log->warn) return;
    char msg[FV_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    log->warn(log->user, msg);
}
