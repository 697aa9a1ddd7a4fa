/* fovea — the SVGF sweeps that dominate a frame (variance, prefilter, À-Trous passes), written once
 * and built twice: by svgf.c for the baseline x86-64 (SSE2) and by svgf_avx2.c for AVX2, each
 * defining SVGF_ISA(name) to name its copies. Neither build enables FMA and every loop keeps its
 * order, so the two give the same bits (tests/unit/test_svgf_isa.c forces each). Included only
 * by those two files, after filter/svgf_impl.h. */

/* One tap of the 7x7 moments estimate, pixel p (chunk slot k) taking pixel q. */
TAP_INLINE void moments_tap(const fv_svgf *f, size_t p, int q, int k, float rz, int sq, float sn, float *a1, float *a2,
                               float *aw)
{
    const float *nx = f->nx[0], *ny = f->ny[0], *nz = f->nz[0], *z = f->z[0];
    float wn = normal_pow(nx[p] * nx[q] + ny[p] * ny[q] + nz[p] * nz[q], sq, sn);
    float wt = wn * exp_neg(fabsf(z[p] - z[q]) * rz);
    a1[k] += wt * f->m1[0][q];
    a2[k] += wt * f->m2[0][q];
    aw[k] += wt;
}

void SVGF_ISA(variance)(fv_svgf *f)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const uint8_t *kind = f->kind;
    const float sd = f->o.sigma_depth, sn = f->o.sigma_normal;
    const int sq = f->normal_squarings;
    float *var = f->val[0][V_VAR], *grad = f->grad;
    const float *m1 = f->m1[0], *m2 = f->m2[0], *len = f->len[0];
    /* The 48 taps of the 7x7 window, the distance classes of their squared distances
     * (1, 2, 4, 5, 8, 9, 10, 13, 18). */
    int di[NTAP7], dj[NTAP7], cls[NTAP7];
    const int d2s[9] = {1, 2, 4, 5, 8, 9, 10, 13, 18};
    float dist[9];
    for (int c = 0; c < 9; c++) dist[c] = sqrtf((float)d2s[c]);
    for (int j = 0, t = 0; j < 7; j++)
        for (int i = 0; i < 7; i++) {
            if (i == 3 && j == 3) continue;
            int d2 = (i - 3) * (i - 3) + (j - 3) * (j - 3);
            di[t] = i - 3, dj[t] = j - 3;
            for (int c = 0; c < 9; c++)
                if (d2s[c] == d2) cls[t] = c;
            t++;
        }
    #pragma omp for schedule(static, ROWS_PER_BLOCK)
    for (int y = 0; y < h; y++) {
        float a1[CHUNK], a2[CHUNK], aw[CHUNK], rz[9][CHUNK];
        int fq[CHUNK];
        chunk_cols cc;
        for (int x0 = 0; x0 < w; x0 += CHUNK) {
            const int x1 = imin(x0 + CHUNK, w), nc = x1 - x0;
            const size_t p0 = (size_t)y * w + x0;
            /* Every pixel's depth gradient (each reads only its neighbours' depths) and temporal
             * variance; the 7x7 estimate below replaces the variance of the young ones. */
            bool young = false;
            /* The four neighbours are plain offsets (the rows above and below wrapped once per row)
             * between full-height columns away from the clamped edge, and inside a screen grid;
             * elsewhere fv_grid_tap works them out. */
            const int xa = g->wrap ? imax(f->full_from + 1, 1) : 1;
            const bool rows_in = g->wrap || (y >= 1 && y + 1 < h);
            const long up = (long)(y > 0 ? y - 1 : h - 1) * w, down = (long)(y + 1 < h ? y + 1 : 0) * w;
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                if (kind[p] != KIND_SURFACE) continue;
                const int x = x0 + k;
                const float zc = f->z[0][p];
                float gx, gy;
                if (rows_in && x >= xa && x + 1 < w) {
                    gx = axis_gradient(f, (long)p - 1, (long)p + 1, zc);
                    gy = axis_gradient(f, up + x, down + x, zc);
                } else {
                    gx = axis_gradient(f, fv_grid_tap(g, x, y, -1, 0), fv_grid_tap(g, x, y, 1, 0), zc);
                    gy = axis_gradient(f, fv_grid_tap(g, x, y, 0, -1), fv_grid_tap(g, x, y, 0, 1), zc);
                }
                grad[p] = gx > gy ? gx : gy;
                float tv = m2[p] - m1[p] * m1[p];
                var[p] = tv > 0.0f ? tv : 0.0f;
                young = young || len[p] < VAR_TEMPORAL_LEN;
            }
            int s0, s1;
            if (!young || !surface_span(kind, p0, x0, x1, &s0, &s1)) continue;
            float zs[CHUNK], ze[CHUNK];
            #pragma omp simd
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                zs[k] = sd * grad[p], ze[k] = depth_eps(f->z[0][p]);
                a1[k] = m1[p], a2[k] = m2[p], aw[k] = 1.0f; /* the centre, weight 1 */
            }
            for (int c = 0; c < 9; c++) {
                const float dc = dist[c];
                #pragma omp simd
                for (int k = 0; k < nc; k++) rz[c][k] = 1.0f / (zs[k] * dc + ze[k]);
            }
            cc.ready = false;
            for (int t = 0; t < NTAP7; t++) {
                int a, b;
                long off;
                tap_run(f, y, di[t], dj[t], s0, s1, &a, &b, &off);
                const float *rzc = rz[cls[t]];
                if (sq == SQ_DEFAULT) {
                    #pragma omp simd
                    for (int x = a; x < b; x++)
                        moments_tap(f, p0 + (x - x0), (int)off + x, x - x0, rzc[x - x0], SQ_DEFAULT, sn, a1, a2, aw);
                } else {
                    for (int x = a; x < b; x++)
                        moments_tap(f, p0 + (x - x0), (int)off + x, x - x0, rzc[x - x0], sq, sn, a1, a2, aw);
                }
                if (!g->wrap || (a == s0 && b == s1)) continue;
                if (!cc.ready) chunk_columns(g, y, x0, s0 - x0, s1 - x0, 1, 7, &cc);
                fallback_taps(g, &cc, di[t] + 3, dj[t], x0, s0, s1, a, b, fq);
                for (int r = 0; r < 2; r++) {
                    const int lo = r ? b : s0, hi = r ? s1 : a;
                    if (sq == SQ_DEFAULT) {
                        #pragma omp simd
                        for (int x = lo; x < hi; x++)
                            moments_tap(f, p0 + (x - x0), fq[x - x0], x - x0, rzc[x - x0], SQ_DEFAULT, sn, a1, a2, aw);
                    } else {
                        for (int x = lo; x < hi; x++)
                            moments_tap(f, p0 + (x - x0), fq[x - x0], x - x0, rzc[x - x0], sq, sn, a1, a2, aw);
                    }
                }
            }
            for (int k = 0; k < nc; k++) {
                size_t p = p0 + k;
                if (kind[p] != KIND_SURFACE || len[p] >= VAR_TEMPORAL_LEN) continue;
                float mean1 = a1[k] / aw[k], mean2 = a2[k] / aw[k], sv = mean2 - mean1 * mean1;
                var[p] = sv > 0.0f ? sv : 0.0f;
            }
        }
    }
}

