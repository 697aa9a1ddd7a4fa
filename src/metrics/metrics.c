/* fovea — MSE, PSNR, E and SSIM per region, and the driver that also runs FLIP (flip.c).
 *
 * Region values are means of per-pixel maps over the pixels of each region. Sums run per row in
 * double precision and are added in row order afterwards, so results do not depend on the number
 * of threads.
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "core/alloc.h"
#include "fovea/film.h"
#include "fovea/metrics.h"

void fv_metric_opts_default(fv_metric_opts *o)
{
    o->exposure = 1.0f;
    o->linear = false;
    o->ppd = 67.0f;
}

void fv_metrics_prepare(const float *rgb, size_t n, const fv_metric_opts *o, float *out)
{
    /* parallel: the sRGB encoding's pow per channel was a serial share of the bench's metrics */
    fv_region_begin();
    #pragma omp parallel for schedule(static)
    for (long long i = 0; i < (long long)(3 * n); i++) {
        float v = rgb[i] * o->exposure;
        if (!isfinite(v)) v = 0.0f; /* a NaN or inf pixel counts as black, not as a poisoned mean */
        out[i] = o->linear ? v : fv_srgb_encode(v);
    }
    fv_region_end();
}

/* ---- SSIM (Wang, Bovik, Sheikh, Simoncelli 2004) on luminance, 11x11 Gaussian window, sigma 1.5,
 * K1 = 0.01, K2 = 0.03, dynamic range 1. At the borders the window is cut to the image and its
 * weights renormalised. ---- */

#define SSIM_R 5

static void blur_sep(const float *in, float *tmp, float *out, int w, int h, const float *k)
{
    fv_region_begin();
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double s = 0.0, ws = 0.0;
            for (int d = -SSIM_R; d <= SSIM_R; d++) {
                int xx = x + d;
                if (xx < 0 || xx >= w) continue;
                s += k[d + SSIM_R] * in[(size_t)y * w + xx];
                ws += k[d + SSIM_R];
            }
            tmp[(size_t)y * w + x] = (float)(s / ws);
        }
    fv_region_end();
    fv_region_begin();
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double s = 0.0, ws = 0.0;
            for (int d = -SSIM_R; d <= SSIM_R; d++) {
                int yy = y + d;
                if (yy < 0 || yy >= h) continue;
                s += k[d + SSIM_R] * tmp[(size_t)yy * w + x];
                ws += k[d + SSIM_R];
            }
            out[(size_t)y * w + x] = (float)(s / ws);
        }
    fv_region_end();
}

fv_status fv_metrics_ssim_map(const float *a, const float *b, int w, int h, float *map, fv_error *err)
{
    fv_status st = fv_film_check_size(w, h, err);
    if (st != FV_OK) return st;
    size_t n = (size_t)w * h;
    float *buf = fv_alloc_array(n, 8 * sizeof(float));
    if (!buf) return fv_error_set(err, FV_ERR_NOMEM, "out of memory computing SSIM of %dx%d", w, h);
    float *ya = buf, *yb = buf + n, *p = buf + 2 * n, *tmp = buf + 3 * n, *ma = buf + 4 * n, *mb = buf + 5 * n, *v = buf + 6 * n,
          *cov = buf + 7 * n;
    float k[2 * SSIM_R + 1];
    for (int d = -SSIM_R; d <= SSIM_R; d++) k[d + SSIM_R] = expf(-(float)(d * d) / (2.0f * 1.5f * 1.5f));
    for (size_t i = 0; i < n; i++) {
        ya[i] = 0.2126f * a[3 * i] + 0.7152f * a[3 * i + 1] + 0.0722f * a[3 * i + 2];
        yb[i] = 0.2126f * b[3 * i] + 0.7152f * b[3 * i + 1] + 0.0722f * b[3 * i + 2];
    }
    blur_sep(ya, tmp, ma, w, h, k);
    blur_sep(yb, tmp, mb, w, h, k);
    for (size_t i = 0; i < n; i++) p[i] = ya[i] * ya[i] + yb[i] * yb[i];
    blur_sep(p, tmp, v, w, h, k); /* E[a^2] + E[b^2] */
    for (size_t i = 0; i < n; i++) p[i] = ya[i] * yb[i];
    blur_sep(p, tmp, cov, w, h, k); /* E[ab] */
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    for (size_t i = 0; i < n; i++) {
        double mua = ma[i], mub = mb[i];
        double sab = cov[i] - mua * mub, s2 = v[i] - mua * mua - mub * mub;
        double s = ((2.0 * mua * mub + c1) * (2.0 * sab + c2)) / ((mua * mua + mub * mub + c1) * (s2 + c2));
        map[i] = (float)s;
    }
    free(buf);
    return FV_OK;
}

