/* fovea — LDR-FLIP, the perceptual difference of Andersson et al., "FLIP: A Difference Evaluator
 * for Alternating Images" (HPG 2020), implemented from the paper's definition:
 *
 *  colour: sRGB -> linear RGB -> XYZ -> the linearised opponent space YyCxCz; each channel is
 *    filtered with its contrast sensitivity function, a sum of Gaussians in visual degrees
 *    (achromatic a=1, b=0.0047; red-green a=1, b=0.0053; blue-yellow a1=34.1, b1=0.04,
 *    a2=13.5, b2=0.025), back to linear RGB clamped to [0,1], then CIELab with the Hunt
 *    adjustment (a*, b* scaled by 0.01 L*), the HyAB distance |dL| + sqrt(da^2 + db^2) raised to
 *    q_c = 0.7, and the compression by the largest such distance (green vs blue) with p_c = 0.4,
 *    p_t = 0.95;
 *  features: edges (first derivative of a Gaussian) and points (second derivative) of the
 *    normalised achromatic channel, sigma = 0.5 * 0.082 degrees; feature error
 *    (max(|d edge|, |d point|) / sqrt 2)^q_f with q_f = 0.5;
 *  FLIP = colour_error ^ (1 - feature_error), per pixel, in [0, 1].
 * Convolutions clamp to the edge. Separable kernels are applied as two 1D passes.
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "core/alloc.h"
#include "fovea/film.h"
#include "fovea/metrics.h"

/* sRGB primaries, D65 white. */
static const float k_rgb2xyz[3][3] = {{0.4124564f, 0.3575761f, 0.1804375f}, {0.2126729f, 0.7151522f, 0.0721750f},
                                      {0.0193339f, 0.1191920f, 0.9503041f}};
static const float k_xyz2rgb[3][3] = {{3.2404542f, -1.5371385f, -0.4985314f}, {-0.9692660f, 1.8760108f, 0.0415560f},
                                      {0.0556434f, -0.2040259f, 1.0572252f}};
static const float k_white[3] = {0.950470f, 1.0f, 1.088830f};

static float srgb_to_linear(float e) { return e <= 0.04045f ? e / 12.92f : powf((e + 0.055f) / 1.055f, 2.4f); }

static void mat3(const float m[3][3], const float *in, float *out)
{
    for (int i = 0; i < 3; i++) out[i] = m[i][0] * in[0] + m[i][1] * in[1] + m[i][2] * in[2];
}

static float lab_f(float t)
{
    const float d = 6.0f / 29.0f;
    return t > d * d * d ? cbrtf(t) : t / (3.0f * d * d) + 4.0f / 29.0f;
}

/* Linear RGB -> Hunt-adjusted CIELab. */
static void hunt_lab(const float *rgb, float *lab)
{
    float xyz[3];
    mat3(k_rgb2xyz, rgb, xyz);
    float fx = lab_f(xyz[0] / k_white[0]), fy = lab_f(xyz[1] / k_white[1]), fz = lab_f(xyz[2] / k_white[2]);
    float l = 116.0f * fy - 16.0f;
    lab[0] = l;
    lab[1] = 0.01f * l * 500.0f * (fx - fy);
    lab[2] = 0.01f * l * 200.0f * (fy - fz);
}

static float hyab(const float *a, const float *b)
{
    float da = a[1] - b[1], db = a[2] - b[2];
    return fabsf(a[0] - b[0]) + sqrtf(da * da + db * db);
}

/* 1D convolution along x (dir 0) or y (dir 1) with clamp-to-edge, one channel. */
static void conv1d(const float *in, float *out, int w, int h, const float *k, int r, int dir)
{
    fv_region_begin();
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float s = 0.0f;
            for (int d = -r; d <= r; d++) {
                int xx = dir ? x : x + d, yy = dir ? y + d : y;
                xx = xx < 0 ? 0 : xx >= w ? w - 1 : xx;
                yy = yy < 0 ? 0 : yy >= h ? h - 1 : yy;
                s += k[d + r] * in[(size_t)yy * w + xx];
            }
            out[(size_t)y * w + x] = s;
        }
    fv_region_end();
}

/* Filters one opponent channel with its CSF, a sum of Gaussian terms
 * a sqrt(pi/b) exp(-pi^2 x^2 / b) with x in degrees (x = pixels / ppd). Each term is separable:
 * exp(-pi^2 (dx^2 + dy^2) / b) = k(dx) k(dy). The 2D kernel as a whole is normalised to sum 1. */
