/* fovea CLI — `fovea bench SCENARIO`: run a benchmark scenario (bench/<name>.json, docs/bench.md)
 * and write its report. A bare name is looked up in $FOVEA_BENCH_DIR, ./bench, the installed
 * share/fovea/bench next to this executable and, for an uninstalled build, the source tree's
 * bench/ folder, so `fovea bench pt-cornell` works both installed and from a fresh clone. */
#include <dirent.h>
#include <getopt.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "bench/scenario.h"
#include "bench_cmdline.h"
#include "cli.h"
#include "core/json_util.h"
#include "core/fileio.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: fovea bench SCENARIO [options]\n"
               "       fovea bench --scene SCENE --methods M1,M2[:KEY=VALUE...] [--reference pt:spp=1024] [--gaze X,Y |\n"
               "                   --gaze-trace F] [--frames N] [--size WxH] [--save-scenario F] [options]\n"
               "       fovea bench scaling [options]  (every method at 1, 2, 4, ... threads; --help there)\n"
               "Renders every method of a scenario side by side, times them (median of repeats) and measures\n"
               "their error per region (fovea, transition, periphery) against a cached reference.\n\n"
               "  SCENARIO          a scenario name (bench/NAME.json) or a path to a .json file\n"
               "  --out DIR         where the report goes [bench-out]: DIR/NAME.json, DIR/NAME.md, DIR/NAME/*.png\n"
               "  --cache DIR       reference cache [DIR/cache]\n"
               "  --quick           small sizes, under a minute (the scenario's \"quick\" block)\n"
               "  --full            the papers' sizes (the scenario's \"full\" block)\n"
               "  --repeats N       timing repeats (overrides the scenario)\n"
               "  --threads N       worker threads, 0 = the thread policy's default [0]\n"
           FV_CLI_THREAD_POLICY_HELP
               "  --device D        run every measured method that has device D there (cpu, portable, cuda,\n"
               "                    auto; docs/gpu.md); methods and references naming a device keep theirs\n"
               "  --progress-every S\n"
               "                    progress within each long step (a reference's frames, the noise probe,\n"
               "                    a method's repeat: percentage, frame, ETA) on stderr: on a terminal one\n"
               "                    line redrawn in place; otherwise a line at most every S seconds of a\n"
               "                    step still running (0: at every change) [20]\n"
               "  --check           only validate the scenario\n"
               "  --list            list the scenarios found, each with its description's first sentence\n"
               "Without a scenario file (the same harness, cache and reports; docs/bench.md):\n"
               "  --scene SCENE     built-in name or scene file to compare the methods on\n"
               "  --methods LIST    methods, comma-separated, each METHOD[:KEY=VALUE...] (e.g. fpm,pm:photons=20000);\n"
               "                    speed-ups are relative to the first\n"
               "  --reference SPEC  the reference, METHOD[:KEY=VALUE...] [pt:spp=1024]\n"
               "  --gaze X,Y        a fixed gaze [the scene's gaze, else the centre];  --gaze-trace F: a CSV trace\n"
               "  --frames N        frames [1; with a temporal method, its still warm-up before one measured frame]\n"
               "  --size WxH        image size [256x256]\n"
               "  --save-scenario F write the scenario built as a JSON file (to rerun or edit)\n"
               "  --quiet           no status or progress lines\n");
}

static bool is_file(const char *p)
{
    struct stat sb;
    return stat(p, &sb) == 0 && S_ISREG(sb.st_mode);
}

static bool is_dir(const char *p)
{
    struct stat sb;
    return stat(p, &sb) == 0 && S_ISDIR(sb.st_mode);
}

/* The installed scenarios: FOVEA_BENCH_FROM_BIN (e.g. ../share/fovea/bench) from the folder of the
 * running executable, so a moved or relocated install still finds its own. PATH_MAX bytes. */
static bool installed_dir(char *out)
{
#ifdef FOVEA_BENCH_FROM_BIN
    char exe[PATH_MAX], joined[PATH_MAX + 64];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len <= 0) return false;
    exe[len] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash) return false;
    *slash = '\0';
    snprintf(joined, sizeof joined, "%s/%s", exe, FOVEA_BENCH_FROM_BIN);
    return realpath(joined, out) && is_dir(out);
#else
    (void)out;
    return false;
#endif
}

