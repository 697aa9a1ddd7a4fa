/* fovea — the sample spaces of Visual-Polar path tracing (technique/vpolar/space.h) as kernel code:
 * the grid-to-screen mapping a sample's path starts from, the arc tangent in turns and the radial
 * table lookups that take a screen position back to the grid (the map stage, the denoiser's
 * reprojection). Compiled by C for the CPU pipeline and the portable backend and by nvcc for CUDA,
 * so the three place every sample with the same arithmetic.
 *
 * What is built once per screen size (the grid, the fitted inverse of Eq. 2) stays on the host in
 * space.c; it fills the flat fv_kvp_space below, which holds no pointer and so copies to a device
 * as it is. A frame's gaze places it (fv_kvp_view, the values of fv_space_view).
 */
#ifndef FV_TECHNIQUE_VPOLAR_KVP_SPACE_H
#define FV_TECHNIQUE_VPOLAR_KVP_SPACE_H

#include <math.h>
#include <stdint.h>
#include "fovea/math.h"
#include "kernel/keye.h"

#define FV_KVP_MAX_COEF 11 /* the fit's degree is at most 10 */

enum { FV_KVP_CARTESIAN = 0, FV_KVP_VPOLAR, FV_KVP_LOGPOLAR }; /* fv_space_kind's values */

typedef struct fv_kvp_space {
    int kind;
    int sw, sh;            /* screen */
    int gw, gh;            /* grid storage */
    double x_f;            /* Visual-Polar: the fovea's edge in columns */
    double s_f;            /* Visual-Polar: the fovea's edge as a fraction of the largest ρ */
    double coef[FV_KVP_MAX_COEF]; /* Visual-Polar: e / E_ref as a polynomial in t, lowest order first */
    int ncoef;
    double lp_alpha;       /* log-polar */
    /* Visual-Polar, screen to grid (fv_kvp_from_screen): the fovea's radius and the centre gaze's
     * largest ρ in planar degrees, and the cumulative acuity at both (fv_kvp_acuity_area) */
    double fovea_deg, e_ref, a_f, a_e;
} fv_kvp_space;

#define FV_KVP_ACUITY_FLAT_DEG 5.79 /* Eq. 1: V(e) = 60 up to here */
#define FV_KVP_EQ2_AT_FLAT 105.04624271125317 /* Eq. 2 at 5.79 degrees (test_vp_space checks it) */

/* The cumulative acuity of Eq. 2 continued as pi e^2 inside 5.79 degrees, where they meet
 * (fv_space_acuity_area): Eq. 2 with its constant adjusted so that the two pieces meet exactly (the
 * printed -612.3 leaves a step of 0.27 at 5.79 degrees, which would make the inverse ambiguous). */
FV_HD static inline double fv_kvp_acuity_area(double e)
{
    if (e <= FV_KVP_ACUITY_FLAT_DEG) return FV_PI_D * e * e;
    return fv_kacuity_cdf(e) - FV_KVP_EQ2_AT_FLAT + FV_PI_D * FV_KVP_ACUITY_FLAT_DEG * FV_KVP_ACUITY_FLAT_DEG;
}

/* Buffers on the grid's storage (w * h cells; host memory on the CPU and the portable backend,
 * device memory on CUDA). */
typedef struct fv_kvp_gbuf {
    float *color, *albedo, *normal, *depth, *position;
    float *reflectance; /* what SVGF demodulates by (fv_bsdf_demod_reflectance); albedo is the film's */
    uint32_t *id;       /* object + 1, 0: no surface */
    uint8_t *sampled;   /* 1 where a path was traced */
} fv_kvp_gbuf;

/* A space placed for one gaze (fv_space_view without its pointer). */
typedef struct fv_kvp_view {
    float gx, gy, rho_max, log_rho_max;
} fv_kvp_view;

FV_HD static inline double fv_kvp_poly(const double *c, int n, double t)
{
    double r = 0.0;
    for (int i = n - 1; i >= 0; i--) r = r * t + c[i];
    return r;
}

