/* fovea — the SDF kernel, written once for any lane count (see sdf_eval.h).
 *
 * Included by eval1.c with FV_K_WIDE 0 (kf = float) and by eval8.c with FV_K_WIDE 1 (kf = eight
 * floats in a GCC vector). Every formula below is spelled with the same operations in the same
 * order for both, and the helpers (k_min, k_sel, k_floor, ...) have identical IEEE semantics per
 * lane, so the two builds agree bit for bit. Not a normal header: it defines static functions and
 * must be included once per translation unit, after FV_K_WIDE.
 *
 * Distances (Polychronakis et al. 2023, Sec. 2.1: the field at p is the distance to the surface
 * f^-1(0), negative inside), each derived in docs/sdf.md:
 *  - primitives are exact Euclidean distances to their solids;
 *  - min/max/max(a, -b) and the polynomial smooth minimum are 1-Lipschitz when their inputs are;
 *  - a rigid motion with uniform scale s multiplies the child's distance by s after dividing the
 *    point by s, which keeps the Lipschitz constant;
 *  - repetition and the height field are bounded by the rules in the REPEAT and HEIGHTFIELD cases.
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include "sdf/sdf_impl.h"

#ifndef FV_K_WIDE
#error "define FV_K_WIDE before including sdf/kernel.h"
#endif

#if FV_K_WIDE
#include <string.h>
#define FV_KFN static inline
/* The culled chains' helpers stay out of k_eval's loop in the eight-lane builds: inlined, they
 * made programs without a culled chain 4-6% slower (sdf-temple, one thread). */
#define FV_KFN_COLD static __attribute__((noinline))
#else
/* The scalar build is also what GPU kernels evaluate (kernel/ksdf_trace.h): host-and-device under
 * nvcc (FV_HD, fovea/math.h), plain static inline for a C compiler, so the CPU's bits do not change. */
#define FV_KFN FV_HD static inline
#define FV_KFN_COLD FV_KFN
#endif

#if FV_K_WIDE
/* Everything here is static to one translation unit, so no 32-byte vector crosses an ABI boundary;
 * GCC's note about the AVX calling convention does not apply. */
#pragma GCC diagnostic ignored "-Wpsabi"
typedef float kf __attribute__((vector_size(32)));
typedef int32_t ki __attribute__((vector_size(32)));
typedef uint32_t ku __attribute__((vector_size(32)));
FV_KFN kf k_splat(float c) { return (kf){0} + c; }
FV_KFN ki k_spliti(int c) { return (ki){0} + c; }
/* Comparisons give -1/0 lanes: blend through the bits. */
FV_KFN kf k_sel(ki m, kf a, kf b) { return (kf)(((ki)a & m) | ((ki)b & ~m)); }
FV_KFN ki k_seli(ki m, ki a, ki b) { return (a & m) | (b & ~m); }
/* Lane by lane so each lane gets the same correctly rounded sqrtf as the scalar build; GCC turns
 * the loop into sqrtps. */
FV_KFN kf k_sqrt(kf x)
{
    kf r;
    for (int i = 0; i < 8; i++) r[i] = sqrtf(x[i]);
    return r;
}
FV_KFN ki k_f2i(kf x) { return __builtin_convertvector(x, ki); }
FV_KFN kf k_i2f(ki x) { return __builtin_convertvector(x, kf); }
FV_KFN ku k_i2u(ki x) { return (ku)x; }
FV_KFN kf k_abs(kf x) { return (kf)((ki)x & 0x7fffffff); }
/* True when every lane of a comparison is set: the eight points take a branch only together. */
FV_KFN bool k_all(ki m)
{
    int r = 1;
    for (int i = 0; i < 8; i++) r &= m[i] != 0;
    return r != 0;
}
#else
typedef float kf;
typedef int32_t ki;
typedef uint32_t ku;
FV_KFN kf k_splat(float c) { return c; }
FV_KFN ki k_spliti(int c) { return c; }
FV_KFN kf k_sel(ki m, kf a, kf b) { return m ? a : b; }
FV_KFN ki k_seli(ki m, ki a, ki b) { return m ? a : b; }
FV_KFN kf k_sqrt(kf x) { return sqrtf(x); }
FV_KFN ki k_f2i(kf x) { return (ki)x; }
FV_KFN kf k_i2f(ki x) { return (kf)x; }
FV_KFN ku k_i2u(ki x) { return (ku)x; }
FV_KFN kf k_abs(kf x) { return fabsf(x); }
FV_KFN bool k_all(ki m) { return m != 0; }
#endif