/* The folders searched for scenario names, in order. The source tree comes last and only when no
 * installed folder exists, so an installed tool never picks up a stale clone's scenarios. */
static int bench_dirs(const char **dirs, char *installed)
{
    int n = 0;
    const char *env = getenv("FOVEA_BENCH_DIR");
    if (env && env[0]) dirs[n++] = env;
    dirs[n++] = "bench";
    if (installed_dir(installed)) dirs[n++] = installed;
#ifdef FOVEA_SOURCE_DIR
    else dirs[n++] = FOVEA_SOURCE_DIR "/bench";
#endif
    return n;
}

static bool resolve(const char *arg, char *out, size_t n)
{
    if (strchr(arg, '/') || strstr(arg, ".json")) {
        snprintf(out, n, "%s", arg);
        return true;
    }
    const char *dirs[4];
    char installed[PATH_MAX];
    int nd = bench_dirs(dirs, installed);
    for (int i = 0; i < nd; i++) {
        snprintf(out, n, "%s/%s.json", dirs[i], arg);
        if (is_file(out)) return true;
    }
    return false;
}

static int is_json(const struct dirent *e)
{
    size_t n = strlen(e->d_name);
    return n > 5 && strcmp(e->d_name + n - 5, ".json") == 0;
}

/* The first sentence of a scenario's "description" (at most 100 characters), or "" when it has
 * none or cannot be read: --list shows it beside the name. */
static void one_line(const char *dir, const char *file, char *out, size_t n)
{
    out[0] = 0;
    char path[PATH_MAX + 256];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    cJSON *root = NULL;
    fv_error err;
    if (fv_json_parse_file(path, &root, &err) != FV_OK) return;
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(root, "description");
    if (cJSON_IsString(d) && d->valuestring) {
        /* A sentence ends at ". " after 40 characters at least: "Figs. 5" or "Eq. 8" end none. */
        const char *t = d->valuestring, *stop = strlen(t) > 40 ? strstr(t + 40, ". ") : NULL;
        size_t len = stop ? (size_t)(stop - t) + 1 : strlen(t);
        if (len > 100) snprintf(out, n, "%.97s...", t);
        else snprintf(out, n, "%.*s", (int)len, t);
    }
    cJSON_Delete(root);
}

static void list_scenarios(void)
{
    const char *dirs[4];
    char installed[PATH_MAX];
    int nd = bench_dirs(dirs, installed);
    char seen[4][PATH_MAX];
    int nseen = 0;
    for (int i = 0; i < nd; i++) {
        if (!is_dir(dirs[i])) continue;
        /* ./bench and the source tree's (or the installed) bench/ are often the same folder: list
         * it once. */
        char real[PATH_MAX];
        if (!realpath(dirs[i], real)) continue;
        bool dup = false;
        for (int k = 0; k < nseen && !dup; k++) dup = strcmp(seen[k], real) == 0;
        if (dup) continue;
        snprintf(seen[nseen++], sizeof seen[0], "%s", real);
        struct dirent **names;
        int nn = scandir(dirs[i], &names, is_json, alphasort);
        if (nn < 0) continue;
        printf("%s:\n", dirs[i]);
        for (int k = 0; k < nn; k++) {
            char line[128];
            one_line(dirs[i], names[k]->d_name, line, sizeof line);
            printf("  %-22.*s %s\n", (int)(strlen(names[k]->d_name) - 5), names[k]->d_name, line);
            free(names[k]);
        }
        free(names);
    }
}

/* What the run says on stderr: a line as each step begins, and the progress within it on the
 * CLI's progress line (cli.h), which a warning or the table first clears. */
typedef struct bench_say {
    fv_cli_progress bar;
    fv_log log; /* the CLI's warning sink */
} bench_say;

/* The result table on stdout, whatever --quiet says: it is the command's output. */
static void on_table(void *user, const char *text)
{
    fv_cli_progress_done(&((bench_say *)user)->bar);
    fputs(text, stdout);
    fflush(stdout);
}

static void on_status(void *user, const char *line)
{
    bench_say *b = user;
    char label[sizeof b->bar.label];
    snprintf(label, sizeof label, "fovea bench: %s", line);
    fv_cli_progress_step(&b->bar, label, 1);
    fprintf(stderr, "%s\n", label);
}

