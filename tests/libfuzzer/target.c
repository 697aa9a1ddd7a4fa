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
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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
} target_state;

static target_state *state(void)
{
    static target_state s;
    return &s;
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
    if (st == FV_OK) s->accepted++;
    else s->refused++;
    if (bad) {
        fprintf(stderr, "FINDING %s: %s\n", s->kind->name, bad);
        abort();
    }
    return 0;
}
