/* fovea CLI — shared helpers (see cli.h). */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli.h"
#include "core/fileio.h"

/* ---- interruption (see cli.h) ----
 *
 * The only mutable globals of fovea: what the signal handler needs, which cannot be passed to it.
 * The lines and the main thread are set before the handler is installed and only read after. */

/* The signals that end a command as SIGTERM does: each asks the process to stop (a closed
 * terminal, a closed pipe, a quit key, a timer, a user's signal a job manager sends), and each
 * would otherwise end it by the default action, mid-write, leaving the atomic writer's temporary
 * file and no message. */
#define NSIGS 8
static const int k_sigs[NSIGS] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM};
static const char *const k_sig_names[NSIGS] = {"SIGINT", "SIGTERM", "SIGHUP", "SIGPIPE", "SIGQUIT", "SIGUSR1", "SIGUSR2", "SIGALRM"};

static volatile sig_atomic_t g_signal; /* the first handled signal received, 0 none */
static volatile sig_atomic_t g_defer;  /* 1: the command stops at its next cancellation point */
static volatile sig_atomic_t g_said;   /* 1: the line has been printed */
static char g_line[NSIGS][160];        /* "fovea <cmd>: interrupted (SIGINT)\n", one per signal */
static size_t g_line_len[NSIGS];
static pthread_t g_main;

/* Async-signal-safe: a loop over a constant table. */
static int sig_index(int sig)
{
    for (int k = 0; k < NSIGS; k++)
        if (k_sigs[k] == sig) return k;
    return 0;
}

/* Every handled signal: blocked while the handler runs, and once the command only returns. */
static void handled_set(sigset_t *set)
{
    sigemptyset(set);
    for (int k = 0; k < NSIGS; k++) sigaddset(set, k_sigs[k]);
}

static void say_interrupted(int sig)
{
    if (g_said) return;
    g_said = 1;
    int k = sig_index(sig);
    const char *p = g_line[k];
    size_t n = g_line_len[k];
    /* A closed stderr (the SIGPIPE case) fails the write with EPIPE: the signal it raises is
     * blocked here (handler or fv_cli_interrupt_exit), so the process still ends by its status. */
    while (n > 0) {
        ssize_t w = write(STDERR_FILENO, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) break;
        p += w;
        n -= (size_t)w;
    }
}

static void on_signal(int sig)
{
    int saved = errno;
    if (!g_signal) g_signal = sig;
    else g_defer = 0; /* a second signal: at once */
    if (g_defer) {
        errno = saved;
        return;
    }
    /* Only the main thread writes files: stopped here, it leaves nothing half done that the
     * sweep below does not see. */
    if (!pthread_equal(pthread_self(), g_main)) {
        pthread_kill(g_main, sig);
        errno = saved;
        return;
    }
    fv_atomic_file_remove_open_temps();
    say_interrupted(g_signal);
    _exit(128 + g_signal);
}

void fv_cli_interrupt_install(const char *cmd)
{
    for (int k = 0; k < NSIGS; k++) {
        int n = snprintf(g_line[k], sizeof g_line[k], "fovea %.100s: interrupted (%s)\n", cmd, k_sig_names[k]);
        g_line_len[k] = n > 0 && (size_t)n < sizeof g_line[k] ? (size_t)n : strlen(g_line[k]);
    }
    g_main = pthread_self();
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    /* Restarted system calls: a deferred signal must not fail a write in progress. */
    sa.sa_flags = SA_RESTART;
    handled_set(&sa.sa_mask);
    for (int k = 0; k < NSIGS; k++) {
        struct sigaction was;
        if (sigaction(k_sigs[k], NULL, &was) == 0 && was.sa_handler == SIG_IGN) continue;
        sigaction(k_sigs[k], &sa, NULL);
    }
}

void fv_cli_interrupt_defer(bool on)
{
    g_defer = on;
}

int fv_cli_interrupted(void)
{
    return g_signal;
}

void fv_cli_interrupt_mute(void)
{
    g_said = 1;
}

int fv_cli_interrupt_exit(void)
{
    int sig = g_signal ? g_signal : SIGINT;
    /* From here on the command only returns: a further signal waits (blocked), so the handler
     * cannot cut this line short or end the process without it. */
    sigset_t all;
    handled_set(&all);
    pthread_sigmask(SIG_BLOCK, &all, NULL);
    say_interrupted(sig);
    return 128 + sig;
}

int fv_cli_interrupt_exit_as(int sig, bool say)
{
    /* The line whole: a signal that comes meanwhile (the launcher's, once a rank exits) waits for
     * it, then finds it said and ends the process without another. */
    sigset_t all, was;
    handled_set(&all);
    pthread_sigmask(SIG_BLOCK, &all, &was);
    if (say) say_interrupted(sig);
    g_said = 1;
    pthread_sigmask(SIG_SETMASK, &was, NULL);
    return 128 + sig;
}

