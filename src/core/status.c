/* fovea — error reports and warnings (see include/fovea/status.h). */
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include "fovea/status.h"

/* Messages are one line for the user, whatever the input they quote: a control byte taken from
 * a file (a raw newline in a JSON key, a CR in a CSV line) is shown escaped ("\n", "\x01")
 * instead of breaking the line. Text that no longer fits is cut. */
static void one_line(char *msg, size_t cap)
{
    bool clean = true;
    for (const unsigned char *p = (const unsigned char *)msg; *p && clean; p++) clean = *p >= 0x20 && *p != 0x7f;
    if (clean) return;
    char out[FV_ERROR_MSG_MAX];
    size_t n = 0, lim = cap < sizeof out ? cap : sizeof out;
    for (const unsigned char *p = (const unsigned char *)msg; *p; p++) {
        char esc[5];
        if (*p == '\n') snprintf(esc, sizeof esc, "\\n");
        else if (*p == '\r') snprintf(esc, sizeof esc, "\\r");
        else if (*p == '\t') snprintf(esc, sizeof esc, "\\t");
        else if (*p < 0x20 || *p == 0x7f) snprintf(esc, sizeof esc, "\\x%02x", *p);
        else esc[0] = (char)*p, esc[1] = '\0';
        size_t l = strlen(esc);
        if (n + l >= lim) break;
        memcpy(out + n, esc, l);
        n += l;
    }
    out[n] = '\0';
    memcpy(msg, out, n + 1);
}

fv_status fv_error_set(fv_error *err, fv_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        one_line(err->msg, sizeof err->msg);
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
    one_line(err->msg, sizeof err->msg);
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
    one_line(msg, sizeof msg);
    log->warn(log->user, msg);
}
