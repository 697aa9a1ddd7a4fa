/* fovea CLI — `fovea compare REF TEST`: every metric per gaze region between two images, as a
 * table or JSON, and optionally a heat map of the per-pixel error. */
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "core/fileio.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: fovea compare REF TEST [options]\n"
               "Compares TEST against REF (PNG, PFM or EXR) over the whole image and per region around the gaze.\n\n"
               "  --gaze X,Y              gaze point in [0,1] screen coordinates [the gaze TEST's metadata records\n"
               "                          (fovea render writes it), else REF's, else 0.5,0.5]\n"
               "  --allow-gaze-mismatch   compare even when REF and TEST were both rendered by foveated methods for\n"
               "                          different gazes (refused otherwise)\n"
               "  --json                  print JSON instead of a table\n"
               "  --heatmap FILE          write a PNG heat map of the per-pixel error, with the eye model's rings\n"
               "                          around the gaze and a colour bar below that gives its scale\n"
               "  --heatmap-metric M      flip | mse | e [flip]\n"
               "  --heatmap-max V         the error drawn as the ramp's top colour (larger errors too): give the heat\n"
               "                          maps of one comparison the same V to compare them by eye [1 for flip, the\n"
               "                          largest error of the map for mse and e]\n"
               "  --exposure E            scale linear values before display encoding [1]\n"
               "  --linear                compare linear values (FLIP still uses display values)\n"
               "  --ppd N                 pixels per degree for FLIP [67]\n"
               "  --fovea-deg D           foveal radius in degrees [9.78]; --transition-deg D [2 x fovea]\n"
               "  --fovea-frac F          foveal radius as a fraction of the width (instead of degrees)\n"
               "  --transition-frac F     transition radius as a fraction of the width [1.5 x fovea]\n"
               "  --ppi N --eye-dist MM   display density and pupil-to-lens distance [615, 18]\n"
               "  --fov-x DEG             horizontal field of view (instead of ppi and eye distance)\n"
               "An image drawn over (fovea render --overlay, or a heat map) is refused: its pixels are not data.\n"
               "Regions and their defaults: docs/gaze.md. Metrics: docs/metrics.md.\n");
}

/* An image whose metadata says something was drawn over its pixels (`overlay`: the eye model's
 * rings, fovea render --overlay; `heatmap`: a heat map) is a picture, not data: the rings would
 * count as error. Refused rather than warned about, since the numbers would be wrong. */
static fv_status drawn_over(const char *path, fv_error *err)
{
    fv_params *meta = NULL;
    fv_error merr;
    if (fv_image_read_meta(path, &meta, &merr) != FV_OK) return FV_OK; /* the reader says what is wrong */
    fv_status s = FV_OK;
    for (int i = 0; i < fv_params_count(meta) && s == FV_OK; i++) {
        const char *k = fv_params_key(meta, i);
        if (strcmp(k, "overlay") == 0)
            s = fv_error_set(err, FV_ERR_INVALID, "%s has the eye model's rings drawn over it (fovea render --overlay): not an image to compare", path);
        else if (strcmp(k, "heatmap") == 0)
            s = fv_error_set(err, FV_ERR_INVALID, "%s is a heat map (fovea compare --heatmap), not an image to compare", path);
    }
    fv_params_destroy(meta);
    return s;
}

static fv_status load(const char *path, fv_image *img, fv_error *err)
{
    /* A regular file only (core/fileio.h): the image readers open it by name, and /dev/zero or a
     * FIFO would hang them. Reading an image that is not there is the user's input problem, as a
     * malformed one is. */
    fv_status s = fv_file_check_read(path, "image", err);
    if (s == FV_OK) s = drawn_over(path, err);
    if (s == FV_OK) s = fv_image_read(path, img, err);
    return s;
}

/* The gaze an image's metadata records (fv_image_read_meta, key "gaze"), and whether the image
 * depends on it (key "foveated"; a file that does not say is taken to depend on it). false when
 * the file records no gaze, or one that is not X,Y in [0,1]. */
