/* fovea — the benchmark runner: every method of a scenario renders the same frames (same scene
 * times, cameras, gaze and seeds) in one process, so the ratios between them are fair on a shared,
 * noisy machine. Timing covers the technique's render call only, repeated with a fresh technique
 * state each repeat (temporal methods replay their whole sequence) and summarised by the median;
 * the methods' repeats are interleaved (round r runs every method once) and the speed-up is the
 * median of the per-round ratios.
 * Errors are measured on the last repeat against a reference rendered once and cached on disk
 * under a hash of everything that determines it.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "bench/bench_impl.h"
#include "core/alloc.h"
#include "core/fileio.h"
#include "core/order_stats.h"
#include "core/params_read.h"
#include "fovea/device.h"
#include "core/rng.h"
#include "drive/frame_meta.h"
#include "fovea/bench.h"
#include "fovea/drive.h"
#include "fovea/film.h"
#include "fovea/metrics.h"
#include "fovea/provenance.h"
#include "fovea/scene.h"
#include "fovea/technique.h"
#include "fovea/view.h"
#include "scene/edit.h"

typedef struct frame_setup {
    double time;
    fv_camera cam;
    fv_gaze gaze;
    uint8_t *labels;
    float *ref[1 + FV_BENCH_MAX_EXTRA]; /* the reference, then the extra ones */
} frame_setup;

static void say(const fv_bench_options *opt, const char *fmt, ...)
{
    if (!opt->status) return;
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    opt->status(opt->status_user, line);
}

#define FNV_BASIS 1469598103934665603ULL

/* FNV-1a, 64 bits, continuing from h (FNV_BASIS to start): a stable name for a reference frame
 * in the cache. */
static uint64_t fnv1a(uint64_t h, const char *s)
{
    for (; *s; s++) {
        h ^= (unsigned char)*s;
        h *= 1099511628211ULL;
    }
    return h;
}

/* The scenario's "animate" entries as one hash, so any number of keys fits in the reference
 * key (the text of every key would not). */
static uint64_t animate_hash(const fv_scenario *sc)
{
    uint64_t h = FNV_BASIS;
    for (int i = 0; i < sc->nanimate; i++) {
        const fv_bench_animate *a = &sc->animate[i];
        char t[512];
        snprintf(t, sizeof t, "|%d:%s:%d", a->light, a->light >= 0 ? "" : a->object, a->nkeys);
        h = fnv1a(h, t);
        for (int k = 0; k < a->nkeys; k++) {
            const fv_anim_key *q = &a->keys[k];
            snprintf(t, sizeof t, "|%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", q->time, q->translate.x, q->translate.y,
                     q->translate.z, q->rotate.x, q->rotate.y, q->rotate.z, q->rotate.w, q->scale.x, q->scale.y, q->scale.z);
            h = fnv1a(h, t);
        }
    }
    return h;
}

/* Everything a reference frame depends on, as text: its hash names the cache file. A scene file's
 * size and modification time stand in for its contents. The gaze is not part of it: a reference
 * is a non-foveated rendering, shared by every gaze path of a scene. */
static void reference_key(const fv_scenario *sc, const fv_bench_method *m, const frame_setup *f, int index, char *buf, size_t n)
{
    size_t len = 0;
#define KEY(...)                                                                      \
    do {                                                                              \
        int w_ = snprintf(buf + len, n - len, __VA_ARGS__);                           \
        if (w_ > 0) len = (size_t)w_ < n - len ? len + (size_t)w_ : n - 1;            \
    } while (0)
    KEY("fovea %s|scene=%s", FOVEA_VERSION_STRING, sc->scene);
    struct stat sb;
    if (stat(sc->scene, &sb) == 0) KEY("|bytes=%lld|mtime=%lld", (long long)sb.st_size, (long long)sb.st_mtime);
    /* Only when set, so the references of scenarios without them keep their names. */
    if (sc->diffuse) KEY("|diffuse");
    if (sc->nanimate) KEY("|animate=%016llx", (unsigned long long)animate_hash(sc));
    KEY("|%dx%d|frame=%d|t=%.9g|seed=%llu|stream=reference|method=%s", sc->width, sc->height, index, f->time, sc->seed, m->method);
    for (int i = 0; i < fv_params_count(m->params); i++) KEY("|%s=%s", fv_params_key(m->params, i), fv_params_value(m->params, i));
    const fv_camera *c = &f->cam;
    KEY("|cam=%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", c->pos.x, c->pos.y, c->pos.z, c->look.x, c->look.y, c->look.z,
        c->up.x, c->up.y, c->up.z, c->fov_y);
#undef KEY
}

/* Progress through the step the last status line began (fv_bench_options.progress): `done` of
 * `total` frames; `within` also reports during a frame, through the driver's progress callback. */
typedef struct step_progress {
    const fv_bench_options *opt;
    int done, total;
    bool within;
} step_progress;

static void step_report(const step_progress *p, double part)
{
    if (p && p->opt->progress) p->opt->progress(p->opt->status_user, p->done, p->total, part);
}

/* Renders frames [first, nframes) of one method with a fresh technique; calls back per frame.
 * The frames come from the sequence driver, as `fovea render` makes them. */
typedef struct render_job {
    const fv_scenario *sc;
    fv_scene *scene;
    fv_driver *driver;
    const fv_bench_method *m;
    const fv_log *log;
    const fv_bench_split *split; /* NULL: one process */
    bool left_only;              /* a stereo scenario's reference: the measured left eye alone */
    step_progress *step;         /* NULL: the frames report no progress */
} render_job;

typedef fv_status (*frame_fn)(void *user, int index, fv_film *film, double ms, const fv_stats *stats, fv_error *err);

static bool keep_going(void *user, double fraction)
{
    (void)fraction;
    const fv_bench_split *sp = user;
    return !sp->stopped(sp->user);
}

/* The driver's callback of a frame that reports progress within it (a reference, the probe): the
 * step's progress, and when split, whether to go on. */
static bool frame_progress(void *user, double fraction)
{
    const render_job *j = user;
    step_report(j->step, fraction);
    return !(j->split && j->split->stopped) || keep_going((void *)j->split, fraction);
}

/* Frame i submitted into films (cleared first) with its stats (cleared); *ms: the submit's time. */
static fv_status submit_into(const render_job *j, fv_technique *t, int i, int first, fv_film *const *films, fv_stats *stats, double *ms,
                             fv_progress_fn fn, void *fn_user, fv_error *err)
{
    fv_stats_clear(stats);
    fv_film_clear(films[0]);
    if (films[1]) fv_film_clear(films[1]);
    const double t0 = fv_time_ms();
    const fv_status st = fv_driver_submit(j->driver, t, i, i > first, films, stats, fn, fn_user, err);
    *ms = fv_time_ms() - t0;
    return st;
}

/* The frames are pipelined (docs/gpu.md, "Frames in flight"): frame i+1 is submitted into the
 * other set of films before frame i is collected and handed to on_frame, so that a device runs
 * i+1 while the host measures i (except in a step whose progress is reported within its frames). A frame's time is what its submit and its collect took. The
 * calls on_frame sees, and its errors, are those of rendering the frames one by one. */
