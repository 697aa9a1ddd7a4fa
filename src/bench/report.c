/* fovea — benchmark reports: <name>.json (every figure, machine-readable), <name>.md (a table like
 * the papers' plus the images), and for a sweep <name>-sweep.csv and <name>-sweep.png (plotted
 * with gnuplot when it is installed; the CSV is written regardless).
 */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "bench/bench_impl.h"
#include "core/fileio.h"
#include "core/provenance_json.h"
#include "core/rng.h"
#include "fovea/bench.h"
#include "fovea/drive.h"
#include "fovea/film.h"
#include "fovea/metrics.h"
#include "fovea/provenance.h"
#include "fovea/scene.h"
#include "fovea/technique.h"
#include "fovea/view.h"
#include "drive/params_json.h"

/* A growable text buffer for the Markdown and CSV files. */
typedef struct text {
    char *s;
    size_t len, cap;
    bool oom;
} text;

static void tprintf(text *t, const char *fmt, ...)
{
    if (t->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int w = vsnprintf(t->s ? t->s + t->len : NULL, t->s ? t->cap - t->len : 0, fmt, ap);
        va_end(ap);
        if (w < 0) {
            t->oom = true;
            return;
        }
        if (t->s && t->len + (size_t)w < t->cap) {
            t->len += (size_t)w;
            return;
        }
        size_t nc = (t->cap ? t->cap * 2 : 4096) + (size_t)w;
        char *ns = realloc(t->s, nc);
        if (!ns) {
            t->oom = true;
            return;
        }
        t->s = ns;
        t->cap = nc;
    }
}

static fv_status text_write(text *t, const char *path, fv_error *err)
{
    fv_status st = t->oom ? fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path)
                          : fv_file_write_atomic(path, t->s ? t->s : "", t->len, err);
    free(t->s);
    memset(t, 0, sizeof *t);
    return st;
}

/* JSON numbers cannot be inf or NaN: those become null. */
static cJSON *num(double v) { return isfinite(v) ? cJSON_CreateNumber(v) : cJSON_CreateNull(); }

/* A method's parameters with their types (numbers as numbers, switches as booleans). */
static cJSON *params_json(const fv_bench_method *m) { return fv_params_typed_json(m->method, m->params); }

static const char *mode_name(fv_bench_mode m) { return m == FV_BENCH_QUICK ? "quick" : m == FV_BENCH_FULL ? "full" : "default"; }

/* One sentence of the settings this run actually used (after the --quick/--full overrides): a
 * quick run's report must not claim the default run's sizes, which the scenario's own description
 * states. */
static void run_settings(const fv_bench_run_info *info, text *t)
{
    const fv_scenario *sc = info->sc;
    int reps = info->opt->repeats > 0 ? info->opt->repeats : sc->repeats;
    tprintf(t, "This %s run: scene `%s`, %dx%d, %d frame(s) at %g fps from t=%g s, %d repeat(s), seed %llu, %d thread(s); reference `%s`",
            mode_name(info->opt->mode), sc->scene, sc->width, sc->height, sc->frames, sc->fps, sc->start_time, reps, sc->seed,
            fv_threads_used(info->threads), sc->reference.method);
    for (int i = 0; i < fv_params_count(sc->reference.params); i++)
        tprintf(t, " %s=%s", fv_params_key(sc->reference.params, i), fv_params_value(sc->reference.params, i));
    if (sc->stereo > 0.0f) tprintf(t, "; stereo, eyes %g apart: a frame is both eyes (both timed), errors and images the left eye's", sc->stereo);
    tprintf(t, "; methods");
    for (int i = 0; i < sc->nmethods; i++) {
        const fv_bench_method *m = &sc->methods[i];
        tprintf(t, "%s `%s`", i ? "," : "", m->label);
        for (int k = 0; k < fv_params_count(m->params); k++)
            tprintf(t, "%s%s=%s", k ? " " : " (", fv_params_key(m->params, k), fv_params_value(m->params, k));
        if (fv_params_count(m->params)) tprintf(t, ")");
    }
    tprintf(t, ".");
}