static bool csf_filter(const float *in, float *out, float *tmp, float *tmp2, int w, int h, int r, float ppd, const float *ab, int terms)
{
    float *k = malloc((size_t)(2 * r + 1) * sizeof *k);
    if (!k) return false;
    size_t n = (size_t)w * h;
    double total = 0.0;
    memset(out, 0, n * sizeof *out);
    for (int t = 0; t < terms; t++) {
        float a = ab[2 * t], b = ab[2 * t + 1], amp = a * sqrtf(FV_PI / b);
        double s = 0.0;
        for (int d = -r; d <= r; d++) {
            float x = d / ppd;
            k[d + r] = expf(-FV_PI * FV_PI * x * x / b);
            s += k[d + r];
        }
        total += amp * s * s;
        conv1d(in, tmp, w, h, k, r, 0);
        conv1d(tmp, tmp2, w, h, k, r, 1);
        for (size_t i = 0; i < n; i++) out[i] += amp * tmp2[i];
    }
    for (size_t i = 0; i < n; i++) out[i] = (float)(out[i] / total);
    free(k);
    return true;
}

/* Gaussian derivative kernels for the feature detectors, normalised so that the positive weights
 * sum to 1 and the negative weights to -1 (the smoothing factor sums to 1). */
static void feature_kernels(float sigma, int r, float *g, float *d1, float *d2)
{
    double sg = 0.0, p1 = 0.0, n1 = 0.0, p2 = 0.0, n2 = 0.0;
    for (int i = -r; i <= r; i++) {
        float x = (float)i, e = expf(-x * x / (2.0f * sigma * sigma));
        g[i + r] = e;
        d1[i + r] = -x / (sigma * sigma) * e;
        d2[i + r] = (x * x / (sigma * sigma) - 1.0f) / (sigma * sigma) * e;
        sg += e;
    }
    /* The 2D kernels are d(x) g(y): their positive (negative) parts sum to sum(d+) sum(g). */
    for (int i = 0; i <= 2 * r; i++) {
        g[i] = (float)(g[i] / sg);
        if (d1[i] > 0) p1 += d1[i]; else n1 -= d1[i];
        if (d2[i] > 0) p2 += d2[i]; else n2 -= d2[i];
    }
    for (int i = 0; i <= 2 * r; i++) {
        d1[i] = (float)(d1[i] > 0 ? d1[i] / p1 : d1[i] / n1);
        d2[i] = (float)(d2[i] > 0 ? d2[i] / p2 : d2[i] / n2);
    }
}

/* Edge and point magnitudes of one achromatic image. */
static void features(const float *y, float *edge, float *point, float *t0, float *t1, float *t2, int w, int h, const float *g,
                     const float *d1, const float *d2, int r)
{
    size_t n = (size_t)w * h;
    conv1d(y, t0, w, h, d1, r, 0);
    conv1d(t0, t1, w, h, g, r, 1); /* d/dx */
    conv1d(y, t0, w, h, g, r, 0);
    conv1d(t0, t2, w, h, d1, r, 1); /* d/dy */
    for (size_t i = 0; i < n; i++) edge[i] = sqrtf(t1[i] * t1[i] + t2[i] * t2[i]);
    conv1d(y, t0, w, h, d2, r, 0);
    conv1d(t0, t1, w, h, g, r, 1);
    conv1d(y, t0, w, h, g, r, 0);
    conv1d(t0, t2, w, h, d2, r, 1);
    for (size_t i = 0; i < n; i++) point[i] = sqrtf(t1[i] * t1[i] + t2[i] * t2[i]);
}

