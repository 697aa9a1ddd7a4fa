/* fovea — the foveated Gaussian blur of Visual-Polar path tracing (Koskela et al., Sec. 3.5; see
 * blur.h for the contract).
 *
 * The work is the direct separable convolution, 2 r + 1 taps per pixel per axis (41 for the
 * paper's sigma of 6.8). What makes it cheap enough to run on every 1280x1440 frame:
 *  - Sigma is rounded to a grid (see quantise), so kernels are built once per call and neighbouring
 *    pixels share one: the whole periphery beyond the ramp, and runs of a few pixels within it.
 *  - A run of pixels with the same kernel is filtered as a sum of shifted, scaled copies of the row
 *    segment, o = k0 c + sum_d k_d (c[-d] + c[+d]): channel-agnostic on interleaved RGB, so it
 *    vectorises across pixels, with 32 outputs held in registers across all taps (SSE, or AVX2
 *    where the CPU has it). The symmetric pairs halve the multiplications.
 *  - The two passes are fused per slab of rows: a ring of horizontally blurred rows (2 r + BATCH
 *    of them) is consumed by the vertical pass strip by strip, so the intermediate image never
 *    leaves the cache and rgb is read once and written once. The rows a slab needs from its
 *    neighbours (r above, r below) are blurred horizontally before any slab writes, because their
 *    owners overwrite them.
 *  - Taps outside the image read zeros (a zero-padded copy of the row, a zero row), and the pixels
 *    within r of the edge are then divided by the weight of the taps that were inside: the border
 *    renormalisation costs nothing in the interior.
 *  - Pixels whose kernel is the centre tap alone are copied by the horizontal pass and not written
 *    by the vertical one, so the fovea costs nothing and keeps its bits.
 * Every output value is the same sequence of IEEE operations whichever thread, slab, vector width
 * or code path computes it, so the result depends neither on the thread count nor on the CPU.
 */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/scratch.h"
#include "core/parallel.h"
#include "filter/blur.h"
#include "filter/kblur.h"

#define Q_BITS FV_KBLUR_Q_BITS       /* sigma grid: 2^Q_BITS values per octave (see quantise) */
#define Q_STEPS FV_KBLUR_Q_STEPS
#define Q_TABLE (6 * Q_STEPS)        /* kernels up to sigma 32 px are built up front */
#define BATCH 64                     /* output rows per batch of a slab */
#define STRIP 32                     /* columns per strip of the vertical pass: its 2 r + 1 rows
                                        (16 KB for sigma 6.8) stay in L1 */
#define PAD 8                        /* floats after every buffer: the last block of a run reads up
                                        to 7 floats beyond it */

/* kernel code (filter/kblur.h): the Visual-Polar device frame tabulates it per gaze on the device */
double fv_blur_sigma_at(double e_deg, double fovea_deg, double ramp_deg, double sigma_max)
{
    return fv_kblur_sigma_at(e_deg, fovea_deg, ramp_deg, sigma_max);
}

/* Sigma is rounded to a grid: multiples of 1/32 up to 2 pixels, then 32 values per octave
 * (2^o (1 + i/32): multiples of 1/16 up to 4, of 1/8 up to 8, ...), so it moves by at most 1/64
 * pixel or 1/64 of itself, far below what anyone can see. Relative steps keep runs of equal kernels
 * a few pixels long even where the paper's profile ramps up (uniform steps of 1/32 would cut the
 * ramp into runs of one or two pixels). q indexes the grid: q / 32 pixels below 64, above it octave
 * q / 32 - 1, step q % 32 (fv_kblur_quantise, filter/kblur.h: it runs for every pixel of the
 * ramp, and on the device backends). */
#define quantise fv_kblur_quantise

static double sigma_of(int q)
{
    if (q < 2 * Q_STEPS) return (double)q / Q_STEPS;
    return ldexp(1.0 + (double)(q % Q_STEPS) / Q_STEPS, q / Q_STEPS - 1);
}

/* Taps reach 3 sigma (floor), but never further than the image: beyond rcap every tap is outside it
 * and carries no weight after the border renormalisation anyway (fv_kblur_radius). */
#define radius_of fv_kblur_radius

