/* fovea — edge-aware fill of a sparse lattice (see lattice.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "core/alloc.h"
#include "filter/atrous.h"
#include "filter/lattice.h"

static inline float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Fills row y (fv_lattice_fill's rule); returns how many of its pixels need shading. */
static long fill_row(int y, float *rgb, const uint8_t *known, const uint8_t *skip, const float *normal, const float *position,
                     int w, int h, const fv_lattice_opts *o, uint8_t *need)
{
    const int S0 = o->step > 1 ? o->step : 1;
    const float inv_s2 = o->sigma_position > 0.0f ? 1.0f / (o->sigma_position * o->sigma_position) : 0.0f;
    long missing = 0;
    for (int x = 0; x < w; x++) {
        size_t i = (size_t)y * w + x;
        need[i] = 0;
        if (known[i] || (skip && skip[i])) continue;
        const int S = o->level ? S0 << o->level[i] : S0, y0 = y / S * S;
        const float *n = &normal[3 * i], *p = &position[3 * i];
        if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f) { /* no surface: nothing to agree with */
            need[i] = 1;
            missing++;
            continue;
        }
        int x0 = x / S * S;
        float fx = (float)(x - x0) / S, fy = (float)(y - y0) / S;
        float sum[3] = {0.0f, 0.0f, 0.0f}, wsum = 0.0f;
        for (int c = 0; c < 4; c++) {
            int cx = x0 + (c & 1) * S, cy = y0 + (c >> 1) * S;
            if (cx >= w || cy >= h) continue;
            size_t j = (size_t)cy * w + cx;
            if (!known[j]) continue;
            const float *nq = &normal[3 * j], *pq = &position[3 * j];
            float cn = dot3(n, nq);
            if (!(cn > 0.0f)) continue;
            float wgt = ((c & 1) ? fx : 1.0f - fx) * ((c >> 1) ? fy : 1.0f - fy);
            wgt *= powf(cn, o->normal_power);
            if (inv_s2 > 0.0f) {
                float d[3] = {p[0] - pq[0], p[1] - pq[1], p[2] - pq[2]};
                wgt *= expf(-dot3(d, d) * inv_s2);
            }
            if (!(wgt > 1e-6f)) continue;
            for (int k = 0; k < 3; k++) sum[k] += wgt * rgb[3 * j + k];
            wsum += wgt;
        }
        if (wsum > 0.0f) {
            for (int k = 0; k < 3; k++) rgb[3 * i + k] = sum[k] / wsum;
        } else {
            need[i] = 1;
            missing++;
        }
    }
    return missing;
}

void fv_lattice_fill_team(float *rgb, const uint8_t *known, const uint8_t *skip, const float *normal, const float *position,
                          int w, int h, const fv_lattice_opts *o, uint8_t *need, long *missing)
{
    long mine = 0;
    #pragma omp for schedule(static) nowait
    for (int y = 0; y < h; y++) mine += fill_row(y, rgb, known, skip, normal, position, w, h, o, need);
    /* a count: the order the threads add in does not matter */
    #pragma omp atomic
    *missing += mine;
    #pragma omp barrier
}

long fv_lattice_fill(float *rgb, const uint8_t *known, const uint8_t *skip, const float *normal, const float *position, int w,
                     int h, const fv_lattice_opts *o, uint8_t *need)
{
    long missing = 0;
    fv_region_begin();
    #pragma omp parallel
    fv_lattice_fill_team(rgb, known, skip, normal, position, w, h, o, need, &missing);
    fv_region_end();
    return missing;
}

size_t fv_lattice_scratch_floats(int w, int h, int step)
{
    const int S = step > 1 ? step : 1;
    return 9 * (size_t)((w + S - 1) / S) * (size_t)((h + S - 1) / S);
}

void fv_lattice_filter_team(float *rgb, const uint8_t *known, const uint8_t *filter_mask, const float *normal,
                            const float *position, int w, int h, int step, const fv_atrous_opts *ao, float *scratch)
{
    const int S = step > 1 ? step : 1, lw = (w + S - 1) / S, lh = (h + S - 1) / S;
    const size_t n = (size_t)lw * lh;
    float *c = scratch, *nb = scratch + 3 * n, *pb = scratch + 6 * n;
    #pragma omp for schedule(static)
    for (int ly = 0; ly < lh; ly++)
        for (int lx = 0; lx < lw; lx++) {
            size_t i = (size_t)(ly * S) * w + (size_t)lx * S, j = (size_t)ly * lw + lx;
            memcpy(&c[3 * j], &rgb[3 * i], 3 * sizeof(float));
            memcpy(&pb[3 * j], &position[3 * i], 3 * sizeof(float));
            if (known[i]) memcpy(&nb[3 * j], &normal[3 * i], 3 * sizeof(float));
            else memset(&nb[3 * j], 0, 3 * sizeof(float)); /* not estimated: neither filtered nor used */
        }
    fv_atrous_team(c, nb, pb, lw, lh, ao); /* ends with the team's barrier */
    #pragma omp for schedule(static)
    for (int ly = 0; ly < lh; ly++)
        for (int lx = 0; lx < lw; lx++) {
            size_t i = (size_t)(ly * S) * w + (size_t)lx * S, j = (size_t)ly * lw + lx;
            if (known[i] && filter_mask[i]) memcpy(&rgb[3 * i], &c[3 * j], 3 * sizeof(float));
        }
}

fv_status fv_lattice_filter(float *rgb, const uint8_t *known, const uint8_t *filter_mask, const float *normal,
                            const float *position, int w, int h, int step, int iterations, fv_atrous *workspace, int threads,
                            float sigma_position, fv_error *err)
{
    const int S = step > 1 ? step : 1, lw = (w + S - 1) / S, lh = (h + S - 1) / S;
    fv_atrous_opts ao;
    fv_atrous_opts_default(&ao);
    ao.sigma_position = sigma_position;
    ao.iterations = iterations;
    ao.threads = threads;
    ao.workspace = workspace;
    fv_status rc = workspace ? FV_OK : fv_atrous_create(&ao.workspace, err);
    float *scratch = rc == FV_OK ? fv_alloc_array(fv_lattice_scratch_floats(w, h, step), sizeof(float)) : NULL;
    if (rc == FV_OK && !scratch) rc = fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d lattice", lw, lh);
    if (rc == FV_OK) rc = fv_atrous_prepare(ao.workspace, lw, lh, &ao, err);
    if (rc == FV_OK) {
        fv_region_begin();
        #pragma omp parallel num_threads(fv_thread_count(threads))
        fv_lattice_filter_team(rgb, known, filter_mask, normal, position, w, h, step, &ao, scratch);
        fv_region_end();
    }
    free(scratch);
    if (!workspace) fv_atrous_destroy(ao.workspace);
    return rc;
}