static fv_status render_sequence(const render_job *j, int first, int nframes, frame_fn on_frame, void *user, fv_error *err)
{
    fv_technique *t = NULL;
    /* A stereo scenario renders both eyes per frame of a method (both timed); the left eye is
     * the one measured and shown, so its reference renders the left eye alone. */
    fv_film *films[2][2] = {{NULL, NULL}, {NULL, NULL}};
    fv_status st = fv_technique_create(j->m->method, j->scene, j->m->params, j->log, &t, err);
    if (st != FV_OK) fv_error_prefix(err, "%s: ", j->m->label);
    const int eyes = j->left_only ? 1 : fv_driver_eye_count(j->driver);
    for (int k = 0; k < (nframes - first > 1 ? 2 : 1); k++)
        for (int e = 0; e < eyes && st == FV_OK; e++) st = fv_film_create(j->sc->width, j->sc->height, 0, &films[k][e], err);
    /* split over processes: a frame stops early once another rank has failed; a measured
     * method's frame reports no progress within it (only between frames, below, outside the
     * timed calls) */
    const bool poll = j->split && j->split->stopped;
    const bool within = j->step && j->step->within && j->step->opt->progress;
    fv_progress_fn fn = within ? frame_progress : poll ? keep_going : NULL;
    void *fn_user = within ? (void *)j : poll ? (void *)j->split : NULL;
    fv_stats stats[2];
    double ms[2] = {0.0, 0.0};
    int k = 0;
    if (st == FV_OK && first < nframes) {
        st = submit_into(j, t, first, first, films[0], &stats[0], &ms[0], fn, fn_user, err);
        if (st != FV_OK) fv_error_prefix(err, "%s, frame %d: ", j->m->label, first);
    }
    /* A step that reports progress within its frames (a reference, the probe: not timed) counts
     * them as they are collected, so it submits the next one only then. */
    const bool ahead = !within;
    for (int i = first; i < nframes && st == FV_OK; i++, k ^= 1) {
        const bool more = i + 1 < nframes;
        fv_status sn = FV_OK;
        fv_error errn;
        if (more && ahead) sn = submit_into(j, t, i + 1, first, films[k ^ 1], &stats[k ^ 1], &ms[k ^ 1], fn, fn_user, &errn);
        const double t0 = fv_time_ms();
        st = fv_driver_collect(j->driver, t, err);
        ms[k] += fv_time_ms() - t0;
        if (st != FV_OK) {
            fv_error_prefix(err, "%s, frame %d: ", j->m->label, i);
            break;
        }
        st = on_frame(user, i, films[k][0], ms[k], &stats[k], err);
        if (st == FV_OK && j->step) {
            j->step->done++;
            step_report(j->step, 0.0);
        }
        if (st == FV_OK && more && !ahead) sn = submit_into(j, t, i + 1, first, films[k ^ 1], &stats[k ^ 1], &ms[k ^ 1], fn, fn_user, &errn);
        if (st == FV_OK && sn != FV_OK) {
            *err = errn;
            fv_error_prefix(err, "%s, frame %d: ", j->m->label, i + 1);
            st = sn;
        }
    }
    /* a frame still in flight (the loop stopped early) is collected and dropped */
    while (t && fv_technique_in_flight(t) > 0) {
        fv_error dropped;
        (void)fv_driver_collect(j->driver, t, &dropped);
    }
    for (int q = 0; q < 2; q++)
        for (int e = 0; e < 2; e++) fv_film_destroy(films[q][e]);
    fv_technique_destroy(t);
    return st;
}

/* ---- the reference ---- */

/* The job's status when the run is split over processes (fv_bench_split), else this one's. A
 * rank that failed says so first, so that the others stop rendering at their next frame. */
static fv_status agree(const fv_bench_split *sp, fv_status s, fv_error *err)
{
    if (!sp) return s;
    if (s != FV_OK && sp->failed) sp->failed(sp->user);
    return sp->agree(sp->user, s, err);
}


typedef struct ref_ctx {
    frame_setup *frames;
    const char *const *paths;
    int slot;
    double ms;
} ref_ctx;

static fv_status on_reference_frame(void *user, int i, fv_film *film, double ms, const fv_stats *stats, fv_error *err)
{
    (void)stats;
    ref_ctx *c = user;
    c->ms += ms;
    size_t n = (size_t)fv_film_width(film) * fv_film_height(film) * 3;
    memcpy(c->frames[i].ref[c->slot], fv_film_color(film), n * sizeof(float));
    if (!c->paths[i]) return FV_OK;
    return fv_image_write(c->paths[i], c->frames[i].ref[c->slot], fv_film_width(film), fv_film_height(film), 1.0f, err);
}

/* Every rank agrees, then rank 0's n ints go to every other rank (a split run; nothing in one
 * process): what rank 0 found in its cache, so that every rank knows what is left to render. */
static fv_status share_plan(const fv_bench_split *sp, fv_status st, int *v, int n, fv_error *err)
{
    if (!sp) return st;
    if ((st = agree(sp, st, err)) != FV_OK) return st;
    for (int to = 1; to < sp->size && st == FV_OK; to++)
        if (sp->rank == 0 || sp->rank == to) st = sp->move(sp->user, 0, to, v, (size_t)n * sizeof *v, err);
    return agree(sp, st, err);
}

/* A still across every rank through the split's `still` (fv_bench_split): *split says whether it
 * was; on rank 0 rgb then holds the image. A failure is the job's (agreed). */
static fv_status split_still(const render_job *j, int index, float *rgb, bool *split, fv_error *err)
{
    *split = false;
    const fv_bench_split *sp = j->split;
    /* a split still is one film: a stereo pair renders on one rank */
    if (!sp || !sp->still || fv_driver_eye_count(j->driver) > 1) return FV_OK;
    fv_film *film = NULL;
    fv_status st = fv_film_create(j->sc->width, j->sc->height, 0, &film, err);
    /* a film that cannot be made here fails the job before any rank splits */
    if (st != FV_OK) return agree(sp, st, err);
    const fv_bench_still still = {j->m->method, j->m->params, j->scene, j->driver, index, j->log};
    st = sp->still(sp->user, &still, film, split, err);
    if (*split && st == FV_OK && sp->rank == 0)
        memcpy(rgb, fv_film_color(film), (size_t)j->sc->width * j->sc->height * 3 * sizeof(float));
    fv_film_destroy(film);
    return st;
}

/* The missing frames of a reference without state between frames, split over the ranks: one frame
 * across every rank (sample blocks, split_still) when the split can; else the q-th missing frame
 * rendered by rank q % size, on its own (the conformance suite's history check: such a method's
 * frame is the same image alone or after its predecessors), and sent to rank 0, which writes it
 * to the cache. Either way the cache holds the one-process frames bit for bit. */
static fv_status split_references(const render_job *j, ref_ctx *c, const int *missing, int first, int n, fv_error *err)
{
    const fv_bench_split *sp = j->split;
    const size_t bytes = (size_t)j->sc->width * j->sc->height * 3 * sizeof(float);
    int k = 0, one = -1;
    for (int i = first; i < n; i++)
        if (missing[i]) k++, one = i;
    fv_status st = FV_OK;
    if (k == 1) {
        bool split;
        if ((st = split_still(j, one, c->frames[one].ref[c->slot], &split, err)) != FV_OK) return st;
        if (split) {
            if (sp->rank == 0 && c->paths[one])
                st = fv_image_write(c->paths[one], c->frames[one].ref[c->slot], j->sc->width, j->sc->height, 1.0f, err);
            return agree(sp, st, err);
        }
    }
    for (int i = first, q = 0; i < n && st == FV_OK; i++)
        if (missing[i] && q++ % sp->size == sp->rank) st = render_sequence(j, i, i + 1, on_reference_frame, c, err);
    if ((st = agree(sp, st, err)) != FV_OK) return st;
    /* a cache file that cannot be written fails the job once every frame has arrived: a rank still
     * sending must not wait for a receive that never comes */
    fv_status written = FV_OK;
    for (int i = first, q = 0; i < n && st == FV_OK; i++) {
        if (!missing[i]) continue;
        const int from = q++ % sp->size;
        if (from == 0 || (sp->rank != 0 && sp->rank != from)) continue;
        st = sp->move(sp->user, from, 0, c->frames[i].ref[c->slot], bytes, err);
        if (st == FV_OK && sp->rank == 0 && written == FV_OK && c->paths[i])
            written = fv_image_write(c->paths[i], c->frames[i].ref[c->slot], j->sc->width, j->sc->height, 1.0f, err);
    }
    return agree(sp, st != FV_OK ? st : written, err);
}

/* Reference `slot` (0: the scenario's reference, k: extra reference k - 1) for every frame, from
 * the cache or rendered. Split over processes, every rank calls it: rank 0 reads the cache and
 * says what is missing, and the missing frames are split (split_references) unless the method
 * keeps state between frames, whose sequence rank 0 renders alone (a frame needs its history).
 * Returns the job's status (agreed: after a failure no rank agrees again). */