/* ---- C. the À-Trous passes */

/* The variance that guides the luminance weight, prefiltered with a 3x3 Gaussian over the surface
 * neighbours (Sec. 4.3: one pixel's variance estimate is itself noisy). */
void SVGF_ISA(prefilter)(fv_svgf *f, const float *var)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const uint8_t *kind = f->kind;
    const float *surf = f->surf;
    float *gvar = f->gvar;
    #pragma omp for schedule(static, ROWS_PER_BLOCK)
    for (int y = 0; y < h; y++) {
        float av[CHUNK], aw[CHUNK];
        int fq[CHUNK];
        chunk_cols cc;
        /* Only the columns this pass filters need their prefiltered variance. */
        for (int x0 = 0; x0 < f->pass_cut; x0 += CHUNK) {
            const int x1 = imin(x0 + CHUNK, w), nc = x1 - x0;
            const size_t p0 = (size_t)y * w + x0;
            int s0, s1;
            if (!surface_span(kind, p0, x0, x1, &s0, &s1)) {
                memset(&gvar[p0], 0, (size_t)nc * sizeof(float));
                continue;
            }
            for (int k = 0; k < nc; k++) av[k] = aw[k] = 0.0f;
            cc.ready = false;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    const float kk = k_g3[i] * k_g3[j];
                    int a, b;
                    long off;
                    tap_run(f, y, i - 1, j - 1, s0, s1, &a, &b, &off);
                    #pragma omp simd
                    for (int x = a; x < b; x++) {
                        av[x - x0] += kk * var[off + x];
                        aw[x - x0] += kk * surf[off + x];
                    }
                    if (!g->wrap || (a == s0 && b == s1)) continue;
                    if (!cc.ready) chunk_columns(g, y, x0, s0 - x0, s1 - x0, 1, 3, &cc);
                    fallback_taps(g, &cc, i, j - 1, x0, s0, s1, a, b, fq);
                    for (int r = 0; r < 2; r++) {
                        const int lo = r ? b : s0, hi = r ? s1 : a;
                        #pragma omp simd
                        for (int x = lo; x < hi; x++) {
                            av[x - x0] += kk * var[fq[x - x0]];
                            aw[x - x0] += kk * surf[fq[x - x0]];
                        }
                    }
                }
            /* Not a surface: aw may be 0 (no surface around), and the value is never read. */
            for (int k = 0; k < nc; k++) gvar[p0 + k] = kind[p0 + k] == KIND_SURFACE ? av[k] / aw[k] : 0.0f;
        }
    }
}

