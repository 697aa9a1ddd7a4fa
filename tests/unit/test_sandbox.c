/* The child process of a third-party parser (core/sandbox.h) is always waited for: a signal
 * arriving while fv_sandbox_finish waits (a handler without SA_RESTART, as libFuzzer's SIGALRM
 * timer, found by the libFuzzer scene target, docs/fuzzing.md) neither leaves the child a zombie
 * nor turns its result into "lost the child process". A timer interrupts every 50 us while 200
 * children are ended: killed while they still run, and after they answered. */
#include <errno.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>
#include "core/sandbox.h"

static void on_alarm(int sig) { (void)sig; }

static int child_sleeps(void *user, int fd)
{
    (void)user;
    (void)fd;
    usleep(200000);
    return 0;
}

static int child_answers(void *user, int fd)
{
    (void)user;
    return fv_sandbox_write(fd, "ok", 2) ? 0 : 3;
}

/* No child of ours is left, running or ended. */
static void assert_no_child(void)
{
    int status;
    errno = 0;
    assert_int_equal(waitpid(-1, &status, WNOHANG), -1);
    assert_int_equal(errno, ECHILD);
}

static void test_finish_waits_through_signals(void **st)
{
    (void)st;
    struct sigaction sa, old_sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART: a blocked waitpid returns EINTR */
    assert_int_equal(sigaction(SIGALRM, &sa, &old_sa), 0);
    struct itimerval it = {{0, 50}, {0, 50}}, old_it;
    assert_int_equal(setitimer(ITIMER_REAL, &it, &old_it), 0);
    for (int i = 0; i < 100; i++) {
        /* still running at finish: killed, and said so */
        fv_sandbox *sb = NULL;
        fv_error err;
        assert_int_equal(fv_sandbox_start(child_sleeps, NULL, 0, 5, &sb, &err), FV_OK);
        assert_int_equal(fv_sandbox_finish(sb, "the sleeping child", &err), FV_ERR_INVALID);
        assert_non_null(strstr(err.msg, "the sleeping child: crashed (signal 9"));
        assert_no_child();
        /* answered and ended: the answer arrives whole, and the end is a verdict on the child
         * (exited, or killed when it had not yet exited), never a lost child */
        assert_int_equal(fv_sandbox_start(child_answers, NULL, 0, 5, &sb, &err), FV_OK);
        char got[3] = "";
        assert_true(fv_sandbox_read(sb, got, 2));
        assert_string_equal(got, "ok");
        assert_false(fv_sandbox_read(sb, got, 1)); /* the end of its stream */
        fv_status fin = fv_sandbox_finish(sb, "the answering child", &err);
        assert_true(fin == FV_OK || (fin == FV_ERR_INVALID && strstr(err.msg, "signal 9")));
        assert_no_child();
    }
    struct itimerval off = {{0, 0}, {0, 0}};
    setitimer(ITIMER_REAL, &off, NULL);
    sigaction(SIGALRM, &old_sa, NULL);
    (void)old_it;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_finish_waits_through_signals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
