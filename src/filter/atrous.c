/* fovea — edge-avoiding À-Trous wavelet filter (Dammertz et al., HPG 2010; see atrous.h).
 *
 * Defaults, chosen for our linear radiance with no fixed exposure:
 *  - sigma_color 0.8 is a fraction of the mean luminance of the surface pixels, so scaling the
 *    image by any constant scales the result by the same constant. At iteration i it is 0.8 * 2^-i,
 *    so the first pass averages away noise of the order of the mean (photon-map noise at a few
 *    photons per gather disc) while the 16-pixel pass only mixes values within ~5% of each other.
 *  - sigma_normal 0.3 on |n_p - n_q|^2: surfaces 10 degrees apart (|dn|^2 = 0.03) still mix at
 *    weight 0.72, a 90-degree crease (|dn|^2 = 2) is cut at e^-22.
 *  - sigma_position is off by default because only the caller knows the scene's scale (the photon
 *    mappers pass twice their gather radius).
 * Limits: 25 taps per pixel per pass, one image-sized scratch buffer (a workspace's, kept from call
 * to call, or the call's own); pixels whose colour is not
 * finite are never used as taps and keep their own value.
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "core/alloc.h"
#include "filter/atrous.h"
#include "filter/demod.h"
#include "fovea/math.h"

void fv_atrous_opts_default(fv_atrous_opts *o)
{
    o->iterations = 5;
    o->sigma_color = 0.8f;
    o->sigma_normal = 0.3f;
    o->sigma_position = 0.0f;
    o->demod = NULL;
    o->threads = 0;
    o->workspace = NULL;
}

struct fv_atrous {
    float *tmp;       /* the ping-pong image, 3 floats per pixel */
    double *row_lum;  /* per-row luminance sums */
    long *row_count;
    size_t npix;      /* capacity of tmp, in pixels */
    int rows;         /* capacity of the row sums */
};

fv_status fv_atrous_create(fv_atrous **out, fv_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
}

void fv_atrous_destroy(fv_atrous *a)
{
    if (!a) return;
    free(a->tmp), free(a->row_lum), free(a->row_count);
    free(a);
}

/* Grows a's buffers to a w x h image; on failure a keeps what it had. */
static bool reserve(fv_atrous *a, int w, int h)
{
    const size_t n = (size_t)w * (size_t)h;
    if (n > a->npix) {
        float *t = fv_alloc_array(n, 3 * sizeof(float));
        if (!t) return false;
        free(a->tmp);
        a->tmp = t;
        a->npix = n;
    }
    if (h > a->rows) {
        double *l = fv_alloc_array((size_t)h, sizeof(double));
        long *c = fv_alloc_array((size_t)h, sizeof(long));
        if (!l || !c) {
            free(l), free(c);
            return false;
        }
        free(a->row_lum), free(a->row_count);
        a->row_lum = l, a->row_count = c;
        a->rows = h;
    }
    return true;
}

static const float k_b3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};

static bool has_surface(const float *normal, size_t i)
{
    return !normal || normal[3 * i] != 0.0f || normal[3 * i + 1] != 0.0f || normal[3 * i + 2] != 0.0f;
}

/* The checks of fv_atrous_filter (its errors, its messages). */
static fv_status check(int w, int h, const fv_atrous_opts *o, fv_error *err)
{
    if (w < 1 || h < 1) return fv_error_set(err, FV_ERR_INVALID, "A-Trous filter: image size %dx%d", w, h);
    if (o->iterations < 0 || o->iterations > 12)
        return fv_error_set(err, FV_ERR_INVALID, "A-Trous filter: iterations %d not in [0, 12]", o->iterations);
    if (!(o->sigma_color > 0.0f))
        return fv_error_set(err, FV_ERR_INVALID, "A-Trous filter: sigma_color %g must be positive", (double)o->sigma_color);
    if (!(o->sigma_normal > 0.0f))
        return fv_error_set(err, FV_ERR_INVALID, "A-Trous filter: sigma_normal %g must be positive", (double)o->sigma_normal);
    if (!(o->sigma_position >= 0.0f))
        return fv_error_set(err, FV_ERR_INVALID, "A-Trous filter: sigma_position %g must be >= 0 (0 = off)",
                            (double)o->sigma_position);
    return FV_OK;
}

fv_status fv_atrous_prepare(fv_atrous *ws, int w, int h, const fv_atrous_opts *o, fv_error *err)
{
    fv_atrous_opts def;
    if (!o) {
        fv_atrous_opts_default(&def);
        o = &def;
    }
    fv_status st = check(w, h, o, err);
    if (st != FV_OK) return st;
    return reserve(ws, w, h) ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory filtering a %dx%d image", w, h);
}