/* k[d] for d = 0..r: exp(-d^2 / 2 sigma^2), normalised so that k[0] + 2 sum k[d] = 1 (double
 * precision, so the normalisation is exact to float rounding even for thousands of taps). */
static void make_kernel(int q, int r, float *k)
{
    if (r == 0) {
        k[0] = 1.0f;
        return;
    }
    double s = sigma_of(q), c = -0.5 / (s * s), sum = 1.0;
    for (int d = 1; d <= r; d++) sum += 2.0 * exp(c * d * d);
    for (int d = 0; d <= r; d++) k[d] = (float)(exp(c * d * d) / sum);
}

typedef struct kernel_set {
    int rcap;
    int nq;        /* kernels held for q in [0, nq) */
    int *off;      /* kernel q starts at k + off[q] */
    float *k;
} kernel_set;

static int kernel_set_init(kernel_set *ks, int qmax, int rcap, fv_scratch *room)
{
    ks->rcap = rcap;
    ks->nq = (qmax < Q_TABLE ? qmax : Q_TABLE) + 1;
    ks->off = fv_scratch_take(room, (size_t)ks->nq, sizeof(int));
    if (!ks->off) return -1;
    size_t total = 0;
    for (int q = 0; q < ks->nq; q++) {
        ks->off[q] = (int)total;
        total += (size_t)radius_of(q, rcap) + 1;
    }
    ks->k = fv_scratch_take(room, total, sizeof(float));
    if (!ks->k) return -1;
    for (int q = 0; q < ks->nq; q++) make_kernel(q, radius_of(q, rcap), ks->k + ks->off[q]);
    return 0;
}

void fv_blur_table_size(float smax, int w, int h, int *nq, size_t *nk)
{
    const int rcap = (w > h ? w : h) - 1;
    *nq = quantise(smax) + 1;
    *nk = 0;
    for (int q = 0; q < *nq; q++) *nk += (size_t)radius_of(q, rcap) + 1;
}

void fv_blur_table_fill(int w, int h, int nq, int *off, float *k)
{
    const int rcap = (w > h ? w : h) - 1;
    size_t total = 0;
    for (int q = 0; q < nq; q++) {
        off[q] = (int)total;
        make_kernel(q, radius_of(q, rcap), k + total);
        total += (size_t)radius_of(q, rcap) + 1;
    }
}

#define inside_weight fv_kblur_inside_weight

/* The kernels below compute, for the run of n pixels starting at float offset off of the rows,
 *   o[i] = k[0] rows[0][off + i] + sum_{d=1..r} k[d] (rows[-d][off + i] + rows[d][off + i]),
 * where rows[d] is the row of tap d: the zero-padded source row shifted by d pixels in the
 * horizontal pass, the blurred row d below in the vertical one. Every output float gets exactly
 * these IEEE operations in this order on every path (blocks of 32 floats, then one last block of up
 * to 32 whose extra lanes are computed from the padding and dropped), and there is no FMA (ISO C
 * mode does not contract), so the SSE and AVX2 copies give the same bits. */
typedef void (*taps_fn)(float *restrict o, const float *const *rows, size_t off, const float *k, int r, size_t n);

#if defined(__GNUC__)
/* Four and eight floats loaded from or stored to any float address (GCC and Clang vector
 * extensions). */
typedef float v4f __attribute__((vector_size(16), aligned(4), may_alias));
#define LD4(p) (*(const v4f *)(const void *)(p))
#define ST4(p, v) (*(v4f *)(void *)(p) = (v))

/* The last rem (< 32) floats of a run as nv vectors of four, all accumulated at once so that short
 * runs (the ramp of the sigma profile) are not one long chain of dependent adds. The loads may run
 * up to 3 floats past the run (every buffer has PAD floats after it); only rem floats are stored. */
