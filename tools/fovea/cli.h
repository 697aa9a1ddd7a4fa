/* fovea CLI — helpers shared by the subcommands: argument parsing, exit codes, the warning sink
 * and the progress bar. The library never exits or prints; this is where that happens. */
#ifndef FV_CLI_H
#define FV_CLI_H

#include <stdbool.h>
#include <stdio.h>
#include "core/inputs.h"
#include "fovea/fovea.h"

/* Exit statuses of every subcommand. */
enum { FV_EXIT_OK = 0, FV_EXIT_INTERNAL = 1, FV_EXIT_USAGE = 2 };

/* Status -> exit code: bad input and file problems are the user's (2), the rest ours (1). */
int fv_cli_exit_code(fv_status s);
/* Prints "fovea <cmd>: <msg>" on stderr and returns the exit code for s. */
int fv_cli_fail(const char *cmd, fv_status s, const char *msg);
/* Prints "fovea <cmd>: <printf...>" on stderr and returns FV_EXIT_USAGE. */
int fv_cli_usage_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Before any work, for each file a command will write: refused (one line, exit 2) when it is one
 * of the command's inputs, or an existing device, FIFO, folder or read-only file (core/inputs.h).
 * what names the output in the message ("--out"). Returns 0 or the exit code. */
int fv_cli_check_output(const char *cmd, const fv_inputs *in, const char *path, const char *what);

/* Parsers for option values; false with a message in err when malformed. */
bool fv_cli_parse_int(const char *s, long lo, long hi, long *out);
bool fv_cli_parse_float(const char *s, double *out);
bool fv_cli_parse_doubles(const char *s, int n, double *out); /* "x,y,z" with exactly n finite numbers */
bool fv_cli_parse_floats(const char *s, int n, float *out);   /* the same, each within the float range */
/* The options `fovea render` and `fovea view` both take, read and checked once so both word a bad
 * value alike: 0 when arg is good (the value in *out), else the exit status after the message. */
int fv_cli_opt_size(const char *cmd, const char *arg, int *w, int *h);
int fv_cli_opt_gaze(const char *cmd, const char *arg, float xy[2]);
int fv_cli_opt_stereo(const char *cmd, const char *arg, double *sep);
/* Coordinates and intensities within the ray kernels' range (fovea/limits.h), as the scene files
 * and traces check them: an option of three coordinates (--camera-pos, ...), and --point-light
 * x,y,z,r,g,b. */
int fv_cli_opt_vec3(const char *cmd, const char *opt, const char *arg, float out[3]);
int fv_cli_opt_light(const char *cmd, const char *arg, float out[6]);
/* --param KEY=VALUE into params; a key given twice is refused (the last would silently win). */
int fv_cli_opt_param(const char *cmd, const char *arg, fv_params *params);
bool fv_cli_parse_size(const char *s, int *w, int *h);      /* "WxH" */

/* Warning sink printing "fovea: warning: ..." on stderr (silenced when quiet). */
fv_log fv_cli_log(bool *quiet);

/* ---- interruption (SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM) ----
 *
 * The CLI, not the library, handles these signals, every one as SIGTERM (the library installs no
 * handler and keeps no state). A command ends at once with one line on stderr, "fovea <cmd>:
 * interrupted (SIGINT)", and exit status 128 + the signal (130 INT, 143 TERM, 129 HUP, 141 PIPE,
 * 131 QUIT, 138 USR1, 140 USR2, 142 ALRM), leaving no temporary file of an unfinished write and no
 * child process (a write to a closed pipe, `fovea methods | head -1`, ends the same way):
 *  - at once by default: the handler runs on the main thread (another thread that receives the
 *    signal passes it there), removes the temporary files of the atomic writes the process has
 *    open (fv_atomic_file_remove_open_temps: whatever the main thread was doing, it never
 *    resumes), prints the line and _exits. Sandbox children (assimp, image decoding) die with the
 *    process (sandbox.h). Loading, bench and gaze import end this way: the library offers them
 *    no cancellation point;
 *  - at the next cancellation point while deferred (fv_cli_interrupt_defer): the handler only
 *    records the signal, fv_cli_progress_frame then returns false (the render ends with
 *    FV_ERR_CANCELLED), a write in progress completes, and the command checks
 *    fv_cli_interrupted and returns fv_cli_interrupt_exit. A second signal ends it at once.
 * A signal ignored when fovea starts (a background job of a shell without job control) stays
 * ignored. */