static void on_progress(void *user, int done, int total, double part)
{
    bench_say *b = user;
    b->bar.frames = total > 0 ? total : 1;
    b->bar.frame = done;
    fv_cli_progress_frame(&b->bar, part);
    if (done >= total) fv_cli_progress_done(&b->bar); /* the step's frames are all done */
}

static void on_warning(void *user, const char *msg)
{
    bench_say *b = user;
    fv_cli_progress_done(&b->bar);
    b->log.warn(b->log.user, msg);
}

/* The run's callbacks on opt (on the process that speaks) and its warnings into *log. */
static void bench_say_init(bench_say *b, bool quiet, double every_s, bool speaks, fv_bench_options *opt, bool *quiet_flag, fv_log *log)
{
    fv_cli_progress_init_steps(&b->bar, quiet || !speaks, every_s);
    b->log = fv_cli_log(quiet_flag);
    *log = (fv_log){on_warning, b};
    opt->log = log;
    opt->status_user = b;
    if (!quiet && speaks) {
        opt->status = on_status;
        opt->progress = on_progress;
    }
    if (speaks) opt->table = on_table;
}

#ifdef FOVEA_HAVE_MPI
#include "dist/split.h"
/* `mpirun -n N fovea bench`: the library deals the rows (and the references' frames) to the ranks
 * (fv_bench_split); here its callbacks over src/dist, a reference still split by sample blocks as
 * `fovea render` splits one, and the one line a failed job prints. */
typedef struct bench_dist {
    fv_dist *d;
    bool agreed;             /* the library ran at least one agreement */
    bool print_it, name_rank; /* from the last failed agreement: whether this rank says the job's line */
} bench_dist;

static fv_status split_move(void *user, int from, int to, void *buf, size_t n, fv_error *err)
{
    bench_dist *b = user;
    return fv_dist_rank(b->d) == from ? fv_dist_send_bytes(b->d, to, buf, n, err) : fv_dist_recv_bytes(b->d, from, buf, n, err);
}

static fv_status split_agree(void *user, fv_status s, fv_error *err)
{
    bench_dist *b = user;
    b->agreed = true;
    fv_error mpi;
    fv_error_clear(&mpi);
    fv_status js = fv_dist_agree(b->d, s, &b->print_it, &b->name_rank, &mpi);
    if (js != FV_OK) fv_cli_interrupt_mute(); /* the launcher may now signal this rank */
    if (js != FV_OK && s == FV_OK) *err = mpi.msg[0] ? mpi : (fv_error_set(err, js, "another rank failed"), *err);
    return js;
}

/* The still over every rank when src/dist splits it (pt's sample blocks, ppm's blocks of passes):
 * the same decision on every rank, from the method and its parameters alone. */
static fv_status split_still(void *user, const fv_bench_still *still, fv_film *film, bool *split, fv_error *err)
{
    bench_dist *b = user;
    fv_dist_still_job job;
    fv_dist_still_job_init(&job, still->method, still->params, still->scene, still->log, still->driver, still->frame);
    if (!(*split = fv_dist_still_splits(&job, fv_dist_size(b->d)))) return FV_OK;
    fv_stats stats;
    fv_stats_clear(&stats);
    fv_error mine;
    fv_error_clear(&mine);
    b->agreed = true;
    fv_status js = fv_dist_still(b->d, &job, &film, 1, &stats, &b->print_it, &b->name_rank, &mine);
    if (js != FV_OK) {
        fv_cli_interrupt_mute(); /* the launcher may now signal this rank */
        if (mine.msg[0]) *err = mine;
        else fv_error_set(err, js, "another rank failed");
    }
    return js;
}

static bool split_stopped(void *user) { return fv_dist_poll(((bench_dist *)user)->d); }
static void split_failed(void *user) { fv_dist_tell_failure(((bench_dist *)user)->d); }
#else
typedef struct bench_dist bench_dist;
#endif

/* A failed run's exit status, its line printed by the one rank whose words stand when split. */
static int bench_fail(const bench_dist *bd, fv_status s, const char *msg)
{
#ifdef FOVEA_HAVE_MPI
    if (bd && bd->agreed) {
        if (!bd->print_it) return fv_cli_exit_code(s);
        if (bd->name_rank) fprintf(stderr, "rank %d: ", fv_dist_rank(bd->d));
    }
#else
    (void)bd;
#endif
    return fv_cli_fail("bench", s, msg);
}

