/* fovea — the benchmark harness: renders a scenario's methods side by side in one run, times them
 * (median of repeats), measures their error per region against a cached reference, and writes a
 * JSON report, a Markdown table, images and, for parameter sweeps, a CSV and a plot.
 *
 * The scenario file format is documented in docs/bench.md; scenarios live in bench/.
 */
#ifndef FOVEA_BENCH_H
#define FOVEA_BENCH_H

#include <stdbool.h>
#include <stddef.h>
#include "fovea/drive.h"
#include "fovea/export.h"
#include "fovea/film.h"
#include "fovea/params.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum fv_bench_mode {
    FV_BENCH_DEFAULT = 0, /* a few minutes on a 2-core machine */
    FV_BENCH_QUICK,       /* under a minute: used by the tests */
    FV_BENCH_FULL         /* the papers' sizes */
} fv_bench_mode;

/* One still that a split run renders across every process at once (fv_bench_split.still): frame
 * `frame` of `driver` with a fresh technique `method` of `params` on `scene`. */
typedef struct fv_bench_still {
    const char *method;
    const fv_params *params;
    const fv_scene *scene;
    fv_driver *driver;
    int frame;
    const fv_log *log;
} fv_bench_still;

/* A run split over cooperating processes (the CLI implements it over MPI ranks, src/dist): every
 * process runs fv_bench_run with the same scenario and options and renders its share of the rows
 * (methods, sweep points; rank r times the rows i with i % size == r, all their repeats) and of the
 * references that are not in rank 0's cache (a single missing frame through `still` when it splits
 * it, else the missing frames dealt round-robin when the method keeps no state between frames,
 * else rank 0 renders them); rank 0 reads and writes the cache, runs the match searches, gathers
 * the rows and writes every file. The cached references are a one-process run's bit for bit; what
 * a report says equals a one-process run's except timings (each row records the rank that timed
 * it). Every process calls the callbacks at the same points of a run, so that a failure anywhere
 * ends every process at the next one. */
typedef struct fv_bench_split {
    int rank, size;
    void *user; /* given to the callbacks */
    /* Moves n bytes from rank `from`'s buf into rank `to`'s; called by those two ranks only. */
    fv_status (*move)(void *user, int from, int to, void *buf, size_t n, fv_error *err);
    /* Called by every rank with its own status: the job's, FV_OK when every rank succeeded (err is
     * then left alone); otherwise a failure on every rank, err saying why where it is known. */
    fv_status (*agree)(void *user, fv_status s, fv_error *err);
    /* Polled while rendering: true once another rank has failed (this rank then stops at its next
     * frame); and said by a rank that has just failed. Both may be NULL. */
    bool (*stopped)(void *user);
    void (*failed)(void *user);
    /* Optional (NULL: never split by samples): called by every rank with the same still. When it
     * splits that still (the same answer on every rank) it sets *split, renders it across the
     * ranks into film (on rank 0 then the one-process image bit for bit) and returns the job's
     * status, as agree does; else it leaves *split false, renders nothing and returns FV_OK. */
    fv_status (*still)(void *user, const fv_bench_still *still, fv_film *film, bool *split, fv_error *err);
} fv_bench_split;

typedef struct fv_bench_options {
    const char *out_dir;    /* where reports and images go (created if missing) */
    const char *cache_dir;  /* reference cache; NULL: <out_dir>/cache */
    fv_bench_mode mode;
    int threads;            /* 0: all */
    int repeats;            /* > 0 overrides the scenario's */
    const fv_log *log;      /* warnings */
    /* Status lines, one as each step begins ("[2/6] pt-4: repeat 1/3, 5 frame(s)"); may be NULL. */
    void (*status)(void *user, const char *line);
    void *status_user;
    /* "cpu", "portable", "cuda", "auto" or NULL: the device of every measured method that has it
     * and whose parameters name none (fovea/device.h); references stay where the scenario puts them. */
    const char *device;
    /* Called once when the run has written its reports, with the main result table (Markdown,
     * one row per method: time, speed-up, errors per region) for the caller to show; may be NULL.
     * Gets status_user. */
    void (*table)(void *user, const char *text);
    /* The command that ran this, recorded in the reports as it is (e.g. "fovea bench pt-cornell
     * --quick"); may be NULL. */
    const char *command;
    /* Called once when the run has written its reports, with the JSON report's text (what
     * <out_dir>/<name>.json holds), so a caller that wants the figures (the Python package) need
     * not work out the report's name and read it back; may be NULL. Gets status_user. Not called
     * when the run fails. */
    void (*report)(void *user, const char *json);
    /* NULL: one process; else the run is split over size processes (above). */
    const fv_bench_split *split;
    /* Progress within the step the last status line began (a reference's frames, the noise probe,
     * a method's repeat): `done` of the step's `total` frames that this process renders are done,
     * and the fraction `part` of the next one; may be NULL. Gets status_user; never called from two
     * threads at once. A reference and the probe report during a frame too (through the driver's
     * fv_progress_fn, as the technique's work goes on); a measured method only between frames,
     * after its frame's time is taken: its timed render call is the same with or without this. */
    void (*progress)(void *user, int done, int total, double part);
} fv_bench_options;

/* Runs the scenario file at `path`. Bad scenario -> FV_ERR_INVALID naming file and field. Writes
 * <out_dir>/<name>.json, <name>.md, <name>/ images and, with a sweep, <name>-sweep.csv and .png.
 * Every file is written whole or not at all. */
FV_API fv_status fv_bench_run(const char *path, const fv_bench_options *opt, fv_error *err);

/* Only parses and validates the scenario (for `fovea bench --check`). */
FV_API fv_status fv_bench_check(const char *path, fv_bench_mode mode, fv_error *err);

/* The same for a scenario given as JSON text (`fovea bench --scene ...` builds one): `label`
 * stands for its file name (messages, and the report's name when the text has no "name"), `dir`
 * for its folder (relative scene and gaze-trace paths resolve against it). */
FV_API fv_status fv_bench_run_text(const char *json, const char *label, const char *dir, const fv_bench_options *opt, fv_error *err);
FV_API fv_status fv_bench_check_text(const char *json, const char *label, const char *dir, fv_bench_mode mode, fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