static fv_status load_references(const fv_bench_run_info *info, fv_scene *scene, frame_setup *frames, const char *cache_dir, int slot,
                                 int *cached, double *ms, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    const fv_bench_split *sp = info->opt->split;
    const int rank = sp ? sp->rank : 0;
    const fv_bench_method *m = slot == 0 ? &sc->reference : &sc->extra[slot - 1];
    int n = sc->frames, first = sc->measure_from;
    char **paths = calloc((size_t)n, sizeof *paths);
    int *missing = calloc((size_t)n, sizeof *missing);
    fv_status st = paths && missing ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    int nmissing = 0;
    for (int i = first; i < n && st == FV_OK && rank == 0; i++) {
        char key[2048];
        reference_key(sc, m, &frames[i], i, key, sizeof key);
        char path[4096 + 64];
        snprintf(path, sizeof path, "%s/ref-%016llx.pfm", cache_dir, (unsigned long long)fnv1a(FNV_BASIS, key));
        fv_image img;
        fv_error e2;
        if (fv_file_exists(path) && fv_image_read(path, &img, &e2) == FV_OK) {
            if (img.width == sc->width && img.height == sc->height) {
                memcpy(frames[i].ref[slot], img.rgb, (size_t)sc->width * sc->height * 3 * sizeof(float));
                (*cached)++;
                fv_image_free(&img);
                continue;
            }
            fv_image_free(&img);
        }
        if (!(paths[i] = strdup(path))) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        missing[i] = 1;
    }
    st = share_plan(sp, st, missing, n, err);
    int mine = 0; /* the missing frames this rank renders when they are dealt round-robin */
    for (int i = first; i < n && st == FV_OK; i++) {
        if (missing[i] && (!sp || nmissing % sp->size == sp->rank)) mine++;
        nmissing += missing[i];
    }
    if (st == FV_OK && nmissing > 0) {
        const bool alone = !sp || fv_technique_warmup_frames(fv_technique_index(m->method)) > 0;
        say(info->opt, "%s: rendering %d frame(s) with %s (%d cached)%s", m->label, alone ? n - first : nmissing, m->method, *cached,
            alone ? "" : ", split over the ranks");
        /* References are rendered on their own random stream (core/rng.h). */
        step_progress prog = {info->opt, 0, alone ? n - first : mine, true};
        render_job j = {sc, scene, info->ref_driver, m, info->opt->log, sp, true, &prog};
        ref_ctx c = {frames, (const char *const *)paths, slot, 0.0};
        step_report(&prog, 0.0);
        if (alone) {
            /* Render the whole measured sequence (a temporal reference needs its history); frames
             * already cached are simply not written again. Frames before measure_from are never
             * compared, so they need no reference. */
            if (rank == 0) st = render_sequence(&j, first, n, on_reference_frame, &c, err);
            *ms = c.ms / (n - first);
            if (st != FV_OK) fv_error_prefix(err, "%s: ", m->label);
            st = agree(sp, st, err);
        } else {
            /* the job's wall time per frame rendered */
            double t0 = fv_time_ms();
            if ((st = split_references(&j, &c, missing, first, n, err)) != FV_OK) fv_error_prefix(err, "%s: ", m->label);
            *ms = (fv_time_ms() - t0) / nmissing;
        }
    } else if (st == FV_OK) {
        say(info->opt, "%s: %d frame(s) from the cache", m->label, n - first);
    }
    for (int i = 0; paths && i < n; i++) free(paths[i]);
    free(paths);
    free(missing);
    return st;
}

/* The reference's own noise (ref_noise.c): a probe of its method with fewer samples on another
 * stream renders the last frame (cached like a reference), and its errors against the reference
 * give the estimate. */
typedef struct probe_ctx {
    float *rgb;
    const char *path;
} probe_ctx;

static fv_status on_probe_frame(void *user, int i, fv_film *film, double ms, const fv_stats *stats, fv_error *err)
{
    (void)i, (void)ms, (void)stats;
    probe_ctx *c = user;
    const int w = fv_film_width(film), h = fv_film_height(film);
    memcpy(c->rgb, fv_film_color(film), (size_t)w * h * 3 * sizeof(float));
    return fv_image_write(c->path, c->rgb, w, h, 1.0f, err);
}

/* Split over processes, every rank calls it: rank 0 reads the cache and says whether the probe is
 * in it; a missing probe is rendered across the ranks when the split's `still` splits it (as the
 * reference's own frame is), else by rank 0 alone. Returns the job's status (agreed). */
static fv_status probe_reference(fv_bench_run_info *info, fv_scene *scene, const fv_view *view, const fv_drive_opts *dopt, frame_setup *frames,
                                 const char *cache_dir, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    const fv_bench_split *sp = info->opt->split;
    const int rank = sp ? sp->rank : 0;
    fv_bench_ref_noise *rn = &info->ref_noise;
    if (!fv_bench_ref_noise_plan(sc, rn)) return FV_OK;
    const int last = sc->frames - 1;
    const size_t npix = (size_t)sc->width * sc->height;
    fv_bench_method probe = sc->reference;
    probe.params = NULL;
    fv_driver *driver = NULL;
    float *rgb = fv_alloc_array(npix, 3 * sizeof(float));
    char v[32], key[2048 + 32], path[4096 + 64];
    int need = 0; /* rank 0's: the probe is not in the cache */
    snprintf(v, sizeof v, "%d", rn->probe_spp);
    fv_status st = rgb ? fv_params_clone(sc->reference.params, &probe.params, err) : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (st == FV_OK) st = fv_params_set(probe.params, rn->spp_key, v, err);
    if (st == FV_OK) {
        reference_key(sc, &probe, &frames[last], last, key, sizeof key - 32);
        strcat(key, "|stream=probe");
        snprintf(path, sizeof path, "%s/probe-%016llx.pfm", cache_dir, (unsigned long long)fnv1a(FNV_BASIS, key));
        fv_image img;
        fv_error e2;
        need = rank == 0;
        if (rank == 0 && fv_file_exists(path) && fv_image_read(path, &img, &e2) == FV_OK) {
            bool fits = img.width == sc->width && img.height == sc->height;
            if (fits) memcpy(rgb, img.rgb, npix * 3 * sizeof(float));
            fv_image_free(&img);
            need = !fits;
        }
    }
    if ((st = share_plan(sp, st, &need, 1, err)) != FV_OK || !need) goto compare;
    say(info->opt, "reference noise: probing with %s=%d on its own stream", rn->spp_key, rn->probe_spp);
    fv_drive_opts o = *dopt;
    o.seed = fv_seed_reference_probe(sc->seed);
    st = fv_driver_create(scene, view, &o, &driver, err);
    step_progress prog = {info->opt, 0, 1, true};
    render_job j = {sc, scene, driver, &probe, info->opt->log, sp, true, &prog};
    bool split = false;
    /* every rank has its driver before any splits the still; a failure there or in the split is
     * already the job's */
    if (sp && ((st = agree(sp, st, err)) != FV_OK || (st = split_still(&j, last, rgb, &split, err)) != FV_OK)) goto compare;
    if (split && rank == 0) st = fv_image_write(path, rgb, sc->width, sc->height, 1.0f, err);
    probe_ctx c = {rgb, path};
    if (!split && rank == 0) {
        step_report(&prog, 0.0);
        st = render_sequence(&j, last, last + 1, on_probe_frame, &c, err);
    }
    if (st != FV_OK) fv_error_prefix(err, "the reference's noise probe: ");
    st = agree(sp, st, err);
compare:
    if (st == FV_OK && rank == 0) {
        fv_metric_opts mo;
        fv_metric_opts_default(&mo);
        mo.exposure = sc->exposure;
        fv_metric_report rep;
        if ((st = fv_metrics_compare(frames[last].ref[0], rgb, sc->width, sc->height, frames[last].labels, &mo, &rep, NULL, err)) == FV_OK)
            fv_bench_ref_noise_estimate(rn, &rep);
    }
    fv_driver_destroy(driver);
    fv_params_destroy(probe.params);
    free(rgb);
    return st;
}