int fv_cli_exit_code(fv_status s)
{
    switch (s) {
    case FV_OK: return FV_EXIT_OK;
    case FV_ERR_INVALID:
    case FV_ERR_IO: return FV_EXIT_USAGE;
    default: return FV_EXIT_INTERNAL;
    }
}

int fv_cli_fail(const char *cmd, fv_status s, const char *msg)
{
    fprintf(stderr, "fovea %s: %s\n", cmd, msg && *msg ? msg : fv_status_name(s));
    return fv_cli_exit_code(s);
}

int fv_cli_usage_error(const char *cmd, const char *fmt, ...)
{
    char msg[FV_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* Through fv_error_set, which escapes control bytes: an argument may hold a newline. */
    fv_error e;
    fv_error_set(&e, FV_ERR_INVALID, "%s", msg);
    fprintf(stderr, "fovea %s: %s\n", cmd, e.msg);
    return FV_EXIT_USAGE;
}

int fv_cli_check_output(const char *cmd, const fv_inputs *in, const char *path, const char *what)
{
    fv_error err;
    fv_error_clear(&err);
    fv_status s = fv_inputs_check_output(in, path, what, &err);
    return s == FV_OK ? 0 : fv_cli_fail(cmd, s, err.msg);
}

bool fv_cli_parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return false;
    *out = v;
    return true;
}

bool fv_cli_parse_float(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return false;
    *out = v;
    return true;
}

bool fv_cli_parse_doubles(const char *s, int n, double *out)
{
    const char *p = s;
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || !isfinite(v) || (errno && fabs(v) > 1.0)) return false; /* underflow to 0 is fine */
        out[i] = v;
        p = end;
        if (i < n - 1) {
            if (*p != ',') return false;
            p++;
        }
    }
    return *p == '\0';
}

bool fv_cli_parse_floats(const char *s, int n, float *out)
{
    double v[16];
    if (n > 16 || !fv_cli_parse_doubles(s, n, v)) return false;
    for (int i = 0; i < n; i++)
        if (fabs(v[i]) > FLT_MAX) return false;
    for (int i = 0; i < n; i++) out[i] = (float)v[i];
    return true;
}

bool fv_cli_parse_size(const char *s, int *w, int *h)
{
    char *end;
    errno = 0;
    long a = strtol(s, &end, 10);
    if (errno || end == s || (*end != 'x' && *end != 'X')) return false;
    const char *q = end + 1;
    long b = strtol(q, &end, 10);
    if (errno || end == q || *end) return false;
    /* Range is checked by fv_film_check_size so the message is the same everywhere. */
    if (a < -1000000000L || a > 1000000000L || b < -1000000000L || b > 1000000000L) return false;
    *w = (int)a;
    *h = (int)b;
    return true;
}

static void warn_sink(void *user, const char *msg)
{
    const bool *quiet = user;
    if (!quiet || !*quiet) fprintf(stderr, "fovea: warning: %s\n", msg);
}

fv_log fv_cli_log(bool *quiet)
{
    fv_log l = {warn_sink, quiet};
    return l;
}

int fv_cli_check_method(const char *cmd, const char *method)
{
    if (fv_technique_index(method) >= 0) return 0;
    fv_error err;
    fv_error_clear(&err);
    fv_technique *t = NULL;
    fv_status s = fv_technique_create(method, NULL, NULL, NULL, &t, &err); /* builds the message listing methods */
    fv_technique_destroy(t);
    return fv_cli_fail(cmd, s, err.msg);
}

int fv_cli_open_scene(const char *cmd, const char *name, const fv_log *log, const fv_cli_scene_opts *o, fv_scene **scene, fv_view **view)
{
    fv_error err;
    fv_error_clear(&err);
    *scene = NULL;
    *view = NULL;
    fv_cli_scene_opts none;
    memset(&none, 0, sizeof none);
    if (!o) o = &none;
    fv_status s = fv_scene_open(name, log, scene, view, &err);
    for (int i = 0; i < o->nlights && s == FV_OK; i++) {
        const float *v = o->lights[i];
        fv_light_desc l = {FV_LIGHT_POINT, fv_v3(v[0], v[1], v[2]), fv_v3(0, -1, 0), fv_v3(v[3], v[4], v[5]), 0, 0};
        s = fv_scene_add_light(*scene, &l, &err);
    }
    if (s == FV_OK && o->has_env) {
        fv_env_desc e = fv_env_uniform(fv_v3(o->env[0], o->env[1], o->env[2]));
        fv_env_desc had;
        if (fv_scene_env(*scene, &had)) e.up = had.up;
        s = fv_scene_set_env(*scene, &e, &err);
    }
    if (s == FV_OK && o->has_frame) fv_view_set_frame(*view, o->frame);
    if (s == FV_OK && !o->no_default_light) s = fv_scene_add_default_lighting(*scene, *view, log, NULL, &err);
    if (s == FV_OK && (s = fv_scene_commit(*scene, log, &err)) != FV_OK) fv_error_prefix(&err, "%s: ", name);
    if (s == FV_OK) return 0;
    fv_scene_destroy(*scene);
    fv_view_destroy(*view);
    *scene = NULL;
    *view = NULL;
    return fv_cli_fail(cmd, s, err.msg);
}

