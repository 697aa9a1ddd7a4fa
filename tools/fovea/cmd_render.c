/* fovea CLI — `fovea render`: load a scene, create a method, render frames, write images.
 *
 * Everything the user typed is validated before any long work starts (size, output format and
 * directory, method and parameters), so a typo costs no render time and leaves no file behind.
 */
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli.h"
#include "core/alloc.h"
#include "core/parallel.h"
#include "gaze/overlay.h"
#include "render_record.h"
#ifdef FOVEA_HAVE_MPI
#include "dist/dist_progress.h"
#include "dist/split.h"
#endif

#define MAX_LIGHTS 64

static void help(void)
{
    printf("usage: fovea render [SCENE] [options]\n"
           "  SCENE                 built-in name (fovea scenes) or a .json/.obj/.gltf/.glb/.ply file [cornell]\n"
           "  --method NAME         rendering method (fovea methods) [pt]\n"
           "  --spp N               samples per pixel: sets the method's own parameter for it (an error names\n"
           "                        what to use instead for a method without one)\n"
           "  --device D            cpu, portable (the GPU kernels on the CPU), cuda or auto (cuda when built with\n"
           "                        it, a GPU is present and the method has it) [cpu] (docs/gpu.md)\n"
           "  --size WxH            image size [512x512]\n"
           "  --frames N            number of frames; >1 writes numbered files OUT_0000.ext ... [1]\n"
           "  --fps F               frames per second of scene time [30]\n"
           "  --time T              scene time of the first frame in seconds [0]\n"
           "  --seed S              random seed [1]\n"
           "  --threads T           worker threads, 0 = the thread policy's default [0]\n"
           FV_CLI_THREAD_POLICY_HELP
           "  --out FILE            output .png (tone-mapped sRGB), .pfm or .exr (linear, + aux channels) [fovea.png]\n"
           "  --exposure E          scale applied before PNG tone mapping [1]\n"
           "  --overlay             draw the eye model over the PNG: a ring at the foveal radius (magenta), one at\n"
           "                        the transition radius (cyan), a cross at the gaze (yellow), each eye its own\n"
           "                        gaze; a .png --out only (PFM and EXR hold data: refused), and the file says so\n"
           "                        in its metadata (overlay, kept with --no-metadata); fovea compare refuses it\n"
           "  --camera-pos x,y,z    camera position      --camera-look x,y,z  point looked at\n"
           "  --camera-up x,y,z     camera up vector     --fov DEG            vertical field of view\n"
           "  --point-light x,y,z,r,g,b  add a point light (intensity W/sr), repeatable\n"
           FV_CLI_SCENE_HELP
           "                        (replaces the scene's camera) [the scene's camera, else three-quarter]\n"
           "  --gaze X,Y            gaze point in normalised screen coordinates [the scene's gaze, or 0.5,0.5]\n"
           "  --gaze-trace FILE     gaze over time from a CSV trace (docs/gaze.md)\n"
           "  --gaze-missing P      while the trace's gaze is missing: hold (the last known gaze) or widen (the fovea\n"
           "                        to the whole screen) [the trace's own, hold]\n"
           "  --camera-trace FILE   camera over time from a CSV trace (docs/gaze.md)\n"
           "  --stereo SEP          render a stereo pair with eye separation SEP: OUT_left.ext, OUT_right.ext\n"
           "  --param KEY=VALUE     method parameter, repeatable (fovea methods NAME lists them)\n"
           "  --warmup N            frames rendered before the first written one, unwritten: at frame 0's view, so\n"
           "                        that a temporal method's still is converged; under MPI (docs/distributed.md)\n"
           "                        also the frames each rank's block of a sequence starts with [the method's\n"
           "                        own: fovea methods NAME]\n"
           "  --stats               print every counter of each frame (rays, steps, ...) after its timings\n"
           "  --no-metadata         write images without the metadata that says how they were made (method,\n"
           "                        parameters, camera, gaze, build, date: docs/metrics.md), byte-reproducible\n"
           "  --stats-json FILE     write every frame's stage timings and counters, with the method, its\n"
           "                        parameters and the build, as JSON (written whole at the end)\n"
           "  --quiet               no progress bar, warnings or per-frame lines\n"
           "Exit status: 0 ok, 1 internal error, 2 bad input (the message names it), 128+N interrupted by\n"
           "signal N (130 SIGINT, 143 SIGTERM; also HUP, PIPE, QUIT, USR1, USR2, ALRM: frames already written\n"
           "stay; no partial or temporary file).\n");
}

/* "dir/name.ext" + tag -> "dir/name<tag>.ext" */
static void tagged_path(const char *path, const char *tag, char *out, size_t n)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) dot = path + strlen(path);
    snprintf(out, n, "%.*s%s%s", (int)(dot - path), path, tag, dot);
}

static bool dir_writable(const char *path)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s", path);
    const char *dir = dirname(tmp);
    return access(dir, W_OK | X_OK) == 0;
}