/* A far value that stays finite, so b + m and m - b below never produce inf - inf. */
#define FV_K_FAR 1e30f

FV_KFN kf k_min(kf a, kf b) { return k_sel(a < b, a, b); }
FV_KFN kf k_max(kf a, kf b) { return k_sel(a > b, a, b); }
FV_KFN kf k_clamp(kf x, kf lo, kf hi) { return k_min(k_max(x, lo), hi); }
/* floor through truncation; callers clamp x to +-1e9 first so the conversion stays in range. */
FV_KFN kf k_floor(kf x)
{
    kf t = k_i2f(k_f2i(x));
    return k_sel(t > x, t - 1.0f, t);
}
FV_KFN kf k_len3(kf x, kf y, kf z) { return k_sqrt(x * x + y * y + z * z); }
FV_KFN kf k_len2(kf x, kf y) { return k_sqrt(x * x + y * y); }

/* Box of half extents (bx, by, bz): the length of the outside part plus the (negative) largest
 * axis distance inside. */
FV_KFN kf k_box(kf x, kf y, kf z, float bx, float by, float bz)
{
    kf qx = k_abs(x) - bx, qy = k_abs(y) - by, qz = k_abs(z) - bz;
    kf zero = k_splat(0.0f);
    kf out = k_len3(k_max(qx, zero), k_max(qy, zero), k_max(qz, zero));
    kf in = k_min(k_max(qx, k_max(qy, qz)), zero);
    return out + in;
}

/* Capped cone in the (rho, y) half plane: the section is the trapezoid (0,-h) (r1,-h) (r2,h) (0,h);
 * its surface edges are the two caps and the slanted side (the rho = 0 edge is the axis, not
 * surface). The distance is to the nearest of the three edges, negative inside. */
FV_KFN kf k_cone(kf x, kf y, kf z, const float *f)
{
    float r1 = f[0], r2 = f[1], h = f[2], er = f[3], ey = f[4], inv = f[5];
    kf zero = k_splat(0.0f), one = k_splat(1.0f);
    kf rho = k_len2(x, z);
    kf yb = y + h, yt = y - h;
    kf ob = k_max(rho - r1, zero), ot = k_max(rho - r2, zero);
    kf d1 = ob * ob + yb * yb;
    kf d2 = ot * ot + yt * yt;
    kf wr = rho - r1;
    kf t = k_clamp((wr * er + yb * ey) * inv, zero, one);
    kf sr = wr - t * er, sy = yb - t * ey;
    kf d3 = sr * sr + sy * sy;
    kf d = k_sqrt(k_min(d1, k_min(d2, d3)));
    /* Inside: between the caps and on the axis side of the slanted edge (cross(e, w) >= 0). */
    ki inside = (k_abs(y) <= h) & ((er * yb - ey * wr) >= 0.0f);
    return k_sel(inside, -d, d);
}

/* Lattice value in [-1, 1): an integer hash of the cell and the octave's seed, mixed with the
 * "lowbias32" finaliser (shift-xor-multiply, constants from C. Wellons' hash-prospector). */
FV_KFN kf k_lattice(ki iu, ki iw, uint32_t seed)
{
    ku h = (k_i2u(iu) * 0x8da6b343u) ^ (k_i2u(iw) * 0xd8163841u) ^ (seed * 0xcb1ab31fu);
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return k_i2f((ki)(h >> 8)) * (2.0f / 16777216.0f) - 1.0f;
}

