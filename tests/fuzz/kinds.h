/* The kinds of input fovea reads, the library entry points that run each, and the verdict on an
 * outcome (docs/fuzzing.md). Shared by the mutation fuzzer (fuzz.c) and the libFuzzer targets
 * (tests/libfuzzer), so both fuzzers hold every input to the same rules. */
#ifndef FV_FUZZ_KINDS_H
#define FV_FUZZ_KINDS_H
#include <stdbool.h>
#include <stddef.h>
#include "fovea/fovea.h"

#define FV_FUZZ_NAME_MAX 256

/* What one fuzzing process keeps between inputs. */
typedef struct fv_fuzz_ctx {
    char work[64];          /* the private work folder (/dev/shm or /tmp): inputs are written there, and nothing else may appear */
    fv_scene *cornell;      /* for gaze and camera traces, built once */
    fv_view *cornell_view;
    bool bad_warning;       /* a warning with a control byte */
    char note[700];         /* what went wrong after a load accepted the input */
} fv_fuzz_ctx;

typedef fv_status (*fv_fuzz_run_fn)(fv_fuzz_ctx *c, const char *path, fv_error *err);

typedef struct fv_fuzz_kind {
    const char *name, *ext; /* an input of this kind is written as in<ext> */
    fv_fuzz_run_fn run;
    const char *seed_dirs[3]; /* relative to the source tree: files ending in ext ... */
    const char *seed_prefix;  /* ... and starting with this (NULL: any name) */
    bool images;              /* seeds written by fv_fuzz_write_image_seeds, not in the repository */
} fv_fuzz_kind;

int fv_fuzz_kind_count(void);
const fv_fuzz_kind *fv_fuzz_kind_at(int i);
const fv_fuzz_kind *fv_fuzz_kind_find(const char *name); /* NULL when unknown */

/* Makes the work folder under /tmp and copies in what the seeds name (the test meshes, traces and
 * materials), so a scene input can load them. false (and a message on stderr) on failure. */
bool fv_fuzz_ctx_init(fv_fuzz_ctx *c, const char *src);
/* Frees what the context holds; remove_work also deletes the work folder. */
void fv_fuzz_ctx_free(fv_fuzz_ctx *c, bool remove_work);
/* Clears the per-input flags before an input runs. */
void fv_fuzz_ctx_begin(fv_fuzz_ctx *c);

/* Up to max names in dir (not . and ..); the count. */
int fv_fuzz_list_dir(const char *dir, char names[][FV_FUZZ_NAME_MAX], int max);
/* Removes from the work folder whatever is not in before[] or the input itself. */
void fv_fuzz_clean_work(const fv_fuzz_ctx *c, char (*before)[FV_FUZZ_NAME_MAX], int nbefore);

/* NULL when the outcome of running input (a name in the work folder) follows the rules, else why
 * not (in why or a static string): accepted and everything after the load worked, or refused with
 * FV_ERR_INVALID or FV_ERR_IO and a one-line message that names the input; no file left in the
 * work folder but those in before[]; no warning of several lines. */
const char *fv_fuzz_judge(const fv_fuzz_ctx *c, const char *input, fv_status st, const fv_error *err, char (*before)[FV_FUZZ_NAME_MAX],
                          int nbefore, char *why, size_t n);

/* Writes the image seeds (PNG, PFM, EXR, one PFM with a NaN) with our own writers into dir. */
void fv_fuzz_write_image_seeds(const char *dir);

/* Recomputes the CRC of every whole chunk of a PNG file in p[0..n), so a mutated chunk reaches
 * libpng's parsing of its contents instead of its CRC check. */
void fv_fuzz_png_fix_crcs(unsigned char *p, size_t n);

#endif