__attribute__((always_inline)) static inline void taps_tail4(float *restrict o, const float *const *rows, size_t off,
                                                              const float *k, int r, size_t rem, const int nv)
{
    v4f a[8];
#pragma GCC unroll 8
    for (int v = 0; v < nv; v++) a[v] = k[0] * LD4(rows[0] + off + 4 * v);
    for (int d = 1; d <= r; d++) {
        const float *m = rows[-d] + off, *p = rows[d] + off;
        const float kd = k[d];
#pragma GCC unroll 8
        for (int v = 0; v < nv; v++) a[v] += kd * (LD4(m + 4 * v) + LD4(p + 4 * v));
    }
#pragma GCC unroll 8
    for (int v = 0; v < nv; v++)
        if (4 * (size_t)v + 4 <= rem)
            ST4(o + 4 * v, a[v]);
        else
            for (size_t l = 0; l < rem - 4 * (size_t)v; l++) o[4 * v + l] = a[v][l];
}

/* Baseline: 4-wide vectors (SSE2 on x86-64, NEON on ARM), eight accumulators. */
static void taps_v4(float *restrict o, const float *const *rows, size_t off, const float *k, int r, size_t n)
{
    const float k0 = k[0];
    const size_t nf = 3 * n;
    size_t i0 = 0;
    for (; i0 + 32 <= nf; i0 += 32) {
        const float *c = rows[0] + off + i0;
        v4f a0 = k0 * LD4(c), a1 = k0 * LD4(c + 4), a2 = k0 * LD4(c + 8), a3 = k0 * LD4(c + 12);
        v4f a4 = k0 * LD4(c + 16), a5 = k0 * LD4(c + 20), a6 = k0 * LD4(c + 24), a7 = k0 * LD4(c + 28);
        for (int d = 1; d <= r; d++) {
            const float *m = rows[-d] + off + i0, *p = rows[d] + off + i0;
            const float kd = k[d];
            a0 += kd * (LD4(m) + LD4(p));
            a1 += kd * (LD4(m + 4) + LD4(p + 4));
            a2 += kd * (LD4(m + 8) + LD4(p + 8));
            a3 += kd * (LD4(m + 12) + LD4(p + 12));
            a4 += kd * (LD4(m + 16) + LD4(p + 16));
            a5 += kd * (LD4(m + 20) + LD4(p + 20));
            a6 += kd * (LD4(m + 24) + LD4(p + 24));
            a7 += kd * (LD4(m + 28) + LD4(p + 28));
        }
        float *oo = o + i0;
        ST4(oo, a0), ST4(oo + 4, a1), ST4(oo + 8, a2), ST4(oo + 12, a3);
        ST4(oo + 16, a4), ST4(oo + 20, a5), ST4(oo + 24, a6), ST4(oo + 28, a7);
    }
    if (i0 < nf) {
        const size_t rem = nf - i0;
        switch ((rem + 3) / 4) {
        case 1: taps_tail4(o + i0, rows, off + i0, k, r, rem, 1); break;
        case 2: taps_tail4(o + i0, rows, off + i0, k, r, rem, 2); break;
        case 3: taps_tail4(o + i0, rows, off + i0, k, r, rem, 3); break;
        case 4: taps_tail4(o + i0, rows, off + i0, k, r, rem, 4); break;
        case 5: taps_tail4(o + i0, rows, off + i0, k, r, rem, 5); break;
        case 6: taps_tail4(o + i0, rows, off + i0, k, r, rem, 6); break;
        case 7: taps_tail4(o + i0, rows, off + i0, k, r, rem, 7); break;
        default: taps_tail4(o + i0, rows, off + i0, k, r, rem, 8); break;
        }
    }
}

#if defined(__x86_64__)
#define FV_BLUR_AVX2 1
/* AVX2: the same sums eight floats at a time. The library is built for baseline x86-64, so this
 * copy is compiled for AVX2 alone and picked at run time; it halves the instructions of the loop
 * that is nearly all of the blur's time. */
typedef float v8f __attribute__((vector_size(32), aligned(4), may_alias));
#define LD8(p) (*(const v8f *)(const void *)(p))
#define ST8(p, v) (*(v8f *)(void *)(p) = (v))

/* The last rem (< 32) floats of a run as nv vectors of eight, all accumulated at once so that
 * short runs (the ramp of the sigma profile) are not one long chain of dependent adds. Loads may run
 * up to 7 floats past the run (every buffer has PAD floats after it); only rem floats are stored. */