/* The sums of one pass over a chunk, and the per-pixel terms of its weights. */
typedef struct pass_acc {
    float r[CHUNK], g[CHUNK], b[CHUNK], v[CHUNK], w[CHUNK];
    float inv_l[CHUNK];
    float rz[5][CHUNK];
} pass_acc;

/* The buffers a pass reads. */
typedef struct pass_src {
    const float *nx, *ny, *nz, *z;
    const float *r, *g, *b, *v, *l;
} pass_src;

/* One tap of a pass, pixel p (chunk slot k) taking pixel q with kernel weight kw. */
TAP_INLINE void atrous_tap(const pass_src *s, size_t p, int q, int k, float kw, const float *rz, int sq, float sn,
                              pass_acc *acc)
{
    float wn = normal_pow(s->nx[p] * s->nx[q] + s->ny[p] * s->ny[q] + s->nz[p] * s->nz[q], sq, sn);
    float e = fabsf(s->z[p] - s->z[q]) * rz[k] + fabsf(s->l[p] - s->l[q]) * acc->inv_l[k];
    float wt = kw * wn * exp_neg(e);
    acc->r[k] += wt * s->r[q];
    acc->g[k] += wt * s->g[q];
    acc->b[k] += wt * s->b[q];
    acc->v[k] += wt * wt * s->v[q];
    acc->w[k] += wt;
}

/* A pass's result for chunk slot k at index q of dst (and its illumination into hist, when given):
 * the sums over their weight, or zeros off a surface. Divisions, not a reciprocal: a mean of equal
 * values then comes out exactly equal. */
static inline void pass_result(const pass_acc *acc, int k, bool surface, float *const *dst, size_t q, float *hist)
{
    if (!surface) {
        for (int c = 0; c < NVAL; c++) dst[c][q] = 0.0f;
        return;
    }
    float ws = acc->w[k], r = acc->r[k] / ws, gg = acc->g[k] / ws, b = acc->b[k] / ws;
    dst[V_R][q] = r, dst[V_G][q] = gg, dst[V_B][q] = b;
    dst[V_VAR][q] = acc->v[k] / (ws * ws);
    dst[V_LUM][q] = luminance(r, gg, b);
    if (hist) hist[0] = r, hist[1] = gg, hist[2] = b;
}

/* The per-pixel terms of a pass for chunk slots [0, n), pixel k at index p0 + k of s, gvar and grad
 * (the grid's buffers or the fovea's lines): the luminance weight's 1 / (sigma_l sqrt(var) + eps),
 * 1 / (sigma_depth |grad z| |p - q| + eps) for the five tap distances, and the sums started with
 * the centre. One vectorised loop per term (the divisions dominate). */
TAP_INLINE void pass_terms(const fv_svgf *f, const pass_src *s, const float *gvar, const float *grad, size_t p0, int n,
                           int step, pass_acc *acc)
{
    const float sd = f->o.sigma_depth, sl = f->o.sigma_lum, wc = k_b3[2] * k_b3[2];
    const float dist[5] = {1.0f, sqrtf(2.0f), 2.0f, sqrtf(5.0f), sqrtf(8.0f)};
    float zs[CHUNK], ze[CHUNK];
    #pragma omp simd
    for (int k = 0; k < n; k++) {
        size_t p = p0 + k;
        acc->inv_l[k] = 1.0f / (sl * sqrtf(gvar[p]) + LUM_EPS);
        zs[k] = sd * grad[p] * (float)step, ze[k] = depth_eps(s->z[p]);
        acc->r[k] = wc * s->r[p], acc->g[k] = wc * s->g[p], acc->b[k] = wc * s->b[p];
        acc->v[k] = wc * wc * s->v[p], acc->w[k] = wc;
    }
    for (int c = 0; c < 5; c++) {
        const float dc = dist[c];
        #pragma omp simd
        for (int k = 0; k < n; k++) acc->rz[c][k] = 1.0f / (zs[k] * dc + ze[k]);
    }
}

/* SVGF_VW pixels at a time with every tap inner (the pixels whose 24 taps are all plain shifts):
 * the sums and the centre pixels' features stay in registers across the taps, where the per-tap
 * loops above load and store them once per tap. The arithmetic is atrous_tap's, operation for
 * operation in the same order (GCC vector extensions, no FMA), so the bits are the same. */