/* Screen radius (pixels from the gaze) of column coordinate X (fv_space_radius). */
FV_HD static inline float fv_kvp_radius(const fv_kvp_space *s, const fv_kvp_view *v, float X)
{
    if (s->kind == FV_KVP_VPOLAR) {
        double frac;
        if (X <= s->x_f) {
            frac = s->s_f * (X > 0.0f ? X : 0.0f) / s->x_f;
        } else {
            double t = (X - s->x_f) / (s->gw - s->x_f);
            frac = fv_kvp_poly(s->coef, s->ncoef, t > 1.0 ? 1.0 : t);
        }
        return (float)(frac * v->rho_max);
    }
    if (s->kind == FV_KVP_LOGPOLAR) {
        float u = X / (float)s->gw;
        u = u < 0.0f ? 0.0f : u;
        return expf(v->log_rho_max * powf(u, (float)s->lp_alpha));
    }
    return 0.0f;
}

/* Grid (X, V) to screen position in pixels (fv_space_to_screen). */
FV_HD static inline void fv_kvp_to_screen(const fv_kvp_space *s, const fv_kvp_view *v, float X, float V, float *px, float *py)
{
    if (s->kind == FV_KVP_CARTESIAN) {
        *px = X * (float)s->sw / (float)s->gw;
        *py = V * (float)s->sh;
        return;
    }
    float r = fv_kvp_radius(s, v, X);
    float phi = 2.0f * FV_PI * V;
    *px = v->gx + r * cosf(phi);
    *py = v->gy + r * sinf(phi);
}

/* The angle of (dx, dy) in turns, [0, 1) like the V of fv_space_from_screen, within 3e-7 of the
 * exact angle (test_vp_space), written so that a loop over pixels vectorises (the map stage:
 * atan2f from libm was a quarter of its time). The octant is folded onto [0, pi/4] and beyond
 * tan(pi/8) shifted by pi/4 (atan a = pi/4 + atan((a - 1)/(a + 1))), leaving |t| <= tan(pi/8),
 * where t P(t^2) with P of degree 4 (least-squares fit on that interval, ours) is within 4e-9 rad.
 * Every case is arithmetic on a 0-or-1 factor or a select on the integer bits, never a branch
 * around floating-point work: with trapping math on, GCC will not turn such a branch back into
 * a vector select, and the loop would stay scalar. */
FV_HD static inline float fv_space_bit_float(int32_t cond) /* 1.0f when cond, else 0.0f */
{
    union { int32_t i; float f; } u = {-cond & 0x3f800000};
    return u.f;
}

FV_HD static inline float fv_space_turns(float dx, float dy)
{
    const float ax = fabsf(dx), ay = fabsf(dy);
    const float mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
    const float a = mn / (mx > 1e-30f ? mx : 1e-30f);
    const float big = fv_space_bit_float(a > 0.41421356f);
    const float t = (a - big) / (1.0f + big * a), u = t * t; /* a / 1 below tan(pi/8): exact */
    const float poly = 0.999999922f + u * (-0.333323067f + u * (0.199638607f + u * (-0.137683572f + u * 0.0776761543f)));
    float r = big * 0.785398163f + t * poly;                   /* in [0, pi/4] */
    r += fv_space_bit_float(ay > ax) * (1.57079633f - 2.0f * r); /* pi/2 - r */
    r += fv_space_bit_float(dx < 0.0f) * (3.14159265f - 2.0f * r); /* pi - r */
    float v = r * 0.159154943f;
    union { float f; int32_t i; } uv = {v}, uy = {dy};
    uv.i ^= uy.i & (int32_t)0x80000000; /* the lower half plane: -v (v >= 0) */
    v = uv.f + fv_space_bit_float(uv.f < 0.0f);
    uv.f = v;
    uv.i &= -(int32_t)(v < 1.0f); /* rounding up to 1 is the angle 0 */
    return uv.f;
}

/* The column at distance r >= 0 from the gaze, linear between the entries of a radial table
 * (fv_space_radial_table; the last interval continues past its end); 1 / step as inv_step. From
 * table + 1 the same reads the mip level, and any value a caller keeps every `stride` floats beside
 * them (the pipeline's blur sigma). For a Visual-Polar table every 0.5 px at 1280x1440, within 1e-3
 * columns of fv_space_from_screen (test_vp_space): X is linear in the fovea and smooth beyond it
 * (Eq. 2 meets the fovea's pi e^2 with its slope). */