/* The files the run writes that a person names (--save-scenario, the report's DIR/NAME.json and
 * DIR/NAME.md; reports only when it runs), checked against the files it reads before anything is
 * rendered or written: 0 or the exit code. The images and the cache are named by the harness. */
static int check_outputs(const fv_inputs *in, const char *save, const char *out_dir, const char *name, bool reports)
{
    int rc = save ? fv_cli_check_output("bench", in, save, "--save-scenario") : 0;
    static const char *const ext[2] = {"json", "md"};
    for (int k = 0; k < 2 && reports && rc == 0; k++) {
        char path[4096], what[4096 + 32];
        snprintf(path, sizeof path, "%s/%s.%s", out_dir, name, ext[k]);
        snprintf(what, sizeof what, "--out %s: the report", out_dir);
        rc = fv_cli_check_output("bench", in, path, what);
    }
    return rc;
}

/* --scene: the scenario built from the command line is checked first, then saved (--save-scenario:
 * nothing is written for bad input), then run as a scenario file would be. */
/* argv as one line for the reports: "fovea bench ARG..." (arguments with spaces quoted). */
static void command_line(int argc, char **argv, char *out, size_t n)
{
    size_t len = (size_t)snprintf(out, n, "fovea bench");
    for (int i = 1; i < argc && len < n; i++) {
        bool quote = strpbrk(argv[i], " \t'\"") != NULL;
        len += (size_t)snprintf(out + len, n - len, quote ? " '%s'" : " %s", argv[i]);
    }
}

static int run_cmdline(const fv_bench_cmdline *cl, const char *save, bool check, bool quiet, double every_s, fv_bench_options *opt,
                       const bench_dist *bd)
{
    const char *cmd = "bench";
    char *json = NULL, label[128];
    int rc = fv_bench_cmdline_json(cmd, cl, &json, label, sizeof label);
    if (rc) return rc;
    fv_inputs in;
    fv_inputs_init(&in);
    fv_inputs_add(&in, cl->scene, "scene file");
    fv_inputs_add(&in, cl->gaze_trace, "gaze trace");
    char name[sizeof label];
    snprintf(name, sizeof name, "%.*s", (int)strlen(label) - 5, label); /* NAME.json: the report's NAME */
    rc = check_outputs(&in, save, opt->out_dir, name, !check);
    if (rc) {
        free(json);
        return rc;
    }
    const bool speaks = !opt->split || opt->split->rank == 0;
    bench_say say;
    fv_log log;
    bench_say_init(&say, quiet, every_s, speaks, opt, &quiet, &log);
    fv_error err;
    fv_error_clear(&err);
    /* Relative paths in the JSON are already absolute (bench_cmdline.c): "." is only a fallback. */
    fv_status s = fv_bench_check_text(json, label, ".", opt->mode, &err);
    if (s == FV_OK && save && speaks) s = fv_file_write_atomic(save, json, strlen(json), &err);
    if (s == FV_OK && !check) s = fv_bench_run_text(json, label, ".", opt, &err);
    free(json);
    fv_cli_progress_done(&say.bar);
    if (s != FV_OK) return bench_fail(bd, s, err.msg);
    if (check && speaks) printf("%s: ok\n", save ? save : label);
    else if (!quiet && speaks) fprintf(stderr, "fovea bench: wrote %s/\n", opt->out_dir);
    return FV_EXIT_OK;
}