typedef float vfw __attribute__((vector_size(4 * SVGF_VW)));
typedef int32_t viw __attribute__((vector_size(4 * SVGF_VW)));
typedef float vfw_u __attribute__((vector_size(4 * SVGF_VW), aligned(4), may_alias));
#define LDW(ptr) (*(const vfw_u *)(const void *)(ptr))
#define STW(ptr, v) (*(vfw_u *)(void *)(ptr) = (v))

TAP_INLINE vfw fabs_w(vfw x) { return (vfw)((viw)x & 0x7fffffff); }

/* exp_neg, lane by lane the same operations. */
TAP_INLINE vfw exp_neg_w(vfw x)
{
    const union { float f; int32_t i; } lim = {87.0f};
    viw u = (viw)x;
    const viw in = u < lim.i; /* -1 or 0 */
    u = (u & in) | (lim.i & ~in);
    const vfw t = -(vfw)u * 1.44269504f;
    const viw i = __builtin_convertvector(t - 0.5f, viw);
    const vfw a = (t - __builtin_convertvector(i, vfw)) * 0.693147181f, a2 = a * a;
    const vfw p = (1.0f + a) + a2 * ((1.0f / 2 + a * (1.0f / 6)) + a2 * (1.0f / 24 + a * (1.0f / 120)));
    const viw scale = ((i + 127) * (1 << 23)) & in;
    return p * (vfw)scale;
}

/* The tap values of SVGF_VW pixels: a plain load from q (qi NULL) or gathered from the indices
 * qi[0..SVGF_VW) (lane by lane: on the CPUs measured, faster than AVX2's vgatherdps). */
TAP_INLINE vfw tap_load(const float *b, long q, const int *qi)
{
    if (!qi) return LDW(&b[q]);
    vfw r;
    for (int j = 0; j < SVGF_VW; j++) r[j] = b[qi[j]];
    return r;
}

/* The tap values of SVGF_VW pixels whose indices lie within two vectors from q: two loads and a
 * shuffle (on AVX2 two vpermps and a blend) instead of a load per lane. */
typedef int32_t viw_u __attribute__((vector_size(4 * SVGF_VW), aligned(4), may_alias));
TAP_INLINE vfw tap_window(const float *b, long q, viw d)
{
#if defined(__clang__)
    /* clang has no two-vector shuffle by variable indices (__builtin_shuffle is GCC's); the same
     * values lane by lane, for the clang build of the libFuzzer targets (docs/fuzzing.md). */
    vfw r;
    for (int j = 0; j < SVGF_VW; j++) r[j] = b[q + d[j]];
    return r;
#else
    return __builtin_shuffle(LDW(&b[q]), LDW(&b[q + SVGF_VW]), d);
#endif
}

/* For the gathered taps of the fovea's lines: true when the indices qi[0..SVGF_VW) lie in
 * [qi[0], qi[0] + 2 SVGF_VW), with *d their offsets from qi[0]. */
TAP_INLINE bool tap_window_fits(const int *qi, viw *d)
{
    *d = *(const viw_u *)(const void *)qi - qi[0];
    bool fits = true;
    for (int j = 0; j < SVGF_VW; j++) fits &= (uint32_t)(*d)[j] < 2u * SVGF_VW;
    return fits;
}

/* SVGF_VW pixels from chunk slot k (pixel x, index p) with their 24 taps: tap t is at off[t] + x (qt
 * NULL: every tap a plain shift) or at the indices qt[t][k..] (any taps, gathered; with gath, only
 * the taps t with gath[t], the others shifts). Only the lanes [from, to) are stored (a span's last
 * pixels, in a vector that overlaps other pixels). */