static void print_frame(int f, double ms, const fv_stats *stats, bool show_stats)
{
    double rays = fv_stats_get_count(stats, "rays"), bad = fv_stats_get_count(stats, "nan_samples");
    fprintf(stderr, "frame %d: %.1f ms", f, ms);
    for (int i = 0; i < stats->n_stages; i++) fprintf(stderr, "  %s %.1f ms", stats->stage[i].name, stats->stage[i].value);
    if (rays > 0) fprintf(stderr, "  %.2f Mrays/s", rays / (ms * 1e3));
    if (bad > 0) fprintf(stderr, "  (%.0f NaN/Inf samples discarded)", bad);
    fputc('\n', stderr);
    if (show_stats) {
        fprintf(stderr, "  counters:");
        for (int i = 0; i < stats->n_counters; i++) fprintf(stderr, " %s=%.10g", stats->counter[i].name, stats->counter[i].value);
        fputc('\n', stderr);
        /* each stage's serial part: its time outside parallel regions (docs/threads.md) */
        if (stats->n_serial > 0) {
            fprintf(stderr, "  serial:");
            for (int i = 0; i < stats->n_stages; i++) {
                const double ser = fv_stats_get_serial_ms(stats, stats->stage[i].name), stage_ms = stats->stage[i].value;
                if (ser >= 0.0) fprintf(stderr, "  %s %.1f ms (%.0f%%)", stats->stage[i].name, ser, stage_ms > 0.0 ? 100.0 * ser / stage_ms : 0.0);
            }
            fputc('\n', stderr);
        }
    }
}

typedef struct render_opts {
    const char *scene, *method, *out, *device;
    int width, height, frames, threads, spp;
    int warmup; /* -1: the method's own */
    double fps, time0, exposure, stereo;
    unsigned long long seed;
    bool quiet, show_stats, no_meta, overlay, has_pos, has_look, has_up, has_fov, has_gaze;
    const char *gaze_trace, *camera_trace, *stats_json;
    fv_gaze_missing missing;
    float pos[3], look[3], up[3], fov, gaze[2];
    int nlights;
    float lights[MAX_LIGHTS][6];
    fv_cli_scene_opts scene_opts;  /* --env, --no-default-light, --frame-view */
} render_opts;

/* --overlay: the PNG of a film with the eye model's rings and the gaze cross drawn over a copy of
 * its pixels (gaze/overlay.h), for this eye's gaze; the film itself stays data. */
static fv_status write_overlaid(const fv_film *film, const char *path, float exposure, const fv_eye_model *m, fv_gaze g, const fv_params *meta,
                                fv_error *err)
{
    const int w = fv_film_width(film), h = fv_film_height(film);
    float *rgb = fv_alloc_array((size_t)w * h, 3 * sizeof(float));
    if (!rgb) return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    memcpy(rgb, fv_film_color_const(film), (size_t)w * h * 3 * sizeof(float));
    fv_overlay_draw_rgb(rgb, w, m, g, FV_OVERLAY_ON_IMAGE, exposure);
    fv_status s = fv_image_write_meta(path, rgb, w, h, exposure, meta, err);
    free(rgb);
    return s;
}

/* The method's warm-up frames before frame 0 (fv_driver_warm_up), said in one line unless quiet;
 * bar (may be NULL) is drawn meanwhile. */
static fv_status warm_up(const render_opts *o, const fv_frame_meta_run *rec, fv_driver *driver, fv_technique *tech, fv_film *const *film,
                         fv_progress_fn progress, void *user, fv_cli_progress *bar, fv_error *err)
{
    if (rec->warmup == 0) return FV_OK;
    fv_stats stats;
    fv_stats_clear(&stats);
    double t0 = fv_time_ms();
    fv_status s = fv_driver_warm_up(driver, tech, film, &stats, progress, user, err);
    if (bar) fv_cli_progress_done(bar);
    if (s == FV_OK && bar && !o->quiet)
        fprintf(stderr, "warm-up: %d frame%s at frame 0's view in %.1f ms (--warmup N changes it)\n", rec->warmup, rec->warmup == 1 ? "" : "s",
                fv_time_ms() - t0);
    return s;
}

/* The files of frame f: OUT.ext, OUT_left/_right.ext for stereo, _NNNN before the extension for a
 * sequence; each written whole or not at all, and each saying how it was made (method,
 * parameters, camera, gaze of its eye, ...; docs/metrics.md) unless --no-metadata; with
 * --overlay, the eye model drawn over it for its eye's gaze and the `overlay` key in any case. */
static void frame_path(const render_opts *o, int neyes, int f, int e, char path[4096])
{
    char tmp[4096];
    snprintf(path, 4096, "%s", o->out);
    if (neyes == 2) {
        tagged_path(o->out, e ? "_right" : "_left", tmp, sizeof tmp);
        snprintf(path, 4096, "%s", tmp);
    }
    if (o->frames > 1) {
        char tag[32];
        snprintf(tag, sizeof tag, "_%04d", f);
        tagged_path(path, tag, tmp, sizeof tmp);
        snprintf(path, 4096, "%s", tmp);
    }
}

static fv_status write_frame(const render_opts *o, const fv_frame_meta_run *rec, fv_driver *driver, fv_film *const *film, int neyes,
                             int f, double ms, fv_error *err)
{
    fv_frame_views views;
    fv_driver_views(driver, f, &views);
    fv_status s = FV_OK;
    for (int e = 0; e < neyes && s == FV_OK; e++) {
        char path[4096];
        frame_path(o, neyes, f, e, path);
        fv_params *meta = NULL;
        if (!o->no_meta) s = fv_frame_meta(rec, f, &views, e, ms, &meta, err);
        else if (o->overlay) s = fv_params_create(&meta, err); /* the overlay mark alone (frame_meta.h) */
        if (s == FV_OK && o->overlay) s = fv_frame_meta_overlay(meta, err);
        if (s == FV_OK && o->overlay) s = write_overlaid(film[e], path, (float)o->exposure, views.eye_model, views.gaze[e], meta, err);
        else if (s == FV_OK) s = fv_film_write_meta(film[e], path, (float)o->exposure, meta, err);
        fv_params_destroy(meta);
    }
    return s;
}


