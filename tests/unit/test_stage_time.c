/* Stage clocks and the region clock (core/stage_time.h, core/parallel.h): each stage's serial part
 * is its wall time outside parallel regions, plus the one-thread parts reported inside them. The
 * checks are orderings of readings of one monotonic clock, never a timing threshold: a loaded
 * machine can stretch every interval without breaking them. Also the team loops merged regions
 * are built of (fv_team_for): every index once, inside a region and outside. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>
#include "core/parallel.h"
#include "core/stage_time.h"

/* Reads the clock until at least ms have passed (a busy wait: no sleep to be descheduled in). */
static void spin(double ms)
{
    const double t = fv_time_ms();
    while (fv_time_ms() - t < ms) {
    }
}

/* A stage without a region: all of it is serial, exactly (the parallel clock does not move). */
static void test_no_region_all_serial(void **st)
{
    (void)st;
    fv_stats s;
    fv_stats_clear(&s);
    const fv_stage_clock a = fv_stage_clock_now();
    spin(2.0);
    const fv_stage_clock b = fv_stage_clock_now();
    assert_true(b.parallel == a.parallel);
    fv_stage_add(&s, "setup", a, b);
    assert_true(fv_stats_get_ms(&s, "setup") >= 2.0);
    assert_true(fv_stats_get_serial_ms(&s, "setup") == fv_stats_get_ms(&s, "setup"));
    /* a stage never timed with the clock has no serial part */
    fv_stats_add_ms(&s, "plain", 1.0);
    assert_true(fv_stats_get_serial_ms(&s, "plain") == -1.0);
}

/* A region inside a stage: its time leaves the serial part; before and after stay in it. */
static void test_region_counts_as_parallel(void **st)
{
    (void)st;
    fv_stats s;
    fv_stats_clear(&s);
    const uint64_t regions = fv_region_count();
    const fv_stage_clock a = fv_stage_clock_now();
    spin(1.0); /* serial set-up */
    const double before = fv_time_ms();
    fv_region_begin();
    spin(3.0);
    /* an open region counts up to now */
    const double open_par = fv_region_parallel_ms() - a.parallel;
    fv_region_end();
    const double after = fv_time_ms();
    spin(1.0); /* serial reduction */
    const fv_stage_clock b = fv_stage_clock_now();
    assert_true(fv_region_count() == regions + 1);
    const double par = b.parallel - a.parallel;
    /* (1e-9: sums of clock readings round) */
    assert_true(open_par >= 3.0 - 1e-9 && open_par <= par + 1e-9);
    assert_true(par >= 3.0 - 1e-9 && par <= after - before + 1e-9);
    fv_stage_add(&s, "stage", a, b);
    const double wall = fv_stats_get_ms(&s, "stage"), ser = fv_stats_get_serial_ms(&s, "stage");
    assert_true(wall >= 5.0);
    /* the serial part is the wall time less the region's: at least the 2 ms around it */
    assert_true(ser >= 2.0 - 1e-9 && ser <= wall - 3.0 + 1e-9);
    assert_true(ser >= wall - (after - before) - 1e-9);
    /* a second stage with the same name adds up */
    fv_stage_add(&s, "stage", a, b);
    assert_true(fv_stats_get_serial_ms(&s, "stage") == 2.0 * ser);
}

/* One thread's work inside a region (reported with fv_region_serial) is serial too. */
static void test_serial_part_of_region(void **st)
{
    (void)st;
    fv_stats s;
    fv_stats_clear(&s);
    const fv_stage_clock a = fv_stage_clock_now();
    double alone = 0.0;
    fv_region_begin();
#pragma omp parallel num_threads(2)
    {
#pragma omp master
        {
            const double t = fv_time_ms();
            spin(3.0);
            alone = fv_time_ms() - t;
            fv_region_serial(alone);
        }
#pragma omp barrier
    }
    fv_region_end();
    fv_stage_stop(&s, "mixed", a);
    const double wall = fv_stats_get_ms(&s, "mixed"), ser = fv_stats_get_serial_ms(&s, "mixed");
    assert_true(alone >= 3.0);
    assert_true(ser >= alone - 1e-9 && ser <= wall);
}

typedef struct {
    int hits[1000];
} cover;

static void mark(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    cover *c = ctx;
    for (int64_t i = b; i < e; i++) {
#pragma omp atomic
        c->hits[i]++;
    }
}

/* fv_team_for covers [0, n) once, shared by the team (no region of its own), or by one thread. */
static void test_team_for(void **st)
{
    (void)st;
    static cover c;
    memset(&c, 0, sizeof c);
    const uint64_t regions = fv_region_count();
    fv_team_for(1000, 7, mark, &c);
    for (int i = 0; i < 1000; i++) assert_int_equal(c.hits[i], 1);
    fv_region_begin();
#pragma omp parallel num_threads(3)
    {
        fv_team_for(1000, 7, mark, &c);
        fv_team_for(999, 50, mark, &c);
    }
    fv_region_end();
    assert_true(fv_region_count() == regions + 1);
    for (int i = 0; i < 999; i++) assert_int_equal(c.hits[i], 3);
    assert_int_equal(c.hits[999], 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_region_all_serial),
        cmocka_unit_test(test_region_counts_as_parallel),
        cmocka_unit_test(test_serial_part_of_region),
        cmocka_unit_test(test_team_for),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