__attribute__((target("avx2"), always_inline)) static inline void taps_tail8(float *restrict o, const float *const *rows,
                                                                               size_t off, const float *k, int r,
                                                                               size_t rem, const int nv)
{
    v8f a[4];
#pragma GCC unroll 4
    for (int v = 0; v < nv; v++) a[v] = k[0] * LD8(rows[0] + off + 8 * v);
    for (int d = 1; d <= r; d++) {
        const float *m = rows[-d] + off, *p = rows[d] + off;
        const float kd = k[d];
#pragma GCC unroll 4
        for (int v = 0; v < nv; v++) a[v] += kd * (LD8(m + 8 * v) + LD8(p + 8 * v));
    }
#pragma GCC unroll 4
    for (int v = 0; v < nv; v++)
        if (8 * (size_t)v + 8 <= rem)
            ST8(o + 8 * v, a[v]);
        else
            for (size_t l = 0; l < rem - 8 * (size_t)v; l++) o[8 * v + l] = a[v][l];
}

__attribute__((target("avx2"))) static void taps_v8(float *restrict o, const float *const *rows, size_t off,
                                                    const float *k, int r, size_t n)
{
    const float k0 = k[0];
    const size_t nf = 3 * n;
    size_t i0 = 0;
    for (; i0 + 32 <= nf; i0 += 32) {
        const float *c = rows[0] + off + i0;
        v8f a0 = k0 * LD8(c), a1 = k0 * LD8(c + 8), a2 = k0 * LD8(c + 16), a3 = k0 * LD8(c + 24);
        for (int d = 1; d <= r; d++) {
            const float *m = rows[-d] + off + i0, *p = rows[d] + off + i0;
            const float kd = k[d];
            a0 += kd * (LD8(m) + LD8(p));
            a1 += kd * (LD8(m + 8) + LD8(p + 8));
            a2 += kd * (LD8(m + 16) + LD8(p + 16));
            a3 += kd * (LD8(m + 24) + LD8(p + 24));
        }
        ST8(o + i0, a0), ST8(o + i0 + 8, a1), ST8(o + i0 + 16, a2), ST8(o + i0 + 24, a3);
    }
    if (i0 < nf) {
        const size_t rem = nf - i0;
        switch ((rem + 7) / 8) {
        case 1: taps_tail8(o + i0, rows, off + i0, k, r, rem, 1); break;
        case 2: taps_tail8(o + i0, rows, off + i0, k, r, rem, 2); break;
        case 3: taps_tail8(o + i0, rows, off + i0, k, r, rem, 3); break;
        default: taps_tail8(o + i0, rows, off + i0, k, r, rem, 4); break;
        }
    }
}
#endif

#else
/* Other compilers: plain C, element by element. */
static void taps_v4(float *restrict o, const float *const *rows, size_t off, const float *k, int r, size_t n)
{
    for (size_t i = 0; i < 3 * n; i++) {
        float a = k[0] * rows[0][off + i];
        for (int d = 1; d <= r; d++) a += k[d] * (rows[-d][off + i] + rows[d][off + i]);
        o[i] = a;
    }
}
#endif

static taps_fn pick_taps(void)
{
#if defined(FV_BLUR_AVX2)
    if (__builtin_cpu_supports("avx2")) return taps_v8;
#endif
    return taps_v4;
}

/* The run of pixels in [x, end) whose quantised sigma equals that of x: returns where it stops.
 * Eight pixels bitwise equal to their left neighbours (the whole periphery beyond the ramp, the
 * whole fovea) are skipped at once, without rounding. */
static int run_end(const float *sig, int x, int end, int *q)
{
    *q = quantise(sig[x]);
    int e = x + 1;
    for (;;) {
        while (e + 8 <= end && memcmp(sig + e, sig + e - 1, 8 * sizeof(float)) == 0) e += 8;
        if (e >= end || quantise(sig[e]) != *q) return e;
        e++;
    }
}

typedef struct blur_job {
    float *rgb;
    const float *sigma;
    int w, h;
    int R;                 /* the largest radius in the image */
    size_t w3;             /* floats per image row */
    int nstrips;           /* strips of STRIP columns (the last may be narrower) */
    kernel_set ks;
    taps_fn taps;
    const float *zero;     /* a strip row of zeros: the vertical taps outside the image */
} blur_job;