TAP_INLINE void atrous_block(const pass_src *s, size_t p, int x, int k, const long *off, const int (*qt)[CHUNK],
                             const bool *gath, const float *kw, const int *cls, int from, int to, pass_acc *acc)
{
    const vfw nxp = LDW(&s->nx[p]), nyp = LDW(&s->ny[p]), nzp = LDW(&s->nz[p]), zp = LDW(&s->z[p]), lp = LDW(&s->l[p]);
    const vfw il = LDW(&acc->inv_l[k]);
    vfw rz[5];
    for (int c = 0; c < 5; c++) rz[c] = LDW(&acc->rz[c][k]);
    vfw ar = LDW(&acc->r[k]), ag = LDW(&acc->g[k]), ab = LDW(&acc->b[k]), av = LDW(&acc->v[k]), aw = LDW(&acc->w[k]);
    for (int t = 0; t < NTAP; t++) {
        const int *qi = qt && (!gath || gath[t]) ? &qt[t][k] : NULL;
        const long q = qi ? 0 : off[t] + x;
        viw d;
        /* The lines' gathered taps mostly fit a window of two vectors (neighbouring rows of a
         * column land on neighbouring rows of the next). */
        const bool win = gath && qi && tap_window_fits(qi, &d);
#define TAP_VALUES(b) (win ? tap_window((b), qi[0], d) : tap_load((b), q, qi))
        vfw c = nxp * TAP_VALUES(s->nx) + nyp * TAP_VALUES(s->ny) + nzp * TAP_VALUES(s->nz);
        c = 0.5f * (c + fabs_w(c));
        for (int i = 0; i < SQ_DEFAULT; i++) c *= c;
        const vfw e = fabs_w(zp - TAP_VALUES(s->z)) * rz[cls[t]] + fabs_w(lp - TAP_VALUES(s->l)) * il;
        const vfw wt = kw[t] * c * exp_neg_w(e);
        ar += wt * TAP_VALUES(s->r);
        ag += wt * TAP_VALUES(s->g);
        ab += wt * TAP_VALUES(s->b);
        av += wt * wt * TAP_VALUES(s->v);
        aw += wt;
#undef TAP_VALUES
    }
    if (from == 0 && to == SVGF_VW) {
        STW(&acc->r[k], ar), STW(&acc->g[k], ag), STW(&acc->b[k], ab), STW(&acc->v[k], av), STW(&acc->w[k], aw);
        return;
    }
    for (int j = from; j < to; j++)
        acc->r[k + j] = ar[j], acc->g[k + j] = ag[j], acc->b[k + j] = ab[j], acc->v[k + j] = av[j], acc->w[k + j] = aw[j];
}

/* ---- C2. the fovea's lines (polar grids with short columns; issue 16)
 *
 * Row-major, a short column's taps into its neighbours land on other rows (the same angle in a
 * column of another height): a different row, kilobytes from the next, for each pixel of a vector,
 * so the row loop gathers them lane by lane from all over the grid. Column-major, the taps of
 * neighbouring rows of a column lie a lane or two apart in the neighbouring column's line, mostly
 * within two vectors (tap_window). So the passes with taps up to
 * LINE_STEP_MAX apart copy the columns they reach into the lines (the features once a frame, the
 * values once a pass), filter the short columns and the columns within two taps of them along
 * their lines, SVGF_VW rows at a time, and write the results in the grid's order. The taps are
 * fv_grid_tap's and each pixel adds them in the same order, so the bits are those of the row loop
 * (test_svgf_isa: against one tap at a time). */

/* The most rows any column of [xb, xe) holds. */
static int block_rows(const fv_grid *g, int xb, int xe)
{
    int most = 0;
    for (int x = xb; x < xe; x++) most = imax(most, fv_grid_col_h(g, x));
    return most;
}

/* Copies the columns [0, xr) of the n grid-ordered buffers src into the lines dst, ghosts included
 * (a column shorter than the ghosts wraps more than once). Blocks of 8 columns, rows outer: the
 * reads are runs of a row. */
static void lines_load(const fv_svgf *f, float *const *dst, float *const *src, int n, int xr)
{
    const fv_grid *g = &f->g;
    const int w = g->w, stride = f->line_stride;
    #pragma omp for schedule(dynamic, 1)
    for (int xb = 0; xb < xr; xb += 8) {
        const int xe = imin(xb + 8, xr), lmax = block_rows(g, xb, xe);
        for (int b = 0; b < n; b++)
            for (int y = -LINE_GHOST; y < lmax + LINE_GHOST; y++)
                for (int x = xb; x < xe; x++) {
                    const int n_rows = fv_grid_col_h(g, x);
                    if (y >= n_rows + LINE_GHOST) continue;
                    const int yy = y >= 0 && y < n_rows ? y : fv_grid_wrap_row(y, n_rows);
                    dst[b][(size_t)x * stride + LINE_GHOST + y] = src[b][(size_t)yy * w + x];
                }
    }
}

/* The lines' output values of the columns [0, xt) back in the grid's order (dst), and into the
 * history where write_hist; blocks of 8 columns, rows outer, like lines_load. */
static void lines_store(fv_svgf *f, float *const *dst, bool write_hist, int xt)
{
    const fv_grid *g = &f->g;
    const int w = g->w, stride = f->line_stride;
    #pragma omp for schedule(dynamic, 1)
    for (int xb = 0; xb < xt; xb += 8) {
        const int xe = imin(xb + 8, xt), lmax = block_rows(g, xb, xe);
        for (int c = 0; c < NVAL; c++) {
            const float *o = f->ln[LN_OUT + c] + LINE_GHOST;
            for (int y = 0; y < lmax; y++)
                for (int x = xb; x < xe; x++)
                    if (y < fv_grid_col_h(g, x)) dst[c][(size_t)y * w + x] = o[(size_t)x * stride + y];
        }
        if (!write_hist) continue;
        for (int y = 0; y < lmax; y++)
            for (int x = xb; x < xe; x++) {
                const size_t p = (size_t)y * w + x, q = (size_t)x * stride + LINE_GHOST + y;
                if (y >= fv_grid_col_h(g, x) || f->kind[p] != KIND_SURFACE) continue;
                for (int c = 0; c < 3; c++) f->hist_illum[3 * p + c] = f->ln[LN_OUT + V_R + c][q];
            }
    }
}

