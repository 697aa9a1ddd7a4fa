/* fovea — Visual-Polar, log-polar and Cartesian sample spaces (see space.h).
 *
 * Visual-Polar layout (Foveated Real-Time Path Tracing in Visual-Polar Space, Sec. 3.2), worked out
 * so that the sample count is fixed and the densities follow the acuity model:
 *  - The samples within e planar degrees of the gaze should grow like the area-weighted acuity A(e):
 *    pi e^2 where V(e) of Eq. 1 is flat (e <= 5.79), Eq. 2 beyond (Eq. 2 is the integral of
 *    2 pi e V(e) / 60, i.e. a density proportional to V). The profile is built for the gaze at the
 *    screen's centre, where the largest ρ, the half diagonal, is E_ref planar degrees; for another
 *    gaze it is stretched to that gaze's farthest corner (up to 2x at a corner), which enlarges the
 *    fovea as the paper describes.
 *  - The fovea (e <= fovea_deg) gets F = N A(e_f) / A(E_ref) of the N samples, raised if needed so
 *    that it keeps at least one sample per pixel even at a corner gaze (where it is 4x larger).
 *  - Grid: H_v rows (φ) by W_v columns (ρ) with the screen's aspect and H_v W_v = N + F: the fovea's
 *    columns 0..X_f are clipped to a triangle of area F (column height H_v X / X_f), which leaves
 *    exactly N valid samples, and X_f = 2 F / H_v.
 *  - Fovea: ρ linear in X, so with heights proportional to X the screen density is constant.
 *  - Periphery: X - X_f proportional to A(e) - A(e_f), i.e. ρ scaled by the acuity distribution;
 *    grid-to-screen uses a least-squares polynomial in t = (X - X_f) / (W_v - X_f) for e / E_ref
 *    (the paper's Eq. 3 is its fit of the same kind for its display; ours is refitted for each
 *    screen and fovea since both change the curve), screen-to-grid evaluates Eq. 2 directly.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "fovea/film.h"
#include "technique/vpolar/kvp_tables.h"
#include "technique/vpolar/space.h"

#define ACUITY_FLAT_DEG FV_KVP_ACUITY_FLAT_DEG
#define FIT_MAX_DEGREE 10
#define FIT_POINTS 1025
_Static_assert(FIT_MAX_DEGREE + 1 == FV_KVP_MAX_COEF, "the kernel's copy of the fit holds every coefficient");

struct fv_space {
    fv_space_opts o;
    int sw, sh;            /* screen */
    fv_grid grid;
    int *col_h;
    float *row_cs;         /* polar grids: cos and sin of each full-height row's angle (onscreen mask) */
    long count;
    /* Visual-Polar profile */
    double ppd, rho_ref, e_ref, a_f, a_e;
    double x_f;            /* fovea edge in columns */
    double s_f;            /* fovea edge as a fraction of the largest ρ */
    double coef[FIT_MAX_DEGREE + 1];
    int ncoef;
    fv_space_info info;
    fv_kvp_space k;        /* the flat copy the kernels read */
};

void fv_space_opts_default(fv_space_kind kind, fv_space_opts *o)
{
    memset(o, 0, sizeof *o);
    o->kind = kind;
    o->reduction = kind == FV_SPACE_VPOLAR ? 0.61 : 0.0;
    o->fovea_deg = ACUITY_FLAT_DEG;
    o->fit_degree = 6;
    o->lp_sigma = 1.8;
    o->lp_alpha = 4.0;
}

double fv_space_acuity_area(double e)
{
    return fv_kvp_acuity_area(e);
}

/* e with A(e) = a, for a in [A(lo), A(hi)]: A is increasing, so bisection converges. */
static double acuity_area_inverse(double a, double lo, double hi)
{
    for (int i = 0; i < 80; i++) {
        double m = 0.5 * (lo + hi);
        if (fv_space_acuity_area(m) < a) lo = m;
        else hi = m;
    }
    return 0.5 * (lo + hi);
}

/* Least-squares fit of y(t) on [0, 1] by a polynomial of degree n - 1: normal equations solved by
 * Gaussian elimination with partial pivoting, in double (well enough conditioned up to degree 10
 * with 1025 points). */
