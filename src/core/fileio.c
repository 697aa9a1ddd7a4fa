/* fovea — whole-or-nothing file writes and mkdir -p (see fileio.h). */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "core/fileio.h"

fv_status fv_file_write_atomic(const char *path, const void *data, size_t len, fv_error *err)
{
    char tmp[4096];
    if (snprintf(tmp, sizeof tmp, "%s.tmp.XXXXXX", path) >= (int)sizeof tmp)
        return fv_error_set(err, FV_ERR_IO, "cannot write '%s': path too long", path);
    int fd = mkstemp(tmp);
    if (fd < 0) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", path, strerror(errno));
    mode_t mask = umask(0);
    umask(mask);
    fchmod(fd, 0666 & ~mask);
    const char *p = data;
    size_t left = len;
    while (left > 0) {
        ssize_t w = write(fd, p, left);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            int e = errno;
            close(fd);
            unlink(tmp);
            return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", path, strerror(e));
        }
        p += w;
        left -= (size_t)w;
    }
    if (close(fd) != 0 || rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", path, strerror(e));
    }
    return FV_OK;
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
