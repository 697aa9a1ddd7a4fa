/* fovea CLI — the thread policy put into effect (see cli.h, src/core/thread_policy.h,
 * docs/threads.md).
 *
 * libgomp reads its variables in a constructor before main() runs, so setting them here would
 * change nothing in this process: the policy's variables are set and the program executes itself
 * again (/proc/self/exe, same arguments), which costs a few milliseconds once. The marker
 * FOVEA_THREAD_PLAN tells the second run that the plan is in place and says what it is (--stats
 * prints it); a plan that needs no variable (openmp) is marked without executing again.
 */
#define _GNU_SOURCE
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "cli.h"
#include "core/fileio.h"
#include "core/thread_policy.h"

#define PLAN_VAR "FOVEA_THREAD_PLAN"
/* Long enough for /proc/stat's 10 ms ticks to say something on every CPU, short beside a render. */
#define SAMPLE_MS 40

/* The allowed CPUs (affinity mask) as flags, and how many there are. */
static int allowed_cpus(bool *mask, int cap)
{
    cpu_set_t set;
    memset(mask, 0, (size_t)cap * sizeof *mask);
    if (sched_getaffinity(0, sizeof set, &set) != 0) return 0;
    int n = 0;
    for (int i = 0; i < cap && i < CPU_SETSIZE; i++)
        if (CPU_ISSET(i, &set)) mask[i] = true, n++;
    return n;
}

static bool sample(const bool *mask, int cap, fv_cpu_sample *out)
{
    FILE *f;
    fv_error err;
    memset(out, 0, sizeof *out);
    if (fv_file_open_read("/proc/stat", NULL, &f, &err) != FV_OK) return false;
    char *line = NULL;
    size_t linecap = 0;
    while (fv_file_getline(f, &line, &linecap, FV_LINE_MAX) > 0) fv_cpu_sample_line(line, mask, cap, out);
    free(line);
    fclose(f);
    return out->cpus > 0;
}

/* The value of --thread-policy (or NULL) and of --threads (0 when absent) among the arguments.
 * getopt in the command parses them again (and rejects a malformed --threads). */
static const char *scan_args(int argc, char **argv, int *threads)
{
    const char *policy = NULL;
    *threads = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        if (!strcmp(a, "--")) break;
        if (!strncmp(a, "--thread-policy", 15) && (a[15] == '=' || a[15] == '\0')) {
            v = a[15] == '=' ? a + 16 : i + 1 < argc ? argv[++i] : "";
            policy = v;
        } else if (!strncmp(a, "--threads", 9) && (a[9] == '=' || a[9] == '\0')) {
            v = a[9] == '=' ? a + 10 : i + 1 < argc ? argv[++i] : "";
            long l;
            if (fv_cli_parse_int(v, 0, 256, &l)) *threads = (int)l;
        }
    }
    return policy;
}

int fv_cli_thread_policy(int argc, char **argv, const char *cmd)
{
    if (getenv(PLAN_VAR)) return -1;
    int requested;
    const char *name = scan_args(argc, argv, &requested), *from = "--thread-policy";
    if (!name && (name = getenv("FOVEA_THREAD_POLICY")) != NULL) from = "FOVEA_THREAD_POLICY";
    fv_thread_policy policy = FV_THREADS_AUTO;
    if (name && !fv_thread_policy_parse(name, &policy))
        return fv_cli_usage_error(cmd, "%s %s: expected auto, pace, share or openmp", from, name);
    char desc[200];
    if (policy == FV_THREADS_OPENMP) {
        setenv(PLAN_VAR, "openmp: OpenMP's defaults and variables", 1);
        return -1;
    }
    enum { CAP = 1024 };
    bool mask[CAP];
    int cpus = allowed_cpus(mask, CAP);
    fv_cpu_sample a, b;
    double idle = cpus;
    if (cpus > 0 && policy != FV_THREADS_PACE && sample(mask, CAP, &a)) {
        struct timespec ts = {0, SAMPLE_MS * 1000000L};
        nanosleep(&ts, NULL);
        if (sample(mask, CAP, &b)) idle = fv_cpu_idle(&a, &b);
    }
    if (cpus < 1) cpus = 1, idle = 1.0;
    const char *user_n = getenv("OMP_NUM_THREADS");
    long un = 0;
    if (user_n && !fv_cli_parse_int(user_n, 1, 1 << 20, &un)) un = 1 << 20; /* a list or junk: set, unknown */
    bool user_wait = getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT");
    fv_thread_plan plan;
    fv_thread_plan_make(policy, cpus, idle, requested, (int)un, user_wait, &plan);
    char num[16];
    if (plan.threads > 0) {
        snprintf(num, sizeof num, "%d", plan.threads);
        setenv("OMP_NUM_THREADS", num, 1);
    }
    if (plan.wait_policy) setenv("OMP_WAIT_POLICY", plan.wait_policy, 1);
    if (plan.spin_count) setenv("GOMP_SPINCOUNT", plan.spin_count, 1);
    const char *w = getenv("OMP_WAIT_POLICY"), *s = getenv("GOMP_SPINCOUNT"), *n = getenv("OMP_NUM_THREADS");
    snprintf(desc, sizeof desc, "%s: %.1f of %d CPUs idle; OMP_NUM_THREADS=%s OMP_WAIT_POLICY=%s GOMP_SPINCOUNT=%s%s",
             fv_thread_policy_name(policy), idle, cpus, n ? n : "(unset)", w ? w : "(unset)", s ? s : "(unset)",
             user_wait || (un > 0) ? " (yours kept)" : "");
    setenv(PLAN_VAR, desc, 1);
    /* When the exec fails (no /proc), the command runs on with the runtime's defaults: the plan's
     * variables still reach any child process, and nothing is wrong but the pacing. */
    execv("/proc/self/exe", argv);
    return -1;
}

int fv_cli_opt_thread_policy(const char *cmd, const char *arg)
{
    fv_thread_policy p;
    if (!fv_thread_policy_parse(arg, &p)) return fv_cli_usage_error(cmd, "--thread-policy %s: expected auto, pace, share or openmp", arg);
    return 0;
}

const char *fv_cli_thread_plan(void)
{
    const char *p = getenv(PLAN_VAR);
    return p ? p : "not applied";
}