static cJSON *result_json(const fv_bench_run_info *info, const fv_bench_result *r)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "method", r->m->label);
    cJSON_AddStringToObject(o, "technique", r->m->method);
    cJSON_AddItemToObject(o, "params", params_json(r->m));
    if (r->m->from_sweep) cJSON_AddItemToObject(o, "sweep_value", num(r->m->sweep_value));
    /* With several sweeps a row also says which parameter it varies (one sweep: the old output). */
    if (r->m->from_sweep && info->sc->sweep_array) cJSON_AddStringToObject(o, "sweep_param", info->sc->sweeps[r->m->sweep].param);
    if (r->m->match > 0) {
        const fv_bench_match *mt = &info->sc->matches[r->m->match - 1];
        cJSON *mo = cJSON_AddObjectToObject(o, "match");
        cJSON_AddStringToObject(mo, "target", mt->target);
        cJSON_AddStringToObject(mo, "metric", mt->metric);
        cJSON_AddStringToObject(mo, "region", fv_region_name(mt->region));
        cJSON_AddStringToObject(mo, "param", mt->param);
        cJSON_AddBoolToObject(mo, "reached", r->m->match_reached);
    }
    cJSON *ms = cJSON_AddObjectToObject(o, "ms_per_frame");
    cJSON_AddItemToObject(ms, "median", num(r->ms_median));
    cJSON_AddItemToObject(ms, "min", num(r->ms_min));
    cJSON_AddItemToObject(ms, "max", num(r->ms_max));
    int reps = info->opt->repeats > 0 ? info->opt->repeats : info->sc->repeats;
    cJSON *all = cJSON_AddArrayToObject(ms, "repeats");
    for (int i = 0; i < reps; i++) cJSON_AddItemToArray(all, num(r->ms[i]));
    /* Frame pacing (docs/bench.md): nearest-rank percentiles over every timed frame of every
     * repeat, and the worst of them. */
    cJSON *fm = cJSON_AddObjectToObject(o, "frame_ms");
    cJSON_AddItemToObject(fm, "p50", num(r->frame_p50));
    cJSON_AddItemToObject(fm, "p99", num(r->frame_p99));
    cJSON_AddItemToObject(fm, "max", num(r->frame_max));
    cJSON_AddNumberToObject(fm, "frames", reps * info->sc->frames);
    cJSON *st = cJSON_AddObjectToObject(o, "stages_ms");
    for (int i = 0; i < r->stages.n_stages; i++) cJSON_AddItemToObject(st, r->stages.stage[i].name, num(r->stages.stage[i].value));
    /* Each stage's serial share in [0, 1]: the part of its time outside parallel regions, or inside
     * them with one thread working while the others wait (core/stage_time.h, docs/threads.md);
     * stages without a measured serial part are left out. */
    cJSON *ss = cJSON_AddObjectToObject(o, "stages_serial_share");
    for (int i = 0; i < r->stages.n_stages; i++) {
        const double ser = fv_stats_get_serial_ms(&r->stages, r->stages.stage[i].name), sms = r->stages.stage[i].value;
        if (ser >= 0.0) cJSON_AddItemToObject(ss, r->stages.stage[i].name, num(sms > 0.0 ? fmin(1.0, ser / sms) : 0.0));
    }
    /* Every timing with its spread over the repeats (stages_ms keeps the medians, as before). */
    cJSON *sr = cJSON_AddObjectToObject(o, "stages_ms_range");
    for (int i = 0; i < r->stages.n_stages; i++) {
        cJSON *one = cJSON_AddObjectToObject(sr, r->stages.stage[i].name);
        cJSON_AddItemToObject(one, "median", num(r->stages.stage[i].value));
        cJSON_AddItemToObject(one, "min", num(r->stages_min.stage[i].value));
        cJSON_AddItemToObject(one, "max", num(r->stages_max.stage[i].value));
    }
    cJSON_AddItemToObject(o, "speedup", num(r->speedup));
    /* split over processes: who timed the row, sharing the machine (or cluster) with the others */
    if (info->opt->split) cJSON_AddNumberToObject(o, "timed_on_rank", r->rank);
    cJSON *er = cJSON_AddObjectToObject(o, "error");
    for (int g = 0; g < FV_REGION_COUNT; g++) {
        const fv_metric_values *v = &r->error.region[g];
        cJSON *e = cJSON_AddObjectToObject(er, fv_region_name((fv_region)g));
        cJSON_AddNumberToObject(e, "pixels", (double)v->pixels);
        cJSON_AddItemToObject(e, "mse", num(v->mse));
        cJSON_AddItemToObject(e, "psnr", num(v->psnr));
        cJSON_AddItemToObject(e, "e", num(v->e));
        cJSON_AddItemToObject(e, "ssim", num(v->ssim));
        cJSON_AddItemToObject(e, "flip", num(v->flip));
    }
    if (info->sc->nextra > 0) {
        cJSON *ev = cJSON_AddObjectToObject(o, "error_vs");
        for (int k = 0; k < info->sc->nextra; k++) {
            cJSON *one = cJSON_AddObjectToObject(ev, info->sc->extra[k].label);
            for (int g = 0; g < FV_REGION_COUNT; g++) {
                const fv_metric_values *v = &r->error_vs[k].region[g];
                cJSON *e = cJSON_AddObjectToObject(one, fv_region_name((fv_region)g));
                cJSON_AddItemToObject(e, "mse", num(v->mse));
                cJSON_AddItemToObject(e, "psnr", num(v->psnr));
                cJSON_AddItemToObject(e, "e", num(v->e));
                cJSON_AddItemToObject(e, "ssim", num(v->ssim));
                cJSON_AddItemToObject(e, "flip", num(v->flip));
            }
        }
    }
    cJSON *te = cJSON_AddObjectToObject(o, "temporal");
    for (int g = 0; g < FV_REGION_COUNT; g++) {
        cJSON *e = cJSON_AddObjectToObject(te, fv_region_name((fv_region)g));
        cJSON_AddItemToObject(e, "mse", r->has_temporal ? num(r->temporal_mse[g]) : cJSON_CreateNull());
        cJSON_AddItemToObject(e, "e", r->has_temporal ? num(r->temporal_e[g]) : cJSON_CreateNull());
    }
    cJSON *mean = cJSON_AddArrayToObject(o, "image_mean");
    for (int k = 0; k < 3; k++) cJSON_AddItemToArray(mean, num(r->image_mean[k]));
    cJSON *co = cJSON_AddObjectToObject(o, "counters");
    for (int i = 0; i < r->counters.n_counters; i++)
        cJSON_AddItemToObject(co, r->counters.counter[i].name, num(r->counters.counter[i].value));
    cJSON *im = cJSON_AddObjectToObject(o, "images");
    cJSON_AddStringToObject(im, "frame", r->img);
    cJSON_AddStringToObject(im, "flip", r->heat);
    cJSON_AddStringToObject(im, "fovea", r->crop);
    return o;
}

