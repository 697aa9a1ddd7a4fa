/* fovea — opening inputs, whole-or-nothing file writes and mkdir -p (see fileio.h). */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE /* fopencookie: a stream that remembers why a write failed */
#endif
#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#if defined(__linux__)
#include <sys/syscall.h>
#endif
#include <time.h>
#include <unistd.h>
#include "core/fileio.h"
#include "core/rng.h"

/* ---- inputs ---- */

static const char *kind_of(mode_t m)
{
    if (S_ISDIR(m)) return "a directory";
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISFIFO(m)) return "a FIFO";
    if (S_ISSOCK(m)) return "a socket";
    return "not a plain file";
}

static fv_status refuse_input(const char *path, const char *what, mode_t m, fv_error *err)
{
    const char *sp = what && what[0] ? " " : "";
    return fv_error_set(err, FV_ERR_IO, "cannot open %s%s'%s': not a regular file (%s)", what ? what : "", sp, path, kind_of(m));
}

fv_status fv_file_open_read(const char *path, const char *what, FILE **out, fv_error *err)
{
    *out = NULL;
    const char *w = what ? what : "", *sp = w[0] ? " " : "";
    if (!path || !path[0]) return fv_error_set(err, FV_ERR_IO, "cannot open %s%s'': empty file name", w, sp);
    /* Looked at before opening (opening a device may do something: a tape rewinds), and again
     * after, on what was opened. O_NONBLOCK: opening a FIFO without a writer would wait for one. */
    struct stat sb;
    if (stat(path, &sb) == 0 && !S_ISREG(sb.st_mode)) return refuse_input(path, what, sb.st_mode, err);
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return fv_error_set(err, FV_ERR_IO, "cannot open %s%s'%s': %s", w, sp, path, strerror(errno));
    if (fstat(fd, &sb) != 0) {
        int e = errno;
        close(fd);
        return fv_error_set(err, FV_ERR_IO, "cannot open %s%s'%s': %s", w, sp, path, strerror(e));
    }
    if (!S_ISREG(sb.st_mode)) {
        close(fd);
        return refuse_input(path, what, sb.st_mode, err);
    }
    int fl = fcntl(fd, F_GETFL);
    FILE *f = fl >= 0 && fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) == 0 ? fdopen(fd, "rb") : NULL;
    if (!f) {
        int e = errno;
        close(fd);
        return fv_error_set(err, FV_ERR_IO, "cannot open %s%s'%s': %s", w, sp, path, strerror(e));
    }
    *out = f;
    return FV_OK;
}

fv_status fv_file_check_read(const char *path, const char *what, fv_error *err)
{
    FILE *f;
    fv_status st = fv_file_open_read(path, what, &f, err);
    if (st == FV_OK) fclose(f);
    return st;
}

long fv_file_getline(FILE *f, char **line, size_t *cap, size_t max)
{
    size_t len = 0;
    if (max < 1) max = 1;
    for (;;) {
        if (len >= max) {
            /* Exactly max bytes and then the end of the file is still a line. */
            int c = getc(f);
            if (c == EOF) return (long)len;
            return -1;
        }
        if (!*line || *cap < len + 2) {
            size_t want = *cap ? *cap * 2 : 256;
            if (want > max + 1) want = max + 1;
            if (want < len + 2) want = len + 2;
            char *p = realloc(*line, want);
            if (!p) return -2;
            *line = p;
            *cap = want;
        }
        size_t room = (*cap < max + 1 ? *cap : max + 1) - len;
        if (!fgets(*line + len, room > INT32_MAX ? INT32_MAX : (int)room, f)) {
            (*line)[len] = '\0';
            return (long)len;
        }
        len += strlen(*line + len);
        if (len > 0 && (*line)[len - 1] == '\n') return (long)len;
    }
}

long fv_file_strip_bom(char *line, long len)
{
    /* EF BB BF: what Windows tools (Notepad, Excel's "CSV UTF-8") put before the first line. */
    if (len < 3 || memcmp(line, "\xEF\xBB\xBF", 3) != 0) return len;
    memmove(line, line + 3, (size_t)(len - 3) + 1);
    return len - 3;
}

/* ---- outputs ---- */

/* dest = target with its symbolic links followed (at most 40 of them, as the kernel allows); the
 * file named need not exist. Relative links are read from the link's folder. */
static fv_status follow_links(const char *target, char *dest, size_t n, fv_error *err)
{
    snprintf(dest, n, "%s", target);
    for (int hops = 0;; hops++) {
        struct stat sb;
        if (lstat(dest, &sb) != 0 || !S_ISLNK(sb.st_mode)) return FV_OK;
        if (hops == 40) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", target, strerror(ELOOP));
        char link[4096];
        ssize_t k = readlink(dest, link, sizeof link - 1);
        if (k < 0) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", target, strerror(errno));
        link[k] = '\0';
        char next[4096];
        const char *slash = strrchr(dest, '/');
        int dir = link[0] == '/' || !slash ? 0 : (int)(slash - dest + 1);
        if (snprintf(next, sizeof next, "%.*s%s", dir, dest, link) >= (int)sizeof next || strlen(next) >= n)
            return fv_error_set(err, FV_ERR_IO, "cannot write '%s': path too long", target);
        snprintf(dest, n, "%s", next);
    }
}

