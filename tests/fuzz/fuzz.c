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

/* PNG chunks carry CRCs; without fixing them libpng refuses every mutated chunk before its
 * contents are read. */
static uint32_t crc32_of(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}

static void png_fix_crcs(buf *b)
{
    size_t at = 8;
    while (at + 12 <= b->n) {
        uint32_t len = (uint32_t)b->p[at] << 24 | (uint32_t)b->p[at + 1] << 16 | (uint32_t)b->p[at + 2] << 8 | b->p[at + 3];
        if (len > b->n - at - 12) break;
        uint32_t c = crc32_of(b->p + at + 4, len + 4);
        unsigned char *q = b->p + at + 8 + len;
        q[0] = (unsigned char)(c >> 24), q[1] = (unsigned char)(c >> 16), q[2] = (unsigned char)(c >> 8), q[3] = (unsigned char)c;
        at += 12 + len;
    }
}

/* ---- kinds of input ---- */

typedef struct fuzz_ctx {
    const char *work;      /* the work folder (the current directory) */
    fv_scene *cornell;     /* for camera traces, built once per batch */
    fv_view *cornell_view;
    bool bad_warning;      /* a warning with a control byte */
    char note[700];         /* what went wrong after a load accepted the input */
} fuzz_ctx;

static void on_warning(void *user, const char *msg)
{
    fuzz_ctx *c = user;
    for (const char *p = msg; *p; p++)
        if ((unsigned char)*p < 0x20) c->bad_warning = true;
}

/* Renders frame 0 (and the last key's time, `t1`) at 4x4 with pt: an accepted input must render. */
static fv_status render_check(fuzz_ctx *c, fv_scene *s, const fv_view *v, const fv_camera_path *cpath, const fv_gaze_path *gpath, fv_error *err)
{
    fv_log log = {on_warning, c};
    fv_technique *t = NULL;
    fv_driver *d = NULL;
    fv_film *f = NULL;
    fv_params *p = NULL;
    fv_status st = fv_params_create(&p, err);
    if (st == FV_OK) st = fv_params_set(p, "spp", "1", err);
    if (st == FV_OK) st = fv_technique_create("pt", s, p, &log, &t, err);
    fv_drive_opts o;
    fv_drive_opts_init(&o);
    o.width = o.height = 4;
    o.threads = 1;
    o.camera_path = cpath;
    o.gaze_path = gpath;
    if (st == FV_OK) st = fv_driver_create(s, v, &o, &d, err);
    if (st == FV_OK) st = fv_film_create(4, 4, 0, &f, err);
    fv_stats stats;
    fv_stats_clear(&stats);
    if (st == FV_OK) st = fv_driver_render(d, t, 0, false, &f, &stats, NULL, NULL, err);
    if (st != FV_OK) snprintf(c->note, sizeof c->note, "accepted, then the render failed: %s", err->msg);
    fv_film_destroy(f);
    fv_driver_destroy(d);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return st == FV_OK ? FV_OK : FV_ERR_INTERNAL;
}

static fv_status run_scene(fuzz_ctx *c, const char *path, fv_error *err)
{
    fv_log log = {on_warning, c};
    fv_scene *s = NULL;
    fv_view *v = NULL;
    fv_status st = fv_scene_open(path, &log, &s, &v, err);
    if (st == FV_OK && (st = fv_scene_commit(s, &log, err)) != FV_OK) fv_error_prefix(err, "%s: ", path);
    if (st == FV_OK) st = render_check(c, s, v, NULL, NULL, err);
    fv_view_destroy(v);
    fv_scene_destroy(s);
    return st;
}

static fv_status cornell(fuzz_ctx *c, fv_error *err)
{
    if (c->cornell) return FV_OK;
    return fv_scene_load("cornell", NULL, &c->cornell, &c->cornell_view, err);
}

static fv_status run_gaze(fuzz_ctx *c, const char *path, fv_error *err)
{
    fv_gaze_path *g = NULL;
    fv_status st = fv_gaze_path_load_csv(path, &g, err);
    if (st != FV_OK) return st;
    if ((st = cornell(c, err)) == FV_OK) st = render_check(c, c->cornell, c->cornell_view, NULL, g, err);
    fv_gaze_path_destroy(g);
    return st;
}

