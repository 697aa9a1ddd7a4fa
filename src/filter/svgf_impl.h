/* fovea — SVGF internals shared by svgf.c and the sweeps it builds twice (svgf_sweeps.h: for the
 * baseline x86-64 in svgf.c, for AVX2 in svgf_avx2.c). Private to src/filter/svgf*.c. */
#ifndef FV_FILTER_SVGF_IMPL_H
#define FV_FILTER_SVGF_IMPL_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include "filter/svgf.h"
#include "filter/ksvgf.h"

/* The constants, the weights' arithmetic and the per-pixel steps that are not sweeps are the
 * kernels' (filter/ksvgf.h): one implementation for the CPU and the devices. */
#define LEN_MAX FV_KSVGF_LEN_MAX
#define LUM_EPS FV_KSVGF_LUM_EPS
#define VAR_TEMPORAL_LEN FV_KSVGF_VAR_TEMPORAL_LEN
#define CHUNK 64
#define NTAP 24                 /* taps of the 5x5 kernel besides the centre */
#define NTAP7 48                /* the same for the 7x7 moments */
#define SQ_DEFAULT 7            /* sigma_normal 128 = 2^7: the case compiled with a constant */
/* Rows are dealt to the threads in interleaved blocks (still a static schedule): the fovea's short
 * columns make the first rows of a polar grid heavier, and halves would leave one thread waiting. */
#define ROWS_PER_BLOCK 8

/* The per-tap functions must be inlined into the loops marked omp simd, or nothing vectorises. */
#if defined(__GNUC__)
#define TAP_INLINE static inline __attribute__((always_inline))
#else
#define TAP_INLINE static inline
#endif

enum { KIND_NONE = FV_KSVGF_NONE, KIND_SURFACE = FV_KSVGF_SURFACE, KIND_HOLE = FV_KSVGF_HOLE };
enum { V_R = FV_KSVGF_R, V_G = FV_KSVGF_G, V_B = FV_KSVGF_B, V_VAR = FV_KSVGF_VAR, V_LUM = FV_KSVGF_LUM, NVAL = FV_KSVGF_NVAL };
/* The fovea's lines: the frame's features (normal, depth, depth gradient, 1 on a surface), the
 * pass's inputs (prefiltered variance, values) and its output values. */
enum { LN_NX, LN_NY, LN_NZ, LN_Z, LN_GRAD, LN_SURF, LN_FEATURES, LN_GVAR = LN_FEATURES, LN_VAL, LN_OUT = LN_VAL + NVAL,
       LN_COUNT = LN_OUT + NVAL };
#define LINE_STEP_MAX 16        /* passes with taps this far apart or closer use the lines */
#define LINE_GHOST (2 * LINE_STEP_MAX) /* the farthest tap along a line */
#define LINE_CHUNK (CHUNK - 8)  /* lanes per chunk: a vector may run 7 lanes past the chunk */

static const float k_b3[5] = {FV_KSVGF_B3_0, FV_KSVGF_B3_1, FV_KSVGF_B3_2, FV_KSVGF_B3_1, FV_KSVGF_B3_0};
static const float k_g3[3] = {FV_KSVGF_G3_0, FV_KSVGF_G3_1, FV_KSVGF_G3_0};

