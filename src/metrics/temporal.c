/* fovea — temporal error over a frame sequence: MSE' (Foveated Photon Mapping, Eq. 9) and E'
 * (Foveated Instant Radiosity, Eq. 4) are the means over the n - 1 consecutive pairs of the pair's
 * MSE and E. Each pair is split into regions with the later frame's labels, since the gaze may
 * move; a region's mean runs over the pairs in which it has pixels, so a pair where the moving
 * gaze leaves a region empty does not count as a pair without change. Only the previous frame
 * is kept.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "fovea/metrics.h"

struct fv_temporal {
    int w, h;
    fv_metric_opts opts;
    float *prev, *cur;
    int frames;
    double mse_sum[FV_REGION_COUNT], e_sum[FV_REGION_COUNT];
    int pairs[FV_REGION_COUNT]; /* pairs in which the region had pixels */
};

fv_status fv_temporal_create(int w, int h, const fv_metric_opts *opts, fv_temporal **out, fv_error *err)
{
    if (w < 1 || h < 1) return fv_error_set(err, FV_ERR_INVALID, "temporal metric: bad size %dx%d", w, h);
    fv_temporal *t = calloc(1, sizeof *t);
    if (!t) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    t->w = w;
    t->h = h;
    if (opts) t->opts = *opts;
    else fv_metric_opts_default(&t->opts);
    t->prev = fv_alloc_array((size_t)w * h, 3 * sizeof(float));
    t->cur = fv_alloc_array((size_t)w * h, 3 * sizeof(float));
    if (!t->prev || !t->cur) {
        fv_temporal_destroy(t);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the temporal metric of %dx%d", w, h);
    }
    *out = t;
    return FV_OK;
}

void fv_temporal_destroy(fv_temporal *t)
{
    if (!t) return;
    free(t->prev);
    free(t->cur);
    free(t);
}

fv_status fv_temporal_push(fv_temporal *t, const float *rgb, const uint8_t *labels, fv_error *err)
{
    if (!rgb) return fv_error_set(err, FV_ERR_INVALID, "temporal metric: frame %d has no pixels", t->frames);
    size_t n = (size_t)t->w * t->h;
    fv_metrics_prepare(rgb, n, &t->opts, t->cur);
    if (t->frames > 0) {
        double se[FV_REGION_COUNT] = {0}, ae[FV_REGION_COUNT] = {0}, cnt[FV_REGION_COUNT] = {0};
        for (size_t i = 0; i < n; i++) {
            double s = 0.0, a = 0.0;
            for (int c = 0; c < 3; c++) {
                double d = (double)t->cur[3 * i + c] - t->prev[3 * i + c];
                s += d * d;
                a += fabs(d);
            }
            int regs[2] = {FV_REGION_ALL, labels && labels[i] < FV_REGION_ALL ? labels[i] : -1};
            for (int k = 0; k < 2; k++)
                if (regs[k] >= 0) {
                    se[regs[k]] += s / 3.0;
                    ae[regs[k]] += a / 3.0;
                    cnt[regs[k]] += 1.0;
                }
        }
        for (int r = 0; r < FV_REGION_COUNT; r++)
            if (cnt[r] > 0) {
                t->mse_sum[r] += se[r] / cnt[r];
                t->e_sum[r] += ae[r] / cnt[r];
                t->pairs[r]++;
            }
    }
    float *sw = t->prev;
    t->prev = t->cur;
    t->cur = sw;
    t->frames++;
    return FV_OK;
}

void fv_temporal_result(const fv_temporal *t, fv_region region, double *mse, double *e)
{
    double m = 0.0, a = 0.0;
    if ((unsigned)region >= FV_REGION_COUNT) {
        m = a = NAN;
    } else if (t->frames > 1) {
        int pairs = t->pairs[region];
        m = pairs > 0 ? t->mse_sum[region] / pairs : NAN;
        a = pairs > 0 ? t->e_sum[region] / pairs : NAN;
    }
    if (mse) *mse = m;
    if (e) *e = a;
}

int fv_temporal_frames(const fv_temporal *t) { return t->frames; }