static int parse(int argc, char **argv, render_opts *o, fv_params *params)
{
    enum { O_METHOD = 256, O_SPP, O_DEVICE, O_SIZE, O_FRAMES, O_FPS, O_TIME, O_SEED, O_THREADS, O_TPOLICY, O_OUT, O_EXPOSURE, O_POS,
           O_LOOK, O_UP, O_FOV, O_LIGHT, O_GAZE, O_TRACE, O_CTRACE, O_STEREO, O_PARAM, O_QUIET, O_STATS, O_HELP,
           O_MISSING, O_STATS_JSON, O_NO_META, O_WARMUP, O_OVERLAY };
    static const struct option longs[] = {
        {"method", 1, 0, O_METHOD}, {"spp", 1, 0, O_SPP}, {"device", 1, 0, O_DEVICE}, {"size", 1, 0, O_SIZE}, {"frames", 1, 0, O_FRAMES},
        {"fps", 1, 0, O_FPS}, {"time", 1, 0, O_TIME}, {"seed", 1, 0, O_SEED}, {"threads", 1, 0, O_THREADS}, {"thread-policy", 1, 0, O_TPOLICY},
        {"out", 1, 0, O_OUT}, {"exposure", 1, 0, O_EXPOSURE}, {"camera-pos", 1, 0, O_POS}, {"camera-look", 1, 0, O_LOOK},
        {"camera-up", 1, 0, O_UP}, {"fov", 1, 0, O_FOV}, {"point-light", 1, 0, O_LIGHT}, {"gaze", 1, 0, O_GAZE}, {"gaze-trace", 1, 0, O_TRACE}, {"camera-trace", 1, 0, O_CTRACE}, {"gaze-missing", 1, 0, O_MISSING},
        {"stereo", 1, 0, O_STEREO}, {"param", 1, 0, O_PARAM}, {"quiet", 0, 0, O_QUIET}, {"stats", 0, 0, O_STATS}, {"stats-json", 1, 0, O_STATS_JSON}, {"no-metadata", 0, 0, O_NO_META}, {"help", 0, 0, O_HELP}, {"warmup", 1, 0, O_WARMUP},
        {"overlay", 0, 0, O_OVERLAY}, FV_CLI_SCENE_LONGOPTS, {0, 0, 0, 0}};
    const char *cmd = "render";
    long l;
    double d;
    int rc;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        if ((rc = fv_cli_scene_option(cmd, c, optarg, &o->scene_opts)) >= 0) {
            if (rc) return rc;
            continue;
        }
        switch (c) {
        case O_METHOD: o->method = optarg; break;
        case O_DEVICE: o->device = optarg; break;
        case O_SPP:
            if (!fv_cli_parse_int(optarg, 1, 1 << 20, &l)) return fv_cli_usage_error(cmd, "--spp %s: expected an integer in [1, 1048576]", optarg);
            o->spp = (int)l;
            break;
        case O_SIZE:
            if ((rc = fv_cli_opt_size(cmd, optarg, &o->width, &o->height))) return rc;
            break;
        case O_FRAMES:
            if (!fv_cli_parse_int(optarg, 1, 1000000, &l)) return fv_cli_usage_error(cmd, "--frames %s: expected an integer in [1, 1000000]", optarg);
            o->frames = (int)l;
            break;
        case O_FPS:
            if (!fv_cli_parse_float(optarg, &d) || d <= 0) return fv_cli_usage_error(cmd, "--fps %s: expected a positive number", optarg);
            o->fps = d;
            break;
        case O_TIME:
            if (!fv_cli_parse_float(optarg, &d)) return fv_cli_usage_error(cmd, "--time %s: expected a number", optarg);
            o->time0 = d;
            break;
        case O_SEED: {
            char *end;
            errno = 0;
            o->seed = strtoull(optarg, &end, 10);
            if (errno || end == optarg || *end || optarg[0] == '-') return fv_cli_usage_error(cmd, "--seed %s: expected a non-negative integer", optarg);
            break;
        }
        case O_TPOLICY:
            if (fv_cli_opt_thread_policy(cmd, optarg)) return FV_EXIT_USAGE;
            break;
        case O_THREADS:
            if (!fv_cli_parse_int(optarg, 0, 256, &l)) return fv_cli_usage_error(cmd, "--threads %s: expected an integer in [0, 256]", optarg);
            o->threads = (int)l;
            break;
        case O_OUT: o->out = optarg; break;
        case O_EXPOSURE:
            if (!fv_cli_parse_float(optarg, &d) || d <= 0) return fv_cli_usage_error(cmd, "--exposure %s: expected a positive number", optarg);
            o->exposure = d;
            break;
        case O_POS:
            if ((rc = fv_cli_opt_vec3(cmd, "--camera-pos", optarg, o->pos))) return rc;
            o->has_pos = true;
            break;
        case O_LOOK:
            if ((rc = fv_cli_opt_vec3(cmd, "--camera-look", optarg, o->look))) return rc;
            o->has_look = true;
            break;
        case O_UP:
            if ((rc = fv_cli_opt_vec3(cmd, "--camera-up", optarg, o->up))) return rc;
            o->has_up = true;
            break;
        case O_FOV:
            if (!fv_cli_parse_float(optarg, &d) || d <= 0 || d >= 180) return fv_cli_usage_error(cmd, "--fov %s: expected degrees in (0, 180)", optarg);
            o->fov = (float)d;
            o->has_fov = true;
            break;
        case O_LIGHT:
            if (o->nlights >= MAX_LIGHTS) return fv_cli_usage_error(cmd, "--point-light: at most %d lights", MAX_LIGHTS);
            if ((rc = fv_cli_opt_light(cmd, optarg, o->lights[o->nlights]))) return rc;
            o->nlights++;
            break;
        case O_GAZE:
            if ((rc = fv_cli_opt_gaze(cmd, optarg, o->gaze))) return rc;
            o->has_gaze = true;
            break;
        case O_TRACE: o->gaze_trace = optarg; break;
        case O_MISSING:
            if (!fv_gaze_missing_from_name(optarg, &o->missing)) return fv_cli_usage_error(cmd, "--gaze-missing %s: expected hold or widen", optarg);
            break;
        case O_CTRACE: o->camera_trace = optarg; break;
        case O_STEREO:
            if ((rc = fv_cli_opt_stereo(cmd, optarg, &d))) return rc;
            o->stereo = d;
            break;
        case O_PARAM:
            if ((rc = fv_cli_opt_param(cmd, optarg, params))) return rc;
            break;
        case O_WARMUP:
            if (!fv_cli_parse_int(optarg, 0, FV_DRIVE_MAX_WARMUP, &l))
                return fv_cli_usage_error(cmd, "--warmup %s: expected an integer in [0, %d]", optarg, FV_DRIVE_MAX_WARMUP);
            o->warmup = (int)l;
            break;
        case O_QUIET: o->quiet = true; break;
        case O_STATS: o->show_stats = true; break;
        case O_STATS_JSON: o->stats_json = optarg; break;
        case O_NO_META: o->no_meta = true; break;
        case O_OVERLAY: o->overlay = true; break;
        case O_HELP:
        case 'h': help(); return -1;
        default:
            return fv_cli_usage_error(cmd, "unknown or incomplete option '%s' (see fovea render --help)", argv[optind - 1]);
        }
    }
    if (optind < argc) o->scene = argv[optind++];
    if (optind < argc) return fv_cli_usage_error(cmd, "unexpected argument '%s'", argv[optind]);
    return 0;
}