static void poly_fit(const double *t, const double *y, int m, int n, double *c)
{
    double a[FIT_MAX_DEGREE + 1][FIT_MAX_DEGREE + 2];
    memset(a, 0, sizeof a);
    for (int k = 0; k < m; k++) {
        double p[2 * FIT_MAX_DEGREE + 1];
        p[0] = 1.0;
        for (int i = 1; i < 2 * n - 1; i++) p[i] = p[i - 1] * t[k];
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++) a[i][j] += p[i + j];
            a[i][n] += p[i] * y[k];
        }
    }
    for (int col = 0; col < n; col++) {
        int piv = col;
        for (int r = col + 1; r < n; r++)
            if (fabs(a[r][col]) > fabs(a[piv][col])) piv = r;
        if (piv != col)
            for (int j = 0; j <= n; j++) {
                double tmp = a[col][j];
                a[col][j] = a[piv][j];
                a[piv][j] = tmp;
            }
        for (int r = col + 1; r < n; r++) {
            double f = a[r][col] / a[col][col];
            for (int j = col; j <= n; j++) a[r][j] -= f * a[col][j];
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = a[i][n];
        for (int j = i + 1; j < n; j++) s -= a[i][j] * c[j];
        c[i] = s / a[i][i];
    }
}

static fv_status check_grid_size(int w, int h, const char *what, fv_error *err)
{
    if (w < 2 || h < 2) return fv_error_set(err, FV_ERR_INVALID, "%s grid %dx%d is too small (at least 2x2)", what, w, h);
    if (w > FV_FILM_MAX_DIM || h > FV_FILM_MAX_DIM || (long long)w * h > FV_FILM_MAX_PIXELS)
        return fv_error_set(err, FV_ERR_INVALID, "%s grid %dx%d is too large", what, w, h);
    return FV_OK;
}

static fv_status build_vpolar(fv_space *s, fv_error *err)
{
    const fv_space_opts *o = &s->o;
    const double W = s->sw, H = s->sh;
    s->rho_ref = 0.5 * sqrt(W * W + H * H);
    s->e_ref = s->rho_ref / s->ppd;
    if (!(o->fovea_deg < 0.5 * s->e_ref))
        return fv_error_set(err, FV_ERR_INVALID, "Visual-Polar fovea of %g degrees does not fit a screen reaching %.1f degrees",
                            o->fovea_deg, s->e_ref);
    const double n = (1.0 - o->reduction) * W * H;
    s->a_f = fv_space_acuity_area(o->fovea_deg);
    s->a_e = fv_space_acuity_area(s->e_ref);
    double f = n * s->a_f / s->a_e;
    /* At a corner gaze the fovea's radius doubles (the profile stretches to the full diagonal). */
    double r_corner = 2.0 * o->fovea_deg * s->ppd;
    double f_floor = FV_PI_D * r_corner * r_corner;
    if (f < f_floor) f = f_floor;
    if (f > 0.5 * n)
        return fv_error_set(err, FV_ERR_INVALID,
                            "reduction %g leaves %.0f samples, too few: the fovea alone needs %.0f for one sample per pixel",
                            o->reduction, n, f);
    double hv = sqrt((n + f) * H / W);
    int rows = (int)lround(hv), cols = (int)lround((n + f) / (rows > 0 ? rows : 1));
    fv_status st = check_grid_size(cols, rows, "Visual-Polar", err);
    if (st != FV_OK) return st;
    s->grid.w = cols;
    s->grid.h = rows;
    s->x_f = 2.0 * f / rows;
    if (!(s->x_f < cols))
        return fv_error_set(err, FV_ERR_INVALID, "Visual-Polar fovea (%.1f columns) wider than the grid (%d)", s->x_f, cols);
    s->s_f = o->fovea_deg / s->e_ref;
    s->col_h = fv_alloc_array((size_t)cols, sizeof(int));
    if (!s->col_h) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (int x = 0; x < cols; x++) {
        double c = x + 0.5;
        int hgt = rows;
        if (c < s->x_f) {
            hgt = (int)lround(rows * c / s->x_f);
            hgt = hgt < 1 ? 1 : (hgt > rows ? rows : hgt);
        }
        s->col_h[x] = hgt;
    }
    /* The periphery's inverse: e / E_ref as a polynomial in t. */
    double *t = fv_alloc_array(FIT_POINTS, 2 * sizeof(double));
    if (!t) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    double *y = t + FIT_POINTS;
    for (int k = 0; k < FIT_POINTS; k++) {
        t[k] = (double)k / (FIT_POINTS - 1);
        y[k] = acuity_area_inverse(s->a_f + t[k] * (s->a_e - s->a_f), o->fovea_deg, s->e_ref) / s->e_ref;
    }
    s->ncoef = o->fit_degree + 1;
    poly_fit(t, y, FIT_POINTS, s->ncoef, s->coef);
    double worst = 0.0;
    for (int k = 0; k < FIT_POINTS; k++) {
        double e = fabs(fv_kvp_poly(s->coef, s->ncoef, t[k]) - y[k]);
        if (e > worst) worst = e;
    }
    free(t);
    s->info.fovea_share = f / n;
    s->info.fit_error_px = worst * s->rho_ref;
    s->info.fovea_columns = s->x_f;
    double r_centre = o->fovea_deg * s->ppd;
    s->info.fovea_density_centre = f / (FV_PI_D * r_centre * r_centre);
    s->info.fovea_density_corner = f / (FV_PI_D * r_corner * r_corner);
    return FV_OK;
}