/* Installs the handler for command cmd (kept, not copied: a string literal or argv). */
void fv_cli_interrupt_install(const char *cmd);
/* Deferred (on) or at once (off, the default). */
void fv_cli_interrupt_defer(bool on);
/* The signal received (one of the above), 0 when none. */
int fv_cli_interrupted(void);
/* Prints the interruption line (once) and returns the exit status, 128 + the signal. */
int fv_cli_interrupt_exit(void);
/* The command's outcome is decided and its one line said (or about to be, by another process of
 * the job): a signal from now on ends it without a line of its own. For an MPI job, whose
 * launcher signals the other ranks once a failed rank exits (docs/distributed.md). */
void fv_cli_interrupt_mute(void);
/* An MPI job interrupted by signal sig on some rank (fv_dist_signal): this rank says the job's line
 * when say (the one rank the agreement chose), is muted either way, and returns 128 + sig. */
int fv_cli_interrupt_exit_as(int sig, bool say);

/* ---- the thread policy (cli_threads.c, docs/threads.md) ----
 *
 * Puts the policy chosen by --thread-policy, else FOVEA_THREAD_POLICY, else auto, into OpenMP's
 * variables and executes the program again so that the runtime reads them; call it first thing in
 * main for a command that renders, with main's own argc and argv. Returns -1 to go on (the plan is in place, or cannot be), or an
 * exit status (a bad policy name: 2). */
int fv_cli_thread_policy(int argc, char **argv, const char *cmd);
/* --thread-policy NAME as a command's option: only checked here (main applied it already). */
int fv_cli_opt_thread_policy(const char *cmd, const char *arg);
#define FV_CLI_THREAD_POLICY_HELP \
    "  --thread-policy P     auto, pace, share or openmp: how many threads by default and how they\n" \
    "                        wait between parallel regions (docs/threads.md) [auto]\n"
/* One line saying which plan is in effect, for --stats. */
const char *fv_cli_thread_plan(void);

/* ---- the progress line (cli_progress.c) ----
 *
 * On stderr: a bar, the percentage, the frame under way, the time so far and the ETA (once a
 * thousandth of the work is done). On a terminal, one line drawn in place (\r) when its
 * percentage changes or a second has passed, and cleared when the work or the step ends. Not on a
 * terminal (a pipe, a CI log) nothing, unless the command asks for lines (init_steps with every_s
 * >= 0): then a plain line "LABEL: 42%, frame 2/3, 1m12s elapsed, ETA 1m40s" when the percentage
 * has changed and every_s seconds have passed since the step began and since its last line (a
 * step shorter than that adds nothing to the log). quiet: nothing at all. */
typedef struct fv_cli_progress {
    bool enabled;     /* anything is shown */
    bool tty;         /* stderr is a terminal */
    double every_ms;  /* not a terminal: the least time between two lines; < 0: no lines */
    double t0;        /* the work's (the step's) start, fv_time_ms */
    double last_ms;   /* the last line drawn, else t0 */
    int frame, frames; /* the frame under way (0-based) of how many: set by the caller */
    int last_percent;
    int shown;        /* characters of the terminal's line now drawn (0: none) */
    char label[160];  /* the step, leading a line that is not a terminal's */
} fv_cli_progress;
/* One run of frames (`fovea render`): the bar on a terminal only. */
void fv_cli_progress_init(fv_cli_progress *p, bool quiet, int frames);
/* A command of several steps (`fovea bench`): the bar on a terminal, else lines (every_s). */
void fv_cli_progress_init_steps(fv_cli_progress *p, bool quiet, double every_s);
/* Ends the step shown (fv_cli_progress_done) and begins the next: its label, its frames, its clock. */
void fv_cli_progress_step(fv_cli_progress *p, const char *label, int frames);
bool fv_cli_progress_frame(void *user, double fraction); /* fv_progress_fn; cancels once interrupted */
/* Clears the terminal's line, if drawn (again: nothing). */
void fv_cli_progress_done(fv_cli_progress *p);
/* The rules, for the tests: whether a line showing `percent` is due at now_ms; the line for
 * `total` (0..1) of the work at now_ms into buf (snprintf's return); a duration as "42s",
 * "3m05s", "1h02m" (whole seconds, rounded). */