/* *json: a copy of the text written (NULL when out of memory), for fv_bench_options.report. */
static fv_status write_json(const fv_bench_run_info *info, const fv_bench_result *res, int n, char **json, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scenario", sc->name);
    if (sc->description) cJSON_AddStringToObject(root, "description", sc->description);
    text settings = {0};
    run_settings(info, &settings);
    cJSON_AddStringToObject(root, "run_description", settings.s ? settings.s : "");
    free(settings.s);
    cJSON_AddStringToObject(root, "fovea_version", FOVEA_VERSION_STRING);
    cJSON *prov = fv_provenance_json(info->threads);
    if (prov && info->opt->command) cJSON_AddStringToObject(prov, "command", info->opt->command);
    cJSON_AddItemToObject(root, "provenance", prov);
    cJSON_AddStringToObject(root, "scene", sc->scene);
    /* The scene edits, only when asked for (reports of other scenarios stay as they were). */
    if (sc->diffuse) cJSON_AddBoolToObject(root, "diffuse", true);
    /* Only when set: a stereo run's frame is both eyes (its times), its errors the left eye's. */
    if (sc->stereo > 0.0f) cJSON_AddNumberToObject(root, "stereo", sc->stereo);
    if (sc->nanimate) {
        cJSON *an = cJSON_AddArrayToObject(root, "animate");
        for (int i = 0; an && i < sc->nanimate; i++) {
            cJSON *e = cJSON_CreateObject();
            if (sc->animate[i].light >= 0) cJSON_AddNumberToObject(e, "light", sc->animate[i].light);
            else cJSON_AddStringToObject(e, "object", sc->animate[i].object);
            cJSON_AddNumberToObject(e, "keys", sc->animate[i].nkeys);
            cJSON_AddItemToArray(an, e);
        }
    }
    cJSON *size = cJSON_AddArrayToObject(root, "size");
    cJSON_AddItemToArray(size, cJSON_CreateNumber(sc->width));
    cJSON_AddItemToArray(size, cJSON_CreateNumber(sc->height));
    cJSON_AddNumberToObject(root, "frames", sc->frames);
    cJSON_AddNumberToObject(root, "measure_from", sc->measure_from);
    cJSON_AddNumberToObject(root, "fps", sc->fps);
    cJSON_AddNumberToObject(root, "repeats", info->opt->repeats > 0 ? info->opt->repeats : sc->repeats);
    /* The threads the renders used (0 asked for "all": this says how many that was). */
    cJSON_AddNumberToObject(root, "threads", fv_threads_used(info->threads));
    /* Processes the rows were dealt to (fv_bench_split): each timed its rows with `threads`
     * threads while the others ran theirs, so a row's time depends on what shared its machine. */
    cJSON_AddNumberToObject(root, "ranks", info->opt->split ? info->opt->split->size : 1);
    cJSON_AddStringToObject(root, "mode", mode_name(info->opt->mode));
    cJSON_AddNumberToObject(root, "start_time", sc->start_time);
    cJSON_AddNumberToObject(root, "exposure", sc->exposure);
    /* Seeds are 64-bit: as decimal text, which a JSON number (a double) could not hold exactly. */
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", sc->seed);
    cJSON_AddStringToObject(root, "seed", seed);
    cJSON *eye = cJSON_AddObjectToObject(root, "eye");
    cJSON_AddItemToObject(eye, "fovea_radius_px", num(fv_eye_fovea_radius_px(&sc->eye)));
    cJSON_AddItemToObject(eye, "transition_radius_px", num(fv_eye_transition_radius_px(&sc->eye)));
    /* The one scale of every method's heat map (images.flip): its colour bar goes from 0 to max. */
    cJSON *hm = cJSON_AddObjectToObject(root, "heatmaps");
    cJSON_AddStringToObject(hm, "metric", "flip");
    cJSON_AddItemToObject(hm, "max", num(FV_BENCH_HEAT_MAX));
    cJSON_AddBoolToObject(hm, "shared", true);
    cJSON *ref = cJSON_AddObjectToObject(root, "reference");
    cJSON_AddStringToObject(ref, "method", sc->reference.method);
    cJSON_AddItemToObject(ref, "params", params_json(&sc->reference));
    /* The reference's own random stream (core/rng.h: fv_seed_reference), never a measured method's. */
    cJSON_AddStringToObject(ref, "stream", "reference");
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)fv_seed_reference(sc->seed));
    cJSON_AddStringToObject(ref, "seed", seed);
    cJSON_AddNumberToObject(ref, "cached_frames", info->ref_cached);
    cJSON_AddItemToObject(ref, "ms_per_frame", info->ref_ms > 0 ? num(info->ref_ms) : cJSON_CreateNull());
    cJSON_AddStringToObject(ref, "image", info->ref_img);
    /* its own error, estimated from a probe (ref_noise.c), and whether it is too noisy */
    const fv_bench_ref_noise *rn = &info->ref_noise;
    cJSON *noise = cJSON_AddObjectToObject(ref, "noise");
    cJSON_AddBoolToObject(noise, "estimated", rn->estimated);
    if (!rn->estimated) {
        cJSON_AddStringToObject(noise, "why_not", rn->why_not);
    } else {
        cJSON_AddNumberToObject(noise, "probe_spp", rn->probe_spp);
        cJSON *mse = cJSON_AddObjectToObject(noise, "mse");
        for (int r = 0; r < FV_REGION_COUNT; r++) cJSON_AddItemToObject(mse, fv_region_name(r), num(rn->mse[r]));
        char w[1024];
        fv_bench_ref_noise_message(rn, sc, w, sizeof w);
        cJSON_AddItemToObject(noise, "warning", rn->warn ? cJSON_CreateString(w) : cJSON_CreateNull());
    }
    if (sc->nextra > 0) {
        cJSON *ex = cJSON_AddArrayToObject(root, "extra_references");
        for (int k = 0; k < sc->nextra; k++) {
            cJSON *e = cJSON_CreateObject();
            cJSON_AddStringToObject(e, "label", sc->extra[k].label);
            cJSON_AddStringToObject(e, "method", sc->extra[k].method);
            cJSON_AddItemToObject(e, "params", params_json(&sc->extra[k]));
            cJSON_AddStringToObject(e, "stream", "reference");
            cJSON_AddNumberToObject(e, "cached_frames", info->extra_cached[k]);
            cJSON_AddItemToObject(e, "ms_per_frame", info->extra_ms[k] > 0 ? num(info->extra_ms[k]) : cJSON_CreateNull());
            cJSON_AddItemToArray(ex, e);
        }
    }
    cJSON_AddStringToObject(root, "baseline", sc->baseline);
    cJSON *rows = cJSON_AddArrayToObject(root, "results");
    for (int i = 0; i < n; i++) cJSON_AddItemToArray(rows, result_json(info, &res[i]));
    char *textj = cJSON_Print(root);
    cJSON_Delete(root);
    if (!textj) return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing the JSON report");
    char path[4096 + 128];
    snprintf(path, sizeof path, "%s/%s.json", info->out_dir, sc->name);
    fv_status st = fv_file_write_atomic(path, textj, strlen(textj), err);
    if (st == FV_OK && info->opt->report) *json = textj;
    else free(textj);
    return st;
}