/* ---- the methods ---- */

typedef struct method_ctx {
    const fv_bench_run_info *info;
    frame_setup *frames;
    fv_bench_result *res;
    bool measure;              /* last repeat: compute errors and keep images */
    double ms_sum;
    double *frame_ms;          /* this repeat's row of method_run.frame_ms */
    fv_stats stage_sum, counter_sum;
    fv_temporal *temporal;
    fv_metric_opts mopts;
    float *flip_map;
    float *last;               /* the last frame, for the images */
} method_ctx;

static void stats_accumulate(fv_stats *sum, const fv_stats *s)
{
    for (int k = 0; k < s->n_stages; k++) fv_stats_add_ms(sum, s->stage[k].name, s->stage[k].value);
    /* each stage's serial part (core/stage_time.h), for its serial share */
    for (int k = 0; k < s->n_serial; k++) fv_stats_add_serial_ms(sum, s->serial[k].name, s->serial[k].value);
    for (int k = 0; k < s->n_counters; k++) fv_stats_add_count(sum, s->counter[k].name, s->counter[k].value);
}

static fv_status on_method_frame(void *user, int i, fv_film *film, double ms, const fv_stats *stats, fv_error *err)
{
    method_ctx *c = user;
    const fv_scenario *sc = c->info->sc;
    c->ms_sum += ms;
    c->frame_ms[i] = ms;
    stats_accumulate(&c->stage_sum, stats);
    stats_accumulate(&c->counter_sum, stats);
    if (!c->measure || i < sc->measure_from) return FV_OK;
    const double nm = sc->frames - sc->measure_from; /* measured frames */
    const float *rgb = fv_film_color(film);
    fv_metric_report rep;
    fv_status st = fv_metrics_compare(c->frames[i].ref[0], rgb, sc->width, sc->height, c->frames[i].labels, &c->mopts, &rep,
                                      i == sc->frames - 1 ? c->flip_map : NULL, err);
    if (st != FV_OK) return st;
    for (int k = 0; k < sc->nextra; k++) {
        fv_metric_report ex;
        if ((st = fv_metrics_compare(c->frames[i].ref[1 + k], rgb, sc->width, sc->height, c->frames[i].labels, &c->mopts, &ex, NULL, err)) != FV_OK)
            return st;
        for (int r = 0; r < FV_REGION_COUNT; r++) {
            fv_metric_values *d = &c->res->error_vs[k].region[r];
            d->pixels = ex.region[r].pixels;
            d->mse += ex.region[r].mse / nm;
            d->e += ex.region[r].e / nm;
            d->ssim += ex.region[r].ssim / nm;
            d->flip += ex.region[r].flip / nm;
        }
    }
    for (int r = 0; r < FV_REGION_COUNT; r++) {
        fv_metric_values *d = &c->res->error.region[r];
        const fv_metric_values *v = &rep.region[r];
        d->pixels = v->pixels;
        d->mse += v->mse / nm;
        d->e += v->e / nm;
        d->ssim += v->ssim / nm;
        d->flip += v->flip / nm;
    }
    if (c->temporal && (st = fv_temporal_push(c->temporal, rgb, c->frames[i].labels, err)) != FV_OK) return st;
    if (i == sc->frames - 1) memcpy(c->last, rgb, (size_t)sc->width * sc->height * 3 * sizeof(float));
    return FV_OK;
}

static fv_status on_warmup_frame(void *user, int i, fv_film *film, double ms, const fv_stats *stats, fv_error *err)
{
    (void)user, (void)i, (void)film, (void)ms, (void)stats, (void)err;
    return FV_OK;
}

/* A square crop around the gaze point of side 2 r_t (at least 32 px), clamped to the image. */
static fv_status write_crop(const fv_scenario *sc, const float *rgb, fv_gaze g, const char *path, fv_error *err)
{
    int side = (int)ceil(2.0 * fv_eye_transition_radius_px(&sc->eye));
    if (side < 32) side = 32;
    if (side > sc->width) side = sc->width;
    if (side > sc->height) side = sc->height;
    int x0 = (int)lround(g.x * sc->width - 0.5 * side), y0 = (int)lround(g.y * sc->height - 0.5 * side);
    x0 = x0 < 0 ? 0 : x0 + side > sc->width ? sc->width - side : x0;
    y0 = y0 < 0 ? 0 : y0 + side > sc->height ? sc->height - side : y0;
    float *crop = fv_alloc_array((size_t)side * side, 3 * sizeof(float));
    if (!crop) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (int y = 0; y < side; y++)
        memcpy(crop + (size_t)y * side * 3, rgb + ((size_t)(y0 + y) * sc->width + x0) * 3, (size_t)side * 3 * sizeof(float));
    fv_status st = fv_image_write(path, crop, side, side, sc->exposure, err);
    free(crop);
    return st;
}

/* One method's measurement, split so that the runner can interleave the methods' repeats. */
typedef struct method_run {
    method_ctx c;
    render_job j;
    int reps;
    double *stage_per_rep;     /* per stage name (stage_names' order), per repeat */
    double *frame_ms;          /* every repeat's frame times, reps x frames (the row's pacing) */
    fv_stats stage_names;
} method_run;

static void method_free(method_run *mr)
{
    fv_temporal_destroy(mr->c.temporal);
    free(mr->stage_per_rep);
    free(mr->frame_ms);
    free(mr->c.flip_map);
    free(mr->c.last);
    memset(mr, 0, sizeof *mr);
}

/* Buffers and one untimed frame: thread start-up and cold caches would otherwise land in the first
 * repeat of whichever method runs first. */
static fv_status method_begin(const fv_bench_run_info *info, fv_scene *scene, frame_setup *frames, fv_bench_result *res,
                              method_run *mr, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    memset(mr, 0, sizeof *mr);
    mr->reps = info->opt->repeats > 0 ? info->opt->repeats : sc->repeats;
    size_t npix = (size_t)sc->width * sc->height;
    method_ctx *c = &mr->c;
    c->info = info;
    c->frames = frames;
    c->res = res;
    fv_metric_opts_default(&c->mopts);
    c->mopts.exposure = sc->exposure;
    res->ms = calloc((size_t)mr->reps, sizeof(double));
    res->speedup = 0.0;
    mr->stage_per_rep = calloc((size_t)mr->reps * FV_STATS_MAX, sizeof(double));
    mr->frame_ms = fv_calloc_array((size_t)mr->reps * sc->frames, sizeof(double));
    c->flip_map = fv_alloc_array(npix, sizeof(float));
    c->last = fv_alloc_array(npix, 3 * sizeof(float));
    if (!res->ms || !mr->stage_per_rep || !mr->frame_ms || !c->flip_map || !c->last) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_stats_clear(&mr->stage_names);
    mr->j = (render_job){sc, scene, info->driver, res->m, info->opt->log, info->opt->split, false, NULL};
    return render_sequence(&mr->j, 0, 1, on_warmup_frame, NULL, err);
}