/* Value noise: lattice values blended with the smoothstep s(t) = t^2 (3 - 2t), |s'| <= 3/2, so each
 * partial derivative is at most 3/2 * 2 = 3 and the gradient at most 3 sqrt(2) (docs/sdf.md). */
FV_KFN kf k_value_noise(kf u, kf w, uint32_t seed)
{
    u = k_clamp(u, k_splat(-1e9f), k_splat(1e9f));
    w = k_clamp(w, k_splat(-1e9f), k_splat(1e9f));
    kf fu = k_floor(u), fw = k_floor(w);
    ki iu = k_f2i(fu), iw = k_f2i(fw);
    kf tu = u - fu, tw = w - fw;
    kf su = tu * tu * (3.0f - 2.0f * tu), sw = tw * tw * (3.0f - 2.0f * tw);
    kf v00 = k_lattice(iu, iw, seed), v10 = k_lattice(iu + 1, iw, seed);
    kf v01 = k_lattice(iu, iw + 1, seed), v11 = k_lattice(iu + 1, iw + 1, seed);
    kf a = v00 + su * (v10 - v00), b = v01 + su * (v11 - v01);
    return a + sw * (b - a);
}

/* Height field y = base + sum_o A 2^-o noise(F 2^o (x, z)): g = y - height has gradient norm at most
 * sqrt(1 + L_h^2) with L_h = octaves * A * F * 3 sqrt(2) (every octave contributes A F 3 sqrt(2)),
 * so g / sqrt(1 + L_h^2) (f[3] holds the reciprocal) is 1-Lipschitz and never exceeds the distance. */
FV_KFN kf k_heightfield(kf x, kf y, kf z, const fv_sdf_op *op)
{
    kf hsum = k_splat(0.0f);
    float amp = op->f[1], freq = op->f[2];
    for (int o = 0; o < op->ia; o++) {
        hsum = hsum + amp * k_value_noise(x * freq, z * freq, (uint32_t)op->ib + (uint32_t)o * 0x9e3779b9u);
        amp *= 0.5f;
        freq *= 2.0f;
    }
    return (y - op->f[0] - hsum) * op->f[3];
}

/* One repeated axis: the cell index k = round(x / c) (clamped to -n..n when limited), the point in
 * the cell q = x - k c, and the distance to the cell's walls on this axis (FV_K_FAR where the cell
 * is open: beyond the last cell of a limited repetition). */
FV_KFN kf k_repeat_axis(kf x, float c, float ic, float n, kf *wall)
{
    kf k = k_floor(k_clamp(x * ic, k_splat(-1e9f), k_splat(1e9f)) + 0.5f);
    if (n > 0.0f) k = k_clamp(k, k_splat(-n), k_splat(n));
    kf q = x - k * c;
    kf lo = q + 0.5f * c, hi = 0.5f * c - q;
    if (n > 0.0f) {
        lo = k_sel(k > -n, lo, k_splat(FV_K_FAR));
        hi = k_sel(k < n, hi, k_splat(FV_K_FAR));
    }
    *wall = k_min(*wall, k_min(lo, hi));
    return q;
}

/* Distance from (x, y, z) to the box of a CULL_DATA op (0 inside), and to its farthest point. */
FV_KFN kf k_box_dist(kf x, kf y, kf z, const float *f)
{
    kf zero = k_splat(0.0f);
    kf ex = k_max(k_max(f[0] - x, x - f[3]), zero), ey = k_max(k_max(f[1] - y, y - f[4]), zero);
    kf ez = k_max(k_max(f[2] - z, z - f[5]), zero);
    return k_len3(ex, ey, ez);
}
FV_KFN kf k_box_far(kf x, kf y, kf z, const float *f)
{
    kf fx = k_max(k_abs(x - f[0]), k_abs(x - f[3])), fy = k_max(k_abs(y - f[1]), k_abs(y - f[4]));
    kf fz = k_max(k_abs(z - f[2]), k_abs(z - f[5]));
    return k_len3(fx, fy, fz);
}

