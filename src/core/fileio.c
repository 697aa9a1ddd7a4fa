/* fovea — whole-or-nothing file writes and mkdir -p (see fileio.h). */
#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "core/fileio.h"
#include "core/rng.h"

/* The temporary name is made here rather than by mkstemp: mkstemp creates its file 0600, and the
 * only way to learn the umask to fix that is to change it, which races with every other thread
 * creating files. O_EXCL gives the same no-clobber guarantee, and mode 0666 lets the kernel apply
 * the umask as for any other output. */
fv_status fv_atomic_file_begin(const char *target, fv_atomic_file *out, fv_error *err)
{
    memset(out, 0, sizeof *out);
    out->fd = -1;
    if (!target || !target[0]) return fv_error_set(err, FV_ERR_IO, "cannot write '': empty file name");
    if (snprintf(out->target, sizeof out->target, "%s", target) >= (int)sizeof out->target)
        return fv_error_set(err, FV_ERR_IO, "cannot write '%s': path too long", target);
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t h = fv_hash_combine(fv_hash_combine(fv_hash64((uint64_t)getpid()), (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec),
                                 (uint64_t)(uintptr_t)out);
    for (int attempt = 0; attempt < 64; attempt++) {
        h = fv_hash_combine(h, (uint64_t)attempt);
        snprintf(out->path, sizeof out->path, "%s.tmp.%06x", target, (unsigned)(h & 0xffffffu));
        int fd = open(out->path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            out->fd = fd;
            out->active = true;
            return FV_OK;
        }
        if (errno != EEXIST) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", target, strerror(errno));
    }
    return fv_error_set(err, FV_ERR_IO, "cannot write '%s': no free temporary file name next to it", target);
}

fv_status fv_atomic_file_stream(fv_atomic_file *af, FILE **out, fv_error *err)
{
    if (!af->stream) {
        FILE *f = af->active ? fdopen(af->fd, "wb") : NULL;
        if (!f) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", af->target, af->active ? strerror(errno) : "not open");
        af->stream = f;
        af->fd = -1;
    }
    *out = af->stream;
    return FV_OK;
}

const char *fv_atomic_file_path(const fv_atomic_file *af)
{
    return af->path;
}

/* Closes whatever is open on the temporary file; the errno of the first failure, 0, or -1 for a
 * write error the stream recorded earlier (it counts even when the final flush succeeds, and its
 * errno is long gone). */
static int close_temp(fv_atomic_file *af)
{
    int e = 0;
    if (af->stream) {
        bool bad = ferror(af->stream) != 0;
        if (fclose(af->stream) != 0) e = errno;
        if (bad && !e) e = -1;
        af->stream = NULL;
    } else if (af->fd >= 0 && close(af->fd) != 0) {
        e = errno;
    }
    af->fd = -1;
    return e;
}

fv_status fv_atomic_file_commit(fv_atomic_file *af, fv_error *err)
{
    if (!af->active) return fv_error_set(err, FV_ERR_INTERNAL, "cannot write '%s': the file was not open", af->target);
    af->active = false;
    int e = close_temp(af);
    if (!e && rename(af->path, af->target) != 0) e = errno;
    if (e) {
        unlink(af->path);
        return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", af->target, e > 0 ? strerror(e) : "write failed");
    }
    return FV_OK;
}

void fv_atomic_file_abort(fv_atomic_file *af)
{
    if (!af->active) return;
    af->active = false;
    close_temp(af);
    unlink(af->path);
}

fv_status fv_file_write_atomic(const char *path, const void *data, size_t len, fv_error *err)
{
    fv_atomic_file af;
    fv_status st = fv_atomic_file_begin(path, &af, err);
    if (st != FV_OK) return st;
    const char *p = data;
    size_t left = len;
    while (left > 0) {
        ssize_t w = write(af.fd, p, left);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            int e = w < 0 ? errno : EIO;
            fv_atomic_file_abort(&af);
            return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", path, strerror(e));
        }
        p += w;
        left -= (size_t)w;
    }
    return fv_atomic_file_commit(&af, err);
}

fv_status fv_mkdirs(const char *path, fv_error *err)
{
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf)
        return fv_error_set(err, FV_ERR_IO, "cannot create '%s': path too long", path);
    for (char *c = buf + 1;; c++) {
        bool end = *c == '\0';
        if (*c == '/' || end) {
            *c = '\0';
            struct stat sb;
            if (stat(buf, &sb) != 0) {
                if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                    return fv_error_set(err, FV_ERR_IO, "cannot create folder '%s': %s", buf, strerror(errno));
            } else if (!S_ISDIR(sb.st_mode)) {
                return fv_error_set(err, FV_ERR_IO, "cannot create folder '%s': a file of that name exists", buf);
            }
            if (end) break;
            *c = '/';
        }
    }
    return FV_OK;
}

bool fv_file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}