struct fv_svgf {
    fv_grid g;
    fv_svgf_opts o;
    int normal_squarings;   /* sigma_normal = 2^k, k <= 16: k; else -1 (powf) */
    int full_from;          /* polar grids: columns from here on all hold h rows */
    bool have_history;
    size_t n;
    uint8_t *kind;
    float *surf;            /* 1 on a surface pixel, else 0 (the variance prefilter's weights) */
    float *nx[2], *ny[2], *nz[2], *z[2]; /* normal and depth; [0] this frame, [1] the history */
    float *val[2][NVAL];    /* demodulated rgb, variance, luminance; ping-pong over the passes */
    float *gvar;            /* variance after the 3x3 prefilter, for the current pass */
    float *grad;            /* depth gradient magnitude */
    float *m1[2], *m2[2];   /* luminance moments; [0] this frame, [1] the history */
    float *len[2];          /* history length; 0: not a surface pixel (cannot serve as history) */
    float *hist_illum;      /* rgb after the first pass, for the next frame */
    float *hist_pos;        /* xyz */
    uint32_t *hist_id;
    long *row_surface, *row_hist, *row_holes;
    double *row_len;
    bool avx2;              /* the sweeps' AVX2 build (svgf_avx2.c), else the baseline one */
    bool blocks;            /* À-Trous pixels with every tap inner (register blocks, gathers); false:
                               FV_SVGF_ISA_PLAIN, one tap at a time */
    int periph_x, periph_passes; /* fv_svgf_set_periphery (w, iterations: off) */
    int pass_cut;           /* the current pass filters the columns [0, pass_cut) */
    /* Polar grids with short columns: the fovea's lines (see "C2." in svgf_sweeps.h). The columns
     * [0, lines_w) copied column-major, a line of line_stride floats per column: LINE_GHOST lanes
     * holding its last rows, its col_h rows, LINE_GHOST lanes holding its first rows (wrapped as
     * often as a short column needs), then unused lanes up to h. NULL: no lines (screen grids,
     * full polar grids). */
    int lines_w, line_stride;
    float *ln[LN_COUNT];
    bool ln_features;       /* ln's features hold this frame's (set by the first pass that needs them) */
};

/* ---- small helpers */

static inline int imin(int a, int b) { return a < b ? a : b; }
static inline int imax(int a, int b) { return a > b ? a : b; }

TAP_INLINE float luminance(float r, float g, float b) { return fv_ksvgf_luminance(r, g, b); }
TAP_INLINE float depth_eps(float z) { return fv_ksvgf_depth_eps(z); }
TAP_INLINE float exp_neg(float x) { return fv_ksvgf_exp_neg(x); }
/* Called with the literal SQ_DEFAULT in the hot loops so that the squarings unroll and the loop
 * vectorises. */
TAP_INLINE float normal_pow(float c, int sq, float sn) { return fv_ksvgf_normal_pow(c, sq, sn); }

/* For the pixels [x0, x1) of row y: the run [*a, *b) whose tap (dx, dy) is the pixel x + *off (a
 * plain shift: fv_grid_tap reduces to it there). Pixels outside the run need fv_grid_tap on a polar
 * grid; on a screen grid their tap lies outside the image. An empty run is returned as a = b = x1.
 * (x0, x1 here are any span of a row, not necessarily a whole chunk.) */
static inline void tap_run(const fv_svgf *f, int y, int dx, int dy, int x0, int x1, int *a, int *b, long *off)
{
    const fv_grid *g = &f->g;
    int row, lo, hi;
    if (!g->wrap) {
        row = y + dy;
        lo = imax(x0, -dx);
        hi = imin(x1, g->w - dx);
        if (row < 0 || row >= g->h) lo = hi = x1;
    } else {
        /* Both columns full height: no remapping between heights, the row wraps modulo h. */
        row = fv_grid_wrap_row(y + dy, g->h);
        lo = imax(imax(x0, f->full_from), imax(f->full_from - dx, -dx));
        hi = imin(x1, g->w - dx);
    }
    if (lo >= hi) lo = hi = x1;
    *a = lo;
    *b = hi;
    *off = (long)row * g->w + dx;
}

/* The span [*lo, *hi) of the chunk [x0, x1) (pixel x0 at index p0) from its first to its last
 * surface pixel; false when the chunk has none. Only the span is filtered (the fovea's short columns leave most of a chunk's row
 * beyond their heights, and a background stays out of the loops). */
static inline bool surface_span(const uint8_t *kind, size_t p0, int x0, int x1, int *lo, int *hi)
{
    int a = x0, b = x1;
    while (a < b && kind[p0 + (a - x0)] != KIND_SURFACE) a++;
    while (b > a && kind[p0 + (b - 1 - x0)] != KIND_SURFACE) b--;
    *lo = a, *hi = b;
    return a < b;
}

