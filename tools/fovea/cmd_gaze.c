/* fovea CLI — `fovea gaze import IN --out TRACE.csv`: an eye tracker's recording (EyeLink ASC,
 * Pupil Labs gaze_positions.csv, Tobii Pro Lab's data export, any delimited table under a column
 * mapping) into the gaze trace format `fovea render --gaze-trace` reads. */
#include <getopt.h>
#include <string.h>
#include "cli.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: fovea gaze import RECORDING --out TRACE.csv [options]\n"
               "Converts an eye tracker's recording into a gaze trace (docs/gaze.md): normalised coordinates,\n"
               "seconds from the first sample, blinks and lost samples as missing (empty) fields.\n\n"
               "  RECORDING             an EyeLink .asc sample file, a Pupil Labs gaze_positions.csv, a Tobii Pro Lab\n"
               "                        data export (.tsv), or any CSV/TSV table with the column options below\n"
               "                        (each may be gzip-compressed: .asc.gz)\n"
               "  --out FILE            the trace to write (required)\n"
               "  --format F            eyelink | pupil | tobii | table [from the extension: .asc eyelink, .csv pupil,\n"
               "                        .tsv tobii (by its header); table when a column option is given]\n"
               "  --confidence C        Pupil: samples below this confidence are missing [0.6]\n"
               "  --screen WxH          the screen in pixels: EyeLink, instead of DISPLAY_COORDS; a table with\n"
               "                        --coords px; Tobii, where the export has no recording resolution\n"
               "  --eye E               left | right | both (the mean of the two eyes) | each (a five-column\n"
               "                        trace: each eye its own gaze, for stereo renders)\n"
               "                        [EyeLink, a table's per-eye columns: each; Pupil, Tobii: both]\n"
               "  --quiet               no summary line\n\n"
               "A table (CSV, TSV or semicolons; docs/gaze.md \"Other tables\"): columns by header text (any case) or\n"
               "by number from 1 (in a file without a header line, by number only).\n"
               "  --time COL            the time of each sample (required)\n"
               "  --x COL --y COL       one gaze, or per eye: --left-x COL --left-y COL --right-x COL --right-y COL\n"
               "  --time-unit U         s | ms | us | ns [s; Tobii: the header's unit, else us]\n"
               "  --coords C            norm | px (pixels of --screen) [norm]\n"
               "  --origin O            top-left | bottom-left [top-left]\n"
               "  --valid COL           a sample is missing unless this column says 1, true, valid or yes\n");
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
    enum {
        O_OUT = 256, O_FORMAT, O_CONF, O_SCREEN, O_QUIET, O_HELP, O_EYE, O_TIME, O_X, O_Y, O_LX, O_LY, O_RX, O_RY, O_VALID, O_UNIT, O_COORDS,
        O_ORIGIN
    };
    static const struct option longs[] = {
        {"out", 1, 0, O_OUT},         {"format", 1, 0, O_FORMAT},   {"confidence", 1, 0, O_CONF}, {"screen", 1, 0, O_SCREEN},
        {"quiet", 0, 0, O_QUIET},     {"help", 0, 0, O_HELP},       {"eye", 1, 0, O_EYE},         {"time", 1, 0, O_TIME},
        {"x", 1, 0, O_X},             {"y", 1, 0, O_Y},             {"left-x", 1, 0, O_LX},       {"left-y", 1, 0, O_LY},
        {"right-x", 1, 0, O_RX},      {"right-y", 1, 0, O_RY},      {"valid", 1, 0, O_VALID},     {"time-unit", 1, 0, O_UNIT},
        {"coords", 1, 0, O_COORDS},   {"origin", 1, 0, O_ORIGIN},   {0, 0, 0, 0}};
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
            else if (!strcmp(optarg, "tobii")) o.format = FV_GAZE_FORMAT_TOBII;
            else if (!strcmp(optarg, "table")) o.format = FV_GAZE_FORMAT_TABLE;
            else return fv_cli_usage_error(cmd, "--format %s: expected eyelink, pupil, tobii or table", optarg);
            break;
        case O_TIME: o.table.time = optarg; break;
        case O_X: o.table.x = optarg; break;
        case O_Y: o.table.y = optarg; break;
        case O_LX: o.table.left_x = optarg; break;
        case O_LY: o.table.left_y = optarg; break;
        case O_RX: o.table.right_x = optarg; break;
        case O_RY: o.table.right_y = optarg; break;
        case O_VALID: o.table.valid = optarg; break;
        case O_UNIT:
            if (!strcmp(optarg, "s")) o.table.time_unit = 1.0;
            else if (!strcmp(optarg, "ms")) o.table.time_unit = 1e-3;
            else if (!strcmp(optarg, "us")) o.table.time_unit = 1e-6;
            else if (!strcmp(optarg, "ns")) o.table.time_unit = 1e-9;
            else return fv_cli_usage_error(cmd, "--time-unit %s: expected s, ms, us or ns", optarg);
            break;
        case O_COORDS:
            if (!strcmp(optarg, "norm") || !strcmp(optarg, "px")) o.table.pixels = optarg[0] == 'p';
            else return fv_cli_usage_error(cmd, "--coords %s: expected norm or px", optarg);
            break;
        case O_ORIGIN:
            if (!strcmp(optarg, "top-left") || !strcmp(optarg, "bottom-left")) o.table.bottom_left = optarg[0] == 'b';
            else return fv_cli_usage_error(cmd, "--origin %s: expected top-left or bottom-left", optarg);
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
    fv_inputs in;
    fv_inputs_init(&in);
    fv_inputs_add(&in, argv[optind], "recording");
    if ((rc = fv_cli_check_output(cmd, &in, out, "--out"))) return rc;
    fv_error err;
    fv_error_clear(&err);
    fv_gaze_import_info info;
    fv_status s = fv_gaze_import(argv[optind], out, &o, &info, &err);
    if (s != FV_OK) return fv_cli_fail(cmd, s, err.msg);
    if (!quiet) {
        fprintf(stderr, "fovea gaze import: %s: %ld samples (%ld missing", out, info.samples, info.missing);
        if (info.dropped) fprintf(stderr, ", %ld dropped: time not increasing", info.dropped);
        fprintf(stderr, ")%s", info.binocular ? ", both eyes" : "");
        if (info.format == FV_GAZE_FORMAT_EYELINK_ASC || (info.format != FV_GAZE_FORMAT_PUPIL_CSV && info.width > 0))
            fprintf(stderr, ", screen %gx%g", info.width, info.height);
        if (info.eyes == FV_GAZE_EYES_LEFT || info.eyes == FV_GAZE_EYES_RIGHT)
            fprintf(stderr, ", %s eye", info.eyes == FV_GAZE_EYES_LEFT ? "left" : "right");
        else if (info.eyes == FV_GAZE_EYES_BOTH)
            fprintf(stderr, ", one gaze for both eyes");
        if (info.paired) fprintf(stderr, " (%ld pair%s of rows, one of each eye)", info.paired, info.paired == 1 ? "" : "s");
        if (info.rate > 0) fprintf(stderr, ", %g Hz", info.rate);
        if (info.gaps) fprintf(stderr, ", %ld gap%s between recording blocks marked missing", info.gaps, info.gaps == 1 ? "" : "s");
        if (info.skipped) fprintf(stderr, ", %ld row%s without gaze data skipped", info.skipped, info.skipped == 1 ? "" : "s");
        if (info.compressed) fprintf(stderr, ", gzip-compressed");
        fputc('\n', stderr);
    }
    return FV_EXIT_OK;
}