static fv_status run_camera(fuzz_ctx *c, const char *path, fv_error *err)
{
    fv_status st = cornell(c, err);
    if (st != FV_OK) return FV_ERR_INTERNAL;
    fv_camera base;
    fv_view_camera(c->cornell_view, c->cornell, 0.0, 4, 4, &base);
    fv_camera_path p = {NULL, 0};
    if ((st = fv_camera_path_load_csv(path, &base, &p.keys, &p.count, err)) != FV_OK) return st;
    st = render_check(c, c->cornell, c->cornell_view, &p, NULL, err);
    fv_camera_keys_free(p.keys);
    return st;
}

static fv_status run_bench(fuzz_ctx *c, const char *path, fv_error *err)
{
    (void)c;
    return fv_bench_check(path, FV_BENCH_QUICK, err);
}

static fv_status run_image(fuzz_ctx *c, const char *path, fv_error *err)
{
    fv_image img;
    fv_status st = fv_image_read(path, &img, err);
    if (st != FV_OK) return st;
    uint8_t *labels = malloc((size_t)img.width * img.height);
    fv_eye_model eye;
    fv_eye_model_default(img.width, img.height, &eye);
    fv_metric_opts mo;
    fv_metric_opts_default(&mo);
    fv_metric_report rep;
    if (!labels) {
        st = FV_ERR_INTERNAL;
        snprintf(c->note, sizeof c->note, "accepted a %dx%d image but no memory for its labels", img.width, img.height);
    } else {
        fv_eye_region_labels(&eye, (fv_gaze){0.5f, 0.5f}, labels);
        if ((st = fv_metrics_compare(img.rgb, img.rgb, img.width, img.height, labels, &mo, &rep, NULL, err)) != FV_OK) {
            snprintf(c->note, sizeof c->note, "accepted, then compare failed: %s", err->msg);
            st = FV_ERR_INTERNAL;
        }
    }
    free(labels);
    fv_image_free(&img);
    return st;
}

/* An eye tracker's recording: imported, and the trace it wrote must load and drive a render. */
static fv_status run_import(fuzz_ctx *c, const char *path, fv_error *err)
{
    fv_status st = fv_gaze_import(path, "trace.csv", NULL, NULL, err);
    if (st != FV_OK) return st;
    fv_error e2;
    if (run_gaze(c, "trace.csv", &e2) != FV_OK && !c->note[0]) snprintf(c->note, sizeof c->note, "imported, then the trace was refused: %s", e2.msg);
    remove("trace.csv");
    return c->note[0] ? FV_ERR_INTERNAL : FV_OK;
}

typedef fv_status (*run_fn)(fuzz_ctx *c, const char *path, fv_error *err);

typedef struct kind {
    const char *name, *ext;
    run_fn run;
    const char *seed_dirs[3]; /* relative to the source tree; files ending in ext */
    buf seeds[MAX_SEEDS];
    int nseeds;
} kind;

static kind k_kinds[] = {
    {"scene", ".json", run_scene, {"tests/data", "scenes", "tests/fuzz/seeds"}, {{0}}, 0},
    {"obj", ".obj", run_scene, {"tests/data", "tests/fuzz/seeds", NULL}, {{0}}, 0},
    {"ply", ".ply", run_scene, {"tests/data", "tests/fuzz/seeds", NULL}, {{0}}, 0},
    {"gltf", ".gltf", run_scene, {"tests/data", "tests/fuzz/seeds", NULL}, {{0}}, 0},
    {"glb", ".glb", run_scene, {"tests/data/textured", NULL, NULL}, {{0}}, 0}, /* embedded textures */
    {"off", ".off", run_scene, {"tests/fuzz/seeds", NULL, NULL}, {{0}}, 0},
    {"gaze", ".csv", run_gaze, {"tests/fuzz/seeds/gaze", "scenes", NULL}, {{0}}, 0},
    {"camera", ".csv", run_camera, {"tests/fuzz/seeds/camera", "tests/data", NULL}, {{0}}, 0},
    {"bench", ".json", run_bench, {"bench", "tests/fuzz/seeds/bench", NULL}, {{0}}, 0},
    {"png", ".png", run_image, {"tests/fuzz/seeds", NULL, NULL}, {{0}}, 0},
    {"pfm", ".pfm", run_image, {"tests/fuzz/seeds", NULL, NULL}, {{0}}, 0},
    {"exr", ".exr", run_image, {"tests/fuzz/seeds", NULL, NULL}, {{0}}, 0},
    {"eyelink", ".asc", run_import, {"tests/data", NULL, NULL}, {{0}}, 0},
    {"pupil", "gaze_positions.csv", run_import, {"tests/data", NULL, NULL}, {{0}}, 0},
};
#define NKINDS ((int)(sizeof k_kinds / sizeof k_kinds[0]))

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