/* bd: the MPI job when launched over several ranks, else NULL. */
static int bench(int argc, char **argv, bench_dist *bd, const fv_bench_split *split)
{
    enum { O_OUT = 256, O_DEVICE, O_CACHE, O_QUICK, O_FULL, O_REPEATS, O_THREADS, O_TPOLICY, O_CHECK, O_LIST, O_QUIET, O_HELP, O_SCENE,
           O_METHODS, O_REFERENCE, O_GAZE, O_GAZE_TRACE, O_FRAMES, O_SIZE, O_SAVE, O_EVERY };
    static const struct option longs[] = {{"out", 1, 0, O_OUT},       {"device", 1, 0, O_DEVICE},   {"cache", 1, 0, O_CACHE},     {"quick", 0, 0, O_QUICK},
                                          {"full", 0, 0, O_FULL},     {"repeats", 1, 0, O_REPEATS}, {"threads", 1, 0, O_THREADS}, {"thread-policy", 1, 0, O_TPOLICY},
                                          {"check", 0, 0, O_CHECK},   {"list", 0, 0, O_LIST},       {"quiet", 0, 0, O_QUIET},
                                          {"help", 0, 0, O_HELP},     {"scene", 1, 0, O_SCENE},     {"methods", 1, 0, O_METHODS},
                                          {"reference", 1, 0, O_REFERENCE}, {"gaze", 1, 0, O_GAZE}, {"gaze-trace", 1, 0, O_GAZE_TRACE},
                                          {"frames", 1, 0, O_FRAMES}, {"size", 1, 0, O_SIZE},       {"save-scenario", 1, 0, O_SAVE},
                                          {"progress-every", 1, 0, O_EVERY}, {0, 0, 0, 0}};
    const char *cmd = "bench";
    fv_bench_options opt;
    memset(&opt, 0, sizeof opt);
    opt.out_dir = "bench-out";
    opt.split = split;
    /* split: rank 0 alone reports progress and prints the table (it writes every file) */
    const bool speaks = !split || split->rank == 0;
    /* Before getopt_long, which reorders argv. */
    char command[2048];
    command_line(argc, argv, command, sizeof command);
    opt.command = command;
    bool check = false, quiet = false, list = false, cmdline = false;
    fv_bench_cmdline cl;
    memset(&cl, 0, sizeof cl);
    const char *save = NULL;
    /* not on a terminal: a line at most this often (docs/bench.md) */
    double every_s = 20.0;
    int rc;
    long l;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        switch (c) {
        case O_OUT: opt.out_dir = optarg; break;
        case O_DEVICE: opt.device = optarg; break;
        case O_CACHE: opt.cache_dir = optarg; break;
        case O_QUICK:
        case O_FULL:
            if (opt.mode != FV_BENCH_DEFAULT) return fv_cli_usage_error(cmd, "--quick and --full exclude each other");
            opt.mode = c == O_QUICK ? FV_BENCH_QUICK : FV_BENCH_FULL;
            break;
        case O_REPEATS:
            if (!fv_cli_parse_int(optarg, 1, 1000, &l)) return fv_cli_usage_error(cmd, "--repeats %s: expected an integer in [1, 1000]", optarg);
            opt.repeats = (int)l;
            break;
        case O_TPOLICY:
            if (fv_cli_opt_thread_policy(cmd, optarg)) return FV_EXIT_USAGE;
            break;
        case O_THREADS:
            if (!fv_cli_parse_int(optarg, 0, 256, &l)) return fv_cli_usage_error(cmd, "--threads %s: expected an integer in [0, 256]", optarg);
            opt.threads = (int)l;
            break;
        case O_SCENE: cl.scene = optarg; break;
        case O_METHODS: cl.methods = optarg, cmdline = true; break;
        case O_REFERENCE: cl.reference = optarg, cmdline = true; break;
        case O_GAZE:
            if ((rc = fv_cli_opt_gaze(cmd, optarg, cl.gaze))) return rc;
            cl.has_gaze = cmdline = true;
            break;
        case O_GAZE_TRACE: cl.gaze_trace = optarg, cmdline = true; break;
        case O_FRAMES:
            if (!fv_cli_parse_int(optarg, 1, 100000, &l)) return fv_cli_usage_error(cmd, "--frames %s: expected an integer in [1, 100000]", optarg);
            cl.frames = (int)l, cmdline = true;
            break;
        case O_SIZE:
            if ((rc = fv_cli_opt_size(cmd, optarg, &cl.width, &cl.height))) return rc;
            cmdline = true;
            break;
        case O_SAVE: save = optarg, cmdline = true; break;
        case O_EVERY:
            if (!fv_cli_parse_float(optarg, &every_s) || every_s < 0.0 || every_s > 86400.0)
                return fv_cli_usage_error(cmd, "--progress-every %s: expected seconds in [0, 86400]", optarg);
            break;
        case O_CHECK: check = true; break;
        case O_LIST: list = true; break;
        case O_QUIET: quiet = true; break;
        case 'h':
        case O_HELP: usage(stdout); return FV_EXIT_OK;
        default: return fv_cli_usage_error(cmd, "unknown option '%s' (try fovea bench --help)", argv[optind - 1]);
        }
    }
    if (list) {
        if (speaks) list_scenarios();
        return FV_EXIT_OK;
    }
    if (cl.scene) {
        if (optind != argc) return fv_cli_usage_error(cmd, "--scene builds the scenario: give no SCENARIO file ('%s')", argv[optind]);
        return run_cmdline(&cl, save, check, quiet, every_s, &opt, bd);
    }
    if (cmdline) return fv_cli_usage_error(cmd, "--methods, --reference, --gaze, --gaze-trace, --frames, --size and --save-scenario need --scene");
    if (optind != argc - 1) return fv_cli_usage_error(cmd, optind >= argc ? "missing SCENARIO (try fovea bench --list)" : "too many arguments");
    char path[4096];
    if (!resolve(argv[optind], path, sizeof path))
        return fv_cli_usage_error(cmd, "unknown scenario '%s' (try fovea bench --list)", argv[optind]);
    bench_say say;
    fv_log log;
    bench_say_init(&say, quiet, every_s, speaks, &opt, &quiet, &log);
    fv_error err;
    fv_error_clear(&err);
    /* A regular file only: the JSON reader opens it by name, and a FIFO would block it. */
    fv_status s = fv_file_check_read(path, "scenario", &err);
    if (s != FV_OK) return fv_cli_fail(cmd, s, err.msg);
    if (!check) {
        /* The report's name and the scene are the scenario's: read here for the check alone (a
         * scenario that does not load is left to the run, which says why). */
        fv_scenario *sc = NULL;
        if (fv_scenario_load(path, opt.mode, &sc, &err) == FV_OK) {
            fv_inputs in;
            fv_inputs_init(&in);
            fv_inputs_add(&in, path, "scenario");
            fv_inputs_add(&in, sc->scene, "scene file");
            rc = check_outputs(&in, NULL, opt.out_dir, sc->name, true);
            fv_scenario_destroy(sc);
            if (rc) return rc;
        }
        fv_error_clear(&err);
    }
    s = check ? fv_bench_check(path, opt.mode, &err) : fv_bench_run(path, &opt, &err);
    fv_cli_progress_done(&say.bar);
    if (s != FV_OK) return bench_fail(bd, s, err.msg);
    if (check && speaks) printf("%s: ok\n", path);
    else if (!quiet && speaks) fprintf(stderr, "fovea bench: wrote %s/\n", opt.out_dir);
    return FV_EXIT_OK;
}