bool fv_cli_progress_due(const fv_cli_progress *p, int percent, double now_ms);
int fv_cli_progress_format(const fv_cli_progress *p, double total, double now_ms, char *buf, size_t n);
void fv_cli_duration(double seconds, char *buf, size_t n);

/* The method check every rendering command makes before loading anything: an unknown name fails
 * with the library's message listing the methods. Returns 0 or the exit code (message printed). */
int fv_cli_check_method(const char *cmd, const char *method);
/* What the command line adds to a scene as it opens it. */
typedef struct fv_cli_scene_opts {
    int nlights;
    const float (*lights)[6];  /* --point-light x,y,z,r,g,b each */
    bool has_env;              /* --env R,G,B: a uniform environment */
    float env[3];
    bool no_default_light;     /* --no-default-light */
    bool has_frame;            /* --frame-view NAME */
    fv_frame_view frame;
} fv_cli_scene_opts;

/* Opens a scene (built-in name or file), adds what o asks (NULL: nothing), then the default
 * lighting when the scene still has no light (unless o->no_default_light), and commits it, with
 * the messages `fovea render` prints. Returns 0 or the exit code; on failure whatever was opened
 * is released and *scene, *view are NULL. */
int fv_cli_open_scene(const char *cmd, const char *name, const fv_log *log, const fv_cli_scene_opts *o, fv_scene **scene, fv_view **view);
/* The scene options every command that opens a scene takes (--env, --no-default-light,
 * --frame-view): their getopt codes (above any command's own), long options and help lines, and
 * the handler. fv_cli_scene_option returns -1 when c is not one of them, else 0 or the exit code
 * (message printed). */
enum { FV_CLI_OPT_ENV = 1000, FV_CLI_OPT_NO_DEFAULT_LIGHT, FV_CLI_OPT_FRAME_VIEW };
#define FV_CLI_SCENE_LONGOPTS \
    {"env", 1, 0, FV_CLI_OPT_ENV}, {"no-default-light", 0, 0, FV_CLI_OPT_NO_DEFAULT_LIGHT}, {"frame-view", 1, 0, FV_CLI_OPT_FRAME_VIEW}
#define FV_CLI_SCENE_HELP \
    "  --env R,G,B           a uniform environment light of that radiance (replaces the scene's)\n" \
    "  --no-default-light    a file without lights gets no sky and key light (docs/scene-format.md)\n" \
    "  --frame-view NAME     frame the scene from three-quarter, front, back, left, right or top\n"
int fv_cli_scene_option(const char *cmd, int c, const char *arg, fv_cli_scene_opts *o);
/* --env and --frame-view's parsing, with their one-line messages: 0 or the exit code. */
int fv_cli_opt_env(const char *cmd, const char *arg, fv_cli_scene_opts *o);
int fv_cli_opt_frame_view(const char *cmd, const char *arg, fv_cli_scene_opts *o);

/* Subcommands. */
int fv_cmd_render(int argc, char **argv);
int fv_cmd_methods(int argc, char **argv);
int fv_cmd_scenes(int argc, char **argv);
int fv_cmd_compare(int argc, char **argv);
int fv_cmd_bench(int argc, char **argv);
int fv_cmd_bench_scaling(int argc, char **argv); /* `fovea bench scaling` (cmd_bench_scaling.c) */
int fv_cmd_view(int argc, char **argv);
int fv_cmd_gaze(int argc, char **argv);

#endif