fv_status fv_space_create(const fv_space_opts *o, int screen_w, int screen_h, double px_per_deg, fv_space **out,
                          fv_error *err)
{
    *out = NULL;
    fv_status st = fv_film_check_size(screen_w, screen_h, err);
    if (st != FV_OK) return st;
    if (!(px_per_deg > 0.0 && isfinite(px_per_deg)))
        return fv_error_set(err, FV_ERR_INVALID, "pixels per degree %g must be positive", px_per_deg);
    switch (o->kind) {
    case FV_SPACE_VPOLAR:
        if (!(o->reduction > 0.0 && o->reduction < 1.0))
            return fv_error_set(err, FV_ERR_INVALID, "reduction %g must be in (0, 1)", o->reduction);
        if (!(o->fovea_deg > 0.0 && isfinite(o->fovea_deg)))
            return fv_error_set(err, FV_ERR_INVALID, "fovea_deg %g must be positive", o->fovea_deg);
        if (o->fit_degree < 2 || o->fit_degree > FIT_MAX_DEGREE)
            return fv_error_set(err, FV_ERR_INVALID, "fit_degree %d must be in [2, %d]", o->fit_degree, FIT_MAX_DEGREE);
        break;
    case FV_SPACE_CARTESIAN:
        if (!(o->reduction >= 0.0 && o->reduction < 1.0))
            return fv_error_set(err, FV_ERR_INVALID, "reduction %g must be in [0, 1)", o->reduction);
        break;
    case FV_SPACE_LOGPOLAR:
        if (!(o->lp_sigma > 1.0 && isfinite(o->lp_sigma)))
            return fv_error_set(err, FV_ERR_INVALID, "log-polar sigma %g must be greater than 1", o->lp_sigma);
        if (!(o->lp_alpha > 0.0 && isfinite(o->lp_alpha)))
            return fv_error_set(err, FV_ERR_INVALID, "log-polar alpha %g must be positive", o->lp_alpha);
        break;
    default:
        return fv_error_set(err, FV_ERR_INVALID, "unknown sample space %d", (int)o->kind);
    }
    fv_space *s = calloc(1, sizeof *s);
    if (!s) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    s->o = *o;
    s->sw = screen_w;
    s->sh = screen_h;
    s->ppd = px_per_deg;
    if (o->kind == FV_SPACE_VPOLAR) {
        st = build_vpolar(s, err);
        s->grid.wrap = true;
    } else if (o->kind == FV_SPACE_LOGPOLAR) {
        st = check_grid_size((int)lround(screen_w / o->lp_sigma), (int)lround(screen_h / o->lp_sigma), "log-polar", err);
        s->grid.w = (int)lround(screen_w / o->lp_sigma);
        s->grid.h = (int)lround(screen_h / o->lp_sigma);
        s->grid.wrap = true;
    } else {
        double k = sqrt(1.0 - o->reduction);
        s->grid.w = (int)lround(screen_w * k);
        s->grid.h = (int)lround(screen_h * k);
        st = check_grid_size(s->grid.w, s->grid.h, "Cartesian", err);
    }
    if (st != FV_OK) {
        fv_space_destroy(s);
        return st;
    }
    s->grid.col_h = s->col_h;
    /* The onscreen mask's angle table, made once here so that a frame that moves the gaze
     * allocates nothing (docs/threads.md, "No allocation in a frame"). */
    if (o->kind != FV_SPACE_CARTESIAN && (s->row_cs = fv_alloc_array((size_t)s->grid.h, 2 * sizeof(float))))
        for (int y = 0; y < s->grid.h; y++) fv_kvp_row_angle(y, s->grid.h, &s->row_cs[2 * y], &s->row_cs[2 * y + 1]);
    s->k.kind = (int)o->kind;
    s->k.sw = s->sw, s->k.sh = s->sh;
    s->k.gw = s->grid.w, s->k.gh = s->grid.h;
    s->k.x_f = s->x_f, s->k.s_f = s->s_f;
    memcpy(s->k.coef, s->coef, sizeof s->coef);
    s->k.ncoef = s->ncoef;
    s->k.lp_alpha = o->lp_alpha;
    s->k.fovea_deg = o->fovea_deg, s->k.e_ref = s->e_ref, s->k.a_f = s->a_f, s->k.a_e = s->a_e;
    s->count = 0;
    for (int x = 0; x < s->grid.w; x++) s->count += fv_grid_col_h(&s->grid, x);
    *out = s;
    return FV_OK;
}