fv_status fv_metrics_flip_map(const float *ref, const float *test, int w, int h, float ppd, float *map, fv_error *err)
{
    if (!(ppd > 0.0f) || !isfinite(ppd)) return fv_error_set(err, FV_ERR_INVALID, "FLIP: pixels per degree %g must be positive", ppd);
    fv_status st = fv_film_check_size(w, h, err);
    if (st != FV_OK) return st;
    size_t n = (size_t)w * h;
    /* 3 opponent channels x 2 images, filtered copies, temporaries. */
    float *buf = fv_alloc_array(n, 16 * sizeof(float));
    if (!buf) return fv_error_set(err, FV_ERR_NOMEM, "out of memory computing FLIP of %dx%d", w, h);
    float *opp[2] = {buf, buf + 3 * n}, *filt[2] = {buf + 6 * n, buf + 9 * n}, *t0 = buf + 12 * n, *t1 = buf + 13 * n,
          *t2 = buf + 14 * n, *t3 = buf + 15 * n;
    const float *img[2] = {ref, test};

    /* To YyCxCz (planar); in parallel, like the filters after it (the colour conversion's pow per
     * channel was a serial share of the bench's metrics). */
    for (int k = 0; k < 2; k++) {
        fv_region_begin();
        #pragma omp parallel for schedule(static)
        for (long long i = 0; i < (long long)n; i++) {
            float lin[3], xyz[3];
            for (int c = 0; c < 3; c++) lin[c] = srgb_to_linear(fv_clampf(img[k][3 * i + c], 0.0f, 1.0f));
            mat3(k_rgb2xyz, lin, xyz);
            float yr = xyz[1] / k_white[1];
            opp[k][i] = 116.0f * yr - 16.0f;
            opp[k][n + i] = 500.0f * (xyz[0] / k_white[0] - yr);
            opp[k][2 * n + i] = 200.0f * (yr - xyz[2] / k_white[2]);
        }
        fv_region_end();
    }

    /* Spatial CSF filtering: the kernel reaches 3 standard deviations of the widest Gaussian. */
    static const float ab[3][4] = {{1.0f, 0.0047f, 0, 0}, {1.0f, 0.0053f, 0, 0}, {34.1f, 0.04f, 13.5f, 0.025f}};
    static const int terms[3] = {1, 1, 2};
    int r = (int)ceilf(3.0f * sqrtf(0.04f / (2.0f * FV_PI * FV_PI)) * ppd);
    for (int k = 0; k < 2; k++)
        for (int c = 0; c < 3; c++)
            if (!csf_filter(opp[k] + c * n, filt[k] + c * n, t0, t1, w, h, r, ppd, ab[c], terms[c])) {
                free(buf);
                return fv_error_set(err, FV_ERR_NOMEM, "out of memory computing FLIP");
            }

    /* Colour error, compressed by the largest Hunt-adjusted HyAB distance (green vs blue). */
    const float qc = 0.7f, pc = 0.4f, pt = 0.95f;
    float green[3] = {0, 1, 0}, blue[3] = {0, 0, 1}, lg[3], lb[3];
    hunt_lab(green, lg);
    hunt_lab(blue, lb);
    const float cmax = powf(hyab(lg, lb), qc);
    fv_region_begin();
    #pragma omp parallel for schedule(static)
    for (long long ii = 0; ii < (long long)n; ii++) {
        size_t i = (size_t)ii;
        float lab[2][3];
        for (int k = 0; k < 2; k++) {
            float ycc[3] = {filt[k][i], filt[k][n + i], filt[k][2 * n + i]}, xyz[3], rgb[3];
            float yr = (ycc[0] + 16.0f) / 116.0f;
            xyz[1] = yr * k_white[1];
            xyz[0] = (ycc[1] / 500.0f + yr) * k_white[0];
            xyz[2] = (yr - ycc[2] / 200.0f) * k_white[2];
            mat3(k_xyz2rgb, xyz, rgb);
            for (int c = 0; c < 3; c++) rgb[c] = fv_clampf(rgb[c], 0.0f, 1.0f);
            hunt_lab(rgb, lab[k]);
        }
        float de = powf(hyab(lab[0], lab[1]), qc);
        map[i] = de < pc * cmax ? pt / (pc * cmax) * de : pt + (de - pc * cmax) / (cmax - pc * cmax) * (1.0f - pt);
    }
    fv_region_end();

    /* Feature error on the achromatic channel normalised to [0, 1]. */
    const float sigma = 0.5f * 0.082f * ppd;
    int rf = (int)ceilf(3.0f * sigma);
    float *kg = malloc((size_t)(2 * rf + 1) * 3 * sizeof(float));
    if (!kg) {
        free(buf);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory computing FLIP");
    }
    float *kd1 = kg + 2 * rf + 1, *kd2 = kd1 + 2 * rf + 1;
    feature_kernels(sigma, rf, kg, kd1, kd2);
    float *edge[2] = {filt[0], filt[1]}, *point[2] = {filt[0] + n, filt[1] + n}; /* reuse the filtered planes */
    for (int k = 0; k < 2; k++) {
        for (size_t i = 0; i < n; i++) t3[i] = (opp[k][i] + 16.0f) / 116.0f;
        features(t3, edge[k], point[k], t0, t1, t2, w, h, kg, kd1, kd2, rf);
    }
    const float qf = 0.5f;
    for (size_t i = 0; i < n; i++) {
        float de = fmaxf(fabsf(edge[0][i] - edge[1][i]), fabsf(point[0][i] - point[1][i]));
        float fe = powf(de / sqrtf(2.0f), qf);
        map[i] = powf(map[i], 1.0f - fe);
    }
    free(kg);
    free(buf);
    return FV_OK;
}
