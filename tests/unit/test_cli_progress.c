/* The CLI's progress line (tools/fovea/cli_progress.c): when a line is due on a terminal and in a
 * log, what it says, and the durations in it, on clocks and fractions worked by hand (the real
 * clock never enters: every function here takes `now`). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <cmocka.h>
#include "cli.h"

static const char *dur(double s)
{
    static char buf[32];
    fv_cli_duration(s, buf, sizeof buf);
    return buf;
}

/* Whole seconds, rounded; minutes from 60 s, hours from 3600 s; nonsense reads as 0s. */
static void test_duration(void **st)
{
    (void)st;
    assert_string_equal(dur(0.0), "0s");
    assert_string_equal(dur(41.6), "42s");
    assert_string_equal(dur(59.4), "59s");
    assert_string_equal(dur(59.5), "1m00s");  /* rounds up into the next unit */
    assert_string_equal(dur(185.0), "3m05s");
    assert_string_equal(dur(3599.4), "59m59s");
    assert_string_equal(dur(3720.0), "1h02m"); /* 62 minutes */
    assert_string_equal(dur(36000.0 + 59 * 60 + 59), "10h59m");
    assert_string_equal(dur(1e12), "100000h00m"); /* capped: an ETA from almost nothing done */
    assert_string_equal(dur(-3.0), "0s");
    assert_string_equal(dur(NAN), "0s");
}

/* A progress struct as init would leave it, with a clock of our own (t0 = last_ms = 0). */
static fv_cli_progress made(bool tty, double every_ms, int frames)
{
    fv_cli_progress p;
    memset(&p, 0, sizeof p);
    p.enabled = true;
    p.tty = tty;
    p.every_ms = every_ms;
    p.frames = frames;
    p.last_percent = -1;
    return p;
}

/* A terminal: a redraw when the percentage changes, else once a second has passed. */
static void test_due_terminal(void **st)
{
    (void)st;
    fv_cli_progress p = made(true, -1.0, 1);
    assert_true(fv_cli_progress_due(&p, 0, 0.0)); /* the first draw */
    p.last_percent = 5;
    p.last_ms = 1000.0;
    assert_false(fv_cli_progress_due(&p, 5, 1500.0));
    assert_true(fv_cli_progress_due(&p, 5, 2000.0)); /* a second on: the clock moves */
    assert_true(fv_cli_progress_due(&p, 6, 1001.0)); /* news at once */
    p.enabled = false;                                /* --quiet */
    assert_false(fv_cli_progress_due(&p, 6, 5000.0));
}

/* A log (every 20 s): nothing for the step's first 20 s, then a line only for news, 20 s apart. */
static void test_due_log(void **st)
{
    (void)st;
    fv_cli_progress p = made(false, 20000.0, 1);
    assert_false(fv_cli_progress_due(&p, 0, 0.0));
    assert_false(fv_cli_progress_due(&p, 10, 19999.0)); /* a step shorter than 20 s adds nothing */
    assert_true(fv_cli_progress_due(&p, 10, 20000.0));
    p.last_percent = 10; /* that line drawn */
    p.last_ms = 20000.0;
    assert_false(fv_cli_progress_due(&p, 10, 50000.0)); /* no news */
    assert_false(fv_cli_progress_due(&p, 11, 39999.0)); /* news, too soon */
    assert_true(fv_cli_progress_due(&p, 11, 40000.0));
    /* every 0 s: each change of the percentage */
    p.every_ms = 0.0;
    assert_false(fv_cli_progress_due(&p, 10, 20000.0));
    assert_true(fv_cli_progress_due(&p, 11, 20000.0));
    /* no lines asked for (`fovea render` off a terminal) */
    p.every_ms = -1.0;
    assert_false(fv_cli_progress_due(&p, 50, 1e9));
}

/* A log's line: the label, the step's percentage (frames done + the fraction of the one under
 * way, over its frames), the frame under way, the time so far and the ETA, elapsed x (1 - f) / f. */
static void test_format_log(void **st)
{
    (void)st;
    fv_cli_progress p = made(false, 20000.0, 3);
    snprintf(p.label, sizeof p.label, "fovea bench: reference: rendering 3 frame(s) with pt (0 cached)");
    p.frame = 1;
    char line[512];
    /* frame 2 of 3 a quarter done: (1 + 0.25) / 3 = 41.7% after 50 s; ETA 50 x 0.5833 / 0.4167 = 70 s */
    int n = fv_cli_progress_format(&p, (1 + 0.25) / 3.0, 50000.0, line, sizeof line);
    assert_string_equal(line, "fovea bench: reference: rendering 3 frame(s) with pt (0 cached): 41%, frame 2/3, 50s elapsed, ETA 1m10s\n");
    assert_int_equal(n, (int)strlen(line));
    /* nothing done yet: no ETA to give */
    p.frame = 0;
    fv_cli_progress_format(&p, 0.0, 3000.0, line, sizeof line);
    assert_string_equal(line, "fovea bench: reference: rendering 3 frame(s) with pt (0 cached): 0%, frame 1/3, 3s elapsed\n");
    /* every frame done: the last one named, 100%, no ETA */
    p.frame = 3;
    p.label[0] = '\0';
    fv_cli_progress_format(&p, 1.0, 125000.0, line, sizeof line);
    assert_string_equal(line, "100%, frame 3/3, 2m05s elapsed\n");
}

/* A terminal's line: drawn over itself from the line's start, the bar's 30 cells filled by the
 * fraction (half: 15). */
static void test_format_terminal(void **st)
{
    (void)st;
    fv_cli_progress p = made(true, -1.0, 1);
    char line[256];
    fv_cli_progress_format(&p, 0.5, 10000.0, line, sizeof line);
    assert_string_equal(line, "\r[###############...............]  50%  frame 1/1  10s elapsed, ETA 10s ");
    p.frames = 4;
    p.frame = 3;
    /* 3.9 / 4 = 97.5%: 29 cells; 1 h in, ETA 3600 x 0.025 / 0.975 = 92.3 s */
    fv_cli_progress_format(&p, 3.9 / 4, 3600000.0, line, sizeof line);
    assert_string_equal(line, "\r[#############################.]  97%  frame 4/4  1h00m elapsed, ETA 1m32s ");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_duration),     cmocka_unit_test(test_due_terminal), cmocka_unit_test(test_due_log),
        cmocka_unit_test(test_format_log),   cmocka_unit_test(test_format_terminal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
