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
#include "core/parallel.h"

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
           "  --stats               print every counter of each frame (rays, steps, ...) after its timings\n"
           "  --quiet               no progress bar, warnings or per-frame lines\n"
           "Exit status: 0 ok, 1 internal error, 2 bad input (the message names it), 130/143 interrupted by\n"
           "SIGINT/SIGTERM (frames already written stay; no partial or temporary file).\n");
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

typedef struct render_opts {
    const char *scene, *method, *out, *device;
    int width, height, frames, threads, spp;
    double fps, time0, exposure, stereo;
    unsigned long long seed;
    bool quiet, show_stats, has_pos, has_look, has_up, has_fov, has_gaze;
    const char *gaze_trace, *camera_trace;
    fv_gaze_missing missing;
    float pos[3], look[3], up[3], fov, gaze[2];
    int nlights;
    float lights[MAX_LIGHTS][6];
    fv_cli_scene_opts scene_opts;  /* --env, --no-default-light, --frame-view */
} render_opts;

static int parse(int argc, char **argv, render_opts *o, fv_params *params)
{
    enum { O_METHOD = 256, O_SPP, O_DEVICE, O_SIZE, O_FRAMES, O_FPS, O_TIME, O_SEED, O_THREADS, O_TPOLICY, O_OUT, O_EXPOSURE, O_POS,
           O_LOOK, O_UP, O_FOV, O_LIGHT, O_GAZE, O_TRACE, O_CTRACE, O_STEREO, O_PARAM, O_QUIET, O_STATS, O_HELP,
           O_MISSING };
    static const struct option longs[] = {
        {"method", 1, 0, O_METHOD}, {"spp", 1, 0, O_SPP}, {"device", 1, 0, O_DEVICE}, {"size", 1, 0, O_SIZE}, {"frames", 1, 0, O_FRAMES},
        {"fps", 1, 0, O_FPS}, {"time", 1, 0, O_TIME}, {"seed", 1, 0, O_SEED}, {"threads", 1, 0, O_THREADS}, {"thread-policy", 1, 0, O_TPOLICY},
        {"out", 1, 0, O_OUT}, {"exposure", 1, 0, O_EXPOSURE}, {"camera-pos", 1, 0, O_POS}, {"camera-look", 1, 0, O_LOOK},
        {"camera-up", 1, 0, O_UP}, {"fov", 1, 0, O_FOV}, {"point-light", 1, 0, O_LIGHT}, {"gaze", 1, 0, O_GAZE}, {"gaze-trace", 1, 0, O_TRACE}, {"camera-trace", 1, 0, O_CTRACE}, {"gaze-missing", 1, 0, O_MISSING},
        {"stereo", 1, 0, O_STEREO}, {"param", 1, 0, O_PARAM}, {"quiet", 0, 0, O_QUIET}, {"stats", 0, 0, O_STATS}, {"help", 0, 0, O_HELP},
        FV_CLI_SCENE_LONGOPTS, {0, 0, 0, 0}};
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
        case O_QUIET: o->quiet = true; break;
        case O_STATS: o->show_stats = true; break;
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

int fv_cmd_render(int argc, char **argv)
{
    const char *cmd = "render";
    render_opts o;
    memset(&o, 0, sizeof o);
    o.scene = "cornell";
    o.method = "pt";
    o.out = "fovea.png";
    o.width = o.height = 512;
    o.frames = 1;
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
    fv_film *film[2] = {NULL, NULL};
    fv_gaze_path *trace = NULL;
    fv_camera_path ctrace = {NULL, 0};
    int rc = FV_EXIT_OK;
    fv_status s;

    if ((s = fv_params_create(&params, &err)) != FV_OK) return fv_cli_fail(cmd, s, err.msg);
    int pr = parse(argc, argv, &o, params);
    if (pr != 0) {
        fv_params_destroy(params);
        return pr < 0 ? FV_EXIT_OK : pr;
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
    if (!dir_writable(o.out)) {
        rc = fv_cli_usage_error(cmd, "--out %s: cannot write there (%s)", o.out, strerror(errno));
        goto done;
    }
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
    if ((s = fv_driver_create(scene, view, &dopt, &driver, &err)) != FV_OK) {
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

    /* From here a signal stops the render at its next cancellation point (the progress callback
     * cancels) or after the frame's files are written, not at once (cli.h). */
    fv_cli_progress prog;
    fv_cli_progress_init(&prog, o.quiet, o.frames);
    fv_cli_interrupt_defer(true);
    for (int f = 0; f < o.frames && !fv_cli_interrupted(); f++) {
        fv_stats stats;
        fv_stats_clear(&stats);
        prog.frame = f;
        double t0 = fv_time_ms();
        if ((s = fv_driver_render(driver, tech, f, f > 0, film, &stats, fv_cli_progress_frame, &prog, &err)) != FV_OK) break;
        double ms = fv_time_ms() - t0;
        for (int e = 0; e < neyes && s == FV_OK; e++) {
            char path[4096], tmp[4096];
            snprintf(path, sizeof path, "%s", o.out);
            if (neyes == 2) {
                tagged_path(o.out, e ? "_right" : "_left", tmp, sizeof tmp);
                snprintf(path, sizeof path, "%s", tmp);
            }
            if (o.frames > 1) {
                char tag[32];
                snprintf(tag, sizeof tag, "_%04d", f);
                tagged_path(path, tag, tmp, sizeof tmp);
                snprintf(path, sizeof path, "%s", tmp);
            }
            s = fv_film_write(film[e], path, (float)o.exposure, &err);
        }
        if (s != FV_OK) break;
        if (!o.quiet) {
            fv_cli_progress_done(&prog);
            double rays = fv_stats_get_count(&stats, "rays"), bad = fv_stats_get_count(&stats, "nan_samples");
            fprintf(stderr, "frame %d: %.1f ms", f, ms);
            for (int i = 0; i < stats.n_stages; i++) fprintf(stderr, "  %s %.1f ms", stats.stage[i].name, stats.stage[i].value);
            if (rays > 0) fprintf(stderr, "  %.2f Mrays/s", rays / (ms * 1e3));
            if (bad > 0) fprintf(stderr, "  (%.0f NaN/Inf samples discarded)", bad);
            fputc('\n', stderr);
            if (o.show_stats) {
                if (f == 0) fprintf(stderr, "  threads: %d (%s)\n", fv_thread_count(o.threads), fv_cli_thread_plan());
                fprintf(stderr, "  counters:");
                for (int i = 0; i < stats.n_counters; i++) fprintf(stderr, " %s=%.10g", stats.counter[i].name, stats.counter[i].value);
                fputc('\n', stderr);
            }
        }
    }
    fv_cli_interrupt_defer(false);
    fv_cli_progress_done(&prog);
    if (fv_cli_interrupted()) rc = fv_cli_interrupt_exit();
    else if (s != FV_OK) rc = fv_cli_fail(cmd, s, err.msg);
done:
    fv_driver_destroy(driver);
    fv_gaze_path_destroy(trace);
    fv_camera_keys_free(ctrace.keys);
    fv_film_destroy(film[0]);
    fv_film_destroy(film[1]);
    fv_technique_destroy(tech);
    fv_scene_destroy(scene);
    fv_view_destroy(view);
    fv_params_destroy(params);
    return rc;
}