/* A band of output rows [y0, y1) and what it works with; one thread at a time.
 * The horizontally blurred rows live in a ring stored strip by strip: strip t holds its rb ring
 * rows (row y in slot (y - y0 + R) % rb), then the `below` rows under the slab, each STRIP pixels
 * wide. The 2 r + 1 rows a vertical tap loop reads are then a few KB apart and stay in L1: rows
 * of the whole image, 15 KB apart, thrash the TLB and run at half the speed. */
typedef struct slab {
    int y0, y1;
    int rb, below;
    size_t region;         /* floats per strip: (rb + below) rows of 3 STRIP floats */
    float *ring;
    float *srow;           /* the source row with R pixels of zeros on each side */
    const float **hrows;   /* 2 R + 1 pointers into srow: tap d of the horizontal pass */
    const float **vrows;   /* BATCH + 2 R pointers: the rows around a batch in one strip */
    float *kscratch;       /* a kernel wider than the table */
    int kq;                /* ... for this q (-1: none yet) */
} slab;

#define STRIP_FLOATS (3 * (size_t)STRIP)

static const float *kernel_of(const blur_job *j, slab *s, int q)
{
    if (q < j->ks.nq) return j->ks.k + j->ks.off[q];
    if (s->kq != q) {
        make_kernel(q, radius_of(q, j->ks.rcap), s->kscratch);
        s->kq = q;
    }
    return s->kscratch;
}

/* Where row y (y0 - R <= y < y1 + below) starts within every strip's region. */
static size_t ring_offset(const blur_job *j, const slab *s, int y)
{
    int slot = y >= s->y1 ? s->rb + (y - s->y1) : (y - s->y0 + j->R) % s->rb;
    return (size_t)slot * STRIP_FLOATS;
}

/* Row y through the horizontal pass (each pixel with its own sigma) into the ring. */
static void horizontal(const blur_job *j, slab *s, int y)
{
    const int w = j->w;
    const float *src = j->rgb + (size_t)y * j->w3, *sig = j->sigma + (size_t)y * w;
    memcpy(s->srow + 3 * (size_t)j->R, src, j->w3 * sizeof(float));
    const float *const *rows = s->hrows + j->R;
    float *out_row = s->ring + ring_offset(j, s, y);
    for (int x = 0, e, q; x < w; x = e) {
        e = run_end(sig, x, w, &q);
        const int r = radius_of(q, j->ks.rcap);
        const float *k = r > 0 ? kernel_of(j, s, q) : NULL;
        for (int a = x, b; a < e; a = b) { /* the run, cut where it crosses into the next strip */
            const int t = a / STRIP;
            b = (t + 1) * STRIP < e ? (t + 1) * STRIP : e;
            float *out = out_row + (size_t)t * s->region + 3 * (size_t)(a - t * STRIP);
            if (r == 0) {
                memcpy(out, src + 3 * (size_t)a, 3 * sizeof(float) * (size_t)(b - a));
                continue;
            }
            j->taps(out, rows, 3 * (size_t)a, k, r, (size_t)(b - a));
            /* Pixels within r of the left or right edge: divide by the weight of the taps that
             * fell inside the image (the others read zeros). */
            if (a < r || b > w - r)
                for (int i = a; i < b; i++)
                    if (i < r || i >= w - r) {
                        const float wsum = inside_weight(k, r, i, w);
                        for (int c = 0; c < 3; c++) out[3 * (i - a) + c] /= wsum;
                    }
        }
    }
}

/* Strip t of output row y from the horizontally blurred rows; rows[d] is row y + d of the strip.
 * Runs whose kernel is the centre alone are not written: rgb already holds the value. */
static void vertical(const blur_job *j, slab *s, int y, int t, const float *const *rows)
{
    const int x0 = t * STRIP, x1 = x0 + STRIP < j->w ? x0 + STRIP : j->w;
    const float *sig = j->sigma + (size_t)y * j->w;
    float *orow = j->rgb + (size_t)y * j->w3;
    for (int x = x0, e, q; x < x1; x = e) {
        e = run_end(sig, x, x1, &q);
        const int r = radius_of(q, j->ks.rcap);
        if (r == 0) continue;
        const float *k = kernel_of(j, s, q);
        float *o = orow + 3 * (size_t)x;
        j->taps(o, rows, 3 * (size_t)(x - x0), k, r, (size_t)(e - x));
        if (y < r || y + r >= j->h) {
            const float wsum = inside_weight(k, r, y, j->h);
            for (size_t i = 0; i < 3 * (size_t)(e - x); i++) o[i] /= wsum;
        }
    }
}

