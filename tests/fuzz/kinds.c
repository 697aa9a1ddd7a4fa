/* The input kinds, what runs each, and the verdict (kinds.h; docs/fuzzing.md). */
#include "kinds.h"
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "bench/scenario.h"

static void on_warning(void *user, const char *msg)
{
    fv_fuzz_ctx *c = user;
    for (const char *p = msg; *p; p++)
        if ((unsigned char)*p < 0x20) c->bad_warning = true;
}

/* Renders frame 0 at 4x4 with pt: an accepted input must render. */
static fv_status render_check(fv_fuzz_ctx *c, fv_scene *s, const fv_view *v, const fv_camera_path *cpath, const fv_gaze_path *gpath,
                              fv_error *err)
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

static fv_status run_scene(fv_fuzz_ctx *c, const char *path, fv_error *err)
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

static fv_status cornell(fv_fuzz_ctx *c, fv_error *err)
{
    if (c->cornell) return FV_OK;
    return fv_scene_load("cornell", NULL, &c->cornell, &c->cornell_view, err);
}

static fv_status run_gaze(fv_fuzz_ctx *c, const char *path, fv_error *err)
{
    fv_gaze_path *g = NULL;
    fv_status st = fv_gaze_path_load_csv(path, &g, err);
    if (st != FV_OK) return st;
    if ((st = cornell(c, err)) == FV_OK) st = render_check(c, c->cornell, c->cornell_view, NULL, g, err);
    fv_gaze_path_destroy(g);
    return st;
}

static fv_status run_camera(fv_fuzz_ctx *c, const char *path, fv_error *err)
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

static fv_status run_bench(fv_fuzz_ctx *c, const char *path, fv_error *err)
{
    (void)c;
    return fv_bench_check(path, FV_BENCH_QUICK, err);
}

/* The scenario parser alone (the first step of fv_bench_check): the scene and techniques a valid
 * scenario names take 20 ms to 1.6 s to build, which would leave the parser few executions. */
static fv_status run_scenario(fv_fuzz_ctx *c, const char *path, fv_error *err)
{
    (void)c;
    fv_scenario *sc = NULL;
    fv_status st = fv_scenario_load(path, FV_BENCH_QUICK, &sc, err);
    fv_scenario_destroy(sc);
    return st;
}

static fv_status run_image(fv_fuzz_ctx *c, const char *path, fv_error *err)
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
static fv_status run_import(fv_fuzz_ctx *c, const char *path, fv_error *err)
{
    char trace[4200];
    snprintf(trace, sizeof trace, "%s/trace.csv", c->work);
    fv_status st = fv_gaze_import(path, trace, NULL, NULL, err);
    if (st != FV_OK) return st;
    fv_error e2;
    if (run_gaze(c, trace, &e2) != FV_OK && !c->note[0]) snprintf(c->note, sizeof c->note, "imported, then the trace was refused: %s", e2.msg);
    remove(trace);
    return c->note[0] ? FV_ERR_INTERNAL : FV_OK;
}

/* A delimited table under a mapping by number (time, x, y in columns 2, 3, 4: the seeds'
 * table_norm.csv, table_noheader.csv), imported like a recording. */
static fv_status run_table(fv_fuzz_ctx *c, const char *path, fv_error *err)
{
    char trace[4200];
    snprintf(trace, sizeof trace, "%s/trace.csv", c->work);
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    o.format = FV_GAZE_FORMAT_TABLE;
    o.table.time = "2";
    o.table.x = "3";
    o.table.y = "4";
    fv_status st = fv_gaze_import(path, trace, &o, NULL, err);
    if (st != FV_OK) return st;
    fv_error e2;
    if (run_gaze(c, trace, &e2) != FV_OK && !c->note[0]) snprintf(c->note, sizeof c->note, "imported, then the trace was refused: %s", e2.msg);
    remove(trace);
    return c->note[0] ? FV_ERR_INTERNAL : FV_OK;
}

static const fv_fuzz_kind k_kinds[] = {
    {"scene", ".json", run_scene, {"tests/data", "scenes", "tests/fuzz/seeds"}, NULL, false},
    {"obj", ".obj", run_scene, {"tests/data", "tests/fuzz/seeds", NULL}, NULL, false},
    {"ply", ".ply", run_scene, {"tests/data", "tests/fuzz/seeds", NULL}, NULL, false},
    {"gltf", ".gltf", run_scene, {"tests/data", "tests/fuzz/seeds", NULL}, NULL, false},
    {"glb", ".glb", run_scene, {"tests/data/textured", NULL, NULL}, NULL, false}, /* embedded textures */
    {"off", ".off", run_scene, {"tests/fuzz/seeds", NULL, NULL}, NULL, false},
    {"gaze", ".csv", run_gaze, {"tests/fuzz/seeds/gaze", "scenes", NULL}, NULL, false},
    {"camera", ".csv", run_camera, {"tests/fuzz/seeds/camera", "tests/data", NULL}, NULL, false},
    {"bench", ".json", run_bench, {"bench", "tests/fuzz/seeds/bench", NULL}, NULL, false},
    {"scenario", ".json", run_scenario, {"bench", "tests/fuzz/seeds/bench", NULL}, NULL, false},
    {"png", ".png", run_image, {NULL, NULL, NULL}, NULL, true},
    {"pfm", ".pfm", run_image, {NULL, NULL, NULL}, NULL, true},
    {"exr", ".exr", run_image, {NULL, NULL, NULL}, NULL, true},
    {"eyelink", ".asc", run_import, {"tests/data", NULL, NULL}, NULL, false},
    {"pupil", ".csv", run_import, {"tests/data", NULL, NULL}, "pupil", false},
    {"tobii", ".tsv", run_import, {"tests/data", NULL, NULL}, "tobii", false},
    {"table", ".csv", run_table, {"tests/data", NULL, NULL}, "table", false},
};