int fv_cli_scene_option(const char *cmd, int c, const char *arg, fv_cli_scene_opts *o)
{
    switch (c) {
    case FV_CLI_OPT_ENV: return fv_cli_opt_env(cmd, arg, o);
    case FV_CLI_OPT_NO_DEFAULT_LIGHT: o->no_default_light = true; return 0;
    case FV_CLI_OPT_FRAME_VIEW: return fv_cli_opt_frame_view(cmd, arg, o);
    default: return -1;
    }
}

int fv_cli_opt_env(const char *cmd, const char *arg, fv_cli_scene_opts *o)
{
    bool ok = fv_cli_parse_floats(arg, 3, o->env);
    for (int i = 0; i < 3 && ok; i++) ok = o->env[i] >= 0 && o->env[i] <= FV_RADIANCE_MAX; /* as a JSON scene's environment */
    if (!ok) return fv_cli_usage_error(cmd, "--env %s: expected R,G,B radiances in [0, %g]", arg, FV_RADIANCE_MAX);
    o->has_env = true;
    return 0;
}

int fv_cli_opt_frame_view(const char *cmd, const char *arg, fv_cli_scene_opts *o)
{
    if (!fv_frame_view_from_name(arg, &o->frame))
        return fv_cli_usage_error(cmd, "--frame-view %s: expected front, back, left, right, top or three-quarter", arg);
    o->has_frame = true;
    return 0;
}

int fv_cli_opt_size(const char *cmd, const char *arg, int *w, int *h)
{
    return fv_cli_parse_size(arg, w, h) ? 0 : fv_cli_usage_error(cmd, "--size %s: expected WxH, e.g. 640x480", arg);
}

int fv_cli_opt_gaze(const char *cmd, const char *arg, float xy[2])
{
    if (fv_cli_parse_floats(arg, 2, xy) && xy[0] >= 0 && xy[0] <= 1 && xy[1] >= 0 && xy[1] <= 1) return 0;
    return fv_cli_usage_error(cmd, "--gaze %s: expected X,Y with both in [0,1]", arg);
}

/* The limit's own message after the option and its value: "--camera-pos 1e19,0,0: coordinate
 * 1e+19 is beyond +-1e+15, the range the ray kernels take". */
static int limit_fail(const char *cmd, const char *opt, const char *arg, fv_status (*check)(const char *, const double *, int, fv_error *),
                      const double *v, int n)
{
    char what[256];
    snprintf(what, sizeof what, "%s %.200s", opt, arg);
    fv_error err;
    fv_status s = check(what, v, n, &err);
    return s == FV_OK ? 0 : fv_cli_fail(cmd, s, err.msg);
}

int fv_cli_opt_stereo(const char *cmd, const char *arg, double *sep)
{
    if (!fv_cli_parse_float(arg, sep) || !(*sep > 0)) return fv_cli_usage_error(cmd, "--stereo %s: expected a positive eye separation", arg);
    return limit_fail(cmd, "--stereo", arg, fv_limit_coords, sep, 1);
}

int fv_cli_opt_vec3(const char *cmd, const char *opt, const char *arg, float out[3])
{
    double v[3];
    if (!fv_cli_parse_doubles(arg, 3, v)) return fv_cli_usage_error(cmd, "%s %s: expected x,y,z", opt, arg);
    int rc = limit_fail(cmd, opt, arg, fv_limit_coords, v, 3);
    for (int i = 0; i < 3 && rc == 0; i++) out[i] = (float)v[i];
    return rc;
}

int fv_cli_opt_param(const char *cmd, const char *arg, fv_params *params)
{
    fv_error err;
    fv_error_clear(&err);
    const char *eq = strchr(arg, '=');
    size_t n = eq ? (size_t)(eq - arg) : 0;
    for (int i = 0; eq && i < fv_params_count(params); i++) {
        const char *k = fv_params_key(params, i);
        if (strlen(k) == n && !strncmp(k, arg, n))
            return fv_cli_usage_error(cmd, "--param %s: %.*s is already set (to %s); give each parameter once", arg, (int)n, arg,
                                      fv_params_value(params, i));
    }
    if (fv_params_parse(params, arg, &err) != FV_OK) return fv_cli_fail(cmd, err.status, err.msg);
    return 0;
}

int fv_cli_opt_light(const char *cmd, const char *arg, float out[6])
{
    double v[6];
    if (!fv_cli_parse_doubles(arg, 6, v)) return fv_cli_usage_error(cmd, "--point-light %s: expected x,y,z,r,g,b", arg);
    int rc = limit_fail(cmd, "--point-light", arg, fv_limit_coords, v, 3);
    if (rc == 0) rc = limit_fail(cmd, "--point-light", arg, fv_limit_intensity, v + 3, 3);
    for (int i = 0; i < 6 && rc == 0; i++) out[i] = (float)v[i];
    return rc;
}
