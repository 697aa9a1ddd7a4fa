/* fovea — a child process for a third-party parser (see sandbox.h). */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#if defined(__linux__)
#include <sys/prctl.h>
#endif
#include <sys/wait.h>
#include <unistd.h>
#include "core/sandbox.h"

/* AddressSanitizer: GCC says so with __SANITIZE_ADDRESS__, clang (the libFuzzer build,
 * docs/fuzzing.md) with __has_feature. */
#if defined(__SANITIZE_ADDRESS__)
#define FV_SANDBOX_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FV_SANDBOX_ASAN 1
#endif
#endif

struct fv_sandbox {
    pid_t pid;
    int fd;
    size_t mem_bytes;
    int cpu_seconds;
    bool timed_out;
};

fv_status fv_sandbox_start(fv_sandbox_fn fn, void *user, size_t mem_bytes, int cpu_seconds, fv_sandbox **out, fv_error *err)
{
    fv_sandbox *sb = calloc(1, sizeof *sb);
    int p[2];
    if (!sb) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (pipe(p) != 0) {
        free(sb);
        return fv_error_set(err, FV_ERR_INTERNAL, "cannot create a pipe: %s", strerror(errno));
    }
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        close(p[0]);
        close(p[1]);
        free(sb);
        return fv_error_set(err, FV_ERR_INTERNAL, "cannot start a child process: %s", strerror(errno));
    }
    if (pid == 0) {
        close(p[0]);
        /* The child dies with its parent, however the parent ends (killed, or a signal handler
         * that exits at once: the CLI's on SIGINT/SIGTERM), instead of parsing on alone. Checked
         * after the request, as the parent may have gone before it. Linux only; elsewhere the
         * child ends at its first write to the closed pipe or at its CPU limit. */
#if defined(__linux__)
        if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent) _exit(127);
#else
        (void)parent;
#endif
        /* The parent's signal handlers are not the child's business (they serve the parent's
         * main thread, which the child does not have): an interrupt from the terminal reaches the
         * child too and simply ends it. Every caught signal goes back to its default, whichever
         * the parent catches (the CLI's SIGINT ... SIGALRM, an embedding program's); an ignored
         * signal stays ignored. */
        for (int sig = 1; sig < NSIG; sig++) {
            struct sigaction was;
            if (sigaction(sig, NULL, &was) == 0 && !(was.sa_flags & SA_SIGINFO) && (was.sa_handler == SIG_IGN || was.sa_handler == SIG_DFL))
                continue;
            signal(sig, SIG_DFL);
        }
        /* The library's own prints would add lines to our one-line messages; the parent reports. */
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, STDOUT_FILENO);
            dup2(null, STDERR_FILENO);
            close(null);
        }
        /* Under AddressSanitizer the address space is mostly shadow memory reserved up front: an
         * RLIMIT_AS would fail its first allocation, so the sanitized build relies on the
         * sanitizer's own allocation limit instead. */
#if !defined(FV_SANDBOX_ASAN)
        if (mem_bytes) {
            struct rlimit rl = {(rlim_t)mem_bytes, (rlim_t)mem_bytes};
            setrlimit(RLIMIT_AS, &rl);
        }
#endif
        struct rlimit cl = {(rlim_t)cpu_seconds, (rlim_t)cpu_seconds + 1};
        setrlimit(RLIMIT_CPU, &cl);
        /* No core dump of a crash we expect and report. */
        struct rlimit core = {0, 0};
        setrlimit(RLIMIT_CORE, &core);
        _exit(fn(user, p[1]));
    }
    close(p[1]);
    sb->pid = pid;
    sb->fd = p[0];
    sb->mem_bytes = mem_bytes;
    sb->cpu_seconds = cpu_seconds;
    *out = sb;
    return FV_OK;
}

bool fv_sandbox_write(int fd, const void *p, size_t n)
{
    const char *c = p;
    while (n > 0) {
        ssize_t w = write(fd, c, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        c += w;
        n -= (size_t)w;
    }
    return true;
}

bool fv_sandbox_read(fv_sandbox *sb, void *dst, size_t n)
{
    char *c = dst;
    while (n > 0) {
        /* A child blocked or sleeping uses no CPU time: silence for twice the CPU limit ends it. */
        struct pollfd pf = {sb->fd, POLLIN, 0};
        int r = poll(&pf, 1, 2000 * sb->cpu_seconds);
        if (r < 0 && errno == EINTR) continue;
        if (r == 0) sb->timed_out = true;
        if (r <= 0) return false;
        ssize_t got = read(sb->fd, c, n);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) return false;
        c += got;
        n -= (size_t)got;
    }
    return true;
}

fv_status fv_sandbox_finish(fv_sandbox *sb, const char *what, fv_error *err)
{
    close(sb->fd);
    int status = 0;
    pid_t w;
    /* The parent stops reading early only on an error of its own or a silent child: either way
     * the child's work is of no use any more. A signal handled while waiting (one without
     * SA_RESTART: libFuzzer's timer, a caller's own) must not end the wait, or the child stays a
     * zombie and its result is lost (tests/unit/test_sandbox.c). */
    while ((w = waitpid(sb->pid, &status, WNOHANG)) < 0 && errno == EINTR) {}
    if (w == 0) {
        kill(sb->pid, SIGKILL);
        while ((w = waitpid(sb->pid, &status, 0)) < 0 && errno == EINTR) {}
    }
    fv_sandbox s = *sb;
    free(sb);
    if (w < 0) return fv_error_set(err, FV_ERR_INTERNAL, "%s: lost the child process: %s", what, strerror(errno));
    if (s.timed_out) return fv_error_set(err, FV_ERR_INVALID, "%s: gave no result for %d s (stopped)", what, 2 * s.cpu_seconds);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return FV_OK;
    if (WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        if (sig == SIGXCPU) return fv_error_set(err, FV_ERR_INVALID, "%s: took more than %d s of CPU time (stopped)", what, s.cpu_seconds);
        if (sig == SIGKILL && s.mem_bytes)
            return fv_error_set(err, FV_ERR_INVALID, "%s: was killed (signal 9), most likely out of memory (limit %zu MiB)", what, s.mem_bytes >> 20);
        return fv_error_set(err, FV_ERR_INVALID, "%s: crashed (signal %d, %s)", what, sig, strsignal(sig));
    }
    return fv_error_set(err, FV_ERR_INVALID, "%s: failed (exit status %d)", what, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
}