#ifdef FOVEA_HAVE_MPI
/* ---- over MPI ranks (docs/distributed.md; the split itself is src/dist's) ---- */

/* What a split sequence writes beside its frames: OUT without its extension + "_ranks.json". */
static void ranks_path(const char *out, char path[4096])
{
    char noext[4096 - 16];
    snprintf(noext, sizeof noext, "%s", out);
    char *dot = strrchr(noext, '.'), *slash = strrchr(noext, '/');
    if (dot && (!slash || dot > slash)) *dot = '\0';
    snprintf(path, 4096, "%s_ranks.json", noext);
}

/* Every rank's progress through its own work (base + span x the render's fraction) goes to the
 * job's bar (src/dist/dist_progress.h), which rank 0 alone draws. */
typedef struct dist_progress {
    fv_dist *d;
    fv_dist_progress *job;
    fv_cli_progress *bar; /* rank 0's: frames = the job's frames, so "frame k/N" counts the job's */
    double base, span;
} dist_progress;

/* Rank 0: the job's fraction on the bar. */
static void show_job(void *user, double job)
{
    fv_cli_progress *bar = user;
    const double at = job * bar->frames;
    bar->frame = at >= bar->frames ? bar->frames - 1 : (int)at;
    fv_cli_progress_frame(bar, at - bar->frame);
}

/* Every rank; it stops here once another failed or a signal came. */
static bool on_dist_progress(void *user, double f)
{
    dist_progress *p = user;
    if (fv_dist_poll(p->d)) return false;
    fv_dist_progress_update(p->job, p->base + p->span * f);
    return !fv_cli_interrupted();
}

/* Why a still is not split over the ranks (docs/distributed.md, "What is split how"): one line,
 * said by rank 0, which renders it alone. */
static void unsplit_note(const char *method, const fv_params *params, int size, const fv_dist_still_job *job)
{
    char why[200], split[120] = "";
    const int mi = fv_technique_index(method);
    const char *param = NULL, *unsplit = fv_technique_unsplit(mi, &param), *unit = fv_technique_block_unit(mi);
    int n = 1;
    for (int i = 0; param && i < fv_params_count(params); i++)
        if (!strcmp(fv_params_key(params, i), param)) n = atoi(fv_params_value(params, i));
    /* what is split, from the registry: "pt's samples and ppm's passes" */
    for (int i = 0, k = 0; i < fv_technique_count(); i++) {
        if (!fv_technique_block_unit(i)) continue;
        size_t l = strlen(split);
        snprintf(split + l, sizeof split - l, "%s%s's %s", k++ ? " and " : "", fv_technique_name(i), fv_technique_block_unit(i));
    }
    if (unsplit && n > 1)
        snprintf(why, sizeof why, "%s's %d %s are %s; %s are split", method, n, param, unsplit, split);
    else if (!unit)
        snprintf(why, sizeof why, "only %s are split", split);
    else if (job->other_device)
        snprintf(why, sizeof why, "it runs on a device other than the cpu");
    else
        snprintf(why, sizeof why, "%s %s fit in one block of 64", job->spp > 0 ? "its" : "its default", unit);
    fprintf(stderr, "mpi: the still is not split over %d ranks (%s): rank 0 renders it alone\n", size, why);
}

/* The one line of a failed job, on the rank the agreement chose: "rank R: fovea render: ..." when
 * not every rank failed (as the held messages of the set-up are replayed), else as one process. */