void fv_space_destroy(fv_space *s)
{
    if (!s) return;
    free(s->col_h);
    free(s->row_cs);
    free(s);
}

const fv_grid *fv_space_grid(const fv_space *s) { return &s->grid; }
fv_space_kind fv_space_kind_of(const fv_space *s) { return s->o.kind; }
long fv_space_sample_count(const fv_space *s) { return s->count; }
void fv_space_get_info(const fv_space *s, fv_space_info *out) { *out = s->info; }

int fv_space_fit_coeffs(const fv_space *s, const double **coeffs)
{
    *coeffs = s->coef;
    return s->ncoef;
}

fv_space_view fv_space_view_at(const fv_space *s, fv_gaze g)
{
    fv_space_view v;
    v.space = s;
    v.gx = g.x * (float)s->sw;
    v.gy = g.y * (float)s->sh;
    float dx = fv_maxf(v.gx, (float)s->sw - v.gx), dy = fv_maxf(v.gy, (float)s->sh - v.gy);
    v.rho_max = sqrtf(dx * dx + dy * dy);
    if (!(v.rho_max > 1.0f)) v.rho_max = 1.0f;
    v.log_rho_max = logf(v.rho_max);
    return v;
}

float fv_space_radius(const fv_space_view *v, float X)
{
    const fv_kvp_view kv = fv_space_kview(v);
    return fv_kvp_radius(&v->space->k, &kv, X);
}

const fv_kvp_space *fv_space_kernel(const fv_space *s) { return &s->k; }

long fv_space_onscreen_mask(const fv_space_view *v, float reach_px, uint8_t *mask)
{
    const fv_space *s = v->space;
    const fv_grid *g = &s->grid;
    const int w = g->w, h = g->h;
    if (s->o.kind == FV_SPACE_CARTESIAN) {
        memset(mask, 1, (size_t)w * h);
        return (long)w * h;
    }
    /* A column's bound, then its cells (technique/vpolar/kvp_tables.h, what the device frame's kernels run);
     * the full-height rows' angles from the table made at create (NULL: computed per cell). */
    const fv_kvp_view kv = fv_space_kview(v);
    long on = 0;
    for (int x = 0; x < w; x++) {
        const int n = fv_grid_col_h(g, x);
        const fv_kvp_onscreen_col c = fv_kvp_onscreen_column(&s->k, &kv, reach_px, x, n);
        for (int y = 0; y < h; y++) {
            const uint8_t in = y < n ? fv_kvp_onscreen_cell(&s->k, &kv, reach_px, &c, n, h, y, s->row_cs) : 0;
            mask[(size_t)y * w + x] = in;
            on += in;
        }
    }
    return on;
}

void fv_space_radial_table(const fv_space_view *v, float step, int n, int stride, float *table)
{
    const fv_kvp_view kv = fv_space_kview(v);
    for (int i = 0; i < n; i++) fv_kvp_radial_coords(&v->space->k, &kv, step, i, &table[stride * i], &table[stride * i + 1]);
}

void fv_space_to_screen(const fv_space_view *v, float X, float V, float *px, float *py)
{
    const fv_kvp_view kv = fv_space_kview(v);
    fv_kvp_to_screen(&v->space->k, &kv, X, V, px, py);
}

void fv_space_from_screen(const fv_space_view *v, float px, float py, float *X, float *V, float *phi_per_px)
{
    const fv_kvp_view kv = fv_space_kview(v);
    fv_kvp_from_screen(&v->space->k, &kv, px, py, X, V, phi_per_px);
}
