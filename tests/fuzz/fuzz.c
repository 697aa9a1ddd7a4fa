/* fovea-fuzz — a small mutation fuzzer for every kind of file fovea reads (docs/fuzzing.md).
 *
 * Each input is a seed file of one kind (the test data, the bench scenarios and hand-made files
 * written at start-up) changed by a few mutations: bit flips, byte changes, inserted, deleted and
 * duplicated chunks, a number replaced by an awkward one (1e19, nan, -0, huge counts), truncation,
 * splicing with another seed. Input i of a kind is a pure function of (seed, kind, i), so any
 * finding is replayed with --kind K --index I.
 *
 * Each input goes through the library entry points the CLI uses for that file (a scene is opened,
 * committed and rendered at 4x4; a trace is loaded and drives a render; a scenario is checked as
 * `fovea bench --check` does; an image is read and compared with itself; an eye-tracker export is
 * imported and the trace it wrote is read back). The verdict for each input:
 *   - it is accepted, and then everything after the load works too; or
 *   - it is refused with FV_ERR_INVALID or FV_ERR_IO (exit status 2) and a message of one line
 *     that names the input file;
 *   - no file appears in the work folder but those there before (nothing half-written);
 *   - no crash, no sanitizer report, no hang (a per-input time limit).
 * The entry points and the verdict live in kinds.c, shared with the libFuzzer targets
 * (tests/libfuzzer), which take their starting corpus from `--seeds-out`.
 * Inputs run in batches inside a child process; the parent watches it, so a crash or a hang is
 * charged to the input that was running, saved, and the next batch starts after it.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "fovea/fovea.h"
#include "kinds.h"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#define FUZZ_ASAN 1
/* A runaway allocation in an input must fail (and be refused), not take the machine's memory. */
const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "allocator_may_return_null=1:max_allocation_size_mb=3072"; }
#else
#define FUZZ_ASAN 0
#endif

#define FUZZ_MAX_INPUT (1 << 20)
#define MAX_SEEDS 128

/* ---- deterministic random numbers ---- */