static bool recorded_gaze(const char *path, float xy[2], bool *foveated)
{
    fv_params *meta = NULL;
    fv_error err;
    if (fv_image_read_meta(path, &meta, &err) != FV_OK) return false;
    const char *gz = NULL, *fov = NULL;
    for (int i = 0; i < fv_params_count(meta); i++) {
        if (strcmp(fv_params_key(meta, i), "gaze") == 0) gz = fv_params_value(meta, i);
        if (strcmp(fv_params_key(meta, i), "foveated") == 0) fov = fv_params_value(meta, i);
    }
    bool ok = gz && fv_cli_parse_floats(gz, 2, xy) && xy[0] >= 0 && xy[0] <= 1 && xy[1] >= 0 && xy[1] <= 1;
    *foveated = !fov || strcmp(fov, "false") != 0;
    fv_params_destroy(meta);
    return ok;
}

/* An empty region has NaN values: the table shows "-" rather than "nan". */
static void print_value(double v)
{
    if (isnan(v)) printf(" %10s", "-");
    else if (isinf(v)) printf(" %10s", v > 0 ? "inf" : "-inf");
    else printf(" %10.4g", v);
}

/* JSON has no inf or NaN: an empty region and an infinite PSNR are null. */
static void json_number(double v)
{
    if (isfinite(v)) printf("%.9g", v);
    else printf("null");
}

/* File names go into JSON strings: quotes, backslashes and control bytes must be escaped. */
static void json_string(const char *s)
{
    putchar('"');
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\') printf("\\%c", *p);
        else if (*p < 0x20) printf("\\u%04x", *p);
        else putchar(*p);
    }
    putchar('"');
}