static int dist_fail(fv_dist *d, fv_status s, bool print_it, bool name_rank, const char *msg)
{
    /* Interrupted (a signal on any rank): as one process, "fovea render: interrupted (SIGTERM)"
     * without a rank, 128 + the signal on every rank, not a failure of the signalled rank. */
    const int sig = s == FV_ERR_CANCELLED ? fv_dist_signal(d) : 0;
    if (sig) return fv_cli_interrupt_exit_as(sig, print_it);
    fv_cli_interrupt_mute(); /* the launcher may now signal this rank: the job's line is said once */
    if (print_it) {
        if (name_rank) fprintf(stderr, "rank %d: ", fv_dist_rank(d));
        return fv_cli_fail("render", s, msg);
    }
    return fv_cli_exit_code(s);
}

static int render_dist(fv_dist *d, const render_opts *o, const fv_frame_meta_run *rec, const fv_params *params, const fv_scene *scene,
                       const fv_log *log, fv_driver *driver, fv_technique *tech, fv_film **film, int neyes)
{
    const int rank = fv_dist_rank(d), size = fv_dist_size(d);
    if (rank == 0 && o->stats_json) fv_log_warn(log, "--stats-json: not written by a run split over MPI ranks (yet)");
    fv_error err;
    fv_error_clear(&err);
    fv_status s = FV_OK;
    bool print_it = false, name_rank = false;
    fv_cli_progress bar;
    fv_cli_progress_init(&bar, o->quiet || rank != 0, o->frames);
    /* Launchers give a rank a terminal for stdout, not for stderr: rank 0 draws the bar when
     * the job's output is a terminal. */
    if (rank == 0 && !o->quiet) bar.enabled = bar.tty = isatty(STDOUT_FILENO);
    dist_progress dp = {d, NULL, &bar, 0.0, 1.0};
    double t0 = fv_time_ms();
    fv_stats stats;
    fv_stats_clear(&stats);
    fv_cli_interrupt_defer(true);
    if (o->frames == 1) {
        fv_dist_still_job job;
        fv_dist_still_job_init(&job, o->method, params, scene, log, driver, 0);
        job.progress = on_dist_progress;
        job.progress_user = &dp;
        const bool split = fv_dist_still_splits(&job, size);
        s = fv_dist_progress_start(d, split ? fv_dist_still_share(&job, rank, size) : rank == 0, show_job, &bar, &dp.job, &err);
        if (s == FV_OK && split) {
            s = fv_dist_still(d, &job, film, neyes, &stats, &print_it, &name_rank, &err);
        } else {
            /* Not split (docs/distributed.md says which stills are): rank 0 renders it alone. */
            if (s == FV_OK && rank == 0 && !o->quiet) unsplit_note(o->method, params, size, &job);
            const double wu = rec->warmup, all = wu + 1.0; /* the still's warm-up frames, then the still */
            dp.span = wu / all;
            if (s == FV_OK && rank == 0) s = warm_up(o, rec, driver, tech, film, on_dist_progress, &dp, &bar, &err);
            dp.base = wu / all, dp.span = 1.0 / all;
            if (rank == 0 && s == FV_OK) s = fv_driver_render(driver, tech, 0, rec->warmup > 0, film, &stats, on_dist_progress, &dp, &err);
            s = fv_dist_agree(d, s, &print_it, &name_rank, &err);
        }
        fv_dist_progress_end(dp.job, s == FV_OK);
        double ms = fv_time_ms() - t0;
        fv_cli_progress_done(&bar);
        if (s != FV_OK) return dist_fail(d, s, print_it, name_rank, err.msg);
        fv_cli_interrupt_defer(false);
        if (rank != 0) return FV_EXIT_OK;
        if ((s = write_frame(o, rec, driver, film, neyes, 0, ms, &err)) != FV_OK) return fv_cli_fail("render", s, err.msg);
        if (!o->quiet) {
            print_frame(0, ms, &stats, o->show_stats);
            fprintf(stderr, "mpi: %d ranks; rank 0 moved data for %.3f s, waited for the others %.3f s\n", size,
                    fv_dist_comm_seconds(d), fv_dist_wait_seconds(d));
        }
        return FV_EXIT_OK;
    }
    /* A sequence: this rank's block of frames, after its warm-up frames. */
    const int mi = fv_technique_index(o->method), seq = fv_technique_warmup_frames(mi), still = fv_technique_still_warmup(mi);
    int warmup = o->warmup >= 0 ? o->warmup : seq > still ? seq : still, start, first, end;
    fv_dist_frames(o->frames, rank, size, warmup, &start, &first, &end);
    /* this rank's work: the still's warm-up frames (the block at frame 0), then its frames */
    const double wu = start == 0 ? rec->warmup : 0, all = wu + (end > start ? end - start : 0);
    s = fv_dist_progress_start(d, fv_dist_frames_share(o->frames, rank, size, warmup, rec->warmup), show_job, &bar, &dp.job, &err);
    dp.span = all > 0 ? wu / all : 0.0;
    /* the block that starts the sequence warms up as one process does, at frame 0's views */
    if (s == FV_OK && start == 0) s = warm_up(o, rec, driver, tech, film, on_dist_progress, &dp, rank == 0 ? &bar : NULL, &err);
    for (int f = start; f < end && s == FV_OK && !fv_cli_interrupted(); f++) {
        fv_stats_clear(&stats);
        dp.base = (wu + (f - start)) / all, dp.span = 1.0 / all;
        double f0 = fv_time_ms();
        s = fv_driver_render(driver, tech, f, f > start || (start == 0 && rec->warmup > 0), film, &stats, on_dist_progress, &dp, &err);
        if (s == FV_OK && f >= first) s = write_frame(o, rec, driver, film, neyes, f, fv_time_ms() - f0, &err);
        if (s != FV_OK) {
            /* the others stop at their next progress step (unless this rank only stopped for another) */
            if (!fv_dist_poll(d)) fv_dist_tell_failure(d);
        } else if (!o->quiet && rank == 0) {
            fv_cli_progress_done(&bar);
            if (f < first) fprintf(stderr, "(warm-up) ");
            print_frame(f, fv_time_ms() - f0, &stats, o->show_stats);
        }
    }
    if (s == FV_OK && fv_cli_interrupted()) s = fv_error_set(&err, FV_ERR_CANCELLED, "interrupted");
    /* Signals stay deferred through the agreement: once a rank fails and exits, the launcher
     * signals the others, which must end with the job's one line, not one each. */
    s = fv_dist_agree(d, s, &print_it, &name_rank, &err);
    fv_dist_progress_end(dp.job, s == FV_OK);
    fv_cli_progress_done(&bar);
    if (s != FV_OK) return dist_fail(d, s, print_it, name_rank, err.msg);
    fv_cli_interrupt_defer(false);
    if (rank != 0) return FV_EXIT_OK;
    /* What was split how, beside the frames: OUT_ranks.json. */
    char path[4096];
    ranks_path(o->out, path);
    if ((s = fv_dist_frames_manifest(path, o->method, o->frames, size, warmup, &err)) != FV_OK) return fv_cli_fail("render", s, err.msg);
    if (!o->quiet)
        fprintf(stderr, "mpi: %d ranks wrote %d frames (%d warm-up frames per block; %s)\n", size, o->frames, warmup, path);
    return FV_EXIT_OK;
}
#endif

