/* fovea — the foveated Gaussian blur of Visual-Polar path tracing (Koskela et al., Sec. 3.5; see
 * blur.h for the contract).
 *
 * How it is made cheap enough to run every frame on 1280x1440 images:
 *  - Sigma is quantised to 1/32 pixel (q = round(32 sigma)), at most 1/64 pixel from the request: far
 *    below what the eye sees, and the paper's profile changes sigma by that much only every few
 *    pixels. All kernels up to sigma 32 are built once per call (a few thousand exp calls for the
 *    paper's 6.8); wider ones, which no sensible profile asks for, are built per run of pixels.
 *  - Along a row, neighbouring pixels nearly always share q (the whole periphery beyond the ramp
 *    does). A run of equal q is filtered as a sum of shifted, scaled copies of the row segment:
 *    o = k0 c + sum_d k_d (c[-d] + c[+d]). That loop is channel-agnostic on interleaved RGB and
 *    vectorises across pixels, whereas a per-pixel tap loop would be 3-wide scalar code. The
 *    vertical pass is the same loop with the taps one row apart, so it needs no transpose: the
 *    2 r + 1 rows it reads (at most 41 for sigma 6.8) stay in cache from one output row to the next.
 *  - Pixels whose kernel is the centre tap alone (truncation at 3 sigma leaves no other tap for
 *    sigma < 1/3) are copied by the horizontal pass and left alone by the vertical one, so the fovea
 *    costs nothing and stays bit-identical.
 *  - Border renormalisation is needed only within r pixels of the image edge: per pixel in the
 *    horizontal pass, and per run (all pixels of a run share the same valid rows) in the vertical one.
 * Every output pixel is computed by one thread in a fixed order of operations, so the result does not
 * depend on the thread count. Memory: one image-sized scratch buffer.
 */
#include <math.h>
#include <omp.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "filter/blur.h"

#define Q_PER_PX 32                  /* sigma quantisation steps per pixel */
#define Q_TABLE (32 * Q_PER_PX)      /* kernels up to sigma 32 px are precomputed */
#define Q_CLAMP 100000000            /* sigma beyond ~3e6 px acts as 3e6 px (keeps q in an int) */
#define ROW_CHUNK 16                 /* rows per scheduling chunk: interleaved, so an off-centre
                                        gaze still splits the work evenly */

double fv_blur_sigma_at(double e_deg, double fovea_deg, double ramp_deg, double sigma_max)
{
    /* Written as negated comparisons so that a NaN eccentricity gets no blur and a ramp that ends at
     * (or before) the fovea's edge becomes a step instead of a division by zero. */
    if (!(e_deg > fovea_deg)) return 0.0;
    if (!(e_deg < ramp_deg)) return sigma_max;
    return sigma_max * (e_deg - fovea_deg) / (ramp_deg - fovea_deg);
}

static int quantise(float s)
{
    float t = s * (float)Q_PER_PX + 0.5f;
    return t < (float)Q_CLAMP ? (int)t : Q_CLAMP;
}

/* Taps reach 3 sigma (floor), but never further than the image: beyond rcap every tap is outside it
 * and would be dropped by the border renormalisation anyway. */
static int radius_of(int q, int rcap)
{
    int r = (int)((3LL * q) / Q_PER_PX);
    return r < rcap ? r : rcap;
}

/* k[d] for d = 0..r: exp(-d^2 / 2 sigma^2), normalised so that k[0] + 2 sum k[d] = 1. Double
 * precision keeps the normalisation exact to float rounding even for r in the thousands. */
static void make_kernel(int q, int r, float *k)
{
    if (r == 0) {
        k[0] = 1.0f;
        return;
    }
    double s = (double)q / Q_PER_PX, c = -0.5 / (s * s), sum = 1.0;
    for (int d = 1; d <= r; d++) sum += 2.0 * exp(c * d * d);
    for (int d = 0; d <= r; d++) k[d] = (float)(exp(c * d * d) / sum);
}

typedef struct kernel_set {
    int rcap;
    int nq;        /* kernels held for q in [0, nq) */
    int *off;      /* kernel q starts at k + off[q] */
    float *k;
} kernel_set;