/* Repeat r of the sequence, timed; the last one also measures the errors. */
static fv_status method_repeat(method_run *mr, int index, int total, int r, fv_error *err)
{
    method_ctx *c = &mr->c;
    const fv_scenario *sc = c->info->sc;
    fv_bench_result *res = c->res;
    const int reps = mr->reps;
    say(c->info->opt, "[%d/%d] %s: repeat %d/%d, %d frame(s)", index + 1, total, res->m->label, r + 1, reps, sc->frames);
    c->measure = r == reps - 1;
    c->ms_sum = 0.0;
    c->frame_ms = mr->frame_ms + (size_t)r * sc->frames;
    fv_stats_clear(&c->stage_sum);
    fv_stats_clear(&c->counter_sum);
    fv_status st = FV_OK;
    if (c->measure) {
        memset(&res->error, 0, sizeof res->error);
        memset(res->error_vs, 0, sizeof res->error_vs);
        if (sc->frames - sc->measure_from > 1 && (st = fv_temporal_create(sc->width, sc->height, &c->mopts, &c->temporal, err)) != FV_OK)
            return st;
    }
    /* frame k of n, between the frames: nothing within the timed render calls */
    step_progress prog = {c->info->opt, 0, sc->frames, false};
    mr->j.step = &prog;
    step_report(&prog, 0.0);
    st = render_sequence(&mr->j, 0, sc->frames, on_method_frame, c, err);
    mr->j.step = NULL;
    if (st != FV_OK) return st;
    res->ms[r] = c->ms_sum / sc->frames;
    for (int k = 0; k < c->stage_sum.n_stages; k++) {
        fv_stats_add_ms(&mr->stage_names, c->stage_sum.stage[k].name, 0.0);
        for (int q = 0; q < mr->stage_names.n_stages; q++)
            if (strcmp(mr->stage_names.stage[q].name, c->stage_sum.stage[k].name) == 0)
                mr->stage_per_rep[(size_t)q * reps + r] = c->stage_sum.stage[k].value / sc->frames;
    }
    return FV_OK;
}

/* Medians over the repeats, the errors' PSNR, and the images of the last frame. */
/* A row's figures from its repeats: medians, stage and counter means, PSNR, temporal errors. */
static void method_figures(method_run *mr)
{
    method_ctx *c = &mr->c;
    const fv_bench_run_info *info = c->info;
    const fv_scenario *sc = info->sc;
    fv_bench_result *res = c->res;
    const int reps = mr->reps;
    res->ms_median = fv_median(res->ms, reps);
    res->ms_min = res->ms_max = res->ms[0];
    for (int r = 1; r < reps; r++) {
        res->ms_min = fmin(res->ms_min, res->ms[r]);
        res->ms_max = fmax(res->ms_max, res->ms[r]);
    }
    /* Frame pacing: every timed frame of every repeat, warm-up frames (before measure_from)
     * included, since a headset shows them too; nearest-rank percentiles (core/order_stats.h).
     * The last use of frame_ms: sorting it in place is fine. */
    const int nf = reps * sc->frames;
    res->frame_p50 = fv_percentile(mr->frame_ms, nf, 50.0);
    res->frame_p99 = fv_percentile(mr->frame_ms, nf, 99.0);
    res->frame_max = mr->frame_ms[nf - 1];
    fv_stats_clear(&res->stages);
    fv_stats_clear(&res->stages_min);
    fv_stats_clear(&res->stages_max);
    for (int q = 0; q < mr->stage_names.n_stages; q++) {
        const double *v = mr->stage_per_rep + (size_t)q * reps;
        double lo = v[0], hi = v[0];
        for (int r = 1; r < reps; r++) lo = fmin(lo, v[r]), hi = fmax(hi, v[r]);
        fv_stats_add_ms(&res->stages, mr->stage_names.stage[q].name, fv_median(v, reps));
        fv_stats_add_ms(&res->stages_min, mr->stage_names.stage[q].name, lo);
        fv_stats_add_ms(&res->stages_max, mr->stage_names.stage[q].name, hi);
        /* The serial share of the measured (last) repeat's frames, as --stats-json gives it, kept as
         * that share of the median: the report divides it back out. */
        const char *name = mr->stage_names.stage[q].name;
        const double tot = fv_stats_get_ms(&c->stage_sum, name), ser = fv_stats_get_serial_ms(&c->stage_sum, name);
        if (ser >= 0.0 && tot > 0.0) fv_stats_add_serial_ms(&res->stages, name, fv_median(v, reps) * fmin(1.0, ser / tot));
    }
    fv_stats_clear(&res->counters);
    for (int k = 0; k < c->counter_sum.n_counters; k++)
        fv_stats_add_count(&res->counters, c->counter_sum.counter[k].name, c->counter_sum.counter[k].value / sc->frames);
    for (int k = -1; k < sc->nextra; k++)
        for (int r = 0; r < FV_REGION_COUNT; r++) {
            fv_metric_values *v = k < 0 ? &res->error.region[r] : &res->error_vs[k].region[r];
            v->psnr = v->mse > 0.0 ? 10.0 * log10(1.0 / v->mse) : v->mse == 0.0 ? INFINITY : NAN;
        }
    if (c->temporal) {
        res->has_temporal = true;
        for (int r = 0; r < FV_REGION_COUNT; r++)
            fv_temporal_result(c->temporal, (fv_region)r, &res->temporal_mse[r], &res->temporal_e[r]);
    }
    const size_t npix = (size_t)sc->width * sc->height;
    for (int k = 0; k < 3; k++) {
        double sum = 0.0;
        for (size_t q = 0; q < npix; q++) sum += c->last[3 * q + k];
        res->image_mean[k] = sum / (double)npix;
    }
    const char *label = res->m->label;
    snprintf(res->img, sizeof res->img, "%s/%s.png", sc->name, label);
    snprintf(res->heat, sizeof res->heat, "%s/%s-flip.png", sc->name, label);
    snprintf(res->crop, sizeof res->crop, "%s/%s-fovea.png", sc->name, label);
}

/* A row's images of the last frame (its colours `last` and FLIP map `flip`): the frame, its FLIP
 * heat map with the region rings and the colour bar of the scale every method shares, the fovea.
 * Written by rank 0 only, with the rows other ranks timed received from them. */
static fv_status write_row_images(const fv_bench_run_info *info, const frame_setup *frames, const fv_bench_result *res, const float *last,
                                  const float *flip, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    char path[4096 + 128];
    const frame_setup *lf = &frames[sc->frames - 1];
    snprintf(path, sizeof path, "%s/%s", info->out_dir, res->img);
    /* The frame says how it was made, as `fovea render`'s images do (drive/frame_meta.h). */
    fv_frame_views v;
    fv_driver_views(info->driver, sc->frames - 1, &v);
    fv_frame_meta_run run = {res->m->method, sc->scene, res->m->params, sc->width, sc->height, info->threads, sc->seed, sc->exposure, 0};
    fv_params *meta = NULL;
    fv_status st = fv_frame_meta(&run, sc->frames - 1, &v, 0, res->ms_median, &meta, err);
    if (st == FV_OK) st = fv_image_write_meta(path, last, sc->width, sc->height, sc->exposure, meta, err);
    fv_params_destroy(meta);
    snprintf(path, sizeof path, "%s/%s", info->out_dir, res->heat);
    const fv_heatmap_opts ho = {FV_BENCH_HEAT_MAX, &sc->eye, lf->gaze, FV_BENCH_HEAT_LABEL};
    if (st == FV_OK) st = fv_heatmap_write(path, flip, sc->width, sc->height, &ho, err);
    snprintf(path, sizeof path, "%s/%s", info->out_dir, res->crop);
    if (st == FV_OK) st = write_crop(sc, last, lf->gaze, path, err);
    return st;
}

static fv_status method_end(method_run *mr, fv_error *err)
{
    method_figures(mr);
    return write_row_images(mr->c.info, mr->c.frames, mr->c.res, mr->c.last, mr->c.flip_map, err);
}

/* One method on its own, every repeat in a row (the match searches). */
static fv_status run_method(const fv_bench_run_info *info, fv_scene *scene, frame_setup *frames, int index, int total,
                            fv_bench_result *res, fv_error *err)
{
    method_run mr;
    fv_status st = method_begin(info, scene, frames, res, &mr, err);
    for (int r = 0; r < mr.reps && st == FV_OK; r++) st = method_repeat(&mr, index, total, r, err);
    if (st == FV_OK) st = method_end(&mr, err);
    method_free(&mr);
    return st;
}

/* Rank `rank` of a split run (fv_bench_split) times the rows i with i % size == rank. */
static bool owns(const fv_bench_split *sp, int i) { return !sp || i % sp->size == sp->rank; }

/* A row another rank timed, to rank 0: its figures (the struct, its pointers re-made there), its
 * repeats' times, its last frame and FLIP map (which rank 0 writes as images). */