FV_HD static inline float fv_space_table_x(const float *table, int stride, int n, float inv_step, float r)
{
    const float t = r * inv_step;
    int i = (int)t;
    i = i < n - 2 ? i : n - 2;
    const float f = t - (float)i;
    return table[stride * i] + f * (table[stride * (i + 1)] - table[stride * i]);
}

/* A screen offset (dx, dy) from the gaze to grid (X, V) on a polar space through its radial table
 * of three floats an entry (column, mip level, blur sigma; the pipeline's): what the map stage
 * does per pixel and the reprojection per sample. level and sigma may be NULL. */
FV_HD static inline void fv_kvp_table_coords(const float *table, int n, float inv_step, float dx, float dy, float *X, float *V, float *level,
                                             float *sigma)
{
    const float r = sqrtf(dx * dx + dy * dy);
    *X = fv_space_table_x(table, 3, n, inv_step, r);
    if (level) *level = fv_space_table_x(table + 1, 3, n, inv_step, r);
    *V = fv_space_turns(dx, dy);
    if (sigma) *sigma = fv_space_table_x(table + 2, 3, n, inv_step, r);
}

/* Screen position to grid (X, V) on a Cartesian space (fv_space_from_screen's Cartesian case). */
FV_HD static inline void fv_kvp_cartesian_from_screen(const fv_kvp_space *s, float px, float py, float *X, float *V)
{
    *X = px * (float)s->gw / (float)s->sw;
    *V = py / (float)s->sh;
}

/* Screen position in pixels to grid (X, V) (fv_space_from_screen); *phi_per_px (optional) receives
 * how many rows of the column one screen pixel spans along φ (0 on a Cartesian space). Visual-Polar
 * evaluates Eq. 2 directly (Sec. 3.2): the periphery's X - X_f is proportional to A(e) - A(e_f). */
FV_HD static inline void fv_kvp_from_screen(const fv_kvp_space *s, const fv_kvp_view *v, float px, float py, float *X, float *V, float *phi_per_px)
{
    if (s->kind == FV_KVP_CARTESIAN) {
        fv_kvp_cartesian_from_screen(s, px, py, X, V);
        if (phi_per_px) *phi_per_px = 0.0f;
        return;
    }
    const float dx = px - v->gx, dy = py - v->gy;
    const float r = sqrtf(dx * dx + dy * dy);
    /* fv_space_turns, not atan2f: the reprojection of every grid sample (the denoiser's history)
     * comes here, and libm's arc tangent was 1.3% of a frame there. */
    *V = fv_space_turns(dx, dy);
    float x, rows;
    if (s->kind == FV_KVP_VPOLAR) {
        const double e = (double)r / v->rho_max * s->e_ref;
        if (e <= s->fovea_deg) {
            x = (float)(s->x_f * e / s->fovea_deg);
            /* Column height grows with X in the fovea, so rows per pixel along φ are constant there. */
            rows = (float)(s->gh / s->x_f) * x;
        } else {
            const double t = (fv_kvp_acuity_area(e) - s->a_f) / (s->a_e - s->a_f);
            x = (float)(s->x_f + t * (s->gw - s->x_f));
            rows = (float)s->gh;
        }
    } else {
        const float lr = r > 1.0f ? logf(r) : 0.0f;
        x = powf(lr / v->log_rho_max, (float)(1.0 / s->lp_alpha)) * (float)s->gw;
        rows = (float)s->gh;
    }
    *X = x;
    if (phi_per_px) {
        const float circ = 2.0f * FV_PI * (r > 0.5f ? r : 0.5f);
        *phi_per_px = rows / circ;
    }
}

/* Entry i of a view's radial table (fv_space_radial_table): the column X at distance i * step from
 * the gaze along +x, and the φ-mip level there (log2 of the rows one pixel spans along φ, 0 below
 * one row). */
FV_HD static inline void fv_kvp_radial_coords(const fv_kvp_space *s, const fv_kvp_view *v, float step, int i, float *X, float *level)
{
    float V, rows;
    fv_kvp_from_screen(s, v, v->gx + (float)i * step, v->gy, X, &V, &rows);
    *level = rows > 1.0f ? log2f(rows) : 0.0f;
}

#endif