/* The filter's passes, run by every thread of the enclosing region with ws reserved. */
static void passes(float *rgb, const float *normal, const float *position, int w, int h, const fv_atrous_opts *o, fv_atrous *ws)
{
    float *tmp = ws->tmp;
    /* per-row luminance sums: added up in row order after, the same whatever the thread count */
    double *row_lum = ws->row_lum;
    long *row_count = ws->row_count;
    const float inv_n2 = 1.0f / (o->sigma_normal * o->sigma_normal);
    const float inv_x2 = o->sigma_position > 0.0f ? 1.0f / (o->sigma_position * o->sigma_position) : 0.0f;
    const float *demod = o->demod;
    float scale = 1.0f;
    #pragma omp for schedule(static)
    for (int y = 0; y < h; y++) {
        double lum = 0.0;
        long count = 0;
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            if (demod) {
                float d[3];
                fv_demod_factors(&demod[3 * i], d);
                for (int k = 0; k < 3; k++) rgb[3 * i + k] /= d[k];
            }
            if (has_surface(normal, i)) {
                float l = 0.2126f * rgb[3 * i] + 0.7152f * rgb[3 * i + 1] + 0.0722f * rgb[3 * i + 2];
                if (isfinite(l)) lum += l, count++;
            }
        }
        row_lum[y] = lum;
        row_count[y] = count;
    }
    /* The colour scale: the mean luminance of the surface pixels (one thread adds the rows up;
     * `copyprivate` hands it to every thread behind the barrier after `single`). */
    #pragma omp single copyprivate(scale)
    {
        double lum = 0.0;
        long count = 0;
        for (int y = 0; y < h; y++) lum += row_lum[y], count += row_count[y];
        scale = count > 0 && lum > 0.0 ? (float)(lum / count) : 1.0f;
    }
    for (int it = 0; it < o->iterations; it++) {
        /* ping-pong: even passes read rgb and write tmp, odd ones the other way */
        const float *src = it % 2 == 0 ? rgb : tmp;
        float *dst = it % 2 == 0 ? tmp : rgb;
        int step = 1 << it;
        float sc = o->sigma_color * scale / (float)(1 << it); /* halves every iteration */
        float inv_c2 = 1.0f / (sc * sc);
        #pragma omp for schedule(static)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t p = (size_t)y * w + x;
                const float *cp = &src[3 * p];
                if (!has_surface(normal, p)) {
                    memcpy(&dst[3 * p], cp, 3 * sizeof(float));
                    continue;
                }
                float sum[3] = {0, 0, 0}, wsum = 0.0f;
                for (int j = -2; j <= 2; j++) {
                    int yy = y + j * step;
                    if (yy < 0 || yy >= h) continue;
                    for (int i = -2; i <= 2; i++) {
                        int xx = x + i * step;
                        if (xx < 0 || xx >= w) continue;
                        size_t q = (size_t)yy * w + xx;
                        if (!has_surface(normal, q)) continue;
                        const float *cq = &src[3 * q];
                        float dc = (cp[0] - cq[0]) * (cp[0] - cq[0]) + (cp[1] - cq[1]) * (cp[1] - cq[1]) + (cp[2] - cq[2]) * (cp[2] - cq[2]);
                        /* dc > 0 test: a tiny image scale can make inv_c2 infinite, and 0 * inf
                         * would turn identical neighbours into NaN weights. */
                        float e = dc > 0.0f ? dc * inv_c2 : 0.0f;
                        if (normal) {
                            const float *np = &normal[3 * p], *nq = &normal[3 * q];
                            float dn = (np[0] - nq[0]) * (np[0] - nq[0]) + (np[1] - nq[1]) * (np[1] - nq[1]) + (np[2] - nq[2]) * (np[2] - nq[2]);
                            if (dn > 0.0f) e += dn * inv_n2;
                        }
                        if (position && inv_x2 > 0.0f) {
                            const float *xp = &position[3 * p], *xq = &position[3 * q];
                            float dx = (xp[0] - xq[0]) * (xp[0] - xq[0]) + (xp[1] - xq[1]) * (xp[1] - xq[1]) + (xp[2] - xq[2]) * (xp[2] - xq[2]);
                            if (dx > 0.0f) e += dx * inv_x2;
                        }
                        float wt = k_b3[i + 2] * k_b3[j + 2] * expf(-e);
                        if (!(wt > 0.0f) || !fv_is_finite3(fv_v3(cq[0], cq[1], cq[2]))) continue;
                        sum[0] += wt * cq[0];
                        sum[1] += wt * cq[1];
                        sum[2] += wt * cq[2];
                        wsum += wt;
                    }
                }
                for (int c = 0; c < 3; c++) dst[3 * p + c] = wsum > 0.0f ? sum[c] / wsum : cp[c];
            }
    }
    /* the result back into rgb (after an odd number of passes it is in tmp), remodulated */
    const float *res = o->iterations % 2 == 1 ? tmp : rgb;
    if (res != rgb || demod) {
        #pragma omp for schedule(static)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x;
                float d[3] = {1.0f, 1.0f, 1.0f};
                if (demod) fv_demod_factors(&demod[3 * i], d);
                for (int k = 0; k < 3; k++) rgb[3 * i + k] = res[3 * i + k] * d[k];
            }
    }
}

void fv_atrous_team(float *rgb, const float *normal, const float *position, int w, int h, const fv_atrous_opts *o)
{
    passes(rgb, normal, position, w, h, o, o->workspace);
}

fv_status fv_atrous_filter(float *rgb, const float *normal, const float *position, int w, int h, const fv_atrous_opts *o, fv_error *err)
{
    fv_atrous_opts def;
    if (!o) {
        fv_atrous_opts_default(&def);
        o = &def;
    }
    if (!rgb) return fv_error_set(err, FV_ERR_INVALID, "A-Trous filter: no image");
    fv_status st = check(w, h, o, err);
    if (st != FV_OK) return st;
    fv_atrous own = {0}, *ws = o->workspace ? o->workspace : &own;
    if (!reserve(ws, w, h)) {
        free(own.tmp), free(own.row_lum), free(own.row_count);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory filtering a %dx%d image", w, h);
    }
    /* One region for the whole filter (docs/threads.md): every pass is an `omp for` whose implicit
     * barrier orders it before the next, instead of a region per pass that wakes the team again. */
    fv_region_begin();
    #pragma omp parallel num_threads(fv_thread_count(o->threads))
    passes(rgb, normal, position, w, h, o, ws);
    fv_region_end();
    free(own.tmp), free(own.row_lum), free(own.row_count);
    return FV_OK;
}
