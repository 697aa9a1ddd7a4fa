/* The thread policy's decision (core/thread_policy.h): idle CPUs from two /proc/stat samples of the
 * allowed CPUs only, and the OpenMP variables each policy sets on idle and busy machines, keeping
 * what the user set. Hand-worked numbers; the CLI test (tests/cli/test_threads.sh) checks what
 * libgomp itself then reads. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>
#include "core/thread_policy.h"

/* Two CPUs and a third outside the mask; the summary line must not be counted. */
static const char k_stat0[] = "cpu  900 0 300 9000 100 0 0 0 0 0\n"
                              "cpu0 100 0 50 1000 0 0 0 0 0 0\n"
                              "cpu1 200 10 40 900 20 0 5 5 7 0\n"
                              "cpu2 5 0 5 5 0 0 0 0 0 0\n"
                              "intr 12345 0 0\n"
                              "ctxt 99\n";
/* 100 ticks later on each: cpu0 spent 50 idle, 50 user; cpu1 10 idle + 10 iowait, 70 system,
 * 10 steal; cpu2 idle throughout (but not allowed). */
static const char k_stat1[] = "cpu  0 0 0 0 0 0 0 0 0 0\n"
                              "cpu0 150 0 50 1050 0 0 0 0 0 0\n"
                              "cpu1 200 10 110 910 30 0 5 15 7 0\n"
                              "cpu2 5 0 5 105 0 0 0 0 0 0\n";

static void test_idle_from_stat(void **st)
{
    (void)st;
    bool allowed[3] = {true, true, false};
    fv_cpu_sample a, b;
    assert_true(fv_cpu_sample_parse(k_stat0, allowed, 3, &a));
    assert_int_equal(a.cpus, 2);
    /* cpu0: 100+50+1000 = 1150, cpu1: 200+10+40+900+20+5+5 = 1180 (guest 7 not added again) */
    assert_int_equal(a.total, 1150 + 1180);
    assert_int_equal(a.idle, 1000 + 900 + 20);
    assert_true(fv_cpu_sample_parse(k_stat1, allowed, 3, &b));
    /* idle ticks 50 + 20 out of 200: 0.35 of two CPUs */
    assert_true(fabs(fv_cpu_idle(&a, &b) - 0.7) < 1e-12);
    /* every CPU (no mask): cpu2 adds 100 idle ticks of 100 */
    assert_true(fv_cpu_sample_parse(k_stat0, NULL, 0, &a));
    assert_true(fv_cpu_sample_parse(k_stat1, NULL, 0, &b));
    assert_int_equal(b.cpus, 3);
    assert_true(fabs(fv_cpu_idle(&a, &b) - 3.0 * 170.0 / 300.0) < 1e-12);
    /* no tick between the samples: nothing says the CPUs are busy */
    assert_true(fabs(fv_cpu_idle(&b, &b) - 3.0) < 1e-12);
    /* a text without CPU lines */
    assert_false(fv_cpu_sample_parse("intr 1 2 3\n", NULL, 0, &a));
    assert_false(fv_cpu_sample_parse("cpu0 1 2\n", NULL, 0, &a));
}

static void test_names(void **st)
{
    (void)st;
    fv_thread_policy p;
    const char *names[] = {"auto", "pace", "share", "openmp"};
    for (int i = 0; i < 4; i++) {
        assert_true(fv_thread_policy_parse(names[i], &p));
        assert_int_equal(p, i);
        assert_string_equal(fv_thread_policy_name(p), names[i]);
    }
    assert_false(fv_thread_policy_parse("Auto", &p));
    assert_false(fv_thread_policy_parse("", &p));
    assert_false(fv_thread_policy_parse(NULL, &p));
}

static void test_plans(void **st)
{
    (void)st;
    fv_thread_plan pl;
    /* idle 16-core machine: all 16 threads, spinning a bounded while */
    fv_thread_plan_make(FV_THREADS_AUTO, 16, 15.9, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 16);
    assert_true(pl.pace);
    assert_string_equal(pl.wait_policy, "active");
    assert_string_equal(pl.spin_count, FV_PACE_SPINS);
    /* the busy 2-core machine (two `yes` running): one thread, sleeping waits */
    fv_thread_plan_make(FV_THREADS_AUTO, 2, 0.05, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 1);
    assert_false(pl.pace);
    assert_string_equal(pl.wait_policy, "passive");
    assert_string_equal(pl.spin_count, "0");
    /* one core of two taken: one thread, and it fits the idle core, so it may spin */
    fv_thread_plan_make(FV_THREADS_AUTO, 2, 1.0, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 1);
    assert_true(pl.pace);
    /* three quarters of a CPU count as idle, less does not: 13.8 -> 14, 13.7 -> 13 */
    fv_thread_plan_make(FV_THREADS_AUTO, 16, 13.8, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 14);
    fv_thread_plan_make(FV_THREADS_AUTO, 16, 13.7, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 13);
    /* --threads 16 asked on a half-busy machine: more threads than idle CPUs, so they sleep */
    fv_thread_plan_make(FV_THREADS_AUTO, 16, 8.0, 16, 0, false, &pl);
    assert_int_equal(pl.threads, 8);
    assert_false(pl.pace);
    /* pace takes every CPU whatever the load; share sleeps even on an idle machine */
    fv_thread_plan_make(FV_THREADS_PACE, 16, 2.0, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 16);
    assert_true(pl.pace);
    fv_thread_plan_make(FV_THREADS_SHARE, 16, 16.0, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 16);
    assert_false(pl.pace);
    assert_string_equal(pl.wait_policy, "passive");
    /* the user's variables are kept: OMP_NUM_THREADS=4 is not replaced, and its 4 threads decide
     * whether waiting may spin (4 > 2 idle: no) */
    fv_thread_plan_make(FV_THREADS_AUTO, 16, 2.0, 0, 4, false, &pl);
    assert_int_equal(pl.threads, 0);
    assert_false(pl.pace);
    assert_string_equal(pl.wait_policy, "passive");
    /* OMP_WAIT_POLICY or GOMP_SPINCOUNT set: neither is touched */
    fv_thread_plan_make(FV_THREADS_PACE, 16, 16.0, 0, 0, true, &pl);
    assert_int_equal(pl.threads, 16);
    assert_null(pl.wait_policy);
    assert_null(pl.spin_count);
    /* openmp: nothing at all */
    fv_thread_plan_make(FV_THREADS_OPENMP, 16, 0.0, 0, 0, false, &pl);
    assert_int_equal(pl.threads, 0);
    assert_null(pl.wait_policy);
    assert_null(pl.spin_count);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_idle_from_stat),
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_plans),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