static fv_status gather_row(const fv_bench_run_info *info, const frame_setup *frames, int i, fv_bench_result *res, method_run *mr,
                            int reps, fv_status *written, fv_error *err)
{
    const fv_bench_split *sp = info->opt->split;
    const int from = i % sp->size;
    const size_t npix = (size_t)info->sc->width * info->sc->height;
    if (sp->rank != 0 && sp->rank != from) return FV_OK;
    fv_bench_result r = *res;
    r.m = NULL;
    r.ms = NULL;
    float *last = sp->rank == 0 ? fv_alloc_array(npix, 3 * sizeof(float)) : mr->c.last;
    float *flip = sp->rank == 0 ? fv_alloc_array(npix, sizeof(float)) : mr->c.flip_map;
    double *ms = sp->rank == 0 ? fv_calloc_array((size_t)reps, sizeof(double)) : res->ms;
    fv_status st = last && flip && ms ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (st == FV_OK) st = sp->move(sp->user, from, 0, &r, sizeof r, err);
    if (st == FV_OK) st = sp->move(sp->user, from, 0, ms, (size_t)reps * sizeof(double), err);
    if (st == FV_OK) st = sp->move(sp->user, from, 0, last, npix * 3 * sizeof(float), err);
    if (st == FV_OK) st = sp->move(sp->user, from, 0, flip, npix * sizeof(float), err);
    if (sp->rank == 0) {
        if (st == FV_OK) {
            r.m = res->m;
            r.ms = ms;
            ms = NULL;
            free(res->ms);
            *res = r;
            /* a file that cannot be written fails the run, after every row has arrived: the
             * ranks still sending must not wait for a receive that never comes */
            if (*written == FV_OK) *written = write_row_images(info, frames, res, last, flip, err);
        }
        free(last);
        free(flip);
        free(ms);
    }
    return st;
}

/* The scenario's methods, their repeats interleaved: round r renders every method's repeat r, so a
 * machine that slows down or speeds up (other processes, a shared host) does so for all of them
 * alike, and the speed-up is the median over rounds of the baseline's time over the method's, each
 * ratio taken within one round. */
static fv_status run_methods(const fv_bench_run_info *info, fv_scene *scene, frame_setup *frames, fv_bench_result *res,
                             int total, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    const fv_bench_split *sp = info->opt->split;
    const int reps = info->opt->repeats > 0 ? info->opt->repeats : sc->repeats;
    method_run *mr = fv_calloc_array((size_t)sc->nmethods, sizeof *mr);
    fv_status st = mr ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (int i = 0; i < sc->nmethods; i++) {
        res[i].m = &sc->methods[i];
        res[i].rank = sp ? i % sp->size : 0;
    }
    /* Each rank its rows, their repeats interleaved as in one process; rank 0 writes the images of
     * its own rows at once and those of the others' once they arrive. */
    for (int i = 0; i < sc->nmethods && st == FV_OK; i++)
        if (owns(sp, i)) st = method_begin(info, scene, frames, &res[i], &mr[i], err);
    for (int r = 0; r < reps && st == FV_OK; r++)
        for (int i = 0; i < sc->nmethods && st == FV_OK; i++)
            if (owns(sp, i)) st = method_repeat(&mr[i], i, total, r, err);
    for (int i = 0; i < sc->nmethods && st == FV_OK; i++) {
        if (!owns(sp, i)) continue;
        if (sp && sp->rank != 0) method_figures(&mr[i]);
        else st = method_end(&mr[i], err);
    }
    /* Every rank agrees once its rows are done, and again once rank 0 has them all; after a
     * failed agreement no rank calls another. */
    if (sp && (st = agree(sp, st, err)) == FV_OK) {
        fv_status written = FV_OK;
        for (int i = 0; i < sc->nmethods && st == FV_OK; i++)
            if (i % sp->size != 0) st = gather_row(info, frames, i, &res[i], &mr[i], reps, &written, err);
        st = agree(sp, st != FV_OK ? st : written, err);
    }
    if (st == FV_OK && (!sp || sp->rank == 0)) {
        int b = -1;
        for (int i = 0; i < sc->nmethods; i++)
            if (strcmp(sc->methods[i].label, sc->baseline) == 0) b = i;
        double *ratio = fv_calloc_array((size_t)reps, sizeof(double));
        if (!ratio) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        for (int i = 0; i < sc->nmethods && ratio && b >= 0; i++) {
            for (int r = 0; r < reps; r++) ratio[r] = res[i].ms[r] > 0.0 ? res[b].ms[r] / res[i].ms[r] : 0.0;
            res[i].speedup = fv_median(ratio, reps);
        }
        free(ratio);
    }
    for (int i = 0; mr && i < sc->nmethods; i++) method_free(&mr[i]);
    free(mr);
    return st;
}

/* ---- "match": the smallest parameter value that reaches a target's error ---- */

static double metric_of(const fv_metric_values *v, const char *metric)
{
    return !strcmp(metric, "flip") ? v->flip : !strcmp(metric, "e") ? v->e : v->mse;
}

static fv_status run_match(const fv_bench_run_info *info, fv_scene *scene, frame_setup *frames, const fv_bench_result *res, int k,
                           fv_bench_method *m, fv_bench_result *out, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    const fv_bench_match *mt = &sc->matches[k];
    double target = NAN;
    for (int i = 0; i < sc->nmethods; i++)
        if (!strcmp(sc->methods[i].label, mt->target)) target = metric_of(&res[i].error.region[mt->region], mt->metric);
    fv_status st = FV_OK;
    for (int v = 0; v < mt->nvalues && st == FV_OK; v++) {
        char text[64];
        snprintf(text, sizeof text, "%.17g", mt->values[v]);
        fv_params_destroy(m->params);
        m->params = NULL;
        *m = mt->base;
        m->params = NULL;
        m->match = k + 1;
        if ((st = fv_params_clone(mt->base.params, &m->params, err)) != FV_OK || (st = fv_params_set(m->params, mt->param, text, err)) != FV_OK)
            break;
        free(out->ms);
        memset(out, 0, sizeof *out);
        out->m = m;
        say(info->opt, "match %s: %s=%s against %s's %s %s %.4g", m->label, mt->param, text, mt->target, fv_region_name(mt->region), mt->metric,
            target);
        if ((st = run_method(info, scene, frames, sc->nmethods + k, sc->nmethods + sc->nmatches, out, err)) != FV_OK) break;
        if (metric_of(&out->error.region[mt->region], mt->metric) <= target) {
            m->match_reached = true;
            break;
        }
    }
    return st;
}

/* ---- the scene ---- */

/* Opens the scenario's scene uncommitted, applies "diffuse" and "animate", then commits it. An
 * error names the scenario file and the field. */
static fv_status open_scene(const fv_scenario *sc, const char *path, const fv_log *log, fv_scene **out, fv_view **view, fv_error *err)
{
    fv_scene *scene = NULL;
    fv_status st = fv_scene_open(sc->scene, log, &scene, view, err);
    if (st != FV_OK) {
        /* A scene file's own errors name it; a missing one is named from the scenario. */
        if (!strstr(err->msg, path)) fv_error_prefix(err, "%s: scene: ", path);
        return st;
    }
    if (sc->diffuse && (st = fv_scene_make_diffuse(scene, err)) != FV_OK) fv_error_prefix(err, "%s: diffuse: ", path);
    for (int i = 0; i < sc->nanimate && st == FV_OK; i++) {
        const fv_bench_animate *a = &sc->animate[i];
        if (a->light >= 0) {
            /* Before commit the scene counts only its point and spot lights: the lights that can move. */
            int n = fv_scene_light_count(scene);
            if (a->light >= n)
                st = fv_error_set(err, FV_ERR_INVALID,
                                  "%s: animate[%d].light: scene %s has no light %d (it has %d point/spot light%s, numbered from 0; area lights cannot move)",
                                  path, i, sc->scene, a->light, n, n == 1 ? "" : "s");
            else if ((st = fv_scene_animate_light(scene, a->light, a->keys, a->nkeys, err)) != FV_OK)
                fv_error_prefix(err, "%s: animate[%d].light: ", path, i);
            continue;
        }
        int obj = fv_scene_find_object(scene, a->object);
        if (obj < 0)
            st = fv_error_set(err, FV_ERR_INVALID, "%s: animate[%d].object: scene %s has no object named '%s'", path, i, sc->scene, a->object);
        else if ((st = fv_scene_animate_object(scene, obj, a->keys, a->nkeys, err)) != FV_OK)
            fv_error_prefix(err, "%s: animate[%d].object: ", path, i);
    }
    /* A file without lights is lit as fovea render lights it (the default sky and key light). */
    if (st == FV_OK) st = fv_scene_add_default_lighting(scene, view ? *view : NULL, log, NULL, err);
    /* A commit error names the scene, as fv_scene_load's does. */
    if (st == FV_OK && (st = fv_scene_commit(scene, log, err)) != FV_OK && strncmp(err->msg, sc->scene, strlen(sc->scene)) != 0)
        fv_error_prefix(err, "%s: ", sc->scene);
    if (st != FV_OK) {
        fv_scene_destroy(scene);
        if (view) {
            fv_view_destroy(*view);
            *view = NULL;
        }
        return st;
    }
    *out = scene;
    return FV_OK;
}

