/* fovea CLI — `fovea bench scaling`: how every method's frame scales with the thread count
 * (docs/threads.md, "Scaling"). For each method, on one scene of its family, a fresh technique
 * renders warm-up frames and then timed frames at 1, 2, 4, ... threads up to all CPUs; the table
 * gives frame p50/p99, speed-up and efficiency against one thread, the parallel regions per frame,
 * and the serial share of the frame and of each stage at the most threads, estimated from the
 * measured speed-up with Karp and Flatt's metric (CACM 33(5), 1990):
 *
 *     e = (1/psi - 1/p) / (1 - 1/p),   psi = t(1) / t(p),
 *
 * the fraction of the one-thread time that would have to run serially for Amdahl's law to give
 * the speed-up seen (overheads that grow with p, such as waking threads, count as serial).
 * All thread counts run in one process, interleaved per method, so a machine that slows down for a
 * while slows them alike; compare ratios within one run. */
#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "core/alloc.h"
#include "core/fileio.h"
#include "core/order_stats.h"
#include "fovea/fovea.h"

#define MAX_COUNTS 16

typedef struct scaling_opts {
    int width, height, frames, warmup, max_threads;
    const char *methods; /* comma-separated, NULL: all */
    const char *out;     /* markdown report, NULL: none */
    bool quiet;
} scaling_opts;

static double karp_flatt(double t1, double tp, int p)
{
    if (p < 2 || !(t1 > 0.0) || !(tp > 0.0)) return NAN;
    double psi = t1 / tp;
    return (1.0 / psi - 1.0 / p) / (1.0 - 1.0 / p);
}

typedef struct run_result {
    double p50, p99, regions;
    int n_stages;
    char stage[FV_STATS_MAX][32];
    double stage_ms[FV_STATS_MAX]; /* medians */
    /* measured serial shares (core/stage_time.h, as --stats gives them) over the timed frames: of
     * the frame (its stages' serial ms over its ms) and of each stage (-1: none measured) */
    double serial;
    double stage_serial[FV_STATS_MAX];
} run_result;

/* Renders warmup + frames frames of a fresh technique with `threads` threads. */
static int run_one(const char *cmd, const char *method, fv_scene *scene, const fv_view *view, const scaling_opts *o, int threads,
                   run_result *r)
{
    fv_error err;
    fv_params *params = NULL;
    fv_technique *tech = NULL;
    fv_driver *driver = NULL;
    fv_film *film = NULL;
    int rc = 0;
    double *ms = fv_alloc_array((size_t)o->frames, sizeof(double));
    double *st = fv_alloc_array((size_t)o->frames * FV_STATS_MAX, sizeof(double));
    fv_status s = ms && st ? fv_params_create(&params, &err) : fv_error_set(&err, FV_ERR_NOMEM, "out of memory");
    bool quiet = true;
    fv_log log = fv_cli_log(&quiet);
    if (s == FV_OK) s = fv_technique_create(method, scene, params, &log, &tech, &err);
    fv_drive_opts d;
    fv_drive_opts_init(&d);
    d.width = o->width;
    d.height = o->height;
    d.threads = threads;
    if (s == FV_OK) s = fv_driver_create(scene, view, &d, &driver, &err);
    if (s == FV_OK) s = fv_film_create(o->width, o->height, 0, &film, &err);
    memset(r, 0, sizeof *r);
    double ser_frame = 0.0, frame_sum = 0.0, ser_stage[FV_STATS_MAX] = {0}, stage_sum[FV_STATS_MAX] = {0};
    bool has_ser[FV_STATS_MAX] = {false};
    for (int f = 0; s == FV_OK && f < o->warmup + o->frames; f++) {
        fv_stats stats;
        fv_stats_clear(&stats);
        double t0 = fv_time_ms();
        s = fv_driver_render(driver, tech, f, f > 0, &film, &stats, NULL, NULL, &err);
        double t = fv_time_ms() - t0;
        if (s != FV_OK || f < o->warmup) continue;
        int k = f - o->warmup;
        ms[k] = t;
        r->regions += fv_stats_get_count(&stats, "parallel_regions") / o->frames;
        if (k == 0) {
            r->n_stages = stats.n_stages;
            for (int i = 0; i < stats.n_stages; i++) snprintf(r->stage[i], sizeof r->stage[i], "%s", stats.stage[i].name);
        }
        for (int i = 0; i < r->n_stages; i++) st[(size_t)i * o->frames + k] = fv_stats_get_ms(&stats, r->stage[i]);
        for (int i = 0; i < stats.n_serial; i++) ser_frame += stats.serial[i].value;
        for (int i = 0; i < r->n_stages; i++) {
            const double v = fv_stats_get_serial_ms(&stats, r->stage[i]);
            if (v >= 0.0) ser_stage[i] += v, has_ser[i] = true;
            stage_sum[i] += fv_stats_get_ms(&stats, r->stage[i]);
        }
        frame_sum += t;
    }
    if (s == FV_OK) {
        for (int i = 0; i < r->n_stages; i++) r->stage_ms[i] = fv_percentile(&st[(size_t)i * o->frames], o->frames, 50.0);
        r->p99 = fv_percentile(ms, o->frames, 99.0);
        r->p50 = fv_percentile(ms, o->frames, 50.0);
        r->serial = frame_sum > 0.0 ? fmin(1.0, ser_frame / frame_sum) : 0.0;
        for (int i = 0; i < r->n_stages; i++)
            r->stage_serial[i] = !has_ser[i] ? -1.0 : stage_sum[i] > 0.0 ? fmin(1.0, ser_stage[i] / stage_sum[i]) : 0.0;
    } else {
        rc = fv_cli_fail(cmd, s, err.msg);
    }
    free(ms), free(st);
    fv_film_destroy(film);
    fv_driver_destroy(driver);
    fv_technique_destroy(tech);
    fv_params_destroy(params);
    return rc;
}