/* Every file the command will write (frames, eyes, --stats-json, a split sequence's manifest),
 * checked against the files it reads before anything is loaded (core/inputs.h): 0 or the exit
 * code. A sequence of a million frames costs as many stat calls, a second at most. */
static int check_outputs(const render_opts *o, bool dist)
{
    const char *cmd = "render";
    fv_inputs in;
    fv_inputs_init(&in);
    fv_inputs_add(&in, o->scene, "scene file");
    fv_inputs_add(&in, o->gaze_trace, "gaze trace");
    fv_inputs_add(&in, o->camera_trace, "camera trace");
    int rc = o->stats_json ? fv_cli_check_output(cmd, &in, o->stats_json, "--stats-json") : 0;
    const int neyes = o->stereo > 0 ? 2 : 1;
    for (int f = 0; f < o->frames && rc == 0; f++)
        for (int e = 0; e < neyes && rc == 0; e++) {
            char path[4096];
            frame_path(o, neyes, f, e, path);
            rc = fv_cli_check_output(cmd, &in, path, "--out");
        }
#ifdef FOVEA_HAVE_MPI
    if (rc == 0 && dist && o->frames > 1) {
        char path[4096];
        ranks_path(o->out, path);
        rc = fv_cli_check_output(cmd, &in, path, "--out's manifest");
    }
#else
    (void)dist;
#endif
    return rc;
}