int fv_fuzz_kind_count(void) { return (int)(sizeof k_kinds / sizeof k_kinds[0]); }
const fv_fuzz_kind *fv_fuzz_kind_at(int i) { return i >= 0 && i < fv_fuzz_kind_count() ? &k_kinds[i] : NULL; }

const fv_fuzz_kind *fv_fuzz_kind_find(const char *name)
{
    for (int i = 0; i < fv_fuzz_kind_count(); i++)
        if (!strcmp(k_kinds[i].name, name)) return &k_kinds[i];
    return NULL;
}

bool fv_fuzz_ctx_init(fv_fuzz_ctx *c, const char *src)
{
    memset(c, 0, sizeof *c);
    /* In memory where there is a tmpfs: an input written per execution costs no disk. Under
     * FOVEA_FUZZ_TMPDIR when set (tests/libfuzzer/run.sh: a folder it removes however the target
     * ends, as libFuzzer stopped by SIGINT runs no exit handler). */
    const char *base = getenv("FOVEA_FUZZ_TMPDIR");
    if (!base || !*base || strlen(base) > 30) base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    snprintf(c->work, sizeof c->work, "%s/fovea-fuzz-XXXXXX", base);
    if (!mkdtemp(c->work)) {
        perror("fovea fuzz: mkdtemp");
        return false;
    }
    /* The files the test scenes name, beside the inputs, so a scene input loads them. */
    char cmd[9000];
    snprintf(cmd, sizeof cmd,
             "cp %s/tests/data/*.ply %s/tests/data/*.obj %s/tests/data/*.mtl %s/tests/data/*.gltf %s/tests/data/*.csv %s/ && "
             "cp -r %s/scenes/meshes %s/scenes/*.csv %s/ && cp %s/tests/fuzz/seeds/gaze/mono.csv %s/gaze.csv",
             src, src, src, src, src, c->work, src, src, c->work, src, c->work);
    if (system(cmd) != 0) fprintf(stderr, "fovea fuzz: warning: could not copy the test meshes into %s\n", c->work);
    return true;
}

void fv_fuzz_ctx_free(fv_fuzz_ctx *c, bool remove_work)
{
    fv_scene_destroy(c->cornell);
    fv_view_destroy(c->cornell_view);
    c->cornell = NULL;
    c->cornell_view = NULL;
    if (remove_work && c->work[0]) {
        char cmd[4200];
        snprintf(cmd, sizeof cmd, "rm -rf %s", c->work);
        if (system(cmd) != 0) fprintf(stderr, "fovea fuzz: warning: could not remove %s\n", c->work);
    }
}

void fv_fuzz_ctx_begin(fv_fuzz_ctx *c)
{
    c->bad_warning = false;
    c->note[0] = '\0';
}

int fv_fuzz_list_dir(const char *dir, char names[][FV_FUZZ_NAME_MAX], int max)
{
    DIR *dp = opendir(dir);
    int n = 0;
    if (!dp) return 0;
    struct dirent *e;
    while ((e = readdir(dp)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && n < max) snprintf(names[n++], FV_FUZZ_NAME_MAX, "%s", e->d_name);
    closedir(dp);
    return n;
}

static bool listed(const char *name, char (*names)[FV_FUZZ_NAME_MAX], int n)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(name, names[i])) return true;
    return false;
}

void fv_fuzz_clean_work(const fv_fuzz_ctx *c, char (*before)[FV_FUZZ_NAME_MAX], int nbefore)
{
    char now[64][FV_FUZZ_NAME_MAX];
    int n = fv_fuzz_list_dir(c->work, now, 64);
    for (int i = 0; i < n; i++) {
        if (listed(now[i], before, nbefore)) continue;
        char p[4400];
        snprintf(p, sizeof p, "%s/%.255s", c->work, now[i]);
        remove(p);
    }
}

const char *fv_fuzz_judge(const fv_fuzz_ctx *c, const char *input, fv_status st, const fv_error *err, char (*before)[FV_FUZZ_NAME_MAX],
                          int nbefore, char *why, size_t n)
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
    /* A child process the library started (the mesh import's sandbox) and did not wait for stays
     * a zombie: reaping one here means the library left it behind. */
    int status;
    pid_t z = waitpid(-1, &status, WNOHANG);
    if (z > 0) {
        snprintf(why, n, "left a child process behind (pid %d, ended unreaped)", (int)z);
        return why;
    }
    const char *base = strrchr(input, '/');
    base = base ? base + 1 : input;
    char now[64][FV_FUZZ_NAME_MAX];
    int k = fv_fuzz_list_dir(c->work, now, 64);
    for (int i = 0; i < k; i++)
        if (strcmp(now[i], base) && !listed(now[i], before, nbefore)) {
            snprintf(why, n, "left a file behind: %s", now[i]);
            return why;
        }
    return NULL;
}

void fv_fuzz_write_image_seeds(const char *dir)
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

void fv_fuzz_png_fix_crcs(unsigned char *p, size_t n)
{
    size_t at = 8;
    while (at + 12 <= n) {
        uint32_t len = (uint32_t)p[at] << 24 | (uint32_t)p[at + 1] << 16 | (uint32_t)p[at + 2] << 8 | p[at + 3];
        if (len > n - at - 12) break;
        uint32_t c = crc32_of(p + at + 4, len + 4);
        unsigned char *q = p + at + 8 + len;
        q[0] = (unsigned char)(c >> 24), q[1] = (unsigned char)(c >> 16), q[2] = (unsigned char)(c >> 8), q[3] = (unsigned char)c;
        at += 12 + len;
    }
}