static uint64_t mix(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

typedef struct rng {
    uint64_t s;
} rng;

static uint64_t next(rng *r) { return mix(r->s++); }
static size_t below(rng *r, size_t n) { return n ? (size_t)(next(r) % n) : 0; }

/* ---- inputs ---- */

typedef struct buf {
    unsigned char *p;
    size_t n;
} buf;

static const char *const k_numbers[] = {"1e19",  "-1e19", "1e20",  "1.8e18", "1e38",  "3e38",       "1e39",      "-1e39",
                                        "1e308", "1e400", "nan",   "NaN",    "-nan",  "inf",        "-inf",      "-0",
                                        "0",     "-1",    "1e-45", "1e-320", "65535", "2147483647", "2147483648", "4294967295",
                                        "4294967296", "9999999999999999999", "-2147483648", "1e9", "0.5", "1", "2", "3",
                                        "1000000", "0x7fffffff", "1e15", "-1e15", "1e16", ""};
#define NNUM (sizeof k_numbers / sizeof k_numbers[0])
static const unsigned char k_bytes[] = {0, 0xff, '\n', '\r', ',', '"', '{', '}', '[', ']', '-', '.', 'e', '9', ' ', '#', 0x01, 0x7f, 0x80, ':'};

static bool reserve(buf *b, size_t n)
{
    return n <= FUZZ_MAX_INPUT;
}

static void insert(buf *b, size_t at, const void *src, size_t n)
{
    if (!reserve(b, b->n + n)) return;
    memmove(b->p + at + n, b->p + at, b->n - at);
    memcpy(b->p + at, src, n);
    b->n += n;
}

static void erase(buf *b, size_t at, size_t n)
{
    if (at + n > b->n) n = b->n - at;
    memmove(b->p + at, b->p + at + n, b->n - at - n);
    b->n -= n;
}

static bool numch(unsigned char c) { return (c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-'; }

/* Replaces the number at or after a random position by an awkward one. */
static void swap_number(buf *b, rng *r)
{
    if (!b->n) return;
    size_t at = below(r, b->n), i = at;
    while (i < b->n && !(b->p[i] >= '0' && b->p[i] <= '9')) i++;
    if (i == b->n) return;
    size_t s = i, e = i;
    while (s > 0 && numch(b->p[s - 1])) s--;
    while (e < b->n && numch(b->p[e])) e++;
    const char *v = k_numbers[below(r, NNUM)];
    erase(b, s, e - s);
    insert(b, s, v, strlen(v));
}

static void mutate_once(buf *b, const buf *other, rng *r)
{
    size_t n = b->n;
    switch (below(r, 10)) {
    case 0:
        if (n) b->p[below(r, n)] ^= (unsigned char)(1u << below(r, 8));
        break;
    case 1:
        if (n) b->p[below(r, n)] = k_bytes[below(r, sizeof k_bytes)];
        break;
    case 2: {
        unsigned char c[8];
        size_t k = 1 + below(r, 8);
        for (size_t i = 0; i < k; i++) c[i] = below(r, 2) ? k_bytes[below(r, sizeof k_bytes)] : (unsigned char)next(r);
        insert(b, below(r, n + 1), c, k);
        break;
    }
    case 3:
        if (n) erase(b, below(r, n), 1 + below(r, below(r, 2) ? 8 : 256));
        break;
    case 4:
        if (n) { /* duplicate a chunk somewhere */
            size_t s = below(r, n), k = 1 + below(r, n - s < 512 ? n - s : 512);
            unsigned char tmp[512];
            memcpy(tmp, b->p + s, k);
            insert(b, below(r, n + 1), tmp, k);
        }
        break;
    case 5:
    case 6:
    case 7: swap_number(b, r); break;
    case 8:
        if (n) b->n = below(r, n); /* truncate */
        break;
    default:
        if (other && other->n && n) { /* splice: our head, the other seed's tail */
            size_t a = below(r, n), c = below(r, other->n), k = other->n - c;
            b->n = a;
            if (reserve(b, a + k)) {
                memcpy(b->p + a, other->p + c, k);
                b->n = a + k;
            }
        }
        break;
    }
}

/* ---- seeds ---- */

/* The seeds of one kind (kinds.c says which files), loaded once per run. */
typedef struct seed_set {
    buf seeds[MAX_SEEDS];
    int n;
} seed_set;

static bool ends_with(const char *s, const char *e)
{
    size_t a = strlen(s), b = strlen(e);
    return a >= b && strcmp(s + a - b, e) == 0;
}

static bool read_file(const char *path, buf *out)
{
    FILE *f = fopen(path, "rb");
    if (!f) return false;
    out->p = malloc(FUZZ_MAX_INPUT + 16);
    out->n = out->p ? fread(out->p, 1, FUZZ_MAX_INPUT, f) : 0;
    fclose(f);
    return out->p != NULL;
}

static int cmp_names(const void *a, const void *b) { return strcmp(a, b); }

static void load_seeds_from(const fv_fuzz_kind *k, const char *dir, seed_set *ss)
{
    DIR *dp = opendir(dir);
    if (!dp) return;
    struct dirent *e;
    /* sorted by name, so input i is the same on every machine */
    const int max = MAX_SEEDS;
    char(*names)[256] = malloc((size_t)max * 256);
    int n = 0;
    while (names && (e = readdir(dp)) && n < max)
        if (ends_with(e->d_name, k->ext) && e->d_name[0] != '.' && (!k->seed_prefix || !strncmp(e->d_name, k->seed_prefix, strlen(k->seed_prefix))))
            snprintf(names[n++], 256, "%s", e->d_name);
    closedir(dp);
    if (names) qsort(names, (size_t)n, 256, cmp_names);
    for (int i = 0; i < n && ss->n < MAX_SEEDS; i++) {
        char p[4400];
        if (snprintf(p, sizeof p, "%s/%s", dir, names[i]) >= (int)sizeof p) continue;
        if (read_file(p, &ss->seeds[ss->n])) ss->n++;
    }
    free(names);
}

/* The kind's seeds: its files in the source tree, or the images written into seeddir. */
static void load_seeds(const fv_fuzz_kind *k, const char *src, const char *seeddir, seed_set *ss)
{
    ss->n = 0;
    if (k->images) load_seeds_from(k, seeddir, ss);
    for (int d = 0; d < 3 && k->seed_dirs[d]; d++) {
        char dir[3800];
        if (snprintf(dir, sizeof dir, "%s/%s", src, k->seed_dirs[d]) < (int)sizeof dir) load_seeds_from(k, dir, ss);
    }
}

static void free_seeds(seed_set *ss)
{
    for (int i = 0; i < ss->n; i++) free(ss->seeds[i].p);
    ss->n = 0;
}

/* Writes the seeds as files seed-NNN<ext> into dir: the libFuzzer targets' starting corpus. */
static int write_seeds(const fv_fuzz_kind *k, const seed_set *ss, const char *dir)
{
    if (mkdir(dir, 0755) != 0 && errno != EEXIST) return perror(dir), 2;
    for (int i = 0; i < ss->n; i++) {
        char p[4400];
        snprintf(p, sizeof p, "%s/seed-%03d%s", dir, i, k->ext);
        FILE *f = fopen(p, "wb");
        if (!f || fwrite(ss->seeds[i].p, 1, ss->seeds[i].n, f) != ss->seeds[i].n || fclose(f) != 0) return perror(p), 2;
    }
    printf("%s: %d seeds in %s\n", k->name, ss->n, dir);
    return 0;
}

/* Input i of kind k into b. */
static void make_input(const fv_fuzz_kind *k, const seed_set *ss, uint64_t seed, long i, buf *b)
{
    uint64_t h = seed;
    for (const char *c = k->name; *c; c++) h = mix(h ^ (unsigned char)*c);
    rng r = {mix(h ^ (uint64_t)i * 0x2545f4914f6cdd1dULL)};
    const buf *s = &ss->seeds[below(&r, (size_t)ss->n)];
    memcpy(b->p, s->p, s->n);
    b->n = s->n;
    int m = (int)below(&r, 16) == 0 ? 0 : 1 + (int)below(&r, 4); /* a few seeds go in unchanged */
    for (int j = 0; j < m; j++) mutate_once(b, &ss->seeds[below(&r, (size_t)ss->n)], &r);
    if (!strcmp(k->ext, ".png")) fv_fuzz_png_fix_crcs(b->p, b->n);
}

/* ---- parent and child ---- */

typedef struct shared {
    volatile long cur, done;
    volatile double started;
    volatile long accepted, refused;
} shared;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

/* What one run of a kind needs: the kind, its seeds, the context, where findings go. */
typedef struct job {
    const fv_fuzz_kind *k;
    const seed_set *ss;
    fv_fuzz_ctx *c;
    uint64_t seed;
    const char *outdir;
} job;

static void save_finding(const job *j, long i, const char *why, int *findings)
{
    buf b = {malloc(FUZZ_MAX_INPUT + 16), 0};
    if (!b.p) return;
    make_input(j->k, j->ss, j->seed, i, &b);
    char p[4400];
    snprintf(p, sizeof p, "%s/finding-%s-%ld%s", j->outdir, j->k->name, i, j->k->ext);
    FILE *f = fopen(p, "wb");
    if (f) {
        fwrite(b.p, 1, b.n, f);
        fclose(f);
    }
    free(b.p);
    fprintf(stderr, "FINDING %s #%ld: %s (saved %s)\n", j->k->name, i, why, p);
    snprintf(p, sizeof p, "%s/findings.txt", j->outdir);
    if ((f = fopen(p, "a"))) {
        fprintf(f, "%s %ld %s\n", j->k->name, i, why);
        fclose(f);
    }
    (*findings)++;
}

static void child(const job *j, long from, long to, shared *sh, size_t mem_mb)
{
    if (!FUZZ_ASAN && mem_mb) {
        struct rlimit rl = {(rlim_t)mem_mb << 20, (rlim_t)mem_mb << 20};
        setrlimit(RLIMIT_AS, &rl);
    }
    fv_fuzz_ctx *c = j->c;
    char before[64][FV_FUZZ_NAME_MAX];
    int nbefore = fv_fuzz_list_dir(c->work, before, 64);
    buf b = {malloc(FUZZ_MAX_INPUT + 16), 0};
    char name[4200];
    snprintf(name, sizeof name, "%s/in%s", c->work, j->k->ext);
    int findings = 0;
    for (long i = from; i < to && b.p; i++) {
        sh->cur = i;
        sh->started = now_s();
        make_input(j->k, j->ss, j->seed, i, &b);
        FILE *f = fopen(name, "wb");
        if (!f) _exit(3);
        fwrite(b.p, 1, b.n, f);
        fclose(f);
        fv_error err;
        fv_error_clear(&err);
        fv_fuzz_ctx_begin(c);
        fv_status st = j->k->run(c, name, &err);
        char why[600];
        const char *bad = fv_fuzz_judge(c, name, st, &err, before, nbefore, why, sizeof why);
#if FUZZ_ASAN
        if (!bad && __lsan_do_recoverable_leak_check()) bad = "memory leak";
#endif
        if (bad) save_finding(j, i, bad, &findings);
        if (st == FV_OK) sh->accepted++;
        else sh->refused++;
        fv_fuzz_clean_work(c, before, nbefore); /* whatever it left, for the next input */
        sh->done = i + 1;
    }
    fv_fuzz_ctx_free(c, false);
    free(b.p);
    _exit(findings ? 4 : 0);
}

/* Runs inputs [first, first + count) of the job's kind; returns the number of findings. */
static int fuzz_kind(const job *j, long first, long count, double timeout, size_t mem_mb, long batch, long *accepted, long *refused)
{
    shared *sh = mmap(NULL, sizeof *sh, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (sh == MAP_FAILED) return 1;
    int findings = 0;
    long i = first, end = first + count;
    while (i < end) {
        long to = i + batch < end ? i + batch : end;
        sh->cur = i;
        sh->done = i;
        sh->started = now_s();
        fflush(NULL);
        pid_t pid = fork();
        if (pid < 0) return findings + 1;
        if (pid == 0) child(j, i, to, sh, mem_mb);
        int status = 0;
        bool hung = false;
        for (;;) {
            pid_t w = waitpid(pid, &status, WNOHANG);
            if (w == pid) break;
            if (now_s() - sh->started > timeout) {
                kill(pid, SIGKILL);
                waitpid(pid, &status, 0);
                hung = true;
                break;
            }
            usleep(2000);
        }
        if (hung) {
            char why[64];
            snprintf(why, sizeof why, "no result after %.0f s (hang)", timeout);
            save_finding(j, sh->cur, why, &findings);
            i = sh->cur + 1;
        } else if (WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != 4)) {
            char why[64];
            if (WIFSIGNALED(status)) snprintf(why, sizeof why, "crash: signal %d", WTERMSIG(status));
            else snprintf(why, sizeof why, "crash: exit status %d (a sanitizer report?)", WEXITSTATUS(status));
            save_finding(j, sh->cur, why, &findings);
            i = sh->done > sh->cur ? sh->done : sh->cur + 1;
        } else {
            if (WIFEXITED(status) && WEXITSTATUS(status) == 4) findings++; /* counted by the child, saved already */
            i = to;
        }
    }
    *accepted += sh->accepted;
    *refused += sh->refused;
    munmap(sh, sizeof *sh);
    return findings;
}

static void usage(void)
{
    fprintf(stderr, "usage: fovea-fuzz [--kind NAME|all] [--count N] [--first I] [--seed S] [--timeout SEC] [--batch N]\n"
                    "                  [--mem-mb MB] [--src DIR] [--out DIR]\n"
                    "       fovea-fuzz --kind NAME --seeds-out DIR   (writes the kind's seeds as files, for libFuzzer)\n"
                    "kinds:");
    for (int k = 0; k < fv_fuzz_kind_count(); k++) fprintf(stderr, " %s", fv_fuzz_kind_at(k)->name);
    fprintf(stderr, "\n--count is per kind. Findings go to DIR/findings.txt and DIR/finding-KIND-INDEX.EXT.\n"
                    "Exit status: 0 no finding, 1 findings, 2 bad usage.\n");
}

int main(int argc, char **argv)
{
    const char *only = "all", *src = FOVEA_SOURCE_DIR, *out = ".", *seeds_out = NULL;
    long count = 1000, first = 0, batch = 500;
    uint64_t seed = 1;
    double timeout = 20.0;
    size_t mem_mb = 4096;
    for (int a = 1; a < argc; a++) {
        const char *v = a + 1 < argc ? argv[a + 1] : NULL;
        if (!v) return usage(), 2;
        if (!strcmp(argv[a], "--kind")) only = v;
        else if (!strcmp(argv[a], "--count")) count = atol(v);
        else if (!strcmp(argv[a], "--first")) first = atol(v);
        else if (!strcmp(argv[a], "--seed")) seed = strtoull(v, NULL, 10);
        else if (!strcmp(argv[a], "--timeout")) timeout = atof(v);
        else if (!strcmp(argv[a], "--batch")) batch = atol(v);
        else if (!strcmp(argv[a], "--mem-mb")) mem_mb = (size_t)atol(v);
        else if (!strcmp(argv[a], "--src")) src = v;
        else if (!strcmp(argv[a], "--out")) out = v;
        else if (!strcmp(argv[a], "--seeds-out")) seeds_out = v;
        else return usage(), 2;
        a++;
    }
    if (count < 0 || batch < 1 || !(timeout > 0)) return usage(), 2;
    if (seeds_out && !fv_fuzz_kind_find(only)) return usage(), 2;
    char outabs[4096];
    if (!seeds_out && mkdir(out, 0755) != 0 && errno != EEXIST) return perror(out), 2;
    if (!seeds_out && !realpath(out, outabs)) return perror(out), 2;
    /* A private work folder (kinds.c): inputs are written there and nothing else may appear in it. */
    fv_fuzz_ctx *ctx = malloc(sizeof *ctx);
    seed_set *ss = malloc(sizeof *ss);
    if (!ctx || !ss || !fv_fuzz_ctx_init(ctx, src)) return 2;
    char seeddir[4200];
    snprintf(seeddir, sizeof seeddir, "%s/seeds", ctx->work);
    mkdir(seeddir, 0755);
    fv_fuzz_write_image_seeds(seeddir);
    int findings = 0, ran = 0;
    long total = 0, accepted = 0, refused = 0;
    double t0 = now_s();
    for (int k = 0; k < fv_fuzz_kind_count(); k++) {
        const fv_fuzz_kind *kd = fv_fuzz_kind_at(k);
        if (strcmp(only, "all") && strcmp(only, kd->name)) continue;
        load_seeds(kd, src, seeddir, ss);
        if (seeds_out) {
            findings = write_seeds(kd, ss, seeds_out);
            ran++;
            free_seeds(ss);
            break;
        }
        if (ss->n == 0) {
            fprintf(stderr, "fovea-fuzz: no seeds for %s\n", kd->name);
            findings++;
            continue;
        }
        double tk = now_s();
        long acc = 0, ref = 0;
        job j = {kd, ss, ctx, seed, outabs};
        int f = fuzz_kind(&j, first, count, timeout, mem_mb, batch, &acc, &ref);
        findings += f;
        ran++;
        total += count;
        accepted += acc;
        refused += ref;
        printf("%-7s %ld inputs (%d seeds): %ld accepted, %ld refused, %d finding(s), %.1f s\n", kd->name, count, ss->n, acc, ref, f,
               now_s() - tk);
        fflush(stdout);
        free_seeds(ss);
    }
    fv_fuzz_ctx_free(ctx, true);
    free(ctx);
    free(ss);
    if (!ran) return usage(), 2;
    if (seeds_out) return findings;
    printf("total   %ld inputs: %ld accepted, %ld refused, %d finding(s), %.1f s (seed %llu, first %ld)\n", total, accepted, refused, findings,
           now_s() - t0, (unsigned long long)seed, first);
    return findings ? 1 : 0;
}