/* dist: the MPI job (fv_dist *) when launched over several ranks, else NULL. */
static int render(int argc, char **argv, void *dist)
{
    const char *cmd = "render";
    render_opts o;
    memset(&o, 0, sizeof o);
    o.scene = "cornell";
    o.method = "pt";
    o.out = "fovea.png";
    o.width = o.height = 512;
    o.frames = 1;
    o.warmup = -1;
    o.fps = 30.0;
    o.exposure = 1.0;
    o.seed = 1;
    o.gaze[0] = o.gaze[1] = 0.5f;
    fv_error err;
    fv_error_clear(&err);
    fv_params *params = NULL;
    fv_scene *scene = NULL;
    fv_view *view = NULL;
    fv_technique *tech = NULL;
    fv_driver *driver = NULL;
    fv_film *film[2] = {NULL, NULL}, *film_b[2] = {NULL, NULL}; /* film_b: a sequence's second set */
    fv_gaze_path *trace = NULL;
    fv_camera_path ctrace = {NULL, 0};
    fv_stats_log *slog = NULL;
    int rc = FV_EXIT_OK;
    fv_status s;
    bool setup_agreed = false;

    if ((s = fv_params_create(&params, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    int pr = parse(argc, argv, &o, params);
    if (pr != 0) {
        rc = pr < 0 ? FV_EXIT_OK : pr;
        if (pr < 0) setup_agreed = true; /* --help: every rank printed it, nothing to agree */
        goto done;
    }
    /* Cheap checks first: nothing is loaded or rendered for a typo. */
    if ((s = fv_film_check_size(o.width, o.height, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    fv_image_format fmt = fv_image_format_from_path(o.out);
    if (fmt == FV_IMG_UNKNOWN) {
        rc = fv_cli_usage_error(cmd, "--out %s: unknown image format (use .png, .pfm or .exr)", o.out);
        goto done;
    }
    /* The rings are drawn over the pixels: only where the pixels are a picture, never over the
     * linear data of PFM and EXR (what compare, the bench and other tools read as radiance). */
    if (o.overlay && fmt != FV_IMG_PNG) {
        rc = fv_cli_usage_error(cmd, "--overlay: draws over a .png only; %s would hold linear data (write a .png, or leave --overlay out)", o.out);
        goto done;
    }
    if (!dir_writable(o.out)) {
        rc = fv_cli_usage_error(cmd, "--out %s: cannot write there (%s)", o.out, strerror(errno));
        goto done;
    }
    if (o.stats_json && (!o.stats_json[0] || !dir_writable(o.stats_json))) {
        rc = fv_cli_usage_error(cmd, "--stats-json %s: cannot write there (%s)", o.stats_json, o.stats_json[0] ? strerror(errno) : "empty path");
        goto done;
    }
    if ((rc = check_outputs(&o, dist != NULL)) != 0) goto done;
    if ((rc = fv_cli_check_method(cmd, o.method)) != 0) goto done;
    if (o.device) {
        fv_device dev;
        if ((s = fv_device_check(o.method, o.device, &dev, &err)) != FV_OK || (s = fv_params_set(params, "device", o.device, &err)) != FV_OK) {
            rc = fv_cli_fail(cmd, s, err.msg);
            goto done;
        }
    }
    if (o.spp > 0 && (s = fv_technique_set_spp(o.method, params, o.spp, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }

    bool quiet = o.quiet;
    fv_log log = fv_cli_log(&quiet);
    o.scene_opts.nlights = o.nlights;
    o.scene_opts.lights = (const float(*)[6])o.lights;
    if ((rc = fv_cli_open_scene(cmd, o.scene, &log, &o.scene_opts, &scene, &view)) != 0) goto done;
    if ((s = fv_technique_create(o.method, scene, params, &log, &tech, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    if (o.has_gaze && o.gaze_trace) {
        rc = fv_cli_usage_error(cmd, "--gaze and --gaze-trace exclude each other");
        goto done;
    }
    if (o.gaze_trace && (s = fv_gaze_path_load_csv(o.gaze_trace, &trace, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    if (o.camera_trace) {
        fv_camera base;
        fv_view_camera(view, scene, o.time0, o.width, o.height, &base);
        if ((s = fv_camera_path_load_csv(o.camera_trace, &base, &ctrace.keys, &ctrace.count, &err)) != FV_OK) {
            rc = fv_cli_fail(cmd, s, err.msg);
            goto done;
        }
    }
    /* Everything else (which camera, gaze and eye model each frame gets) is the sequence
     * driver's policy, shared with the bench and the viewer (fovea/drive.h). */
    fv_drive_opts dopt;
    fv_drive_opts_init(&dopt);
    dopt.width = o.width;
    dopt.height = o.height;
    dopt.time0 = o.time0;
    dopt.fps = o.fps;
    dopt.seed = o.seed;
    dopt.threads = o.threads;
    dopt.eye_separation = (float)o.stereo;
    dopt.camera_path = ctrace.keys ? &ctrace : NULL;
    if (o.has_pos) dopt.camera_set |= FV_DRIVE_POS, dopt.pos = fv_v3(o.pos[0], o.pos[1], o.pos[2]);
    if (o.has_look) dopt.camera_set |= FV_DRIVE_LOOK, dopt.look = fv_v3(o.look[0], o.look[1], o.look[2]);
    if (o.has_up) dopt.camera_set |= FV_DRIVE_UP, dopt.up = fv_v3(o.up[0], o.up[1], o.up[2]);
    if (o.has_fov) dopt.camera_set |= FV_DRIVE_FOV, dopt.fov_y = o.fov;
    dopt.fixed_gaze = o.has_gaze;
    dopt.gaze = (fv_gaze){o.gaze[0], o.gaze[1]};
    dopt.gaze_path = trace;
    dopt.gaze_missing = o.missing;
    /* A temporal method's still is converged: its warm-up frames first (fovea methods NAME). */
    dopt.warmup = o.warmup >= 0 ? o.warmup : fv_technique_still_warmup(fv_technique_index(o.method));
    if ((s = fv_driver_create(scene, view, &dopt, &driver, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    fv_frame_meta_run rec = {o.method, o.scene, params, o.width, o.height, o.threads, o.seed, (float)o.exposure, dopt.warmup};
    if (o.stats_json && !dist && (s = fv_stats_log_create(&rec, &slog, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    unsigned aux = fmt == FV_IMG_EXR ? FV_AUX_ALL : 0;
    int neyes = fv_driver_eye_count(driver);
    for (int e = 0; e < neyes; e++)
        if ((s = fv_film_create(o.width, o.height, aux, &film[e], &err)) != FV_OK) {
            rc = fv_cli_fail(cmd, s, err.msg);
            goto done;
        }

#ifdef FOVEA_HAVE_MPI
    if (dist) {
        /* Every rank set up alike: agree, so a problem is said once, then split the work. */
        bool print_it, name_rank;
        setup_agreed = true;
        if ((s = fv_dist_agree(dist, FV_OK, &print_it, &name_rank, &err)) != FV_OK) {
            fv_cli_interrupt_mute(); /* another rank says the job's line; the launcher may signal this one */
            rc = fv_cli_exit_code(s);
            goto done;
        }
        rc = render_dist(dist, &o, &rec, params, scene, &log, driver, tech, film, neyes);
        goto done;
    }
#endif
    /* From here a signal stops the render at its next cancellation point (the progress callback
     * cancels) or after the frame's files are written, not at once (cli.h). */
    fv_cli_progress prog;
    fv_cli_progress_init(&prog, o.quiet, o.frames);
    fv_cli_interrupt_defer(true);
    s = warm_up(&o, &rec, driver, tech, film, fv_cli_progress_frame, &prog, &prog, &err);
    /* A sequence is pipelined (docs/gpu.md, "Frames in flight"): frame f+1 is submitted before
     * frame f is collected and written, each into its own films and stats, so that a device runs
     * f+1 while the host writes f. The files are those of rendering the frames one by one: a
     * submit that is cancelled or fails still lets the frame before it be written, and whatever
     * is in flight when the loop stops is collected and dropped. */
    for (int e = 0; e < neyes && s == FV_OK && o.frames > 1; e++) s = fv_film_create(o.width, o.height, aux, &film_b[e], &err);
    /* PNGs without an overlay need nothing but what a display shows: a device frame converts there
     * and reads back 4 bytes a pixel instead of 12 (docs/gpu.md, "Display output on the device") */
    const bool display_only = fmt == FV_IMG_PNG && !o.overlay;
    for (int e = 0; e < neyes && s == FV_OK && display_only; e++) {
        s = fv_film_set_display(film[e], (float)o.exposure, &err);
        if (s == FV_OK && film_b[e]) s = fv_film_set_display(film_b[e], (float)o.exposure, &err);
    }
    fv_film *const sets[2][2] = {{film[0], film[1]}, {film_b[0], film_b[1]}};
    fv_stats stats[2];
    double frame_ms[2] = {0.0, 0.0}; /* each frame's time in its submit and collect */
    if (s == FV_OK && o.frames > 0 && !fv_cli_interrupted()) {
        fv_stats_clear(&stats[0]);
        const double t0 = fv_time_ms();
        s = fv_driver_submit(driver, tech, 0, rec.warmup > 0, sets[0], &stats[0], fv_cli_progress_frame, &prog, &err);
        frame_ms[0] = fv_time_ms() - t0;
    }
    for (int f = 0; f < o.frames && s == FV_OK; f++) {
        const int k = f % 2, kn = (f + 1) % 2;
        const bool more = f + 1 < o.frames && !fv_cli_interrupted();
        fv_status sn = FV_OK;
        fv_error errn;
        if (more) {
            fv_stats_clear(&stats[kn]);
            prog.frame = f + 1;
            const double t0 = fv_time_ms();
            sn = fv_driver_submit(driver, tech, f + 1, true, sets[kn], &stats[kn], fv_cli_progress_frame, &prog, &errn);
            frame_ms[kn] = fv_time_ms() - t0;
        }
        const double t0 = fv_time_ms();
        s = fv_driver_collect(driver, tech, &err);
        const double ms = frame_ms[k] + fv_time_ms() - t0;
        fv_frame_views views;
        fv_driver_views(driver, f, &views);
        if (s == FV_OK && slog) s = fv_stats_log_add(slog, f, &views, ms, &stats[k], &err);
        if (s == FV_OK) s = write_frame(&o, &rec, driver, sets[k], neyes, f, ms, &err);
        if (s != FV_OK) break;
        if (!o.quiet) {
            fv_cli_progress_done(&prog);
            if (o.show_stats && f == 0) fprintf(stderr, "  threads: %d (%s)\n", fv_thread_count(o.threads), fv_cli_thread_plan());
            print_frame(f, ms, &stats[k], o.show_stats);
        }
        if (!more) break;
        if (sn != FV_OK) s = sn, err = errn;
    }
    while (fv_technique_in_flight(tech) > 0) {
        fv_error dropped;
        (void)fv_driver_collect(driver, tech, &dropped);
    }
    fv_cli_interrupt_defer(false);
    fv_cli_progress_done(&prog);
    /* The log of the frames that were rendered, also after an interruption ("complete": false). */
    if (slog) {
        fv_error werr;
        fv_status ws = fv_stats_log_write(slog, o.stats_json, s == FV_OK && !fv_cli_interrupted(), &werr);
        if (ws != FV_OK && s == FV_OK) s = ws, err = werr;
    }
    if (fv_cli_interrupted()) rc = fv_cli_interrupt_exit();
    else if (s != FV_OK) rc = fv_cli_fail(cmd, s, err.msg);
done:
#ifdef FOVEA_HAVE_MPI
    if (dist && !setup_agreed) {
        /* This rank failed before the split: its message (held) is replayed if the agreement
         * picks it, and every rank ends with the job's exit status. */
        bool print_it, name_rank;
        fv_cli_interrupt_mute(); /* the job has failed: its one line is this rank's or another's */
        fv_status js = fv_dist_agree(dist, rc == FV_EXIT_INTERNAL ? FV_ERR_INTERNAL : FV_ERR_INVALID, &print_it, &name_rank, &err);
        rc = fv_cli_exit_code(js);
    }
#else
    (void)dist;
    (void)setup_agreed;
#endif
    fv_stats_log_destroy(slog);
    fv_driver_destroy(driver);
    fv_gaze_path_destroy(trace);
    fv_camera_keys_free(ctrace.keys);
    fv_film_destroy(film[0]);
    fv_film_destroy(film[1]);
    fv_film_destroy(film_b[0]);
    fv_film_destroy(film_b[1]);
    fv_technique_destroy(tech);
    fv_scene_destroy(scene);
    fv_view_destroy(view);
    fv_params_destroy(params);
    return rc;
}

int fv_cmd_render(int argc, char **argv)
{
#ifdef FOVEA_HAVE_MPI
    /* Launched as one rank of several (mpirun, srun): the job is split (docs/distributed.md). */
    if (fv_dist_launched()) {
        fv_dist *d = NULL;
        fv_error err;
        fv_error_clear(&err);
        fv_status s = fv_dist_start(NULL, NULL, &d, &err);
        if (s != FV_OK) return fv_cli_fail("render", s, err.msg);
        fv_dist_set_signal_source(d, fv_cli_interrupted);
        if (fv_dist_size(d) > 1 && (s = fv_dist_hold(d, &err)) != FV_OK) {
            fv_dist_end(d);
            return fv_cli_fail("render", s, err.msg);
        }
        int rc = render(argc, argv, fv_dist_size(d) > 1 ? d : NULL);
        fv_dist_end(d);
        return rc;
    }
#endif
    return render(argc, argv, NULL);
}