static void load_seeds(kind *k, const char *src)
{
    for (int d = 0; d < 3 && k->seed_dirs[d]; d++) {
        char dir[3800];
        if (snprintf(dir, sizeof dir, "%s/%s", src, k->seed_dirs[d]) >= (int)sizeof dir) continue;
        DIR *dp = opendir(dir);
        if (!dp) continue;
        struct dirent *e;
        /* sorted by name, so input i is the same on every machine */
        char names[MAX_SEEDS][256];
        int n = 0;
        while ((e = readdir(dp)) && n < MAX_SEEDS)
            if (ends_with(e->d_name, k->ext) && e->d_name[0] != '.') snprintf(names[n++], 256, "%s", e->d_name);
        closedir(dp);
        qsort(names, (size_t)n, 256, (int (*)(const void *, const void *))strcmp);
        for (int i = 0; i < n && k->nseeds < MAX_SEEDS; i++) {
            char p[4400];
            if (snprintf(p, sizeof p, "%s/%s", dir, names[i]) >= (int)sizeof p) continue;
            if (read_file(p, &k->seeds[k->nseeds])) k->nseeds++;
        }
    }
}

/* Input i of kind k into b. */
static void make_input(const kind *k, uint64_t seed, long i, buf *b)
{
    uint64_t h = seed;
    for (const char *c = k->name; *c; c++) h = mix(h ^ (unsigned char)*c);
    rng r = {mix(h ^ (uint64_t)i * 0x2545f4914f6cdd1dULL)};
    const buf *s = &k->seeds[below(&r, (size_t)k->nseeds)];
    memcpy(b->p, s->p, s->n);
    b->n = s->n;
    int m = (int)below(&r, 16) == 0 ? 0 : 1 + (int)below(&r, 4); /* a few seeds go in unchanged */
    for (int j = 0; j < m; j++) mutate_once(b, &k->seeds[below(&r, (size_t)k->nseeds)], &r);
    if (!strcmp(k->ext, ".png")) png_fix_crcs(b);
}

/* ---- the verdict ---- */