/* ---- entry points ---- */

/* The driver options of a scenario's frames: its size, times, camera path, gaze and eye model
 * (*cpath holds the path the options point to). */
static void scenario_drive_opts(const fv_scenario *sc, fv_camera_path *cpath, fv_drive_opts *o)
{
    *cpath = (fv_camera_path){sc->cam_keys, sc->ncam_keys};
    fv_drive_opts_init(o);
    o->width = sc->width;
    o->height = sc->height;
    o->time0 = sc->start_time;
    o->fps = sc->fps;
    o->camera_path = sc->ncam_keys ? cpath : NULL;
    o->gaze_path = sc->gaze;
    o->eye_model = sc->has_eye ? &sc->eye : NULL;
    o->eye_separation = sc->stereo;
}

/* Everything a run would refuse, found before anything is rendered or written: the scenario
 * file, its scene with "diffuse" and "animate" applied, every method's parameters (the
 * reference, the extra references, the methods and sweeps, each value a "match" would try) and
 * the camera of every frame. `fovea bench --check` is exactly this. On success the scene and its
 * view stay open for the run. */
static fv_status validate(const fv_scenario *sc, const char *path, const fv_log *log, fv_scene **scene, fv_view **view, fv_error *err)
{
    fv_status st = open_scene(sc, path, log, scene, view, err);
    if (st != FV_OK) return st;
    for (int i = -1 - sc->nextra; i < sc->nmethods && st == FV_OK; i++) {
        const fv_bench_method *m = i >= 0 ? &sc->methods[i] : i == -1 ? &sc->reference : &sc->extra[-2 - i];
        fv_technique *t = NULL;
        if ((st = fv_technique_create(m->method, *scene, m->params, log, &t, err)) != FV_OK) fv_error_prefix(err, "%s: %s: ", path, m->label);
        fv_technique_destroy(t);
    }
    for (int k = 0; k < sc->nmatches && st == FV_OK; k++) {
        const fv_bench_match *mt = &sc->matches[k];
        for (int v = 0; v < mt->nvalues && st == FV_OK; v++) {
            char text[64];
            snprintf(text, sizeof text, "%.17g", mt->values[v]);
            fv_params *p = NULL;
            fv_technique *t = NULL;
            if ((st = fv_params_clone(mt->base.params, &p, err)) == FV_OK && (st = fv_params_set(p, mt->param, text, err)) == FV_OK)
                st = fv_technique_create(mt->base.method, *scene, p, log, &t, err);
            if (st != FV_OK) fv_error_prefix(err, "%s: match[%d] (%s=%s): ", path, k, mt->param, text);
            fv_technique_destroy(t);
            fv_params_destroy(p);
        }
    }
    /* The frames' cameras, as the driver will make them: a degenerate camera path fails here, not
     * after the reference has rendered for minutes. */
    fv_camera_path cpath;
    fv_drive_opts dopt;
    scenario_drive_opts(sc, &cpath, &dopt);
    fv_driver *d = NULL;
    if (st == FV_OK && (st = fv_driver_create(*scene, *view, &dopt, &d, err)) != FV_OK) fv_error_prefix(err, "%s: ", path);
    for (int i = 0; i < sc->frames && st == FV_OK; i++) {
        fv_frame_views v;
        fv_driver_views(d, i, &v);
        fv_camera_basis b;
        if ((st = fv_camera_basis_make(&v.camera[0], &b, err)) != FV_OK)
            fv_error_prefix(err, "%s: frame %d (time %g)%s: ", path, i, v.time, sc->ncam_keys ? ", camera_path" : "");
    }
    fv_driver_destroy(d);
    if (st != FV_OK) {
        fv_scene_destroy(*scene);
        fv_view_destroy(*view);
        *scene = NULL;
        *view = NULL;
    }
    return st;
}

/* Validates a loaded scenario (destroyed here); path names it in messages. */
static fv_status check_loaded(fv_scenario *sc, const char *path, fv_error *err)
{
    fv_status st;
    fv_scene *scene = NULL;
    fv_view *view = NULL;
    st = validate(sc, path, NULL, &scene, &view, err);
    fv_scene_destroy(scene);
    fv_view_destroy(view);
    fv_scenario_destroy(sc);
    return st;
}

/* --device: every measured method that runs on that device and names none in its parameters is
 * moved there; the others stay on the CPU. A name that is no device is refused. */
static fv_status apply_device(fv_scenario *sc, const char *device, fv_error *err)
{
    if (!device) return FV_OK;
    fv_device d;
    fv_status st = fv_device_parse(device, NULL, &d, err);
    if (st != FV_OK) {
        fv_error_prefix(err, "--device: ");
        return st;
    }
    for (int i = 0; i < sc->nmethods && st == FV_OK; i++) {
        fv_bench_method *m = &sc->methods[i];
        fv_device md;
        if (fv_params_has(m->params, "device") || fv_device_parse(device, m->method, &md, err) != FV_OK) continue;
        if (md != FV_DEVICE_CPU && fv_technique_has_device(fv_technique_index(m->method), md)) st = fv_params_set(m->params, "device", device, err);
    }
    return st;
}

fv_status fv_bench_check(const char *path, fv_bench_mode mode, fv_error *err)
{
    fv_scenario *sc;
    fv_status st = fv_scenario_load(path, mode, &sc, err);
    return st == FV_OK ? check_loaded(sc, path, err) : st;
}

fv_status fv_bench_check_text(const char *json, const char *label, const char *dir, fv_bench_mode mode, fv_error *err)
{
    fv_scenario *sc;
    fv_status st = fv_scenario_load_text(json, label, dir, mode, &sc, err);
    return st == FV_OK ? check_loaded(sc, label, err) : st;
}

/* Rank 0's references (every measured frame, every slot) to the other ranks. */
static fv_status share_references(const fv_bench_split *sp, const fv_scenario *sc, frame_setup *frames, fv_error *err)
{
    fv_status st = FV_OK;
    const size_t bytes = (size_t)sc->width * sc->height * 3 * sizeof(float);
    for (int to = 1; sp && to < sp->size && st == FV_OK; to++) {
        if (sp->rank != 0 && sp->rank != to) continue;
        for (int i = sc->measure_from; i < sc->frames && st == FV_OK; i++)
            for (int k = 0; k <= sc->nextra && st == FV_OK; k++) st = sp->move(sp->user, 0, to, frames[i].ref[k], bytes, err);
    }
    return agree(sp, st, err);
}