/* Relative size of the culling margin: the floats of a child's distance and of the box tests are
 * each within a few ulps of their magnitude (nested transforms add a few more per level), far below
 * 2^-12 of it (about 4000 ulps), so a decision taken with the margin holds for the exact values. */
#define FV_K_CULL_REL 2.44140625e-4f

/* CULL_BEGIN of a union of many children (sdf_impl.h): U, an upper bound of its value, is the
 * distance to the farthest point of a box that holds a surface whose field never exceeds that
 * distance (CULL_DATA's material 1); first over the groups, then over the members of the groups
 * that could hold a nearer one (member farthest >= member distance >= group distance); and the
 * rounding margin of the chain's tests. */
FV_KFN_COLD void k_cull_begin(const fv_sdf *s, const fv_sdf_op *op, kf x, kf y, kf z, kf *u_out, kf *m_out)
{
    const fv_sdf_op *data = op + 1;
    kf u = k_splat(FV_K_FAR);
    for (int g = 0; g < op->ia; g++)
        if (data[g].material) u = k_min(u, k_box_far(x, y, z, data[g].f));
    for (int g = 0; g < op->ia; g++) {
        if (!k_all(k_box_dist(x, y, z, data[g].f) >= u)) {
            const fv_sdf_op *m = &s->ops[data[g].ia];
            for (int k = 0; k < data[g].ib; k++)
                if (m[k].material) u = k_min(u, k_box_far(x, y, z, m[k].f));
        }
    }
    *u_out = u;
    *m_out = (k_abs(x) + k_abs(y) + k_abs(z) + op->f[0]) * FV_K_CULL_REL;
}

/* CULL's test, out of k_eval's loop like k_cull_begin: true when c e > max(min(U, acc) + margin, 0). */
FV_KFN_COLD bool k_cull_skip(const float *bf, kf x, kf y, kf z, const kf *u, const kf *m, const kf *acc)
{
    kf thr = k_max(k_min(*u, *acc) + *m, k_splat(0.0f));
    return k_all(k_box_dist(x, y, z, bf) * bf[6] > thr);
}