/* One pass over the columns [0, xt) along their lines (taps `step` apart; di, dj, kw, cls as in the
 * row loop), from the lines' values to their output values. */
static void lines_pass(fv_svgf *f, int step, int xt, const int *di, const int *dj, const float *kw, const int *cls)
{
    const fv_grid *g = &f->g;
    const int w = g->w, stride = f->line_stride;
    float *const *dst = &f->ln[LN_OUT];
    const float *grad = f->ln[LN_GRAD], *gvar = f->ln[LN_GVAR], *surf = f->ln[LN_SURF];
    const pass_src s = {f->ln[LN_NX], f->ln[LN_NY], f->ln[LN_NZ], f->ln[LN_Z], f->ln[LN_VAL + V_R],
                        f->ln[LN_VAL + V_G], f->ln[LN_VAL + V_B], f->ln[LN_VAL + V_VAR], f->ln[LN_VAL + V_LUM]};
    #pragma omp for schedule(dynamic, 2)
    for (int x = 0; x < xt; x++) {
        pass_acc acc;
        int qt[NTAP][CHUNK], rows[5][CHUNK];
        long off[NTAP];
        bool gath[NTAP];
        const int n_rows = fv_grid_col_h(g, x), base = x * stride + LINE_GHOST;
        int cx[5], cn[5]; /* the tap columns (clamped) and their heights */
        for (int c = 0; c < 5; c++) {
            cx[c] = imin(imax(x + (c - 2) * step, 0), w - 1);
            cn[c] = fv_grid_col_h(g, cx[c]);
        }
        for (int y0 = 0; y0 < n_rows; y0 += LINE_CHUNK) {
            const int nc = imin(LINE_CHUNK, n_rows - y0);
            const int q0 = base + y0;
            int s0 = 0, s1 = nc;
            while (s0 < s1 && surf[q0 + s0] == 0.0f) s0++;
            while (s1 > s0 && surf[q0 + s1 - 1] == 0.0f) s1--;
            if (s0 == s1) {
                for (int c = 0; c < NVAL; c++) memset(&dst[c][q0], 0, (size_t)nc * sizeof(float));
                continue;
            }
            /* The slots past the chunk (a vector's last lanes) get finite terms and are never
             * stored. */
            pass_terms(f, &s, gvar, grad, (size_t)q0, nc, step, &acc);
            for (int k = nc; k < CHUNK; k++) {
                acc.inv_l[k] = acc.r[k] = acc.g[k] = acc.b[k] = acc.v[k] = acc.w[k] = 0.0f;
                for (int c = 0; c < 5; c++) acc.rz[c][k] = 1.0f;
            }
            /* The row of each tap column at the same angle, where its height differs: fv_grid_tap's
             * floor((2 y + 1) hd / (2 hs)), one division per chunk and then stepped lane by lane
             * (quotient and remainder of a numerator that grows by 2 hd per row). */
            for (int c = 0; c < 5; c++) {
                if (cn[c] == n_rows) continue;
                const long den = 2L * n_rows, num = ((long)y0 * 2 + 1) * cn[c], inc = 2L * cn[c];
                long q = num / den, r = num % den;
                const long dq = inc / den, dr = inc % den;
                for (int k = 0; k < nc; k++) {
                    rows[c][k] = (int)q;
                    q += dq, r += dr;
                    const long over = r >= den;
                    q += over, r -= over * den;
                }
            }
            for (int t = 0; t < NTAP; t++) {
                const int c = di[t] / step + 2, lb = cx[c] * stride + LINE_GHOST + dj[t];
                gath[t] = cn[c] != n_rows;
                off[t] = lb;
                if (!gath[t]) continue;
                for (int k = 0; k < nc; k++) qt[t][k] = lb + rows[c][k];
                for (int k = nc; k < CHUNK; k++) qt[t][k] = qt[t][nc - 1]; /* unstored lanes: any valid index */
            }
            for (int k = s0; k < s1; k += SVGF_VW)
                atrous_block(&s, (size_t)(base + y0 + k), y0 + k, k, off, qt, gath, kw, cls, 0, SVGF_VW, &acc);
            for (int k = 0; k < nc; k++) pass_result(&acc, k, surf[q0 + k] != 0.0f, dst, (size_t)(q0 + k), NULL);
        }
    }
}