int fv_cmd_bench(int argc, char **argv)
{
    /* a built-in mode rather than a scenario: it sweeps the thread count, not methods' parameters */
    if (argc > 1 && !strcmp(argv[1], "scaling")) return fv_cmd_bench_scaling(argc - 1, argv + 1);
#ifdef FOVEA_HAVE_MPI
    /* Launched as one rank of several (mpirun, srun): the rows are dealt to the ranks. */
    if (fv_dist_launched()) {
        bench_dist bd = {NULL, false, false, false};
        fv_error err;
        fv_error_clear(&err);
        fv_status s = fv_dist_start(NULL, NULL, &bd.d, &err);
        if (s != FV_OK) return fv_cli_fail("bench", s, err.msg);
        if (fv_dist_size(bd.d) == 1) {
            fv_dist_end(bd.d);
            return bench(argc, argv, NULL, NULL);
        }
        if ((s = fv_dist_hold(bd.d, &err)) != FV_OK) {
            fv_dist_end(bd.d);
            return fv_cli_fail("bench", s, err.msg);
        }
        const fv_bench_split split = {fv_dist_rank(bd.d), fv_dist_size(bd.d), &bd, split_move, split_agree, split_stopped, split_failed,
                                     split_still};
        int rc = bench(argc, argv, &bd, &split);
        if (!bd.agreed) {
            /* Ended before the run split (bad options, --check, --list, --help): every rank agrees
             * once, so that what was said (held) is said by one rank only. */
            bool print_it, name_rank;
            fv_status js = fv_dist_agree(bd.d, rc == FV_EXIT_OK ? FV_OK : rc == FV_EXIT_INTERNAL ? FV_ERR_INTERNAL : FV_ERR_INVALID,
                                         &print_it, &name_rank, &err);
            if (js != FV_OK) fv_cli_interrupt_mute();
            rc = fv_cli_exit_code(js);
        }
        fv_dist_end(bd.d);
        return rc;
    }
#endif
    return bench(argc, argv, NULL, NULL);
}
