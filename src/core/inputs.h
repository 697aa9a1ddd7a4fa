/* fovea — a command's input files, so that none of them is also one of its outputs.
 *
 * `fovea gaze import rec.csv --out rec.csv` would read the recording and then replace it with the
 * trace: the input is gone, with exit status 0. So a command lists the files it reads and checks
 * every file it is about to write against them, before any work. Files are compared by device
 * and inode, not by name: "./a.png", a symbolic link to it and a hard link of it are all a.png. */
#ifndef FV_CORE_INPUTS_H
#define FV_CORE_INPUTS_H

#include "fovea/status.h"

/* Scenes, traces, images and scenarios: a command reads a handful. */
#define FV_INPUTS_MAX 8

typedef struct fv_inputs {
    int n;
    struct {
        unsigned long long dev, ino;
        const char *path, *what; /* kept, not copied: they must outlive the checks */
    } in[FV_INPUTS_MAX];
} fv_inputs;

void fv_inputs_init(fv_inputs *s);
/* Adds the file path names (what says what it is: "scene file", "gaze trace"). NULL, a name that
 * is not a file (a built-in scene's) or a file that cannot be looked at adds nothing: the reader
 * says what is wrong with it. Beyond FV_INPUTS_MAX, nothing either (a caller's bug). */
void fv_inputs_add(fv_inputs *s, const char *path, const char *what);
/* The check for one output, path, named in messages by what (its option, "--out"): FV_ERR_IO with
 * "<what> <path> is the <input's what> <input's path>" when it is one of the inputs; then
 * fv_file_check_write's (a device, FIFO, folder or read-only file is refused). A path that does
 * not exist yet passes. */
fv_status fv_inputs_check_output(const fv_inputs *s, const char *path, const char *what, fv_error *err);

#endif