/* Runs the program at one point per lane. */
FV_KFN void k_eval(const fv_sdf *s, kf x0, kf y0, kf z0, kf *dout, ki *mout)
{
    kf PX[FV_SDF_MAX_DEPTH + 2], PY[FV_SDF_MAX_DEPTH + 2], PZ[FV_SDF_MAX_DEPTH + 2], PW[FV_SDF_MAX_DEPTH + 2];
    kf DS[FV_SDF_MAX_DEPTH + 2];
    ki MS[FV_SDF_MAX_DEPTH + 2];
    kf UU[FV_SDF_MAX_DEPTH + 2], UM[FV_SDF_MAX_DEPTH + 2]; /* culled chains: upper bound, margin */
    int pt = 0, dt = 0, ut = 0;
    PX[0] = x0;
    PY[0] = y0;
    PZ[0] = z0;
    PW[0] = k_splat(FV_K_FAR);
    const kf zero = k_splat(0.0f);
    for (int i = 0; i < s->count; i++) {
        const fv_sdf_op *op = &s->ops[i];
        const float *f = op->f;
        kf x = PX[pt], y = PY[pt], z = PZ[pt];
        kf d;
        switch ((fv_sdf_opcode)op->code) {
        case FV_OP_SPHERE: d = k_len3(x, y, z) - f[0]; goto leaf;
        case FV_OP_BOX: d = k_box(x, y, z, f[0], f[1], f[2]); goto leaf;
        case FV_OP_ROUND_BOX: d = k_box(x, y, z, f[0], f[1], f[2]) - f[3]; goto leaf;
        case FV_OP_TORUS: d = k_len2(k_len2(x, z) - f[0], y) - f[1]; goto leaf;
        case FV_OP_CAPSULE: {
            kf ax = x - f[0], ay = y - f[1], az = z - f[2];
            kf t = k_clamp((ax * f[3] + ay * f[4] + az * f[5]) * f[6], zero, k_splat(1.0f));
            d = k_len3(ax - t * f[3], ay - t * f[4], az - t * f[5]) - f[7];
            goto leaf;
        }
        case FV_OP_CYLINDER: {
            kf dr = k_len2(x, z) - f[0], dy = k_abs(y) - f[1];
            d = k_min(k_max(dr, dy), zero) + k_len2(k_max(dr, zero), k_max(dy, zero));
            goto leaf;
        }
        case FV_OP_CONE: d = k_cone(x, y, z, f); goto leaf;
        case FV_OP_PLANE: d = x * f[0] + y * f[1] + z * f[2] - f[3]; goto leaf;
        case FV_OP_HEIGHTFIELD: d = k_heightfield(x, y, z, op); goto leaf;
        leaf:
            DS[dt] = d;
            MS[dt] = k_spliti(op->material);
            dt++;
            break;
        case FV_OP_UNION: {
            kf a = DS[dt - 2], b = DS[dt - 1];
            ki m = b < a;
            DS[dt - 2] = k_sel(m, b, a);
            MS[dt - 2] = k_seli(m, MS[dt - 1], MS[dt - 2]);
            dt--;
            break;
        }
        case FV_OP_SUBTRACT: {
            kf a = DS[dt - 2], nb = -DS[dt - 1];
            ki m = nb > a; /* b's surface bounds the result here */
            DS[dt - 2] = k_sel(m, nb, a);
            MS[dt - 2] = k_seli(m, MS[dt - 1], MS[dt - 2]);
            dt--;
            break;
        }
        case FV_OP_INTERSECT: {
            kf a = DS[dt - 2], b = DS[dt - 1];
            ki m = b > a;
            DS[dt - 2] = k_sel(m, b, a);
            MS[dt - 2] = k_seli(m, MS[dt - 1], MS[dt - 2]);
            dt--;
            break;
        }
        case FV_OP_SMOOTH_UNION: {
            /* min(a, b) - k/4 h^2, h = max(k - |a - b|, 0) / k: a convex blend of the children's
             * gradients where they meet, so still 1-Lipschitz; at most k/4 below min(a, b). */
            kf a = DS[dt - 2], b = DS[dt - 1];
            kf h = k_max(f[0] - k_abs(a - b), zero) * f[1];
            ki m = b < a;
            DS[dt - 2] = k_min(a, b) - h * h * (0.25f * f[0]);
            MS[dt - 2] = k_seli(m, MS[dt - 1], MS[dt - 2]);
            dt--;
            break;
        }
        case FV_OP_XFORM_PUSH: {
            kf tx = x - f[9], ty = y - f[10], tz = z - f[11];
            pt++;
            PX[pt] = (tx * f[0] + ty * f[1] + tz * f[2]) * f[12];
            PY[pt] = (tx * f[3] + ty * f[4] + tz * f[5]) * f[12];
            PZ[pt] = (tx * f[6] + ty * f[7] + tz * f[8]) * f[12];
            PW[pt] = k_splat(FV_K_FAR);
            break;
        }
        case FV_OP_XFORM_POP:
            DS[dt - 1] = DS[dt - 1] * f[0];
            pt--;
            break;
        case FV_OP_REPEAT_PUSH: {
            kf w = k_splat(FV_K_FAR);
            kf qx = f[0] > 0.0f ? k_repeat_axis(x, f[0], f[3], f[6], &w) : x;
            kf qy = f[1] > 0.0f ? k_repeat_axis(y, f[1], f[4], f[7], &w) : y;
            kf qz = f[2] > 0.0f ? k_repeat_axis(z, f[2], f[5], f[8], &w) : z;
            pt++;
            PX[pt] = qx;
            PY[pt] = qy;
            PZ[pt] = qz;
            PW[pt] = w;
            break;
        }
        case FV_OP_REPEAT_POP: {
            /* The child lies at least m inside its cell, every other copy in another cell: the
             * copies elsewhere are at least w + m away (w: distance to this cell's walls), and the
             * own copy at least m - w. min(max(d, m - w), w + m) is therefore a lower bound, equal
             * to min(d', m) on both sides of a wall, hence continuous and 1-Lipschitz. Every copy
             * also lies in the repetition's box (f1..3, f4..6, in the parent's space), so the
             * distance e to that box bounds them all: outside the box max(.., e) is still a lower
             * bound, still continuous and 1-Lipschitz (e and the field are both >= 0 at the box),
             * and no longer caps the distance at w + m far above a repeated floor, where w + m
             * alone stops rays on phantom walls along the cells' borders. */
            kf w = PW[pt], m = k_splat(f[0]);
            kf px = PX[pt - 1], py = PY[pt - 1], pz = PZ[pt - 1];
            kf ex = k_max(k_max(f[1] - px, px - f[4]), zero), ey = k_max(k_max(f[2] - py, py - f[5]), zero);
            kf ez = k_max(k_max(f[3] - pz, pz - f[6]), zero);
            kf v = k_min(k_max(DS[dt - 1], m - w), w + m), e = k_len3(ex, ey, ez);
            DS[dt - 1] = k_sel(e > zero, k_max(v, e), v); /* e is 0 inside the box: keep the sign */
            pt--;
            break;
        }
        case FV_OP_CULL_BEGIN:
            k_cull_begin(s, op, x, y, z, &UU[ut], &UM[ut]);
            ut++;
            DS[dt] = k_splat(FV_K_FAR);
            MS[dt] = k_spliti(0);
            dt++;
            i += op->ib; /* past the CULL_DATA ops */
            break;
        case FV_OP_CULL_DATA: break; /* read by CULL_BEGIN and CULL only */
        case FV_OP_CULL: {
            /* Jump past a child (or a group of children) that cannot change the union: outside
             * its box its value is at least c e (e: distance to the box). Two ways to lose:
             *  - c e > acc + margin: the fold keeps acc (a UNION takes b only when b < a), so
             *    skipping the child and its UNION leaves the same value and material;
             *  - c e > U + margin: U is the farthest-point distance of a box B_j that holds a
             *    child j with d_j <= U; the child's own box cannot be B_j (its farthest point is
             *    at least e >= c e), so some other child is strictly nearer and the child is
             *    never the fold's minimum, nor tied with it.
             * Every child culled either way has a nearer, earlier or unculled, child, so the fold
             * over what remains finds the same first minimum: the same value and material as the
             * unculled fold, bit for bit. Inside the box (e = 0) nothing is known: never culled. */
            if (k_cull_skip(s->ops[op->ib].f, x, y, z, &UU[ut - 1], &UM[ut - 1], &DS[dt - 1])) i = op->ia - 1;
            break;
        }
        case FV_OP_CULL_END: ut--; break;
        }
    }
    *dout = DS[0];
    *mout = MS[0];
}

#if FV_K_WIDE
/* Eight points from plain arrays through the kernel, for the entry points of each vector build. */
FV_KFN void k_eval_arrays(const fv_sdf *s, const float x[8], const float y[8], const float z[8], float d[8], int mat[8])
{
    kf vx, vy, vz, vd;
    ki vm;
    memcpy(&vx, x, sizeof vx);
    memcpy(&vy, y, sizeof vy);
    memcpy(&vz, z, sizeof vz);
    k_eval(s, vx, vy, vz, &vd, &vm);
    memcpy(d, &vd, sizeof vd);
    if (mat) memcpy(mat, &vm, sizeof vm);
}
#endif