static int kernel_set_init(kernel_set *ks, int qmax, int rcap)
{
    ks->rcap = rcap;
    ks->nq = (qmax < Q_TABLE ? qmax : Q_TABLE) + 1;
    ks->off = fv_alloc_array((size_t)ks->nq, sizeof(int));
    size_t total = 0;
    if (ks->off)
        for (int q = 0; q < ks->nq; q++) {
            ks->off[q] = (int)total;
            total += (size_t)radius_of(q, rcap) + 1;
        }
    ks->k = ks->off ? fv_alloc_array(total, sizeof(float)) : NULL;
    if (!ks->k) return -1;
    for (int q = 0; q < ks->nq; q++) make_kernel(q, radius_of(q, rcap), ks->k + ks->off[q]);
    return 0;
}

/* The kernel of q: from the table, or built into the thread's scratch (kept while q repeats). */
static const float *kernel_of(const kernel_set *ks, int q, float *scratch, int *scratch_q)
{
    if (q < ks->nq) return ks->k + ks->off[q];
    if (*scratch_q != q) {
        make_kernel(q, radius_of(q, ks->rcap), scratch);
        *scratch_q = q;
    }
    return scratch;
}

/* o[i] = k[0] c[i] + sum_{d=1..r} k[d] (c[i - d step] + c[i + d step]), i in [0, n): the interior of
 * a run, every tap inside the image. */
static void taps_symmetric(float *restrict o, const float *restrict c, ptrdiff_t step, const float *k, int r, size_t n)
{
    const float k0 = k[0];
#pragma omp simd
    for (size_t i = 0; i < n; i++) o[i] = k0 * c[i];
    for (int d = 1; d <= r; d++) {
        const float *m = c - d * step, *p = c + d * step;
        const float kd = k[d];
#pragma omp simd
        for (size_t i = 0; i < n; i++) o[i] += kd * (m[i] + p[i]);
    }
}

/* The same sum over the taps d in [dlo, dhi] only, renormalised by their weights: a run of the
 * vertical pass whose row is within r of the top or bottom edge. */
static void taps_clipped(float *restrict o, const float *restrict c, ptrdiff_t step, const float *k, int dlo, int dhi, size_t n)
{
    float wsum = 0.0f;
    for (int d = dlo; d <= dhi; d++) wsum += k[d < 0 ? -d : d];
    for (int d = dlo; d <= dhi; d++) {
        const float *p = c + d * step;
        const float kd = k[d < 0 ? -d : d] / wsum;
        if (d == dlo) {
#pragma omp simd
            for (size_t i = 0; i < n; i++) o[i] = kd * p[i];
        } else {
#pragma omp simd
            for (size_t i = 0; i < n; i++) o[i] += kd * p[i];
        }
    }
}

/* One pixel of the horizontal pass within r of the left or right edge. */
static void pixel_clipped(float *o, const float *row, int x, int w, const float *k, int r)
{
    int dlo = x < r ? -x : -r, dhi = x + r >= w ? w - 1 - x : r;
    float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f, wsum = 0.0f;
    for (int d = dlo; d <= dhi; d++) {
        const float kd = k[d < 0 ? -d : d], *p = row + 3 * (ptrdiff_t)(x + d);
        s0 += kd * p[0];
        s1 += kd * p[1];
        s2 += kd * p[2];
        wsum += kd;
    }
    o[0] = s0 / wsum;
    o[1] = s1 / wsum;
    o[2] = s2 / wsum;
}

/* The run of pixels starting at x whose quantised sigma equals that of x: returns its end. */
static int run_end(const float *sig, int x, int w, int *q)
{
    *q = quantise(sig[x]);
    int e = x + 1;
    while (e < w && quantise(sig[e]) == *q) e++;
    return e;
}

static void horizontal_row(const float *src, float *dst, const float *sig, int w, const kernel_set *ks, float *scratch,
                           int *scratch_q)
{
    for (int x = 0, e, q; x < w; x = e) {
        e = run_end(sig, x, w, &q);
        int r = radius_of(q, ks->rcap);
        if (r == 0) {
            memcpy(dst + 3 * (ptrdiff_t)x, src + 3 * (ptrdiff_t)x, 3 * sizeof(float) * (size_t)(e - x));
            continue;
        }
        const float *k = kernel_of(ks, q, scratch, scratch_q);
        int a = x > r ? x : r, b = e < w - r ? e : w - r; /* interior part [a, b) of the run */
        if (b <= a) a = b = e;
        for (int i = x; i < a; i++) pixel_clipped(dst + 3 * (ptrdiff_t)i, src, i, w, k, r);
        if (b > a) taps_symmetric(dst + 3 * (ptrdiff_t)a, src + 3 * (ptrdiff_t)a, 3, k, r, 3 * (size_t)(b - a));
        for (int i = b; i < e; i++) pixel_clipped(dst + 3 * (ptrdiff_t)i, src, i, w, k, r);
    }
}