static const char *sci(char *buf, double v)
{
    if (!isfinite(v)) return strcpy(buf, "–");
    snprintf(buf, 32, "%.3g", v);
    return buf;
}

/* Sweep k's CSV and plot, without the extension: NAME-sweep for the single-object form,
 * NAME-sweep-PARAM for each sweep of an array. */
static void sweep_stem(const fv_scenario *sc, int k, char *out, size_t n)
{
    if (sc->sweep_array) snprintf(out, n, "%s-sweep-%s", sc->name, sc->sweeps[k].param);
    else snprintf(out, n, "%s-sweep", sc->name);
}

/* *table: a copy of the main table (NULL when out of memory), for fv_bench_options.table. */
static fv_status write_markdown(const fv_bench_run_info *info, const fv_bench_result *res, int n, char **table, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    text t = {0};
    char a[32], b[32], c[32], d[32], e[32], f[32], g[32], h[32];
    tprintf(&t, "# Benchmark `%s`\n\n", sc->name);
    if (sc->description) tprintf(&t, "%s%s\n\n", info->opt->mode != FV_BENCH_DEFAULT ? "The scenario (its default run): " : "", sc->description);
    run_settings(info, &t);
    tprintf(&t, "\n\n");
    {
        /* Provenance: which build on which machine, so a figure can be traced (issue 27). */
        char line[512], date[32];
        fv_provenance_line(line, sizeof line);
        fv_host_info host;
        fv_host_info_get(&host);
        fv_utc_now(date, sizeof date);
        tprintf(&t, "Made by %s on %s (%d cores, %s), %d thread(s), %s", line, host.cpu, host.cores, host.os, fv_threads_used(info->threads), date);
        if (info->opt->command) tprintf(&t, ", with `%s`", info->opt->command);
        tprintf(&t, ".\n\n");
    }
    tprintf(&t, "Scene `%s`, %dx%d, %d frame(s) at %g fps (errors from frame %d on), gaze (%.2f, %.2f) at the last frame, fovea radius %.0f px, "
                "transition %.0f px. Reference: `%s`",
            sc->scene, sc->width, sc->height, sc->frames, sc->fps, sc->measure_from, info->last_gaze.x, info->last_gaze.y, fv_eye_fovea_radius_px(&sc->eye),
            fv_eye_transition_radius_px(&sc->eye), sc->reference.method);
    for (int i = 0; i < fv_params_count(sc->reference.params); i++)
        tprintf(&t, " %s=%s", fv_params_key(sc->reference.params, i), fv_params_value(sc->reference.params, i));
    if (info->ref_noise.estimated)
        tprintf(&t, " (its own MSE, estimated from a %d-sample probe: %.3g in the fovea, %.3g overall)", info->ref_noise.probe_spp,
                info->ref_noise.mse[FV_REGION_FOVEA], info->ref_noise.mse[FV_REGION_ALL]);
    if (info->ref_noise.warn) {
        char w[1024];
        fv_bench_ref_noise_message(&info->ref_noise, sc, w, sizeof w);
        tprintf(&t, ". **Warning:** %s", w);
    }
    if (info->opt->split)
        tprintf(&t, ". The rows were dealt to %d processes (MPI ranks; the JSON's `timed_on_rank`), each timing its rows with %d "
                    "thread(s) while the others ran theirs: a row's time includes that sharing",
                info->opt->split->size, fv_threads_used(info->threads));
    int reps = info->opt->repeats > 0 ? info->opt->repeats : sc->repeats;
    tprintf(&t, ". Times are medians of %d repeat(s) (ms per frame, render call only); frame p50 / p99 / worst are the nearest-rank "
                "percentiles and the slowest of all %d timed frames; speed-up is relative to `%s`. "
                "Errors are means over frames on display values (exposure %g, sRGB); MSE' is the temporal error "
                "(Foveated Photon Mapping Eq. 9).\n\n",
            reps, reps * sc->frames, sc->baseline, sc->exposure);
    size_t table_at = t.len;
    tprintf(&t, "| method | params | ms/frame | ms min–max | frame p50 / p99 / worst | speed-up | MSE fovea | MSE transition | MSE periphery | "
                "SSIM fovea | FLIP fovea | FLIP all | MSE' fovea | MSE' periphery |\n"
                "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int i = 0; i < n; i++) {
        const fv_bench_result *r = &res[i];
        tprintf(&t, "| %s%s | ", r->m->label, r->m->match > 0 && !r->m->match_reached ? " (target not reached)" : "");
        for (int k = 0; k < fv_params_count(r->m->params); k++)
            tprintf(&t, "%s%s=%s", k ? " " : "", fv_params_key(r->m->params, k), fv_params_value(r->m->params, k));
        const fv_metric_values *v = r->error.region;
        tprintf(&t, " | %.1f | %.1f–%.1f | %.1f / %.1f / %.1f | %.2f | %s | %s | %s | %s | %s | %s | %s | %s |\n", r->ms_median, r->ms_min,
                r->ms_max, r->frame_p50, r->frame_p99, r->frame_max, r->speedup,
                sci(a, v[FV_REGION_FOVEA].mse), sci(b, v[FV_REGION_TRANSITION].mse), sci(c, v[FV_REGION_PERIPHERY].mse),
                sci(d, v[FV_REGION_FOVEA].ssim), sci(e, v[FV_REGION_FOVEA].flip), sci(f, v[FV_REGION_ALL].flip),
                sci(g, r->has_temporal ? r->temporal_mse[FV_REGION_FOVEA] : NAN),
                sci(h, r->has_temporal ? r->temporal_mse[FV_REGION_PERIPHERY] : NAN));
    }
    if (!t.oom && t.s) *table = strdup(t.s + table_at);    /* Each family's own metrics beside the common ones: instant radiosity reports E (Foveated
     * Instant Radiosity Eq. 3) per region and its temporal E' (Eq. 4), which the table above
     * leaves out. */
    bool ir_family = false;
    for (int i = 0; i < n; i++) {
        const char *fam = fv_technique_family(fv_technique_index(res[i].m->method));
        ir_family |= fam && !strcmp(fam, "instant radiosity");
    }
    if (ir_family) {
        tprintf(&t, "\nInstant radiosity's metrics (Foveated Instant Radiosity Sec. 5): E per region (Eq. 3) and E' over the sequence (Eq. 4):\n\n"
                    "| method | E fovea | E transition | E periphery | E all | E' fovea | E' transition | E' periphery | E' all |\n"
                    "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (int i = 0; i < n; i++) {
            const fv_bench_result *r = &res[i];
            const fv_metric_values *v = r->error.region;
            char ep[FV_REGION_COUNT][32];
            for (int q = 0; q < FV_REGION_COUNT; q++) sci(ep[q], r->has_temporal ? r->temporal_e[q] : NAN);
            tprintf(&t, "| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r->m->label, sci(a, v[FV_REGION_FOVEA].e), sci(b, v[FV_REGION_TRANSITION].e),
                    sci(c, v[FV_REGION_PERIPHERY].e), sci(d, v[FV_REGION_ALL].e), ep[FV_REGION_FOVEA], ep[FV_REGION_TRANSITION],
                    ep[FV_REGION_PERIPHERY], ep[FV_REGION_ALL]);
        }
    }

    /* Ray throughput where a method counts its rays: one camera ray per sample is primary, the
     * rest (bounces and shadow rays) secondary. */
    bool rays = false;
    for (int i = 0; i < n; i++) rays |= fv_stats_get_count(&res[i].counters, "rays") > 0.0;
    if (rays) {
        tprintf(&t, "\n| method | M rays/s | primary M rays/s | secondary M rays/s | rays per sample | image mean (R, G, B) |\n"
                    "|---|---:|---:|---:|---:|---|\n");
        for (int i = 0; i < n; i++) {
            const fv_bench_result *r = &res[i];
            double all = fv_stats_get_count(&r->counters, "rays"), prim = fv_stats_get_count(&r->counters, "samples");
            if (!(all > 0.0) || !(r->ms_median > 0.0)) continue;
            double per_s = 1e3 / r->ms_median / 1e6;
            tprintf(&t, "| %s | %.1f | %.1f | %.1f | %.2f | %.4f, %.4f, %.4f |\n", r->m->label, all * per_s, prim * per_s, (all - prim) * per_s,
                    prim > 0.0 ? all / prim : 0.0, r->image_mean[0], r->image_mean[1], r->image_mean[2]);
        }
    }
    for (int k = 0; k < sc->nextra; k++) {
        tprintf(&t, "\nAgainst `%s` (%s):\n\n| method | MSE fovea | MSE transition | MSE periphery | FLIP fovea | FLIP all |\n|---|---:|---:|---:|---:|---:|\n",
                sc->extra[k].label, sc->extra[k].method);
        for (int i = 0; i < n; i++) {
            const fv_metric_values *v = res[i].error_vs[k].region;
            tprintf(&t, "| %s | %s | %s | %s | %s | %s |\n", res[i].m->label, sci(a, v[FV_REGION_FOVEA].mse), sci(b, v[FV_REGION_TRANSITION].mse),
                    sci(c, v[FV_REGION_PERIPHERY].mse), sci(d, v[FV_REGION_FOVEA].flip), sci(e, v[FV_REGION_ALL].flip));
        }
    }
    tprintf(&t, "\nThe heat maps show each method's %s error on one scale, shared by every method: 0 (no error) to %g, "
                "the bar below each; rings: fovea (cyan), transition (green).\n",
            FV_BENCH_HEAT_LABEL, FV_BENCH_HEAT_MAX);
    tprintf(&t, "\n| method | last frame | %s error, 0 to %g | around the gaze |\n|---|---|---|---|\n", FV_BENCH_HEAT_LABEL, FV_BENCH_HEAT_MAX);
    tprintf(&t, "| reference | ![](%s) | | |\n", info->ref_img);
    for (int i = 0; i < n; i++)
        tprintf(&t, "| %s | ![](%s) | ![](%s) | ![](%s) |\n", res[i].m->label, res[i].img, res[i].heat, res[i].crop);
    for (int k = 0; k < sc->nsweeps; k++) {
        char stem[2 * FV_BENCH_LABEL_MAX + 8];
        sweep_stem(sc, k, stem, sizeof stem);
        tprintf(&t, "%sSweep of `%s` over `%s`: ![](%s.png) (data: %s.csv)\n", k ? "" : "\n", sc->sweeps[k].method, sc->sweeps[k].param, stem, stem);
    }
    char path[4096 + 128];
    snprintf(path, sizeof path, "%s/%s.md", info->out_dir, sc->name);
    return text_write(&t, path, err);
}

