/* fovea — the thread policy: how many OpenMP threads a render uses by default and how they wait
 * between parallel regions, chosen from how busy the machine is.
 *
 * libgomp reads OMP_NUM_THREADS, OMP_WAIT_POLICY and GOMP_SPINCOUNT once, in a constructor that runs
 * when the library is loaded, before main() (verified with GCC 12: a setenv() in main changes
 * nothing that omp_display_env reports). So a policy is a set of environment variables that the
 * tools put in place and then re-execute themselves with (tools/fovea/cli.c); this file only
 * decides, from numbers, which variables those are, so the decision is testable without a machine.
 *
 * Policies (docs/threads.md):
 *   pace   all allowed CPUs; waiting threads spin for a bounded while (OMP_WAIT_POLICY=active,
 *          GOMP_SPINCOUNT=FV_PACE_SPINS) so they are awake for the next region of the frame;
 *   share  as many threads as CPUs are idle (at least one); waiting threads sleep at once
 *          (OMP_WAIT_POLICY=passive), leaving the cores to the machine's other work;
 *   auto   share's thread count; pace's waiting when those threads fit into the idle CPUs, else
 *          share's (the default);
 *   openmp fovea sets nothing: the OpenMP runtime's own defaults and variables.
 * Variables the user already set are never replaced (each one alone: OMP_NUM_THREADS; the wait
 * pair OMP_WAIT_POLICY/GOMP_SPINCOUNT as one, since either changes the other's meaning).
 */
#ifndef FV_CORE_THREAD_POLICY_H
#define FV_CORE_THREAD_POLICY_H

#include <stdbool.h>
#include <stdint.h>

typedef enum fv_thread_policy {
    FV_THREADS_AUTO,
    FV_THREADS_PACE,
    FV_THREADS_SHARE,
    FV_THREADS_OPENMP,
} fv_thread_policy;

/* One spin of libgomp's wait loop is an atomic load and a pause instruction: about 30-45 ns on
 * current x86 (Skylake's pause is ~140 cycles, Zen's ~65). Four million spins are thus 0.1-0.2 s:
 * longer than any gap between the regions of a frame or between the frames of an interactive
 * view (50 ms at 20 fps), short enough that threads left idle after a render go to sleep soon. */
#define FV_PACE_SPINS "4M"

/* "auto", "pace", "share", "openmp" -> policy; false for anything else. */
bool fv_thread_policy_parse(const char *s, fv_thread_policy *out);
const char *fv_thread_policy_name(fv_thread_policy p);

/* CPU time of the allowed CPUs, in /proc/stat's ticks. */
typedef struct fv_cpu_sample {
    uint64_t idle;  /* idle + iowait */
    uint64_t total; /* every field but the guest ones (already counted in user and nice) */
    int cpus;       /* allowed CPUs found in the text */
} fv_cpu_sample;

/* Sums the "cpuN" lines of a /proc/stat text whose N is marked in allowed[0 .. n_allowed-1]
 * (allowed NULL: every CPU). False when no such line was found. */
bool fv_cpu_sample_parse(const char *text, const bool *allowed, int n_allowed, fv_cpu_sample *out);
/* Adds one line of that text to acc when it is an allowed CPU's line (true then). */
bool fv_cpu_sample_line(const char *line, const bool *allowed, int n_allowed, fv_cpu_sample *acc);
/* Idle CPUs between two samples: cpus * d(idle) / d(total), in [0, cpus]; cpus when no tick passed. */
double fv_cpu_idle(const fv_cpu_sample *before, const fv_cpu_sample *after);

typedef struct fv_thread_plan {
    fv_thread_policy policy; /* what was asked */
    bool pace;               /* waiting threads spin (pace) or sleep (share) */
    int threads;             /* OMP_NUM_THREADS to set: the default thread count; 0: leave it */
    const char *wait_policy; /* OMP_WAIT_POLICY to set, NULL: leave it */
    const char *spin_count;  /* GOMP_SPINCOUNT to set, NULL: leave it */
} fv_thread_plan;

/* The plan for `policy` on a machine with `cpus` allowed CPUs of which `idle` are idle, when the
 * user asked for `requested` threads (0: the default), has set OMP_NUM_THREADS to user_threads
 * (0: not set) and has or has not set the wait variables (user_wait). */
void fv_thread_plan_make(fv_thread_policy policy, int cpus, double idle, int requested, int user_threads, bool user_wait,
                         fv_thread_plan *out);

#endif