/* An existing file about to be replaced (sb: its stat): a regular file that may be written. A file
 * with no write bit at all is refused even where access() would let this user (root) write it:
 * whoever made it read-only meant it to stay. */
static fv_status check_replace(const char *target, const char *dest, const struct stat *sb, fv_error *err)
{
    /* Renaming over a device or FIFO would replace the node with a regular file. */
    if (!S_ISREG(sb->st_mode)) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': not a regular file (%s)", target, kind_of(sb->st_mode));
    if ((sb->st_mode & 0222) == 0)
        return fv_error_set(err, FV_ERR_IO, "cannot write '%s': the file is read-only (mode %04o)", target, (unsigned)(sb->st_mode & 07777));
    if (access(dest, W_OK) != 0) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", target, strerror(errno));
    return FV_OK;
}

fv_status fv_file_check_write(const char *path, fv_error *err)
{
    if (!path || !path[0]) return fv_error_set(err, FV_ERR_IO, "cannot write '': empty file name");
    char dest[4096];
    fv_status st = follow_links(path, dest, sizeof dest, err);
    struct stat sb;
    if (st == FV_OK && stat(dest, &sb) == 0) st = check_replace(path, dest, &sb, err);
    return st;
}

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
    fv_status st = follow_links(target, out->dest, sizeof out->dest, err);
    if (st != FV_OK) return st;
    struct stat sb;
    const bool replaces = stat(out->dest, &sb) == 0;
    if (replaces && (st = check_replace(target, out->dest, &sb, err)) != FV_OK) return st;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t h = fv_hash_combine(fv_hash_combine(fv_hash64((uint64_t)getpid()), (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec),
                                 (uint64_t)(uintptr_t)out);
    for (int attempt = 0; attempt < 64; attempt++) {
        h = fv_hash_combine(h, (uint64_t)attempt);
        snprintf(out->path, sizeof out->path, "%s.tmp.%06x", out->dest, (unsigned)(h & 0xffffffu));
        int fd = open(out->path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            /* The replaced file's owner and mode carry over (a private 0600 file stays private).
             * Changing the owner takes privileges most users lack: then the file is theirs, as
             * any file they write. chown first, since it may clear set-id bits. */
            if (replaces) {
                int r = fchown(fd, sb.st_uid, sb.st_gid);
                if (r != 0) r = fchown(fd, (uid_t)-1, sb.st_gid); /* a group of this user's */
                (void)r;                                         /* not permitted: it stays ours */
                if (fchmod(fd, sb.st_mode & 07777) != 0) {
                    int e = errno;
                    close(fd);
                    unlink(out->path);
                    return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", target, strerror(e));
                }
            }
            out->fd = fd;
            out->active = true;
            return FV_OK;
        }
        if (errno != EEXIST) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", target, strerror(errno));
    }
    return fv_error_set(err, FV_ERR_IO, "cannot write '%s': no free temporary file name next to it", target);
}

#if defined(__linux__)
/* The stream writes through these, so the reason of a failed write is kept for the commit's
 * message (stdio keeps only an error flag, and errno is long gone by then). */
static ssize_t stream_write(void *cookie, const char *buf, size_t n)
{
    fv_atomic_file *af = cookie;
    size_t done = 0;
    while (done < n) {
        ssize_t w = write(af->fd, buf + done, n - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            if (!af->werr) af->werr = w < 0 ? errno : EIO;
            errno = af->werr;
            return 0; /* fopencookie: 0 is the error */
        }
        done += (size_t)w;
    }
    return (ssize_t)n;
}

static int stream_seek(void *cookie, off64_t *off, int whence)
{
    fv_atomic_file *af = cookie;
    off_t r = lseek(af->fd, (off_t)*off, whence);
    if (r < 0) return -1;
    *off = r;
    return 0;
}

static int stream_close(void *cookie)
{
    fv_atomic_file *af = cookie;
    int r = close(af->fd);
    if (r != 0 && !af->werr) af->werr = errno;
    af->fd = -1;
    return r;
}
#endif

fv_status fv_atomic_file_stream(fv_atomic_file *af, FILE **out, fv_error *err)
{
    if (!af->stream) {
        if (!af->active) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': not open", af->target);
#if defined(__linux__)
        cookie_io_functions_t io = {NULL, stream_write, stream_seek, stream_close};
        FILE *f = fopencookie(af, "w", io);
        if (!f) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", af->target, strerror(errno));
        af->stream = f; /* af->fd stays open under it; stream_close closes it */
#else
        FILE *f = fdopen(af->fd, "wb");
        if (!f) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", af->target, strerror(errno));
        af->stream = f;
        af->fd = -1;
#endif
    }
    *out = af->stream;
    return FV_OK;
}