/* Before any slab writes: the rows above and below the slab, which their owners will overwrite. */
static void slab_halos(const blur_job *j, slab *s)
{
    for (int y = s->y0 - j->R > 0 ? s->y0 - j->R : 0; y < s->y0; y++) horizontal(j, s, y);
    for (int y = s->y1; y < s->y1 + s->below; y++) horizontal(j, s, y);
}

/* Batches of BATCH output rows: blur the rows the batch needs horizontally (rgb rows not yet
 * overwritten: a row is read here at least one batch before it is written), then walk down each
 * strip of the batch vertically. */
static void slab_run(const blur_job *j, slab *s)
{
    const int R = j->R;
    int next = s->y0; /* the next row of the slab to blur horizontally */
    for (int yb = s->y0; yb < s->y1; yb += BATCH) {
        const int ye = yb + BATCH < s->y1 ? yb + BATCH : s->y1;
        for (; next < s->y1 && next < ye + R; next++) horizontal(j, s, next);
        for (int t = 0; t < j->nstrips; t++) {
            const float *base = s->ring + (size_t)t * s->region;
            for (int y = yb - R; y < ye + R; y++)
                s->vrows[y - (yb - R)] = y >= 0 && y < j->h ? base + ring_offset(j, s, y) : j->zero;
            for (int y = yb; y < ye; y++) vertical(j, s, y, t, s->vrows + (y - yb) + R);
        }
    }
}

static int slab_alloc(const blur_job *j, slab *s, bool wide_kernels, fv_scratch *room)
{
    const int R = j->R;
    const int above = R < s->y0 ? R : s->y0;
    s->below = R < j->h - s->y1 ? R : j->h - s->y1;
    /* The ring holds every row of the slab (and above it) that a batch reads: at most BATCH + 2 R
     * rows, and never more than the slab and the rows above it. */
    const int live = s->y1 - s->y0 + above;
    s->rb = BATCH + 2 * R < live ? BATCH + 2 * R : live;
    s->region = (size_t)(s->rb + s->below) * STRIP_FLOATS;
    s->kq = -1;
    /* Zeroed: the last block of a run reads up to PAD floats beyond it (the next row, an unused
     * part of the last strip, the padding), which must be defined memory. */
    s->ring = fv_scratch_take_zero(room, (size_t)j->nstrips * s->region + PAD, sizeof(float));
    s->srow = fv_scratch_take_zero(room, j->w3 + 6 * (size_t)R + PAD, sizeof(float));
    s->hrows = fv_scratch_take(room, 2 * (size_t)R + 1, sizeof(float *));
    s->vrows = fv_scratch_take(room, BATCH + 2 * (size_t)R, sizeof(float *));
    s->kscratch = wide_kernels ? fv_scratch_take(room, (size_t)j->ks.rcap + 1, sizeof(float)) : NULL;
    if (!s->ring || !s->srow || !s->hrows || !s->vrows || (wide_kernels && !s->kscratch)) return -1;
    for (int d = -R; d <= R; d++) s->hrows[d + R] = s->srow + 3 * (size_t)(R + d);
    return 0;
}

fv_status fv_blur_variable(float *rgb, int w, int h, const float *sigma, int threads, fv_error *err)
{
    fv_scratch room = FV_SCRATCH_INIT;
    fv_status s = fv_blur_variable_in(rgb, w, h, sigma, threads, &room, err);
    fv_scratch_free(&room);
    return s;
}

