/* fovea-view — the command line. Values are checked with the CLI's own parsers and messages
 * (tools/fovea/cli.c), so `fovea view` and `fovea render` reject the same typos the same way. */
#include <getopt.h>
#include <string.h>
#include "cli.h"
#include "view.h"

static void help(void)
{
    printf("usage: fovea view [SCENE] [options]\n"
           "  SCENE                 built-in name (fovea scenes) or a scene file [cornell]\n"
           "  --method NAME         rendering method (fovea methods) [%s]\n"
           "  --param KEY=VALUE     method parameter, repeatable (fovea methods NAME lists them)\n"
           "  --device D            cpu, portable, cuda or auto, for the methods that have it (docs/gpu.md) [cpu]\n"
           "  --size WxH            window size [640x360]\n"
           "  --scale S             render at S x the window size, scaled to it [1]\n"
           "  --gaze X,Y            fixed gaze (normalised) instead of the mouse\n"
           "  --gaze-trace FILE     replay a gaze trace (docs/gaze.md) instead of the mouse\n"
           "  --stereo SEP          left and right eye side by side, eye separation SEP\n"
           "  --threads N           worker threads, 0 = the thread policy's default [0]\n"
           FV_CLI_THREAD_POLICY_HELP
           FV_CLI_SCENE_HELP
           "  --script FILE         timed commands by frame number (docs/viewer.md)\n"
           "  --fps-log FILE        one CSV line per frame: render and frame milliseconds\n"
           "Keys: Tab/Shift-Tab method, +/- main parameter, V split with the baseline, O overlay, H text,\n"
           "WASD/QE move, right-drag look, P pause, R record gaze+camera, F12 screenshot, Esc quit.\n"
           "Exit status: 0 ok, 1 internal error, 2 bad input or no display.\n",
           fv_technique_default_interactive());
}

int fv_vw_args_parse(int argc, char **argv, fv_vw_args *a)
{
    enum { O_METHOD = 256, O_PARAM, O_DEVICE, O_SIZE, O_SCALE, O_GAZE, O_TRACE, O_STEREO, O_THREADS, O_TPOLICY, O_SCRIPT, O_FPSLOG, O_HELP };
    static const struct option longs[] = {
        {"method", 1, 0, O_METHOD}, {"param", 1, 0, O_PARAM}, {"device", 1, 0, O_DEVICE},   {"size", 1, 0, O_SIZE},       {"scale", 1, 0, O_SCALE},
        {"gaze", 1, 0, O_GAZE},     {"gaze-trace", 1, 0, O_TRACE}, {"stereo", 1, 0, O_STEREO}, {"threads", 1, 0, O_THREADS}, {"thread-policy", 1, 0, O_TPOLICY},
        {"script", 1, 0, O_SCRIPT}, {"fps-log", 1, 0, O_FPSLOG}, {"help", 0, 0, O_HELP},
        FV_CLI_SCENE_LONGOPTS, {0, 0, 0, 0}};
    const char *cmd = "view";
    long l;
    double d;
    int rc;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        if ((rc = fv_cli_scene_option(cmd, c, optarg, &a->scene_opts)) >= 0) {
            if (rc) return rc;
            continue;
        }
        switch (c) {
        case O_METHOD: a->method = optarg; break;
        case O_DEVICE: a->device = optarg; break;
        case O_PARAM:
            if ((rc = fv_cli_opt_param(cmd, optarg, a->params))) return rc;
            break;
        case O_SIZE:
            if ((rc = fv_cli_opt_size(cmd, optarg, &a->width, &a->height))) return rc;
            break;
        case O_SCALE:
            if (!fv_cli_parse_float(optarg, &d) || d <= 0 || d > 4) return fv_cli_usage_error(cmd, "--scale %s: expected a number in (0, 4]", optarg);
            a->scale = d;
            break;
        case O_GAZE:
            if ((rc = fv_cli_opt_gaze(cmd, optarg, a->gaze))) return rc;
            a->has_gaze = true;
            break;
        case O_TRACE: a->gaze_trace = optarg; break;
        case O_STEREO:
            if ((rc = fv_cli_opt_stereo(cmd, optarg, &d))) return rc;
            a->stereo = d;
            break;
        case O_TPOLICY:
            if (fv_cli_opt_thread_policy(cmd, optarg)) return FV_EXIT_USAGE;
            break;
        case O_THREADS:
            if (!fv_cli_parse_int(optarg, 0, 256, &l)) return fv_cli_usage_error(cmd, "--threads %s: expected an integer in [0, 256]", optarg);
            a->threads = (int)l;
            break;
        case O_SCRIPT: a->script = optarg; break;
        case O_FPSLOG: a->fps_log = optarg; break;
        case O_HELP:
        case 'h': help(); return -1;
        default: return fv_cli_usage_error(cmd, "unknown or incomplete option '%s' (see fovea view --help)", argv[optind - 1]);
        }
    }
    if (optind < argc) a->scene = argv[optind++];
    if (optind < argc) return fv_cli_usage_error(cmd, "unexpected argument '%s'", argv[optind]);
    if (a->has_gaze && a->gaze_trace) return fv_cli_usage_error(cmd, "--gaze and --gaze-trace exclude each other");
    return 0;
}
