/* fovea CLI — `fovea gaze import IN --out TRACE.csv`: an eye tracker's recording (EyeLink ASC,
 * Pupil Labs gaze_positions.csv) into the gaze trace format `fovea render --gaze-trace` reads. */
#include <getopt.h>
#include <string.h>
#include "cli.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: fovea gaze import RECORDING --out TRACE.csv [options]\n"
               "Converts an eye tracker's recording into a gaze trace (docs/gaze.md): normalised coordinates,\n"
               "seconds from the first sample, blinks and lost samples as missing (empty) fields.\n\n"
               "  RECORDING             an EyeLink .asc sample file or a Pupil Labs gaze_positions.csv (either may\n"
               "                        be gzip-compressed: .asc.gz)\n"
               "  --out FILE            the trace to write (required)\n"
               "  --format F            eyelink | pupil [from the extension: .asc, .csv]\n"
               "  --confidence C        Pupil: samples below this confidence are missing [0.6]\n"
               "  --screen WxH          EyeLink: the screen in pixels, instead of DISPLAY_COORDS\n"
               "  --eye E               left | right | both (the mean of the two eyes) | each (a five-column\n"
               "                        trace: each eye its own gaze, for stereo renders)\n"
               "                        [EyeLink: each eye as recorded; Pupil: both]\n"
               "  --quiet               no summary line\n");
}

int fv_cmd_gaze(int argc, char **argv)
{
    const char *cmd = "gaze import";
    if (argc < 2 || strcmp(argv[1], "import") != 0) {
        if (argc >= 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
            usage(stdout);
            return FV_EXIT_OK;
        }
        return fv_cli_usage_error("gaze", "expected 'import' (try fovea gaze --help)");
    }
    argc--, argv++;
    enum { O_OUT = 256, O_FORMAT, O_CONF, O_SCREEN, O_QUIET, O_HELP, O_EYE };
    static const struct option longs[] = {{"out", 1, 0, O_OUT},       {"format", 1, 0, O_FORMAT}, {"confidence", 1, 0, O_CONF},
                                          {"screen", 1, 0, O_SCREEN}, {"quiet", 0, 0, O_QUIET},   {"help", 0, 0, O_HELP},
                                          {"eye", 1, 0, O_EYE},
                                          {0, 0, 0, 0}};
    fv_gaze_import_opts o;
    fv_gaze_import_opts_init(&o);
    const char *out = NULL;
    bool quiet = false;
    double d;
    int rc;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        switch (c) {
        case O_OUT: out = optarg; break;
        case O_FORMAT:
            if (!strcmp(optarg, "eyelink")) o.format = FV_GAZE_FORMAT_EYELINK_ASC;
            else if (!strcmp(optarg, "pupil")) o.format = FV_GAZE_FORMAT_PUPIL_CSV;
            else return fv_cli_usage_error(cmd, "--format %s: expected eyelink or pupil", optarg);
            break;
        case O_CONF:
            if (!fv_cli_parse_float(optarg, &d) || d < 0 || d > 1) return fv_cli_usage_error(cmd, "--confidence %s: expected a number in [0, 1]", optarg);
            o.min_confidence = d;
            break;
        case O_SCREEN:
            if ((rc = fv_cli_opt_size(cmd, optarg, &o.width, &o.height))) return rc;
            if (o.width < 1 || o.height < 1) return fv_cli_usage_error(cmd, "--screen %s: expected a positive size", optarg);
            break;
        case O_EYE:
            if (!strcmp(optarg, "left")) o.eyes = FV_GAZE_EYES_LEFT;
            else if (!strcmp(optarg, "right")) o.eyes = FV_GAZE_EYES_RIGHT;
            else if (!strcmp(optarg, "both")) o.eyes = FV_GAZE_EYES_BOTH;
            else if (!strcmp(optarg, "each")) o.eyes = FV_GAZE_EYES_EACH;
            else return fv_cli_usage_error(cmd, "--eye %s: expected left, right, both or each", optarg);
            break;
        case O_QUIET: quiet = true; break;
        case 'h':
        case O_HELP: usage(stdout); return FV_EXIT_OK;
        default: return fv_cli_usage_error(cmd, "unknown or incomplete option '%s' (see fovea gaze --help)", argv[optind - 1]);
        }
    }
    if (optind != argc - 1) return fv_cli_usage_error(cmd, optind >= argc ? "missing RECORDING" : "too many arguments");
    if (!out) return fv_cli_usage_error(cmd, "--out TRACE.csv is required");
    fv_error err;
    fv_error_clear(&err);
    fv_gaze_import_info info;
    fv_status s = fv_gaze_import(argv[optind], out, &o, &info, &err);
    if (s != FV_OK) return fv_cli_fail(cmd, s, err.msg);
    if (!quiet) {
        fprintf(stderr, "fovea gaze import: %s: %ld samples (%ld missing", out, info.samples, info.missing);
        if (info.dropped) fprintf(stderr, ", %ld dropped: time not increasing", info.dropped);
        fprintf(stderr, ")%s", info.binocular ? ", both eyes" : "");
        if (info.format == FV_GAZE_FORMAT_EYELINK_ASC) fprintf(stderr, ", screen %gx%g", info.width, info.height);
        if (info.eyes == FV_GAZE_EYES_LEFT || info.eyes == FV_GAZE_EYES_RIGHT)
            fprintf(stderr, ", %s eye", info.eyes == FV_GAZE_EYES_LEFT ? "left" : "right");
        else if (info.eyes == FV_GAZE_EYES_BOTH)
            fprintf(stderr, ", one gaze for both eyes");
        if (info.paired) fprintf(stderr, " (%ld pair%s of rows, one of each eye)", info.paired, info.paired == 1 ? "" : "s");
        if (info.rate > 0) fprintf(stderr, ", %g Hz", info.rate);
        if (info.gaps) fprintf(stderr, ", %ld gap%s between recording blocks marked missing", info.gaps, info.gaps == 1 ? "" : "s");
        if (info.compressed) fprintf(stderr, ", gzip-compressed");
        fputc('\n', stderr);
    }
    return FV_EXIT_OK;
}