/* Row y of the vertical pass, from the horizontally blurred tmp into rgb. Runs with no taps besides
 * the centre are skipped: tmp holds a copy of rgb there. */
static void vertical_row(const float *tmp, float *rgb, const float *sig, int y, int w, int h, const kernel_set *ks,
                         float *scratch, int *scratch_q)
{
    const ptrdiff_t step = 3 * (ptrdiff_t)w;
    for (int x = 0, e, q; x < w; x = e) {
        e = run_end(sig, x, w, &q);
        int r = radius_of(q, ks->rcap);
        if (r == 0) continue;
        const float *k = kernel_of(ks, q, scratch, scratch_q);
        size_t at = 3 * ((size_t)y * w + x), n = 3 * (size_t)(e - x);
        if (y >= r && y + r < h)
            taps_symmetric(rgb + at, tmp + at, step, k, r, n);
        else
            taps_clipped(rgb + at, tmp + at, step, k, y < r ? -y : -r, y + r >= h ? h - 1 - y : r, n);
    }
}

fv_status fv_blur_variable(float *rgb, int w, int h, const float *sigma, int threads, fv_error *err)
{
    if (!rgb || !sigma) return fv_error_set(err, FV_ERR_INVALID, "blur: no %s", rgb ? "sigma buffer" : "image");
    if (w < 1 || h < 1) return fv_error_set(err, FV_ERR_INVALID, "blur: image size %dx%d", w, h);
    const size_t n = (size_t)w * h;
    const int nt = fv_thread_count(threads);

    /* Validate before touching rgb, and find the widest kernel. */
    float smax = 0.0f;
    int bad = 0;
#pragma omp parallel for schedule(static) num_threads(nt) reduction(max : smax) reduction(| : bad)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float s = sigma[(size_t)y * w + x];
            if (s >= 0.0f && s <= 3.4e38f) /* false for NaN, negatives and infinities */
                smax = s > smax ? s : smax;
            else
                bad = 1;
        }
    if (bad)
        for (size_t i = 0; i < n; i++)
            if (!(sigma[i] >= 0.0f && sigma[i] <= 3.4e38f))
                return fv_error_set(err, FV_ERR_INVALID, "blur: sigma %g at pixel (%d, %d) is not a finite value >= 0",
                                    (double)sigma[i], (int)(i % (size_t)w), (int)(i / (size_t)w));

    const int rcap = (w > h ? w : h) - 1;
    const int qmax = quantise(smax);
    if (radius_of(qmax, rcap) == 0) return FV_OK; /* no pixel has a tap besides its centre */

    kernel_set ks = {0};
    float *tmp = fv_alloc_array(n, 3 * sizeof(float));
    float *scratch = qmax >= Q_TABLE ? fv_alloc_array((size_t)nt * ((size_t)rcap + 1), sizeof(float)) : NULL;
    if (!tmp || kernel_set_init(&ks, qmax, rcap) != 0 || (qmax >= Q_TABLE && !scratch)) {
        free(tmp), free(ks.off), free(ks.k), free(scratch);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory blurring a %dx%d image", w, h);
    }

#pragma omp parallel num_threads(nt)
    {
        int t = omp_get_thread_num(), scratch_q = -1;
        float *my_scratch = scratch ? scratch + (size_t)t * ((size_t)rcap + 1) : NULL;
#pragma omp for schedule(static, ROW_CHUNK)
        for (int y = 0; y < h; y++) {
            size_t at = 3 * (size_t)y * w;
            horizontal_row(rgb + at, tmp + at, sigma + (size_t)y * w, w, &ks, my_scratch, &scratch_q);
        }
        /* the implicit barrier: every row of tmp is ready before any column is read */
#pragma omp for schedule(static, ROW_CHUNK)
        for (int y = 0; y < h; y++) vertical_row(tmp, rgb, sigma + (size_t)y * w, y, w, h, &ks, my_scratch, &scratch_q);
    }
    free(tmp), free(ks.off), free(ks.k), free(scratch);
    return FV_OK;
}