/* The pixels of a chunk that are not in a tap's run (polar grids: short columns, clamped edges) take
 * their taps through this table: for each column offset, where fv_grid_tap(x, y, dx, .) starts. The
 * same-angle mapping between columns of different heights is a division, done once per column
 * offset here rather than once per tap, and only for the pixels that need it. */
typedef struct chunk_cols {
    int x[7][CHUNK], row[7][CHUNK], n[7][CHUNK];
    bool ready;     /* built for the current chunk (only chunks that need it build it) */
} chunk_cols;

/* floor(a / b) for a >= 0, b > 0, exactly: the quotient in double is within a few ulps of a / b,
 * and the two integer tests correct the one step it may be off when a / b is (nearly) an integer.
 * fv_grid_tap's integer division, without the 64-bit divide (a chunk of the fovea needs hundreds). */
static inline int floor_div(long a, long b, double inv_b)
{
    long r = (long)((double)a * inv_b);
    r += (r + 1) * b <= a;
    r -= r * b > a;
    return (int)r;
}

/* The table for the pixels [k0, k1) of the chunk at x0 (row y, column offsets (i - ncols / 2) step). */
static void chunk_columns(const fv_grid *g, int y, int x0, int k0, int k1, int step, int ncols, chunk_cols *cc)
{
    const int half = ncols / 2;
    for (int k = k0; k < k1; k++) {
        const int x = x0 + k, hs = fv_grid_col_h(g, x);
        const double inv = 1.0 / (2.0 * (double)hs);
        for (int i = 0; i < ncols; i++) {
            int xx = x + (i - half) * step;
            xx = xx < 0 ? 0 : (xx >= g->w ? g->w - 1 : xx);
            const int hd = fv_grid_col_h(g, xx);
            cc->x[i][k] = xx, cc->n[i][k] = hd;
            cc->row[i][k] = hs == hd ? y : floor_div(((long)y * 2 + 1) * hd, 2L * hs, inv);
        }
    }
    cc->ready = true;
}

/* fv_grid_tap(g, x0 + k, y, (ci - ncols / 2) * step, dy) on a polar grid, from the table. */
static inline int chunk_tap(const fv_grid *g, const chunk_cols *cc, int ci, int k, int dy)
{
    int n = cc->n[ci][k], yy = cc->row[ci][k] + dy;
    yy += yy < 0 ? n : (yy >= n ? -n : 0); /* once around: no division */
    if (yy < 0 || yy >= n) yy = fv_grid_wrap_row(yy, n);
    return yy * g->w + cc->x[ci][k];
}

/* Fills fq[x - x0] for the pixels of [s0, s1) outside the run [a, b): their taps. Their centres may
 * be no surface: the tap is then still a valid pixel and weighs 0. */
static inline void fallback_taps(const fv_grid *g, const chunk_cols *cc, int ci, int dy, int x0, int s0, int s1, int a,
                                 int b, int *fq)
{
    for (int x = s0; x < a; x++) fq[x - x0] = chunk_tap(g, cc, ci, x - x0, dy);
    for (int x = b; x < s1; x++) fq[x - x0] = chunk_tap(g, cc, ci, x - x0, dy);
}

/* ---- B. depth gradient and variance */

static inline float axis_gradient(const fv_svgf *f, long qm, long qp, float zc)
{
    return fv_ksvgf_axis_gradient(f->kind, f->z[0], qm, qp, zc);
}

/* The two builds of svgf_sweeps.h: B. depth gradient and variance; C. the variance prefilter and
 * one À-Trous pass. The _avx2 ones need an AVX2 CPU. Each is an orphaned `omp for`: called by every
 * thread of fv_svgf_filter's one parallel region, it shares its rows among them (called outside a
 * region, by one thread, it does them all). */
void fv_svgf_variance_base(fv_svgf *f);
void fv_svgf_prefilter_base(fv_svgf *f, const float *var);
void fv_svgf_atrous_base(fv_svgf *f, int step, int src, bool write_hist);
void fv_svgf_variance_avx2(fv_svgf *f);
void fv_svgf_prefilter_avx2(fv_svgf *f, const float *var);
void fv_svgf_atrous_avx2(fv_svgf *f, int step, int src, bool write_hist);

#endif
