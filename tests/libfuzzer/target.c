/* One libFuzzer target per input kind (docs/fuzzing.md, "Coverage-guided fuzzing"): built once
 * per kind with FV_FUZZ_KIND naming it (tests/libfuzzer/CMakeLists.txt), in a clang build that
 * instruments the library for coverage and the sanitizers.
 *
 * Each input is written to a file in a private work folder (the loaders take paths, and a scene
 * input finds the meshes and traces the seeds name beside it) and run through the same entry
 * points and verdict as the mutation fuzzer (tests/fuzz/kinds.c): accepted and everything after
 * the load works, or refused with FV_ERR_INVALID/FV_ERR_IO and a one-line message naming the
 * file, nothing left behind. An input that breaks a rule aborts, so libFuzzer saves it as a
 * crash; crashes, hangs, leaks and sanitizer reports libFuzzer finds itself.
 */
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "../fuzz/kinds.h"

#ifndef FV_FUZZ_KIND
#error "FV_FUZZ_KIND names the input kind (tests/fuzz/kinds.c)"
#endif

/* A runaway allocation in an input must fail and be refused, as in the mutation fuzzer, rather
 * than take the machine's memory; libFuzzer's own -malloc_limit_mb is set above this. */
const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "allocator_may_return_null=1:max_allocation_size_mb=3072"; }

/* The process's fuzzing state. libFuzzer's entry points take no user pointer, so it lives here,
 * made once by LLVMFuzzerInitialize and removed at exit. */
typedef struct target_state {
    const fv_fuzz_kind *kind;
    fv_fuzz_ctx ctx;
    char input[4200];
    char before[64][FV_FUZZ_NAME_MAX];
    int nbefore;
    long accepted, refused; /* printed at exit: how far the inputs got */
    char omp_tag[32];       /* our libomp registration's address (see sweep_omp_files); "" when none */
} target_state;

static target_state *state(void)
{
    static target_state s;
    return &s;
}

#define OMP_FILE "__KMP_REGISTERED_LIB_"

/* The first field of libomp's registration file for pid ("ADDRESS-VALUE-libomp.so.5") into tag. */
static bool omp_file_tag(const char *name, char *tag, size_t n)
{
    char path[300];
    snprintf(path, sizeof path, "/dev/shm/%s", name);
    FILE *f = fopen(path, "rb");
    if (!f) return false;
    size_t got = fread(tag, 1, n - 1, f);
    fclose(f);
    tag[got] = '\0';
    char *dash = strchr(tag, '-');
    if (dash) *dash = '\0';
    return dash != NULL;
}

/* clang's OpenMP runtime (libomp; GCC's has no such file) registers each process in
 * /dev/shm/__KMP_REGISTERED_LIB_<pid>_0 and removes the file at exit; a child of fork that ends
 * with _exit, as the sandbox's child does (src/core/sandbox.c), leaves it: one file per mesh
 * import, thousands in a long run. Files of our own children carry our registration's address
 * (they are forks of this process), so those of ended processes are removed. */
static void sweep_omp_files(target_state *s)
{
    if (!s->omp_tag[0]) { /* libomp registers at its first use: until then, nothing to sweep */
        char own[64];
        snprintf(own, sizeof own, OMP_FILE "%d_0", (int)getpid());
        if (!omp_file_tag(own, s->omp_tag, sizeof s->omp_tag)) {
            s->omp_tag[0] = '\0';
            return;
        }
    }
    DIR *d = opendir("/dev/shm");
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d))) {
        int pid;
        char tail[8];
        if (sscanf(e->d_name, OMP_FILE "%d%7s", &pid, tail) != 2 || strcmp(tail, "_0") || pid == (int)getpid()) continue;
        if (kill(pid, 0) == 0 || errno != ESRCH) continue; /* still running */
        char tag[64];
        if (!omp_file_tag(e->d_name, tag, sizeof tag) || strcmp(tag, s->omp_tag)) continue;
        char path[300];
        snprintf(path, sizeof path, "/dev/shm/%s", e->d_name);
        unlink(path);
    }
    closedir(d);
}

static void at_exit(void)
{
    target_state *s = state();
    fprintf(stderr, "fovea libfuzzer: %s: %ld inputs accepted, %ld refused\n", s->kind->name, s->accepted, s->refused);
    fv_fuzz_ctx_free(&s->ctx, true);
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    target_state *s = state();
    s->kind = fv_fuzz_kind_find(FV_FUZZ_KIND);
    const char *src = getenv("FOVEA_SOURCE_DIR");
    if (!s->kind || !fv_fuzz_ctx_init(&s->ctx, src && *src ? src : FOVEA_SOURCE_DIR)) abort();
    atexit(at_exit);
    snprintf(s->input, sizeof s->input, "%s/in%s", s->ctx.work, s->kind->ext);
    /* The input file is made once and rewritten in place: a file created and removed per
     * execution cost a fifth of the time (ext4 inode allocation, measured with perf). */
    FILE *f = fopen(s->input, "wb");
    if (!f || fclose(f) != 0) abort();
    s->nbefore = fv_fuzz_list_dir(s->ctx.work, s->before, 64);
    return 0;
}

#if defined(FV_FUZZ_PNG_CRCS)
/* PNG: libFuzzer's own mutations, then the chunks' CRCs made right again (kinds.h). */
size_t LLVMFuzzerMutate(uint8_t *data, size_t size, size_t max_size);
size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned int seed);
size_t LLVMFuzzerCustomMutator(uint8_t *data, size_t size, size_t max_size, unsigned int seed)
{
    (void)seed;
    size_t n = LLVMFuzzerMutate(data, size, max_size);
    fv_fuzz_png_fix_crcs(data, n);
    return n;
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    target_state *s = state();
    FILE *f = fopen(s->input, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0) {
        fprintf(stderr, "fovea libfuzzer: cannot write %s\n", s->input);
        abort();
    }
    fv_error err;
    fv_error_clear(&err);
    fv_fuzz_ctx_begin(&s->ctx);
    fv_status st = s->kind->run(&s->ctx, s->input, &err);
    char why[600];
    const char *bad = fv_fuzz_judge(&s->ctx, s->input, st, &err, s->before, s->nbefore, why, sizeof why);
    fv_fuzz_clean_work(&s->ctx, s->before, s->nbefore);
    sweep_omp_files(s);
    if (st == FV_OK) s->accepted++;
    else s->refused++;
    if (bad) {
        fprintf(stderr, "FINDING %s: %s\n", s->kind->name, bad);
        abort();
    }
    return 0;
}