const char *fv_atomic_file_path(const fv_atomic_file *af)
{
    return af->path;
}

/* Closes whatever is open on the temporary file; the errno of the first failure, 0, or -1 for a
 * write error the stream recorded earlier whose reason is unknown (a stream without our write
 * function, off Linux). An earlier error counts even when the final flush succeeds. */
static int close_temp(fv_atomic_file *af)
{
    int e = 0;
    if (af->stream) {
        bool bad = ferror(af->stream) != 0;
        int r = fclose(af->stream);
        if (af->werr) e = af->werr;
        else if (r != 0) e = errno;
        else if (bad) e = -1;
        af->stream = NULL;
    } else if (af->fd >= 0 && close(af->fd) != 0) {
        e = errno;
    }
    af->fd = -1;
    return e;
}

/* A second descriptor on the temporary file, closed only once the file has been renamed or
 * removed: so from begin to the end of commit or abort the temporary file is always open in this
 * process, where fv_atomic_file_remove_open_temps finds it (a signal may stop the thread between
 * the close and the rename). -1 when there is none; nothing depends on it. */
static int hold_temp(const fv_atomic_file *af)
{
    int fd = af->fd >= 0 ? af->fd : af->stream ? fileno(af->stream) : -1;
    return fd >= 0 ? fcntl(fd, F_DUPFD_CLOEXEC, 0) : -1;
}

fv_status fv_atomic_file_commit(fv_atomic_file *af, fv_error *err)
{
    if (!af->active) return fv_error_set(err, FV_ERR_INTERNAL, "cannot write '%s': the file was not open", af->target);
    af->active = false;
    int hold = hold_temp(af);
    int e = close_temp(af);
    if (!e && rename(af->path, af->dest) != 0) e = errno;
    if (e) unlink(af->path);
    if (hold >= 0) close(hold);
    if (e) return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", af->target, e > 0 ? strerror(e) : "write failed");
    return FV_OK;
}

void fv_atomic_file_abort(fv_atomic_file *af)
{
    if (!af->active) return;
    af->active = false;
    int hold = hold_temp(af);
    close_temp(af);
    unlink(af->path);
    if (hold >= 0) close(hold);
}

#if defined(__linux__)
/* ".tmp." and six hex digits at the end of name (len bytes): the names fv_atomic_file_begin makes. */
static bool is_temp_name(const char *name, size_t len)
{
    if (len < 11 || memcmp(name + len - 11, ".tmp.", 5) != 0) return false;
    for (size_t i = len - 6; i < len; i++) {
        char c = name[i];
        if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
    }
    return true;
}

/* The record getdents64 returns (the libc's struct dirent64 is not promised to match it). */
struct fd_dirent {
    uint64_t ino;
    int64_t off;
    unsigned short reclen;
    unsigned char type;
    char name[];
};

int fv_atomic_file_remove_open_temps(void)
{
    /* Only system calls and our own string handling: no stdio, malloc or opendir. */
    int dir = open("/proc/self/fd", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir < 0) return 0;
    int removed = 0;
    char buf[4096] __attribute__((aligned(8)));
    for (;;) {
        long n = syscall(SYS_getdents64, dir, buf, sizeof buf);
        if (n <= 0) break;
        for (long off = 0; off < n;) {
            const struct fd_dirent *d = (const struct fd_dirent *)(buf + off);
            off += d->reclen;
            int fd = 0;
            const char *c = d->name;
            if (*c < '0' || *c > '9') continue;
            for (; *c >= '0' && *c <= '9' && fd < 100000000; c++) fd = fd * 10 + (*c - '0');
            if (*c || fd == dir) continue;
            /* Our temporary files are open write-only; an input that happens to have such a name
             * is open read-only and stays. */
            int fl = fcntl(fd, F_GETFL);
            if (fl < 0 || (fl & O_ACCMODE) != O_WRONLY) continue;
            char link[32] = "/proc/self/fd/", target[4096];
            size_t k = 14;
            for (const char *q = d->name; q < c; q++) link[k++] = *q;
            link[k] = '\0';
            ssize_t len = readlink(link, target, sizeof target - 1);
            if (len <= 0 || len >= (ssize_t)sizeof target - 1) continue;
            target[len] = '\0';
            /* A removed file reads as "<path> (deleted)" and does not match. */
            if (is_temp_name(target, (size_t)len) && unlink(target) == 0) removed++;
        }
    }
    close(dir);
    return removed;
}
#else
int fv_atomic_file_remove_open_temps(void)
{
    return 0;
}
#endif

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
