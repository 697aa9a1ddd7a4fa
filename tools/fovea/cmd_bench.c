/* fovea CLI — `fovea bench SCENARIO`: run a benchmark scenario (bench/<name>.json, docs/bench.md)
 * and write its report. A bare name is looked up in $FOVEA_BENCH_DIR, ./bench and the source
 * tree's bench/ folder, so `fovea bench pt-cornell` works from a fresh clone. */
#include <getopt.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "cli.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: fovea bench SCENARIO [options]\n"
               "Renders every method of a scenario side by side, times them (median of repeats) and measures\n"
               "their error per region (fovea, transition, periphery) against a cached reference.\n\n"
               "  SCENARIO          a scenario name (bench/NAME.json) or a path to a .json file\n"
               "  --out DIR         where the report goes [bench-out]: DIR/NAME.json, DIR/NAME.md, DIR/NAME/*.png\n"
               "  --cache DIR       reference cache [DIR/cache]\n"
               "  --quick           small sizes, under a minute (the scenario's \"quick\" block)\n"
               "  --full            the papers' sizes (the scenario's \"full\" block)\n"
               "  --repeats N       timing repeats (overrides the scenario)\n"
               "  --threads N       worker threads, 0 = all [0]\n"
               "  --check           only validate the scenario\n"
               "  --list            list the scenarios found\n"
               "  --quiet           no progress lines\n");
}

static bool is_file(const char *p)
{
    struct stat sb;
    return stat(p, &sb) == 0 && S_ISREG(sb.st_mode);
}

/* The folders searched for scenario names, in order. */
static int bench_dirs(const char **dirs)
{
    int n = 0;
    const char *env = getenv("FOVEA_BENCH_DIR");
    if (env && env[0]) dirs[n++] = env;
    dirs[n++] = "bench";
#ifdef FOVEA_SOURCE_DIR
    dirs[n++] = FOVEA_SOURCE_DIR "/bench";
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
    int nd = bench_dirs(dirs);
    for (int i = 0; i < nd; i++) {
        snprintf(out, n, "%s/%s.json", dirs[i], arg);
        if (is_file(out)) return true;
    }
    return false;
}

static void list_scenarios(void)
{
    const char *dirs[4];
    int nd = bench_dirs(dirs);
    char cmd[8192] = "";
    /* Listing through ls keeps this simple and the order stable. */
    char seen[4][4096];
    int nseen = 0;
    for (int i = 0; i < nd; i++) {
        struct stat sb;
        if (stat(dirs[i], &sb) != 0 || !S_ISDIR(sb.st_mode)) continue;
        /* ./bench and the source tree's bench/ are often the same folder: list it once. */
        char real[4096];
        if (!realpath(dirs[i], real)) continue;
        bool dup = false;
        for (int k = 0; k < nseen && !dup; k++) dup = strcmp(seen[k], real) == 0;
        if (dup) continue;
        snprintf(seen[nseen++], sizeof seen[0], "%s", real);
        printf("%s:\n", dirs[i]);
        snprintf(cmd, sizeof cmd, "ls -1 '%s' | sed -n 's/\\.json$//p' | sed 's/^/  /'", dirs[i]);
        fflush(stdout);
        if (system(cmd) != 0) continue;
    }
}

static void on_status(void *user, const char *line)
{
    (void)user;
    fprintf(stderr, "fovea bench: %s\n", line);
}

int fv_cmd_bench(int argc, char **argv)
{
    enum { O_OUT = 256, O_CACHE, O_QUICK, O_FULL, O_REPEATS, O_THREADS, O_CHECK, O_LIST, O_QUIET, O_HELP };
    static const struct option longs[] = {{"out", 1, 0, O_OUT},       {"cache", 1, 0, O_CACHE},     {"quick", 0, 0, O_QUICK},
                                          {"full", 0, 0, O_FULL},     {"repeats", 1, 0, O_REPEATS}, {"threads", 1, 0, O_THREADS},
                                          {"check", 0, 0, O_CHECK},   {"list", 0, 0, O_LIST},       {"quiet", 0, 0, O_QUIET},
                                          {"help", 0, 0, O_HELP},     {0, 0, 0, 0}};
    const char *cmd = "bench";
    fv_bench_options opt;
    memset(&opt, 0, sizeof opt);
    opt.out_dir = "bench-out";
    bool check = false, quiet = false, list = false;
    long l;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        switch (c) {
        case O_OUT: opt.out_dir = optarg; break;
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
        case O_THREADS:
            if (!fv_cli_parse_int(optarg, 0, 256, &l)) return fv_cli_usage_error(cmd, "--threads %s: expected an integer in [0, 256]", optarg);
            opt.threads = (int)l;
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
        list_scenarios();
        return FV_EXIT_OK;
    }
    if (optind != argc - 1) return fv_cli_usage_error(cmd, optind >= argc ? "missing SCENARIO (try fovea bench --list)" : "too many arguments");
    char path[4096];
    if (!resolve(argv[optind], path, sizeof path))
        return fv_cli_usage_error(cmd, "unknown scenario '%s' (try fovea bench --list)", argv[optind]);
    fv_log log = fv_cli_log(&quiet);
    opt.log = &log;
    if (!quiet) opt.status = on_status;
    fv_error err;
    fv_error_clear(&err);
    fv_status s = check ? fv_bench_check(path, opt.mode, &err) : fv_bench_run(path, &opt, &err);
    if (s != FV_OK) return fv_cli_fail(cmd, s, err.msg);
    if (check) printf("%s: ok\n", path);
    else if (!quiet) fprintf(stderr, "fovea bench: wrote %s/\n", opt.out_dir);
    return FV_EXIT_OK;
}