/* Runs a loaded scenario (destroyed here); path names it in messages. */
static fv_status run_loaded(fv_scenario *sc, const char *path, const fv_bench_options *opt, fv_error *err)
{
    fv_scene *scene = NULL;
    fv_view *view = NULL;
    frame_setup *frames = NULL;
    fv_bench_result *res = NULL;
    fv_bench_method *match_methods = NULL;
    int nrows = 0;
    fv_bench_run_info info;
    memset(&info, 0, sizeof info);
    fv_status st = FV_OK;
    info.sc = sc;
    info.opt = opt;
    info.threads = opt->threads;
    info.out_dir = opt->out_dir ? opt->out_dir : "bench-out";
    char cache_dir[4096], img_dir[4096 + 128];
    snprintf(cache_dir, sizeof cache_dir, "%s", opt->cache_dir ? opt->cache_dir : "");
    if (!opt->cache_dir) snprintf(cache_dir, sizeof cache_dir, "%s/cache", info.out_dir);
    snprintf(img_dir, sizeof img_dir, "%s/%s", info.out_dir, sc->name);

    const fv_bench_split *sp = opt->split;
    const int rank = sp ? sp->rank : 0;
    say(opt, "scenario %s: scene %s, %dx%d, %d frame(s), %d method(s)", sc->name, sc->scene, sc->width, sc->height, sc->frames,
        sc->nmethods);
    if ((st = apply_device(sc, opt->device, err)) != FV_OK) goto setup_end;
    /* Everything --check checks, before anything is rendered. */
    if ((st = validate(sc, path, opt->log, &scene, &view, err)) != FV_OK) goto setup_end;
    /* Folders only once the scenario, its scene and every method are known to be good: bad input
     * writes nothing. */
    if (rank == 0 && ((st = fv_mkdirs(info.out_dir, err)) || (st = fv_mkdirs(cache_dir, err)) || (st = fv_mkdirs(img_dir, err))))
        goto setup_end;
    /* The frames: the same driver policy as `fovea render`; the scenario's camera path, gaze and
     * eye model when it has them, else the scene file's. */
    fv_camera_path cpath;
    fv_drive_opts dopt;
    scenario_drive_opts(sc, &cpath, &dopt);
    dopt.seed = sc->seed;
    dopt.threads = opt->threads;
    if ((st = fv_driver_create(scene, view, &dopt, &info.driver, err)) != FV_OK) goto setup_end;
    dopt.seed = fv_seed_reference(sc->seed);
    if ((st = fv_driver_create(scene, view, &dopt, &info.ref_driver, err)) != FV_OK) goto setup_end;
    sc->eye = *fv_driver_eye_model(info.driver); /* what the reports and heat maps draw */
    size_t npix = (size_t)sc->width * sc->height;
    if (!(frames = fv_calloc_array((size_t)sc->frames, sizeof *frames))) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        goto setup_end;
    }
    for (int i = 0; i < sc->frames; i++) {
        frame_setup *f = &frames[i];
        fv_frame_views v;
        fv_driver_views(info.driver, i, &v);
        f->time = v.time;
        f->cam = v.camera[0];
        f->gaze = v.gaze[0];
        f->labels = fv_alloc_array(npix, 1);
        bool ok = f->labels != NULL;
        for (int k = 0; k <= sc->nextra; k++) ok = ok && (f->ref[k] = fv_alloc_array(npix, 3 * sizeof(float))) != NULL;
        if (!ok) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory for %d frames of %dx%d", sc->frames, sc->width, sc->height);
            goto setup_end;
        }
        fv_eye_region_labels(&sc->eye, f->gaze, f->labels);
    }
setup_end:
    /* Split over processes: every rank has checked the same scenario; a problem is said once. */
    if ((st = agree(sp, st, err)) != FV_OK) goto done;
    /* The references: read from rank 0's cache or rendered (split over the ranks where they can
     * be), then handed to every rank. */
    if ((st = load_references(&info, scene, frames, cache_dir, 0, &info.ref_cached, &info.ref_ms, err)) != FV_OK) goto done;
    dopt.seed = sc->seed;
    if ((st = probe_reference(&info, scene, view, &dopt, frames, cache_dir, err)) != FV_OK) goto done;
    for (int k = 0; k < sc->nextra && st == FV_OK; k++)
        st = load_references(&info, scene, frames, cache_dir, 1 + k, &info.extra_cached[k], &info.extra_ms[k], err);
    /* (each of those ended with the job's status) */
    if (st != FV_OK) goto done;
    if (rank == 0) {
        snprintf(info.ref_img, sizeof info.ref_img, "%s/reference.png", sc->name);
        info.last_gaze = frames[sc->frames - 1].gaze;
        {
            char p[4096 + 160];
            snprintf(p, sizeof p, "%s/%s", info.out_dir, info.ref_img);
            fv_frame_views v;
            fv_driver_views(info.ref_driver, sc->frames - 1, &v);
            fv_frame_meta_run run = {sc->reference.method, sc->scene, sc->reference.params, sc->width, sc->height, info.threads,
                                     fv_seed_reference(sc->seed), sc->exposure, 0};
            fv_params *meta = NULL;
            st = fv_frame_meta(&run, sc->frames - 1, &v, 0, info.ref_ms > 0 ? info.ref_ms : -1.0, &meta, err);
            if (st == FV_OK) st = fv_image_write_meta(p, frames[sc->frames - 1].ref[0], sc->width, sc->height, sc->exposure, meta, err);
            fv_params_destroy(meta);
            if (st != FV_OK) goto refs_end;
        }
    }
refs_end:
    if ((st = agree(sp, st, err)) != FV_OK) goto done;
    if ((st = share_references(sp, sc, frames, err)) != FV_OK) goto done;

    nrows = sc->nmethods + sc->nmatches;
    if (!(res = fv_calloc_array((size_t)nrows, sizeof *res)) || !(match_methods = fv_calloc_array((size_t)sc->nmatches + 1, sizeof *match_methods))) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        goto finish;
    }
    if ((st = run_methods(&info, scene, frames, res, nrows, err)) != FV_OK) goto done;
    /* The match searches and the reports: rank 0's (its rows are all there now). */
    for (int k = 0; rank == 0 && k < sc->nmatches && st == FV_OK; k++)
        st = run_match(&info, scene, frames, res, k, &match_methods[k], &res[sc->nmethods + k], err);
    if (rank != 0 || st != FV_OK) goto finish;
    /* The match searches ran after the rounds: their speed-up is the ratio of medians. */
    double base = 0.0;
    for (int i = 0; i < sc->nmethods; i++)
        if (strcmp(sc->methods[i].label, sc->baseline) == 0) base = res[i].ms_median;
    for (int i = sc->nmethods; i < nrows; i++) res[i].speedup = res[i].ms_median > 0.0 ? base / res[i].ms_median : 0.0;
    fv_bench_ref_noise_check(&info.ref_noise, res, nrows);
    if (info.ref_noise.warn) {
        char line[1024];
        fv_bench_ref_noise_message(&info.ref_noise, sc, line, sizeof line);
        fv_log_warn(opt->log, "bench %s: %s", sc->name, line);
    }
    st = fv_bench_write_reports(&info, res, nrows, err);
finish:
    st = agree(sp, st, err);
done:
    if (frames)
        for (int i = 0; i < sc->frames; i++) {
            free(frames[i].labels);
            for (int k = 0; k <= sc->nextra; k++) free(frames[i].ref[k]);
        }
    free(frames);
    if (res)
        for (int i = 0; i < nrows; i++) free(res[i].ms);
    free(res);
    if (match_methods)
        for (int k = 0; k < sc->nmatches; k++) fv_params_destroy(match_methods[k].params);
    free(match_methods);
    fv_driver_destroy(info.driver);
    fv_driver_destroy(info.ref_driver);
    fv_view_destroy(view);
    fv_scene_destroy(scene);
    fv_scenario_destroy(sc);
    return st;
}

fv_status fv_bench_run(const char *path, const fv_bench_options *opt, fv_error *err)
{
    fv_scenario *sc;
    fv_status st = fv_scenario_load(path, opt->mode, &sc, err);
    return st == FV_OK ? run_loaded(sc, path, opt, err) : st;
}

fv_status fv_bench_run_text(const char *json, const char *label, const char *dir, const fv_bench_options *opt, fv_error *err)
{
    fv_scenario *sc;
    fv_status st = fv_scenario_load_text(json, label, dir, opt->mode, &sc, err);
    return st == FV_OK ? run_loaded(sc, label, opt, err) : st;
}