/* ---- the per-region report ---- */

fv_status fv_metrics_compare(const float *ref, const float *test, int w, int h, const uint8_t *labels, const fv_metric_opts *opts,
                             fv_metric_report *out, float *flip_map, fv_error *err)
{
    fv_status st = fv_film_check_size(w, h, err);
    if (st != FV_OK) return st;
    fv_metric_opts def;
    if (!opts) {
        fv_metric_opts_default(&def);
        opts = &def;
    }
    if (!(opts->ppd > 0.0f) || !isfinite(opts->ppd) || !isfinite(opts->exposure) || opts->exposure < 0.0f)
        return fv_error_set(err, FV_ERR_INVALID, "metrics: pixels per degree (%g) must be positive and exposure (%g) >= 0", opts->ppd,
                            opts->exposure);
    size_t n = (size_t)w * h;
    float *a = fv_alloc_array(n, 3 * sizeof(float)), *b = fv_alloc_array(n, 3 * sizeof(float));
    float *ssim = fv_alloc_array(n, sizeof(float)), *flip = flip_map ? flip_map : fv_alloc_array(n, sizeof(float));
    double *rows = fv_calloc_array((size_t)h * FV_REGION_COUNT * 6, sizeof(double));
    if (!a || !b || !ssim || !flip || !rows) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory comparing %dx%d images", w, h);
        goto done;
    }
    fv_metrics_prepare(ref, n, opts, a);
    fv_metrics_prepare(test, n, opts, b);
    if ((st = fv_metrics_ssim_map(a, b, w, h, ssim, err)) != FV_OK) goto done;
    if (opts->linear) {
        /* FLIP is defined on display values: give it those even in linear mode. */
        fv_metric_opts d = *opts;
        d.linear = false;
        float *da = fv_alloc_array(n, 3 * sizeof(float)), *db = fv_alloc_array(n, 3 * sizeof(float));
        if (!da || !db) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        if (st == FV_OK) {
            fv_metrics_prepare(ref, n, &d, da);
            fv_metrics_prepare(test, n, &d, db);
            st = fv_metrics_flip_map(da, db, w, h, opts->ppd, flip, err);
        }
        free(da);
        free(db);
    } else {
        st = fv_metrics_flip_map(a, b, w, h, opts->ppd, flip, err);
    }
    if (st != FV_OK) goto done;
    /* Per row and region: count, squared error, E, SSIM, FLIP, pixels with a non-finite value. */
    fv_region_begin();
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; y++) {
        double *r = rows + (size_t)y * FV_REGION_COUNT * 6;
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            double se = 0.0, ae = 0.0;
            bool bad = false;
            for (int c = 0; c < 3; c++) bad |= !isfinite(ref[3 * i + c]) || !isfinite(test[3 * i + c]);
            for (int c = 0; c < 3; c++) {
                double d = (double)a[3 * i + c] - b[3 * i + c];
                se += d * d;
                ae += fabs(d);
            }
            int regs[2] = {FV_REGION_ALL, labels && labels[i] < FV_REGION_ALL ? labels[i] : -1};
            for (int k = 0; k < 2; k++) {
                if (regs[k] < 0) continue;
                double *q = r + regs[k] * 6;
                q[5] += bad;
                q[0] += 1.0;
                q[1] += se / 3.0;
                q[2] += ae / 3.0;
                q[3] += ssim[i];
                q[4] += flip[i];
            }
        }
    }
    fv_region_end();
    memset(out, 0, sizeof *out);
    for (int g = 0; g < FV_REGION_COUNT; g++) {
        double s[6] = {0, 0, 0, 0, 0, 0};
        for (int y = 0; y < h; y++)
            for (int k = 0; k < 6; k++) s[k] += rows[((size_t)y * FV_REGION_COUNT + g) * 6 + k];
        fv_metric_values *v = &out->region[g];
        v->pixels = (long long)s[0];
        v->nonfinite = (long long)s[5];
        if (s[0] > 0) {
            v->mse = s[1] / s[0];
            v->e = s[2] / s[0];
            v->ssim = s[3] / s[0];
            v->flip = s[4] / s[0];
            v->psnr = v->mse > 0.0 ? 10.0 * log10(1.0 / v->mse) : INFINITY;
        } else { /* an empty region has no error, not a zero error */
            v->mse = v->e = v->ssim = v->flip = v->psnr = NAN;
        }
    }
done:
    free(a);
    free(b);
    free(ssim);
    if (flip != flip_map) free(flip);
    free(rows);
    return st;
}