/* One pass with taps `step` apart from val[src] to val[1 - src]; the first also writes the history. */
void SVGF_ISA(atrous)(fv_svgf *f, int step, int src, bool write_hist)
{
    const fv_grid *g = &f->g;
    const int w = g->w, h = g->h;
    const uint8_t *kind = f->kind;
    const float sn = f->o.sigma_normal;
    const int sq = f->normal_squarings;
    float *const *dst = f->val[1 - src];
    const float *grad = f->grad, *gvar = f->gvar;
    const pass_src s = {f->nx[0], f->ny[0], f->nz[0], f->z[0], f->val[src][V_R], f->val[src][V_G],
                        f->val[src][V_B], f->val[src][V_VAR], f->val[src][V_LUM]};
    /* The taps around the centre: kernel weight, offsets, and the distance class (1, sqrt 2, 2,
     * sqrt 5, sqrt 8 times the step: pass_terms' five distances). */
    float kw[NTAP];
    int cls[NTAP], di[NTAP], dj[NTAP];
    for (int j = 0, t = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            if (i == 2 && j == 2) continue;
            int d2 = (i - 2) * (i - 2) + (j - 2) * (j - 2);
            kw[t] = k_b3[i] * k_b3[j];
            cls[t] = d2 == 1 ? 0 : d2 == 2 ? 1 : d2 == 4 ? 2 : d2 == 5 ? 3 : 4;
            di[t] = (i - 2) * step, dj[t] = (j - 2) * step;
            t++;
        }
    /* The short columns and the columns within two taps of them go along the fovea's lines (C2);
     * the row loop takes the columns from xt on. */
    int xt = 0;
    if (f->lines_w && f->blocks && sq == SQ_DEFAULT && step <= LINE_STEP_MAX) {
        xt = imin(imin(f->full_from + 2 * step, f->pass_cut), w);
        if (!f->ln_features) {
            float *feat[LN_FEATURES] = {f->nx[0], f->ny[0], f->nz[0], f->z[0], f->grad, f->surf};
            lines_load(f, &f->ln[LN_NX], feat, LN_FEATURES, f->lines_w);
            /* every thread read the flag before the load's barrier; one sets it after, and the
             * barrier of `single` keeps the next pass's readers behind the write */
            #pragma omp single
            f->ln_features = true;
        }
        float *in[1 + NVAL] = {f->gvar};
        for (int c = 0; c < NVAL; c++) in[1 + c] = f->val[src][c];
        lines_load(f, &f->ln[LN_GVAR], in, 1 + NVAL, imin(f->full_from + 4 * step, w));
        lines_pass(f, step, xt, di, dj, kw, cls);
        lines_store(f, dst, write_hist, xt);
    }
    #pragma omp for schedule(static, ROWS_PER_BLOCK)
    for (int y = 0; y < h; y++) {
        pass_acc acc;
        int fq[CHUNK], qt[NTAP][CHUNK];
        chunk_cols cc;
        for (int x0 = xt; x0 < w; x0 += CHUNK) {
            const int x1 = imin(x0 + CHUNK, w), nc = x1 - x0;
            const size_t p0 = (size_t)y * w + x0;
            /* Columns from pass_cut on sit this pass out (fv_svgf_set_periphery): their values go
             * through unchanged, and still serve as taps. */
            const int xe = imin(x1, f->pass_cut), ne = xe > x0 ? xe - x0 : 0;
            if (xe < x1) {
                const int xc = imax(x0, xe);
                const size_t pc = p0 + (size_t)(xc - x0), m = (size_t)(x1 - xc);
                for (int c = 0; c < NVAL; c++) memcpy(&dst[c][pc], &f->val[src][c][pc], m * sizeof(float));
                if (write_hist)
                    for (size_t p = pc; p < pc + m; p++)
                        if (kind[p] == KIND_SURFACE)
                            for (int c = 0; c < 3; c++) f->hist_illum[3 * p + c] = f->val[src][V_R + c][p];
            }
            if (!ne) continue;
            int s0, s1;
            if (!surface_span(kind, p0, x0, xe, &s0, &s1)) {
                for (int c = 0; c < NVAL; c++) memset(&dst[c][p0], 0, (size_t)ne * sizeof(float));
                continue;
            }
            pass_terms(f, &s, gvar, grad, p0, nc, step, &acc);
            cc.ready = false;
            /* [va, vb): the pixels whose taps are all plain shifts, a whole number of vectors,
             * filtered by atrous_block; the per-tap loops do the rest of the span. */
            int va = s0, vb = s0;
            long offs[NTAP];
            if (sq == SQ_DEFAULT && f->blocks) {
                int lo = s0, hi = s1;
                for (int t = 0; t < NTAP && lo < hi; t++) {
                    int a, b;
                    tap_run(f, y, di[t], dj[t], s0, s1, &a, &b, &offs[t]);
                    lo = imax(lo, a), hi = imin(hi, b);
                }
                if (lo < hi) va = lo, vb = lo + (hi - lo) / SVGF_VW * SVGF_VW;
                for (int x = va; x < vb; x += SVGF_VW) atrous_block(&s, p0 + (x - x0), x, x - x0, offs, NULL, NULL, kw, cls, 0, SVGF_VW, &acc);
            }
            for (int part = 0; part < 2; part++) {
                const int u0 = part ? vb : s0, u1 = part ? s1 : va;
                if (u0 >= u1) continue;
                if (g->wrap && sq == SQ_DEFAULT && f->blocks) {
                    /* Polar grids: every tap is a pixel (clamp and wrap), so the rest of the span
                     * (short columns, the clamped edges, the ends of the runs) takes its tap indices
                     * from the runs and the per-chunk table, then goes SVGF_VW pixels at a time with
                     * every tap inner like the shifted pixels, its loads gathered. */
                    cc.ready = false; /* each part builds the table for its own pixels */
                    for (int t = 0; t < NTAP; t++) {
                        int a, b;
                        long off;
                        tap_run(f, y, di[t], dj[t], u0, u1, &a, &b, &off);
                        for (int x = a; x < b; x++) qt[t][x - x0] = (int)off + x;
                        if (a == u0 && b == u1) continue;
                        if (!cc.ready) chunk_columns(g, y, x0, u0 - x0, u1 - x0, step, 5, &cc);
                        fallback_taps(g, &cc, di[t] / step + 2, dj[t], x0, u0, u1, a, b, qt[t]);
                    }
                    int x = u0;
                    for (; x + SVGF_VW <= u1; x += SVGF_VW) atrous_block(&s, p0 + (x - x0), x, x - x0, NULL, qt, NULL, kw, cls, 0, SVGF_VW, &acc);
                    if (x < u1 && nc >= SVGF_VW) {
                        /* The last pixels in one vector ending at u1 (or starting at the chunk's
                         * start): its other lanes are pixels done already or other parts of the
                         * chunk; they tap themselves and are not stored. */
                        const int xs = imax(x0, u1 - SVGF_VW), ks = xs - x0;
                        for (int t = 0; t < NTAP; t++)
                            for (int j = ks; j < x - x0; j++) qt[t][j] = (int)p0 + j;
                        for (int t = 0; t < NTAP; t++)
                            for (int j = u1 - x0; j < ks + SVGF_VW; j++) qt[t][j] = (int)p0 + j;
                        atrous_block(&s, p0 + ks, xs, ks, NULL, qt, NULL, kw, cls, x - xs, u1 - xs, &acc);
                        x = u1;
                    }
                    for (; x < u1; x++)
                        for (int t = 0; t < NTAP; t++)
                            atrous_tap(&s, p0 + (x - x0), qt[t][x - x0], x - x0, kw[t], acc.rz[cls[t]], SQ_DEFAULT, sn, &acc);
                    continue;
                }
                for (int t = 0; t < NTAP; t++) {
                    int a, b;
                    long off;
                    tap_run(f, y, di[t], dj[t], u0, u1, &a, &b, &off);
                    const float *rz = acc.rz[cls[t]];
                    if (sq == SQ_DEFAULT) {
                        #pragma omp simd
                        for (int x = a; x < b; x++)
                            atrous_tap(&s, p0 + (x - x0), (int)off + x, x - x0, kw[t], rz, SQ_DEFAULT, sn, &acc);
                    } else {
                        for (int x = a; x < b; x++) atrous_tap(&s, p0 + (x - x0), (int)off + x, x - x0, kw[t], rz, sq, sn, &acc);
                    }
                    if (!g->wrap || (a == u0 && b == u1)) continue;
                    if (!cc.ready) chunk_columns(g, y, x0, s0 - x0, s1 - x0, step, 5, &cc);
                    fallback_taps(g, &cc, di[t] / step + 2, dj[t], x0, u0, u1, a, b, fq);
                    for (int r = 0; r < 2; r++) {
                        const int lo = r ? b : u0, hi = r ? u1 : a;
                        if (sq == SQ_DEFAULT) {
                            #pragma omp simd
                            for (int x = lo; x < hi; x++)
                                atrous_tap(&s, p0 + (x - x0), fq[x - x0], x - x0, kw[t], rz, SQ_DEFAULT, sn, &acc);
                        } else {
                            for (int x = lo; x < hi; x++)
                                atrous_tap(&s, p0 + (x - x0), fq[x - x0], x - x0, kw[t], rz, sq, sn, &acc);
                        }
                    }
                }
            }
            for (int k = 0; k < ne; k++) {
                const size_t p = p0 + k;
                pass_result(&acc, k, kind[p] == KIND_SURFACE, dst, p, write_hist ? &f->hist_illum[3 * p] : NULL);
            }
        }
    }
}

