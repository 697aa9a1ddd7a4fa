/* fovea — the thread policy's decision (see thread_policy.h; docs/threads.md).
 *
 * Why these rules: OpenMP threads that sleep between the many short regions of a frame wake late,
 * and a frame waits for its slowest thread (issue 29: one frame in five 4x slower at 16 threads);
 * threads that spin keep frames even, but on a machine whose cores are taken by other processes a
 * spinning thread burns the time slice that the thread it waits for needs, and more threads than
 * idle cores make every barrier wait for a descheduled thread (3-5x slower than one thread on a
 * busy 2-core machine). So: spin only where our threads fit into idle CPUs, and never start more
 * threads by default than there are idle CPUs.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/thread_policy.h"

static const char *const k_names[] = {"auto", "pace", "share", "openmp"};

bool fv_thread_policy_parse(const char *s, fv_thread_policy *out)
{
    for (int i = 0; s && i < (int)(sizeof k_names / sizeof k_names[0]); i++)
        if (!strcmp(s, k_names[i])) {
            *out = (fv_thread_policy)i;
            return true;
        }
    return false;
}

const char *fv_thread_policy_name(fv_thread_policy p)
{
    return (unsigned)p < sizeof k_names / sizeof k_names[0] ? k_names[p] : "?";
}

bool fv_cpu_sample_line(const char *line, const bool *allowed, int n_allowed, fv_cpu_sample *acc)
{
    /* "cpu" followed by a digit: one CPU's line; the summary line "cpu " is skipped because it
     * counts CPUs outside our affinity mask too. */
    if (strncmp(line, "cpu", 3) || line[3] < '0' || line[3] > '9') return false;
    char *end;
    long id = strtol(line + 3, &end, 10);
    if (id < 0 || (allowed && (id >= n_allowed || !allowed[id]))) return false;
    /* user nice system idle iowait irq softirq steal guest guest_nice (proc(5)) */
    uint64_t f[10] = {0};
    int nf = 0;
    const char *p = end;
    while (nf < 10 && *p != '\n' && *p != '\0') {
        char *e;
        unsigned long long v = strtoull(p, &e, 10);
        if (e == p) break;
        f[nf++] = v;
        p = e;
    }
    if (nf < 4) return false;
    for (int i = 0; i < nf && i < 8; i++) acc->total += f[i];
    acc->idle += f[3] + f[4];
    acc->cpus++;
    return true;
}

bool fv_cpu_sample_parse(const char *text, const bool *allowed, int n_allowed, fv_cpu_sample *out)
{
    memset(out, 0, sizeof *out);
    for (const char *line = text; line && *line;) {
        fv_cpu_sample_line(line, allowed, n_allowed, out);
        const char *next = strchr(line, '\n');
        line = next ? next + 1 : NULL;
    }
    return out->cpus > 0;
}

double fv_cpu_idle(const fv_cpu_sample *before, const fv_cpu_sample *after)
{
    int cpus = after->cpus;
    if (after->total <= before->total || after->idle < before->idle) return cpus;
    double f = (double)(after->idle - before->idle) / (double)(after->total - before->total);
    if (f > 1.0) f = 1.0;
    return f * cpus;
}

void fv_thread_plan_make(fv_thread_policy policy, int cpus, double idle, int requested, int user_threads, bool user_wait,
                         fv_thread_plan *out)
{
    memset(out, 0, sizeof *out);
    out->policy = policy;
    if (cpus < 1) cpus = 1;
    if (!(idle >= 0.0)) idle = 0.0;
    if (idle > cpus) idle = cpus;
    if (policy == FV_THREADS_OPENMP) return;
    /* A CPU counts as idle from three quarters of it: a neighbour using a quarter of a core
     * (an editor, a shell) should not take a thread away, one using most of it should. */
    const int fit = (int)floor(idle + 0.25); /* threads that fit into the idle CPUs */
    const int idle_threads = fit > 1 ? fit : 1;
    int threads = policy == FV_THREADS_PACE ? cpus : idle_threads;
    if (user_threads < 1) out->threads = threads;
    int used = requested > 0 ? requested : user_threads > 0 ? user_threads : threads;
    if (policy == FV_THREADS_PACE) out->pace = true;
    else if (policy == FV_THREADS_SHARE) out->pace = false;
    else out->pace = used <= fit;
    if (user_wait) return;
    out->wait_policy = out->pace ? "active" : "passive";
    /* passive alone already means zero spins in libgomp; the explicit 0 says so to other runtimes */
    out->spin_count = out->pace ? FV_PACE_SPINS : "0";
}