static bool listed(const char *list, const char *m)
{
    if (!list) return true;
    size_t n = strlen(m);
    for (const char *p = list; *p;) {
        const char *e = strchr(p, ',');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        if (l == n && !strncmp(p, m, n)) return true;
        if (!e) break;
        p = e + 1;
    }
    return false;
}

/* Appends printf-formatted text to a growing buffer (the report, written whole at the end). */
typedef struct text {
    char *buf;
    size_t len, cap;
    bool failed;
} text;

__attribute__((format(printf, 2, 3))) static void put(text *t, const char *fmt, ...)
{
    va_list ap;
    for (int tries = 0; tries < 2 && !t->failed; tries++) {
        va_start(ap, fmt);
        int n = vsnprintf(t->buf ? t->buf + t->len : NULL, t->buf ? t->cap - t->len : 0, fmt, ap);
        va_end(ap);
        if (n < 0) { t->failed = true; return; }
        if (t->buf && t->len + (size_t)n < t->cap) {
            t->len += (size_t)n;
            return;
        }
        size_t cap = (t->cap + (size_t)n + 1) * 2;
        char *b = realloc(t->buf, cap);
        if (!b) { t->failed = true; return; }
        t->buf = b, t->cap = cap;
    }
}

static void usage(FILE *f)
{
    fprintf(f, "usage: fovea bench scaling [options]\n"
               "  every method's frame on one of its scenes at 1, 2, 4, ... threads up to all CPUs: frame p50/p99,\n"
               "  speed-up, efficiency, parallel regions per frame and the serial share of the frame and of each\n"
               "  stage, estimated (Karp-Flatt) and measured (serial %%, as --stats gives it; docs/threads.md)\n"
               "  --size WxH            image size [640x360: the viewer's]\n"
               "  --frames N            timed frames per thread count [20]\n"
               "  --warmup N            frames rendered first and not timed [2]\n"
               "  --max-threads N       the most threads [all CPUs]\n"
               "  --methods A,B,...     only these methods [all]\n"
               "  --report FILE.md      also write the tables to FILE.md (whole or not at all)\n"
               "  --quiet               no progress lines\n"
               FV_CLI_THREAD_POLICY_HELP);
}

