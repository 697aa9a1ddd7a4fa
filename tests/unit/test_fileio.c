/* Whole-or-nothing writes (core/fileio.h): a successful write replaces the target whole, through
 * each way of writing (bytes, stdio stream, a writer that opens the file by name); a write that
 * fails before, during or at the end (missing or read-only folder, file-size limit, rename onto a
 * folder, abort) fails with FV_ERR_IO naming the target, keeps the old target and leaves no
 * temporary file behind. */
#include <dirent.h>
#include <errno.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>
#include "core/fileio.h"

static char g_dir[256];

static int setup(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "/tmp/fovea-test-fileio-XXXXXX");
    if (!mkdtemp(g_dir)) return -1;
    /* The read-only test drops to an unprivileged user, who must be able to enter the folder. */
    return chmod(g_dir, 0755);
}

static int teardown(void **st)
{
    (void)st;
    char cmd[600];
    snprintf(cmd, sizeof cmd, "chmod -R u+w '%s' && rm -rf '%s'", g_dir, g_dir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *in_dir(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

/* Entries of a folder whose name contains ".tmp." (our temporary files). */
static int count_temp(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strstr(e->d_name, ".tmp.")) n++;
    closedir(d);
    return n;
}

/* The whole file in a static buffer (NUL-terminated); its size, or -1 when it cannot be read. */
static long slurp(const char *path, char *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    size_t n = fread(buf, 1, cap - 1, f);
    fclose(f);
    buf[n] = '\0';
    return (long)n;
}

static void test_success_replaces_whole(void **st)
{
    (void)st;
    char p[300], got[20000];
    static char big[16384];
    memset(big, 'x', sizeof big);
    fv_error err;
    in_dir(p, sizeof p, "out.txt");
    assert_int_equal(fv_file_write_atomic(p, big, sizeof big, &err), FV_OK);
    assert_int_equal(slurp(p, got, sizeof got), (long)sizeof big);
    /* A shorter file in its place: nothing of the old one's tail survives. */
    assert_int_equal(fv_file_write_atomic(p, "short", 5, &err), FV_OK);
    assert_int_equal(slurp(p, got, sizeof got), 5);
    assert_string_equal(got, "short");
    assert_int_equal(fv_file_write_atomic(p, "", 0, &err), FV_OK);
    assert_int_equal(slurp(p, got, sizeof got), 0);

    /* Through a stdio stream. */
    fv_atomic_file af;
    FILE *f = NULL;
    assert_int_equal(fv_atomic_file_begin(p, &af, &err), FV_OK);
    assert_int_equal(fv_atomic_file_stream(&af, &f, &err), FV_OK);
    fputs("stream", f);
    assert_int_equal(slurp(p, got, sizeof got), 0); /* the target is untouched until the commit */
    assert_int_equal(fv_atomic_file_commit(&af, &err), FV_OK);
    fv_atomic_file_abort(&af); /* after a commit: nothing to do */
    assert_int_equal(slurp(p, got, sizeof got), 6);
    assert_string_equal(got, "stream");

    /* A writer that opens the temporary file by name, as the EXR library and gnuplot do. */
    assert_int_equal(fv_atomic_file_begin(p, &af, &err), FV_OK);
    assert_non_null(strstr(fv_atomic_file_path(&af), "out.txt.tmp."));
    FILE *g = fopen(fv_atomic_file_path(&af), "wb");
    assert_non_null(g);
    fputs("by name", g);
    fclose(g);
    assert_int_equal(fv_atomic_file_commit(&af, &err), FV_OK);
    assert_int_equal(slurp(p, got, sizeof got), 7);
    assert_string_equal(got, "by name");

    /* The usual permissions (0666 less the umask), not mkstemp's 0600. */
    mode_t mask = umask(022);
    assert_int_equal(fv_file_write_atomic(p, "m", 1, &err), FV_OK);
    umask(mask);
    struct stat sb;
    assert_int_equal(stat(p, &sb), 0);
    assert_int_equal(sb.st_mode & 0777, 0644);
    assert_int_equal(count_temp(g_dir), 0);
}

static void test_missing_folder(void **st)
{
    (void)st;
    char p[300];
    fv_error err;
    in_dir(p, sizeof p, "missing/out.txt");
    assert_int_equal(fv_file_write_atomic(p, "x", 1, &err), FV_ERR_IO);
    assert_non_null(strstr(err.msg, p));
    assert_null(strchr(err.msg, '\n'));
    fv_atomic_file af;
    assert_int_equal(fv_atomic_file_begin(p, &af, &err), FV_ERR_IO);
    assert_non_null(strstr(err.msg, p));
    fv_atomic_file_abort(&af); /* harmless after a failed begin */
    assert_int_equal(count_temp(g_dir), 0);
}

/* Root writes into read-only folders anyway, so the attempt runs in a child that first drops to
 * the unprivileged user "nobody". Exit status: 0 passed, 1 failed, 77 could not drop privileges. */
static int write_as_unprivileged(const char *path, char *msg, size_t cap)
{
    int fds[2];
    if (pipe(fds) != 0) return 1;
    pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(77);
        fv_error err;
        fv_error_clear(&err);
        fv_status s = fv_file_write_atomic(path, "new", 3, &err);
        if (write(fds[1], err.msg, strlen(err.msg)) < 0) _exit(1);
        _exit(s == FV_ERR_IO ? 0 : 1);
    }
    close(fds[1]);
    ssize_t n = read(fds[0], msg, cap - 1);
    msg[n > 0 ? n : 0] = '\0';
    close(fds[0]);
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return 1;
    return WEXITSTATUS(status);
}

static void test_read_only_folder(void **st)
{
    (void)st;
    char dir[300], p[340], got[64], msg[FV_ERROR_MSG_MAX];
    fv_error err;
    in_dir(dir, sizeof dir, "ro");
    assert_int_equal(mkdir(dir, 0755), 0);
    snprintf(p, sizeof p, "%s/out.txt", dir);
    assert_int_equal(fv_file_write_atomic(p, "old", 3, &err), FV_OK);
    assert_int_equal(chmod(dir, 0555), 0);
    int rc = write_as_unprivileged(p, msg, sizeof msg);
    chmod(dir, 0755);
    if (rc == 77) skip();
    assert_int_equal(rc, 0);
    assert_non_null(strstr(msg, p));
    assert_int_equal(slurp(p, got, sizeof got), 3);
    assert_string_equal(got, "old");
    assert_int_equal(count_temp(dir), 0);
}

/* A write that fails half-way (here: the file-size limit) keeps the old target and cleans up,
 * for raw writes and for a stream whose error only surfaces at the commit. */
static void test_failure_mid_write(void **st)
{
    (void)st;
    char p[300], got[64];
    static char big[65536];
    memset(big, 'y', sizeof big);
    fv_error err;
    in_dir(p, sizeof p, "mid.txt");
    assert_int_equal(fv_file_write_atomic(p, "old", 3, &err), FV_OK);

    struct rlimit old, lim;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
    lim = old;
    lim.rlim_cur = 4096;
    void (*prev)(int) = signal(SIGXFSZ, SIG_IGN); /* EFBIG instead of being killed */
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
    fv_status s1 = fv_file_write_atomic(p, big, sizeof big, &err);
    fv_error err1 = err;
    fv_atomic_file af;
    FILE *f = NULL;
    fv_status s2 = fv_atomic_file_begin(p, &af, &err);
    if (s2 == FV_OK) s2 = fv_atomic_file_stream(&af, &f, &err);
    if (s2 == FV_OK) {
        fwrite(big, 1, sizeof big, f);
        s2 = fv_atomic_file_commit(&af, &err);
    }
    fv_atomic_file_abort(&af);
    setrlimit(RLIMIT_FSIZE, &old);
    signal(SIGXFSZ, prev);

    assert_int_equal(s1, FV_ERR_IO);
    assert_non_null(strstr(err1.msg, p));
    assert_int_equal(s2, FV_ERR_IO);
    assert_non_null(strstr(err.msg, p));
    assert_int_equal(slurp(p, got, sizeof got), 3);
    assert_string_equal(got, "old");
    assert_int_equal(count_temp(g_dir), 0);
}

static void test_abort_and_failed_rename(void **st)
{
    (void)st;
    char p[300], got[64];
    fv_error err;
    in_dir(p, sizeof p, "kept.txt");
    assert_int_equal(fv_file_write_atomic(p, "old", 3, &err), FV_OK);
    fv_atomic_file af;
    assert_int_equal(fv_atomic_file_begin(p, &af, &err), FV_OK);
    assert_int_equal(write(af.fd, "new content", 11), 11);
    fv_atomic_file_abort(&af);
    fv_atomic_file_abort(&af);
    assert_int_equal(slurp(p, got, sizeof got), 3);
    assert_string_equal(got, "old");
    assert_int_equal(fv_atomic_file_commit(&af, &err), FV_ERR_INTERNAL); /* nothing left to commit */

    /* The target is a folder: everything is written, then the rename fails. */
    in_dir(p, sizeof p, "isdir");
    assert_int_equal(mkdir(p, 0755), 0);
    assert_int_equal(fv_file_write_atomic(p, "x", 1, &err), FV_ERR_IO);
    assert_non_null(strstr(err.msg, p));
    assert_int_equal(count_temp(g_dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_success_replaces_whole),
        cmocka_unit_test(test_missing_folder),
        cmocka_unit_test(test_read_only_folder),
        cmocka_unit_test(test_failure_mid_write),
        cmocka_unit_test(test_abort_and_failed_rename),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