/* Runs gnuplot on a script; false when gnuplot is missing or fails (the CSV still stands). */
static bool run_gnuplot(const char *script_path)
{
    pid_t pid = fork();
    if (pid < 0) return false;
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout)) _exit(127);
        execlp("gnuplot", "gnuplot", script_path, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    pid_t w;
    /* A handled signal (one without SA_RESTART) must not end the wait: gnuplot would be left a
     * zombie and its plot counted as failed (as in core/sandbox.c). */
    while ((w = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {}
    if (w < 0) return false;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

static fv_status write_sweep(const fv_bench_run_info *info, const fv_bench_result *res, int n, int k, fv_error *err)
{
    const fv_scenario *sc = info->sc;
    const char *param = sc->sweeps[k].param;
    char stem[2 * FV_BENCH_LABEL_MAX + 8];
    sweep_stem(sc, k, stem, sizeof stem);
    text t = {0};
    tprintf(&t, "%s,ms_per_frame,speedup,mse_fovea,mse_transition,mse_periphery,mse_all,ssim_fovea,ssim_all,flip_fovea,flip_"
                "transition,flip_periphery,flip_all,e_fovea,e_transition,e_periphery,e_all\n",
            param);
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < n; i++) {
        const fv_bench_result *r = &res[i];
        if (!r->m->from_sweep || r->m->sweep != k) continue;
        const fv_metric_values *v = r->error.region;
        lo = fmin(lo, r->m->sweep_value);
        hi = fmax(hi, r->m->sweep_value);
        tprintf(&t, "%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", r->m->sweep_value,
                r->ms_median, r->speedup, v[0].mse, v[1].mse, v[2].mse, v[3].mse, v[0].ssim, v[3].ssim, v[0].flip, v[1].flip, v[2].flip,
                v[3].flip, v[0].e, v[1].e, v[2].e, v[3].e);
    }
    char csv[4096 + 128], png[4096 + 128], gp[4096 + 128];
    snprintf(csv, sizeof csv, "%s/%s.csv", info->out_dir, stem);
    snprintf(png, sizeof png, "%s/%s.png", info->out_dir, stem);
    snprintf(gp, sizeof gp, "%s/%s.gp", info->out_dir, stem);
    fv_status st = text_write(&t, csv, err);
    if (st != FV_OK) return st;
    /* MSE per region against the swept value, and the time per frame on the right axis (the
     * papers' Figs. 5 and 7 side by side); log axes when the values span a decade. gnuplot
     * writes the plot by name, into the temporary file of an fv_atomic_file. */
    bool logx = lo > 0 && hi / lo >= 10.0;
    fv_atomic_file plot;
    fv_error perr;
    if (fv_atomic_file_begin(png, &plot, &perr) != FV_OK) {
        fv_log_warn(info->opt->log, "could not plot: %s; the CSV %s is complete", perr.msg, csv);
        return FV_OK;
    }
    tprintf(&t,
            "set terminal png size 800,500\nset output '%s'\nset datafile separator ','\nset key top right\n"
            "set title \"%s: error per region vs %s\" noenhanced\nset xlabel '%s' noenhanced\nset ylabel 'MSE'\n"
            "set logscale y\n%s\nset grid\nset y2label 'ms per frame'\nset y2tics\nset ytics nomirror\n"
            "plot '%s' every ::1 using 1:4 with linespoints lw 2 title 'fovea', "
            "'' every ::1 using 1:5 with linespoints lw 2 title 'transition', "
            "'' every ::1 using 1:6 with linespoints lw 2 title 'periphery', "
            "'' every ::1 using 1:2 axes x1y2 with linespoints lw 1 dt 2 title 'ms per frame'\n",
            fv_atomic_file_path(&plot), sc->name, param, param, logx ? "set logscale x 2" : "", csv);
    if ((st = text_write(&t, gp, err)) != FV_OK) {
        fv_atomic_file_abort(&plot);
        return st;
    }
    bool plotted = run_gnuplot(gp) && fv_atomic_file_commit(&plot, &perr) == FV_OK;
    fv_atomic_file_abort(&plot);
    unlink(gp);
    if (plotted) return FV_OK;
    fv_log_warn(info->opt->log, "could not plot %s with gnuplot (is gnuplot installed?); the CSV %s is complete", png, csv);
    return FV_OK;
}

fv_status fv_bench_write_reports(const fv_bench_run_info *info, const fv_bench_result *res, int n, fv_error *err)
{
    char *table = NULL, *json = NULL;
    fv_status st = write_json(info, res, n, &json, err);
    if (st == FV_OK) st = write_markdown(info, res, n, &table, err);
    for (int k = 0; k < info->sc->nsweeps && st == FV_OK; k++) st = write_sweep(info, res, n, k, err);
    /* Shown only once every file is written. */
    if (st == FV_OK && table && info->opt->table) info->opt->table(info->opt->status_user, table);
    if (st == FV_OK && json) info->opt->report(info->opt->status_user, json);
    free(table);
    free(json);
    return st;
}