int fv_cmd_bench_scaling(int argc, char **argv)
{
    const char *cmd = "bench scaling";
    scaling_opts o = {640, 360, 20, 2, 0, NULL, NULL, false};
    enum { O_SIZE = 256, O_FRAMES, O_WARMUP, O_MAX, O_METHODS, O_REPORT, O_QUIET, O_TPOLICY, O_HELP };
    static const struct option longs[] = {{"size", 1, 0, O_SIZE},       {"frames", 1, 0, O_FRAMES},   {"warmup", 1, 0, O_WARMUP},
                                          {"max-threads", 1, 0, O_MAX}, {"methods", 1, 0, O_METHODS}, {"report", 1, 0, O_REPORT},
                                          {"quiet", 0, 0, O_QUIET},     {"thread-policy", 1, 0, O_TPOLICY}, {"help", 0, 0, O_HELP},
                                          {0, 0, 0, 0}};
    int c, rc;
    long l;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        switch (c) {
        case O_SIZE:
            if ((rc = fv_cli_opt_size(cmd, optarg, &o.width, &o.height))) return rc;
            break;
        case O_FRAMES:
            if (!fv_cli_parse_int(optarg, 1, 100000, &l)) return fv_cli_usage_error(cmd, "--frames %s: expected an integer in [1, 100000]", optarg);
            o.frames = (int)l;
            break;
        case O_WARMUP:
            if (!fv_cli_parse_int(optarg, 0, 1000, &l)) return fv_cli_usage_error(cmd, "--warmup %s: expected an integer in [0, 1000]", optarg);
            o.warmup = (int)l;
            break;
        case O_MAX:
            if (!fv_cli_parse_int(optarg, 1, 256, &l)) return fv_cli_usage_error(cmd, "--max-threads %s: expected an integer in [1, 256]", optarg);
            o.max_threads = (int)l;
            break;
        case O_METHODS:
            o.methods = optarg;
            for (const char *p = optarg; p;) {
                char name[64];
                const char *e = strchr(p, ',');
                snprintf(name, sizeof name, "%.*s", e ? (int)(e - p) : (int)strlen(p), p);
                if ((rc = fv_cli_check_method(cmd, name))) return rc;
                p = e ? e + 1 : NULL;
            }
            break;
        case O_REPORT: o.out = optarg; break;
        case O_QUIET: o.quiet = true; break;
        case O_TPOLICY:
            if ((rc = fv_cli_opt_thread_policy(cmd, optarg))) return rc;
            break;
        case 'h':
        case O_HELP: usage(stdout); return FV_EXIT_OK;
        default: return fv_cli_usage_error(cmd, "unknown option '%s' (try fovea bench scaling --help)", argv[optind - 1]);
        }
    }
    if (optind != argc) return fv_cli_usage_error(cmd, "unexpected argument '%s'", argv[optind]);
    /* all the CPUs the process may run on, not the policy's default (which follows the load) */
    int maxt = o.max_threads > 0 ? o.max_threads : omp_get_num_procs();
    int counts[MAX_COUNTS], nc = 0;
    for (int t = 1; t < maxt && nc < MAX_COUNTS - 1; t *= 2) counts[nc++] = t;
    counts[nc++] = maxt;

    text rep = {0};
    put(&rep, "Frame times at %dx%d, %d timed frames after %d warm-up frames per thread count; "
              "threads: %s.\n\n"
              "| method | scene | threads | p50 ms | p99 ms | p99/p50 | speed-up | efficiency | serial share | serial %% | regions/frame |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|\n",
        o.width, o.height, o.frames, o.warmup, fv_cli_thread_plan());
    text stages = {0};
    put(&stages, "\nSerial share (Karp-Flatt) of each stage at %d threads, its measured serial %% there (as --stats gives it; "
                 "-: none measured), and its share of the one-thread frame:\n\n"
                 "| method | stage: serial share, serial %% (share of the frame at 1 thread) |\n|---|---|\n", maxt);
    rc = 0;
    for (int i = 0; i < fv_technique_count() && rc == 0; i++) {
        const char *m = fv_technique_name(i);
        if (!listed(o.methods, m)) continue;
        fv_scene *scene = NULL;
        fv_view *view = NULL;
        bool quiet = true;
        fv_log log = fv_cli_log(&quiet);
        if ((rc = fv_cli_open_scene(cmd, fv_technique_bench_scene(i), &log, NULL, &scene, &view)) != 0) break;
        run_result res[MAX_COUNTS];
        for (int k = 0; k < nc && rc == 0; k++) {
            if (!o.quiet) fprintf(stderr, "fovea bench scaling: %s, %d thread%s\n", m, counts[k], counts[k] > 1 ? "s" : "");
            rc = run_one(cmd, m, scene, view, &o, counts[k], &res[k]);
        }
        for (int k = 0; k < nc && rc == 0; k++) {
            double sp = res[0].p50 / res[k].p50, kf = karp_flatt(res[0].p50, res[k].p50, counts[k]);
            char share[32] = "-"; /* one thread: no speed-up to read a serial share from */
            if (!isnan(kf)) snprintf(share, sizeof share, "%.1f%%", 100.0 * kf);
            put(&rep, "| %s | %s | %d | %.1f | %.1f | %.2f | %.2f | %.2f | %s | %.1f%% | %.0f |\n", m, fv_technique_bench_scene(i), counts[k], res[k].p50,
                res[k].p99, res[k].p99 / res[k].p50, sp, sp / counts[k], share, 100.0 * res[k].serial, res[k].regions);
        }
        if (rc == 0 && nc > 1) {
            const run_result *a = &res[0], *b = &res[nc - 1];
            put(&stages, "| %s |", m);
            for (int s = 0; s < a->n_stages; s++) {
                double tb = 0.0;
                for (int u = 0; u < b->n_stages; u++)
                    if (!strcmp(b->stage[u], a->stage[s])) tb = b->stage_ms[u];
                double kf = karp_flatt(a->stage_ms[s], tb, maxt), sb = -1.0;
                for (int u = 0; u < b->n_stages; u++)
                    if (!strcmp(b->stage[u], a->stage[s])) sb = b->stage_serial[u];
                char meas[32] = "-";
                if (sb >= 0.0) snprintf(meas, sizeof meas, "%.1f%%", 100.0 * sb);
                put(&stages, " %s: %.1f%%, %s (%.0f%%);", a->stage[s], 100.0 * kf, meas, 100.0 * a->stage_ms[s] / a->p50);
            }
            put(&stages, " |\n");
        }
        fv_scene_destroy(scene);
        fv_view_destroy(view);
    }
    if (rc != 0) {
        free(rep.buf), free(stages.buf);
        return rc;
    }
    put(&rep, "%s", stages.buf ? stages.buf : "");
    if (rep.failed || stages.failed) {
        free(rep.buf), free(stages.buf);
        return fv_cli_fail(cmd, FV_ERR_NOMEM, "out of memory");
    }
    fputs(rep.buf, stdout);
    fv_error err;
    fv_status ws = o.out ? fv_file_write_atomic(o.out, rep.buf, rep.len, &err) : FV_OK;
    if (ws != FV_OK) rc = fv_cli_fail(cmd, ws, err.msg);
    free(rep.buf), free(stages.buf);
    return rc;
}