fv_status fv_blur_variable_in(float *rgb, int w, int h, const float *sigma, int threads, fv_scratch *room, fv_error *err)
{
    fv_scratch_begin(room); /* every temporary of the call below comes from room */
    if (!rgb || !sigma) return fv_error_set(err, FV_ERR_INVALID, "blur: no %s", rgb ? "sigma buffer" : "image");
    if (w < 1 || h < 1) return fv_error_set(err, FV_ERR_INVALID, "blur: image size %dx%d", w, h);
    const int nt = fv_thread_count(threads);

    /* Validate before touching rgb; find the widest kernel and each row's share of the work. */
    float *cost = fv_scratch_take(room, (size_t)h + 1, sizeof(float));
    if (!cost) return fv_error_set(err, FV_ERR_NOMEM, "out of memory blurring a %dx%d image", w, h);
    float smax = 0.0f;
    int bad = 0;
fv_region_begin();
#pragma omp parallel for schedule(static) num_threads(nt) reduction(max : smax) reduction(| : bad)
    for (int y = 0; y < h; y++) {
        const float *row = sigma + (size_t)y * w;
        float m = 0.0f, sum = 0.0f;
        int b = 0;
        /* simd: the sum only steers the split into slabs, so its order does not matter */
#pragma omp simd reduction(max : m) reduction(+ : sum) reduction(| : b)
        for (int x = 0; x < w; x++) {
            float s = row[x];
            b |= (s >= 0.0f) + (s <= FLT_MAX) != 2; /* NaN, negative or infinite (no branch) */
            m = s > m ? s : m;
            sum += s < 1e6f ? s : 1e6f;
        }
        cost[y] = (float)w + 3.0f * sum; /* ~ taps per row: r = 3 sigma, plus a per-pixel cost */
        smax = m > smax ? m : smax;
        bad |= b;
    }
fv_region_end();
    if (bad) {
        for (size_t i = 0; i < (size_t)w * h; i++)
            if (!(sigma[i] >= 0.0f && sigma[i] <= FLT_MAX))
                return fv_error_set(err, FV_ERR_INVALID, "blur: sigma %g at pixel (%d, %d) is not a finite value >= 0",
                                    (double)sigma[i], (int)(i % (size_t)w), (int)(i / (size_t)w));
    }

    blur_job j = {.rgb = rgb, .sigma = sigma, .w = w, .h = h, .w3 = 3 * (size_t)w, .nstrips = (w + STRIP - 1) / STRIP,
                  .taps = pick_taps()};
    const int rcap = (w > h ? w : h) - 1, qmax = quantise(smax);
    j.R = radius_of(qmax, rcap);
    if (j.R == 0) return FV_OK; /* no pixel has a tap besides its centre */

    /* One slab per thread, split so that each gets the same estimated work (the fovea is cheap). */
    int nslab = nt < h ? nt : h;
    slab *slabs = fv_scratch_take_zero(room, (size_t)nslab, sizeof(slab));
    float *zero = fv_scratch_take_zero(room, STRIP_FLOATS + PAD, sizeof(float));
    int fail = !slabs || !zero || kernel_set_init(&j.ks, qmax, rcap, room) != 0;
    if (!fail) {
        double total = 0.0, acc = 0.0;
        for (int y = 0; y < h; y++) total += cost[y];
        for (int i = 0, y = 0; i < nslab; i++) {
            slabs[i].y0 = y;
            if (i == nslab - 1) {
                y = h;
            } else { /* at least one row, and one left for every later slab */
                const double target = total * (i + 1) / nslab;
                const int ymax = h - (nslab - 1 - i);
                do acc += cost[y++];
                while (y < ymax && acc + 0.5 * cost[y] < target);
            }
            slabs[i].y1 = y;
        }
        j.zero = zero;
        for (int i = 0; i < nslab && !fail; i++) fail = slab_alloc(&j, &slabs[i], qmax >= Q_TABLE, room) != 0;
    }
    if (fail) {
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory blurring a %dx%d image", w, h);
    }

fv_region_begin();
#pragma omp parallel num_threads(nt)
    {
#pragma omp for schedule(static, 1)
        for (int i = 0; i < nslab; i++) slab_halos(&j, &slabs[i]);
        /* the implicit barrier: no slab writes before every slab has read its neighbours' rows */
#pragma omp for schedule(static, 1)
        for (int i = 0; i < nslab; i++) slab_run(&j, &slabs[i]);
    }
fv_region_end();
    return FV_OK;
}