static int list_dir(const char *dir, char names[][256], int max)
{
    DIR *dp = opendir(dir);
    int n = 0;
    if (!dp) return 0;
    struct dirent *e;
    while ((e = readdir(dp)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && n < max) snprintf(names[n++], 256, "%s", e->d_name);
    closedir(dp);
    return n;
}

/* NULL when the outcome follows the rules, else why not. */
static const char *judge(fuzz_ctx *c, const char *input, fv_status st, const fv_error *err, char (*before)[256], int nbefore, char *why,
                         size_t n)
{
    if (c->bad_warning) return "a warning spans several lines";
    if (st == FV_ERR_INTERNAL && c->note[0]) return c->note;
    if (st != FV_OK) {
        if (st != FV_ERR_INVALID && st != FV_ERR_IO) {
            snprintf(why, n, "refused with status '%s' (exit 1, not 2): %s", fv_status_name(st), err->msg);
            return why;
        }
        if (!err->msg[0]) return "refused without a message";
        for (const char *p = err->msg; *p; p++)
            if ((unsigned char)*p < 0x20) return "the message spans several lines";
        if (!strstr(err->msg, input)) {
            snprintf(why, n, "the message does not name the file: %s", err->msg);
            return why;
        }
    }
    char now[64][256];
    int k = list_dir(".", now, 64);
    for (int i = 0; i < k; i++) {
        bool known = !strcmp(now[i], input);
        for (int j = 0; j < nbefore && !known; j++) known = !strcmp(now[i], before[j]);
        if (!known) {
            snprintf(why, n, "left a file behind: %s", now[i]);
            return why;
        }
    }
    return NULL;
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

static void input_name(const kind *k, char *out, size_t n) { snprintf(out, n, "in%s", k->ext); }

static void save_finding(const char *outdir, const kind *k, uint64_t seed, long i, const char *why, int *findings)
{
    buf b = {malloc(FUZZ_MAX_INPUT + 16), 0};
    if (!b.p) return;
    make_input(k, seed, i, &b);
    char p[4400];
    snprintf(p, sizeof p, "%s/finding-%s-%ld%s", outdir, k->name, i, k->ext);
    FILE *f = fopen(p, "wb");
    if (f) {
        fwrite(b.p, 1, b.n, f);
        fclose(f);
    }
    free(b.p);
    fprintf(stderr, "FINDING %s #%ld: %s (saved %s)\n", k->name, i, why, p);
    snprintf(p, sizeof p, "%s/findings.txt", outdir);
    if ((f = fopen(p, "a"))) {
        fprintf(f, "%s %ld %s\n", k->name, i, why);
        fclose(f);
    }
    (*findings)++;
}

static void child(const kind *k, uint64_t seed, long from, long to, shared *sh, const char *outdir, size_t mem_mb)
{
    if (!FUZZ_ASAN && mem_mb) {
        struct rlimit rl = {(rlim_t)mem_mb << 20, (rlim_t)mem_mb << 20};
        setrlimit(RLIMIT_AS, &rl);
    }
    fuzz_ctx c;
    memset(&c, 0, sizeof c);
    char before[64][256];
    int nbefore = list_dir(".", before, 64);
    buf b = {malloc(FUZZ_MAX_INPUT + 16), 0};
    char name[32];
    input_name(k, name, sizeof name);
    int findings = 0;
    for (long i = from; i < to && b.p; i++) {
        sh->cur = i;
        sh->started = now_s();
        make_input(k, seed, i, &b);
        FILE *f = fopen(name, "wb");
        if (!f) _exit(3);
        fwrite(b.p, 1, b.n, f);
        fclose(f);
        fv_error err;
        fv_error_clear(&err);
        c.bad_warning = false;
        c.note[0] = '\0';
        fv_status st = k->run(&c, name, &err);
        char why[600];
        const char *bad = judge(&c, name, st, &err, before, nbefore, why, sizeof why);
#if FUZZ_ASAN
        if (!bad && __lsan_do_recoverable_leak_check()) bad = "memory leak";
#endif
        if (bad) save_finding(outdir, k, seed, i, bad, &findings);
        if (st == FV_OK) sh->accepted++;
        else sh->refused++;
        /* clean the folder for the next input, whatever it left */
        char now[64][256];
        int nn = list_dir(".", now, 64);
        for (int j = 0; j < nn; j++) {
            bool keep = false;
            for (int q = 0; q < nbefore && !keep; q++) keep = !strcmp(now[j], before[q]);
            if (!keep) remove(now[j]);
        }
        sh->done = i + 1;
    }
    fv_scene_destroy(c.cornell);
    fv_view_destroy(c.cornell_view);
    free(b.p);
    _exit(findings ? 4 : 0);
}

/* Runs inputs [0, count) of kind k; returns the number of findings. */
static int fuzz_kind(const kind *k, uint64_t seed, long first, long count, double timeout, const char *outdir, size_t mem_mb, long batch,
                     long *accepted, long *refused)
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
        if (pid == 0) child(k, seed, i, to, sh, outdir, mem_mb);
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
            save_finding(outdir, k, seed, sh->cur, why, &findings);
            i = sh->cur + 1;
        } else if (WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != 4)) {
            char why[64];
            if (WIFSIGNALED(status)) snprintf(why, sizeof why, "crash: signal %d", WTERMSIG(status));
            else snprintf(why, sizeof why, "crash: exit status %d (a sanitizer report?)", WEXITSTATUS(status));
            save_finding(outdir, k, seed, sh->cur, why, &findings);
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

/* Hand-made image seeds, written with our own writers (no binary files in the repository). */
static void write_image_seeds(const char *dir)
{
    float rgb[4 * 3 * 3];
    for (int i = 0; i < 36; i++) rgb[i] = (float)(i % 7) / 6.0f;
    char p[4400];
    fv_error err;
    const char *names[] = {"a.png", "a.pfm", "a.exr"};
    for (int i = 0; i < 3; i++) {
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        fv_image_write(p, rgb, 4, 3, 1.0f, &err);
    }
    rgb[5] = NAN;
    snprintf(p, sizeof p, "%s/nan.pfm", dir);
    fv_image_write(p, rgb, 4, 3, 1.0f, &err);
}

static void usage(void)
{
    fprintf(stderr, "usage: fovea-fuzz [--kind NAME|all] [--count N] [--first I] [--seed S] [--timeout SEC] [--batch N]\n"
                    "                  [--mem-mb MB] [--src DIR] [--out DIR]\n"
                    "kinds:");
    for (int k = 0; k < NKINDS; k++) fprintf(stderr, " %s", k_kinds[k].name);
    fprintf(stderr, "\n--count is per kind. Findings go to DIR/findings.txt and DIR/finding-KIND-INDEX.EXT.\n"
                    "Exit status: 0 no finding, 1 findings, 2 bad usage.\n");
}

int main(int argc, char **argv)
{
    const char *only = "all", *src = FOVEA_SOURCE_DIR, *out = ".";
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
        else return usage(), 2;
        a++;
    }
    if (count < 0 || batch < 1 || !(timeout > 0)) return usage(), 2;
    char outabs[4096];
    if (mkdir(out, 0755) != 0 && errno != EEXIST) return perror(out), 2;
    if (!realpath(out, outabs)) return perror(out), 2;
    /* A private work folder: inputs are written there and nothing else may appear in it. The
     * mesh files the test scenes name are copied in, so scene inputs can load them. */
    char work[] = "/tmp/fovea-fuzz-XXXXXX";
    if (!mkdtemp(work)) return perror("mkdtemp"), 2;
    char seeddir[4200];
    snprintf(seeddir, sizeof seeddir, "%s/seeds", work);
    mkdir(seeddir, 0755);
    write_image_seeds(seeddir);
    char cmd[9000];
    snprintf(cmd, sizeof cmd,
             "cp %s/tests/data/*.ply %s/tests/data/*.obj %s/tests/data/*.mtl %s/tests/data/*.gltf %s/tests/data/*.csv %s/ && "
             "cp -r %s/scenes/meshes %s/ && cp %s/tests/fuzz/seeds/gaze/mono.csv %s/gaze.csv",
             src, src, src, src, src, work, src, work, src, work);
    if (system(cmd) != 0) fprintf(stderr, "fovea-fuzz: warning: could not copy the test meshes\n");
    if (chdir(work) != 0) return perror(work), 2;
    int findings = 0, ran = 0;
    long total = 0, accepted = 0, refused = 0;
    double t0 = now_s();
    for (int k = 0; k < NKINDS; k++) {
        kind *kd = &k_kinds[k];
        if (strcmp(only, "all") && strcmp(only, kd->name)) continue;
        load_seeds(kd, src);
        if (!strcmp(kd->ext, ".png") || !strcmp(kd->ext, ".pfm") || !strcmp(kd->ext, ".exr")) {
            const char *save = kd->seed_dirs[0];
            kd->seed_dirs[0] = "seeds";
            load_seeds(kd, work);
            kd->seed_dirs[0] = save;
        }
        if (kd->nseeds == 0) {
            fprintf(stderr, "fovea-fuzz: no seeds for %s\n", kd->name);
            findings++;
            continue;
        }
        double tk = now_s();
        long acc = 0, ref = 0;
        int f = fuzz_kind(kd, seed, first, count, timeout, outabs, mem_mb, batch, &acc, &ref);
        findings += f;
        ran++;
        total += count;
        accepted += acc;
        refused += ref;
        printf("%-7s %ld inputs (%d seeds): %ld accepted, %ld refused, %d finding(s), %.1f s\n", kd->name, count, kd->nseeds, acc, ref, f,
               now_s() - tk);
        fflush(stdout);
    }
    if (!ran) return usage(), 2;
    printf("total   %ld inputs: %ld accepted, %ld refused, %d finding(s), %.1f s (seed %llu, first %ld)\n", total, accepted, refused, findings,
           now_s() - t0, (unsigned long long)seed, first);
    snprintf(cmd, sizeof cmd, "rm -rf %s", work);
    if (chdir("/") != 0 || system(cmd) != 0) fprintf(stderr, "fovea-fuzz: warning: could not remove %s\n", work);
    return findings ? 1 : 0;
}