int fv_cmd_compare(int argc, char **argv)
{
    enum { O_GAZE = 256, O_JSON, O_HEAT, O_HEATM, O_HEATMAX, O_EXPOSURE, O_LINEAR, O_PPD, O_FDEG, O_TDEG, O_FFRAC, O_TFRAC, O_PPI, O_EYED, O_FOVX, O_HELP, O_ALLOW_GAZE };
    static const struct option longs[] = {
        {"gaze", 1, 0, O_GAZE}, {"json", 0, 0, O_JSON}, {"heatmap", 1, 0, O_HEAT}, {"heatmap-metric", 1, 0, O_HEATM},
        {"heatmap-max", 1, 0, O_HEATMAX}, {"exposure", 1, 0, O_EXPOSURE}, {"linear", 0, 0, O_LINEAR}, {"ppd", 1, 0, O_PPD}, {"fovea-deg", 1, 0, O_FDEG},
        {"transition-deg", 1, 0, O_TDEG}, {"fovea-frac", 1, 0, O_FFRAC}, {"transition-frac", 1, 0, O_TFRAC},
        {"ppi", 1, 0, O_PPI}, {"eye-dist", 1, 0, O_EYED}, {"fov-x", 1, 0, O_FOVX}, {"help", 0, 0, O_HELP},
        {"allow-gaze-mismatch", 0, 0, O_ALLOW_GAZE}, {0, 0, 0, 0}};
    const char *cmd = "compare";
    float gaze[2] = {0.5f, 0.5f};
    bool json = false, has_gaze = false, allow_mismatch = false;
    const char *heat = NULL, *heat_metric = "flip";
    double heat_max = 0.0; /* 0: the metric's default scale */
    fv_metric_opts mo;
    fv_metric_opts_default(&mo);
    double fdeg = 0, tdeg = 0, ffrac = 0, tfrac = 0, ppi = 0, eyed = 0, fovx = 0, d;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        double *target = NULL;
        const char *name = NULL;
        switch (c) {
        case O_GAZE:
            if (!fv_cli_parse_floats(optarg, 2, gaze) || !(gaze[0] >= 0 && gaze[0] <= 1 && gaze[1] >= 0 && gaze[1] <= 1))
                return fv_cli_usage_error(cmd, "--gaze %s: expected X,Y with both in [0,1]", optarg);
            has_gaze = true;
            break;
        case O_ALLOW_GAZE: allow_mismatch = true; break;
        case O_JSON: json = true; break;
        case O_HEAT: heat = optarg; break;
        case O_HEATM:
            if (strcmp(optarg, "flip") && strcmp(optarg, "mse") && strcmp(optarg, "e"))
                return fv_cli_usage_error(cmd, "--heatmap-metric %s: expected flip, mse or e", optarg);
            heat_metric = optarg;
            break;
        case O_HEATMAX:
            if (!fv_cli_parse_float(optarg, &d) || !(d > 0) || !isfinite(d) || d > 3e38)
                return fv_cli_usage_error(cmd, "--heatmap-max %s: expected a positive number", optarg);
            heat_max = d;
            break;
        case O_EXPOSURE:
            if (!fv_cli_parse_float(optarg, &d) || !(d > 0)) return fv_cli_usage_error(cmd, "--exposure %s: expected a positive number", optarg);
            mo.exposure = (float)d;
            break;
        case O_LINEAR: mo.linear = true; break;
        case O_PPD: target = &d, name = "--ppd"; break;
        case O_FDEG: target = &fdeg, name = "--fovea-deg"; break;
        case O_TDEG: target = &tdeg, name = "--transition-deg"; break;
        case O_FFRAC: target = &ffrac, name = "--fovea-frac"; break;
        case O_TFRAC: target = &tfrac, name = "--transition-frac"; break;
        case O_PPI: target = &ppi, name = "--ppi"; break;
        case O_EYED: target = &eyed, name = "--eye-dist"; break;
        case O_FOVX: target = &fovx, name = "--fov-x"; break;
        case 'h':
        case O_HELP: usage(stdout); return FV_EXIT_OK;
        default: return fv_cli_usage_error(cmd, "unknown option '%s' (try fovea compare --help)", argv[optind - 1]);
        }
        if (target) {
            if (!fv_cli_parse_float(optarg, target) || !(*target > 0) || !isfinite(*target))
                return fv_cli_usage_error(cmd, "%s %s: expected a positive number", name, optarg);
            if (c == O_PPD) mo.ppd = (float)d;
        }
    }
    if (argc - optind != 2) return fv_cli_usage_error(cmd, "expected two images: REF TEST (try fovea compare --help)");
    const char *ref_path = argv[optind], *test_path = argv[optind + 1];
    if (heat && fv_image_format_from_path(heat) != FV_IMG_PNG) return fv_cli_usage_error(cmd, "--heatmap %s: the heat map is a .png file", heat);
    if (heat_max > 0 && !heat) return fv_cli_usage_error(cmd, "--heatmap-max: only with --heatmap FILE");
    if (heat) {
        fv_inputs in;
        fv_inputs_init(&in);
        fv_inputs_add(&in, ref_path, "reference image");
        fv_inputs_add(&in, test_path, "test image");
        int crc = fv_cli_check_output(cmd, &in, heat, "--heatmap");
        if (crc) return crc;
    }
    fv_error err;
    fv_image ref, test;
    fv_status s = load(ref_path, &ref, &err);
    if (s != FV_OK) return fv_cli_fail(cmd, s == FV_ERR_IO || s == FV_ERR_INVALID ? FV_ERR_INVALID : s, err.msg);
    if ((s = load(test_path, &test, &err)) != FV_OK) {
        fv_image_free(&ref);
        return fv_cli_fail(cmd, s == FV_ERR_IO || s == FV_ERR_INVALID ? FV_ERR_INVALID : s, err.msg);
    }
    int rc = FV_EXIT_OK;
    uint8_t *labels = NULL;
    float *map = NULL;
    if (ref.width != test.width || ref.height != test.height) {
        rc = fv_cli_usage_error(cmd, "size mismatch: %s is %dx%d, %s is %dx%d", ref_path, ref.width, ref.height, test_path, test.width,
                                test.height);
        goto done;
    }
    int w = ref.width, h = ref.height;
    /* The gaze the images were rendered for, from their metadata: two foveated renders for
     * different gazes have their detail in different places, and no one region fits both. A
     * non-foveated image (pt as the reference) looks the same for any gaze: the other's counts. */
    {
        float gr[2], gt[2];
        bool fr = false, ft = false;
        bool hr = recorded_gaze(ref_path, gr, &fr), ht = recorded_gaze(test_path, gt, &ft);
        if (hr && ht && fr && ft && !allow_mismatch && (fabsf(gr[0] - gt[0]) > 1e-4f || fabsf(gr[1] - gt[1]) > 1e-4f)) {
            rc = fv_cli_usage_error(cmd, "%s was rendered for gaze %g,%g and %s for gaze %g,%g: pass --allow-gaze-mismatch to compare them anyway",
                                    ref_path, gr[0], gr[1], test_path, gt[0], gt[1]);
            goto done;
        }
        /* TEST's gaze, unless only REF depends on its gaze. */
        bool from_test = ht && (ft || !(hr && fr));
        if (!has_gaze && (ht || hr)) {
            gaze[0] = from_test ? gt[0] : gr[0];
            gaze[1] = from_test ? gt[1] : gr[1];
            fprintf(stderr, "fovea compare: gaze %g,%g from the metadata of %s (--gaze overrides)\n", gaze[0], gaze[1], from_test ? test_path : ref_path);
        }
    }
    fv_eye_model eye;
    fv_eye_model_default(w, h, &eye);
    if (ffrac > 0 || tfrac > 0) {
        eye.mode = FV_FOVEA_WIDTH;
        if (ffrac > 0) eye.fovea_frac = (float)ffrac;
        eye.transition_frac = tfrac > 0 ? (float)tfrac : 1.5f * eye.fovea_frac;
    }
    if (fdeg > 0) eye.fovea_deg = (float)fdeg;
    eye.transition_deg = tdeg > 0 ? (float)tdeg : 2.0f * eye.fovea_deg;
    if (ppi > 0) eye.ppi = (float)ppi;
    if (eyed > 0) eye.eye_dist_mm = (float)eyed;
    if (fovx > 0) eye.fov_x_deg = (float)fovx;
    if ((s = fv_eye_model_validate(&eye, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    fv_gaze g = {gaze[0], gaze[1]};
    size_t n = (size_t)w * h;
    labels = malloc(n);
    map = malloc(n * sizeof *map);
    if (!labels || !map) {
        rc = fv_cli_fail(cmd, FV_ERR_NOMEM, "out of memory");
        goto done;
    }
    fv_eye_region_labels(&eye, g, labels);
    fv_metric_report rep;
    if ((s = fv_metrics_compare(ref.rgb, test.rgb, w, h, labels, &mo, &rep, map, &err)) != FV_OK) {
        rc = fv_cli_fail(cmd, s, err.msg);
        goto done;
    }
    /* A NaN or infinite channel counts as black in every metric (two all-NaN images would
     * otherwise read as identical): say how many pixels that was, per image. */
    long long bad[2] = {0, 0};
    const float *img[2] = {ref.rgb, test.rgb};
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < n; i++) bad[k] += !isfinite(img[k][3 * i]) || !isfinite(img[k][3 * i + 1]) || !isfinite(img[k][3 * i + 2]);
    if (bad[0] || bad[1])
        fprintf(stderr, "fovea compare: warning: pixels with NaN or Inf values, counted as black in every metric: %lld of %zu in %s, %lld in %s\n",
                bad[0], n, ref_path, bad[1], test_path);
    float vmax = 0.0f;
    if (heat) {
        bool flip = strcmp(heat_metric, "flip") == 0;
        if (!flip) {
            /* Per-pixel squared or absolute error of the compared values. */
            float *a = malloc(n * 3 * sizeof *a), *b = malloc(n * 3 * sizeof *b);
            if (!a || !b) {
                free(a);
                free(b);
                rc = fv_cli_fail(cmd, FV_ERR_NOMEM, "out of memory");
                goto done;
            }
            fv_metrics_prepare(ref.rgb, n, &mo, a);
            fv_metrics_prepare(test.rgb, n, &mo, b);
            bool sq = strcmp(heat_metric, "mse") == 0;
            for (size_t i = 0; i < n; i++) {
                float acc = 0.0f;
                for (int k = 0; k < 3; k++) {
                    float dd = a[3 * i + k] - b[3 * i + k];
                    acc += sq ? dd * dd : fabsf(dd);
                }
                map[i] = acc / 3.0f;
            }
            free(a);
            free(b);
        }
        /* FLIP lies in [0,1]: its fixed scale is comparable across heat maps as it is; MSE and E
         * have no top, so their default scale is this map's largest error (--heatmap-max shares one). */
        vmax = heat_max > 0 ? (float)heat_max : flip ? 1.0f : fv_heatmap_scale(map, w, h);
        const fv_heatmap_opts ho = {vmax, &eye, g, flip ? "FLIP" : strcmp(heat_metric, "mse") == 0 ? "MSE" : "E"};
        if ((s = fv_heatmap_write(heat, map, w, h, &ho, &err)) != FV_OK) {
            rc = fv_cli_fail(cmd, s, err.msg);
            goto done;
        }
    }
    if (json) {
        printf("{\n  \"ref\": ");
        json_string(ref_path);
        printf(",\n  \"test\": ");
        json_string(test_path);
        printf(",\n  \"size\": [%d, %d],\n  \"gaze\": [%g, %g],\n", w, h, g.x, g.y);
        printf("  \"fovea_radius_px\": %.6g,\n  \"transition_radius_px\": %.6g,\n  \"regions\": {\n", fv_eye_fovea_radius_px(&eye),
               fv_eye_transition_radius_px(&eye));
        for (int r = 0; r < FV_REGION_COUNT; r++) {
            const fv_metric_values *v = &rep.region[r];
            printf("    \"%s\": {\"pixels\": %lld, \"mse\": ", fv_region_name((fv_region)r), v->pixels);
            json_number(v->mse);
            printf(", \"psnr\": ");
            json_number(v->psnr);
            printf(", \"e\": ");
            json_number(v->e);
            printf(", \"ssim\": ");
            json_number(v->ssim);
            printf(", \"flip\": ");
            json_number(v->flip);
            printf(", \"nonfinite\": %lld}%s\n", v->nonfinite, r + 1 < FV_REGION_COUNT ? "," : "");
        }
        printf("  },\n  \"nonfinite_pixels\": {\"ref\": %lld, \"test\": %lld}", bad[0], bad[1]);
        if (heat) {
            /* the scale the heat map was drawn with, to give the next one the same (--heatmap-max) */
            printf(",\n  \"heatmap\": {\"file\": ");
            json_string(heat);
            printf(", \"metric\": \"%s\", \"max\": %.9g}", heat_metric, vmax);
        }
        printf("\n}\n");
    } else {
        printf("%-11s %10s %10s %10s %10s %10s %10s %10s\n", "region", "pixels", "MSE", "PSNR", "E", "SSIM", "FLIP", "NaN/Inf");
        for (int r = 0; r < FV_REGION_COUNT; r++) {
            const fv_metric_values *v = &rep.region[r];
            printf("%-11s %10lld", fv_region_name((fv_region)r), v->pixels);
            print_value(v->mse);
            print_value(v->psnr);
            print_value(v->e);
            print_value(v->ssim);
            print_value(v->flip);
            printf(" %10lld\n", v->nonfinite);
        }
    }
done:
    free(labels);
    free(map);
    fv_image_free(&ref);
    fv_image_free(&test);
    return rc;
}
