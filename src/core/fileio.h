/* fovea — small file helpers: opening inputs (regular files only, lines of bounded length),
 * whole-or-nothing writes and creating output folders. */
#ifndef FV_CORE_FILEIO_H
#define FV_CORE_FILEIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include "fovea/status.h"

/* ---- inputs ----
 *
 * Every file the library or the tool reads is opened (or, for a reader that opens by name, checked
 * first) here: anything but a regular file is refused, since a device such as /dev/zero reads
 * forever and a FIFO blocks the open until a writer comes. The open itself does not block (a FIFO
 * is opened with O_NONBLOCK and refused after fstat). Messages are one line:
 * "cannot open <what> '<path>': not a regular file (a FIFO)", or the open's strerror. */

/* The longest line the line readers accept (traces, eye-tracker recordings), '\n' included. */
#define FV_LINE_MAX 65536

/* Opens path for reading as a stdio stream ("rb"); what names the input in messages ("gaze
 * trace"; NULL for none). */
fv_status fv_file_open_read(const char *path, const char *what, FILE **out, fv_error *err);
/* The same check for a path handed to a reader that opens it by name (assimp, the image and JSON
 * readers, a sandbox child): opens it as above and closes it again. */
fv_status fv_file_check_read(const char *path, const char *what, fv_error *err);
/* Reads one line (with its '\n', if any) into *line (malloc'd, grown as needed, NUL-terminated),
 * reading at most max bytes of it: returns its length (> 0), 0 at the end of the file or on a read
 * error (ferror tells which), or -1 for a line longer than max (not read further). */
long fv_file_getline(FILE *f, char **line, size_t *cap, size_t max);

/* A UTF-8 byte order mark at the start of line (len bytes, NUL-terminated) is removed in place: a
 * text file's first line may carry one, which says nothing to a reader of ASCII formats. Returns
 * the new length. */
long fv_file_strip_bom(char *line, long len);

/* ---- outputs ----
 *
 * A file written whole or not at all: the data goes to a temporary file next to the target (same
 * directory, so the final rename is atomic on POSIX) which is renamed over the target only when
 * complete. A failed or interrupted write never leaves a truncated file under the target's name.
 * A target that is a symbolic link is written through: the temporary file goes next to the file
 * the link (or chain of links) points to, which is replaced, and the link stays. An existing target
 * that is not a regular file (a device, FIFO, socket or directory) is refused before anything is
 * written: "cannot write '<path>': not a regular file (a character device)", and so is one that
 * is read-only (no write bit, or no permission for this user). A replaced file's mode (and owner,
 * where the user may set it) carries over to the new one. A failed write, close
 * or rename names the target and keeps the system's reason ("No space left on device").
 *
 * After a successful fv_atomic_file_begin the caller ends with fv_atomic_file_commit or
 * fv_atomic_file_abort, whatever happened in between; abort after a commit (successful or not) does
 * nothing, so one abort on every exit path is enough. Write through the descriptor `fd`, through
 * the stream of fv_atomic_file_stream, or let a library open fv_atomic_file_path by name. */
typedef struct fv_atomic_file {
    char target[4096]; /* the name the caller gave, for messages */
    char dest[4096];   /* the file replaced on commit: target with its symbolic links followed */
    char path[4096 + 16]; /* the temporary file */
    int fd;            /* open on path; the stream writes through it (Linux) or owns it (-1) */
    FILE *stream;      /* set by fv_atomic_file_stream */
    int werr;          /* the errno of the stream's first failed write or close, 0 if none */
    bool active;       /* between begin and commit/abort */
} fv_atomic_file;

/* Creates the temporary file for target (mode 0666 less the umask; a replaced file's own mode). Errors name target. The
 * structure must stay where it is until commit or abort (its stream refers to it). */
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

/* For a signal handler that is about to end the process (the CLI's, on SIGINT/SIGTERM): removes
 * every temporary file of an atomic write that this process has open, and returns how many. From
 * fv_atomic_file_begin to the end of commit or abort the temporary file is open (write-only) in the
 * process, so when the handler runs on the thread that writes, having stopped it anywhere in
 * between, this finds exactly the unfinished writes' files; a committed file is not touched (its
 * descriptor then names the target). Async-signal-safe: system calls only (Linux reads
 * /proc/self/fd; elsewhere it removes nothing and returns 0). The library installs no handler. */
int fv_atomic_file_remove_open_temps(void);

/* Whether path could be replaced by an atomic write, checked before the work that makes its
 * content: a path that does not exist yet passes (its folder is the caller's to check); an
 * existing one must be a regular file (after its links) with write permission, else the message
 * fv_atomic_file_begin would give ("cannot write 'x': not a regular file (a FIFO)", "...: the
 * file is read-only (mode 0444)"). */
fv_status fv_file_check_write(const char *path, fv_error *err);
/* Writes len bytes to path whole or not at all (an fv_atomic_file). */
fv_status fv_file_write_atomic(const char *path, const void *data, size_t len, fv_error *err);
/* mkdir -p. */
fv_status fv_mkdirs(const char *path, fv_error *err);
/* True when path names an existing regular file. */
bool fv_file_exists(const char *path);

#endif
