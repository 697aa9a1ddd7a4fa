/* fovea — small vector math, passed by value, all static inline.
 *
 * Colours are fv_vec3 too (linear RGB). Transforms are affine 3x4 matrices (rotation/scale in the
 * first three columns, translation in the fourth), which is all rigid animation needs.
 */
#ifndef FOVEA_MATH_H
#define FOVEA_MATH_H

#include <math.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The one qualifier of code written once for the CPU and for CUDA kernels (docs/gpu.md): empty for
 * a C compiler, host-and-device for nvcc, which then compiles these same inline functions for the
 * GPU. No CUDA header is needed to read it. */
#ifndef FV_HD
#if defined(__CUDACC__)
#define FV_HD __host__ __device__
#else
#define FV_HD
#endif
#endif

#define FV_PI 3.14159265358979323846f
#define FV_PI_D 3.14159265358979323846
#define FV_INV_PI 0.31830988618379067154f

typedef struct fv_vec3 { float x, y, z; } fv_vec3;
typedef struct fv_vec2 { float x, y; } fv_vec2;
typedef struct fv_quat { float x, y, z, w; } fv_quat;
/* Row-major affine transform: p' = M[0..2][0..2] p + (M[0][3], M[1][3], M[2][3]). */
typedef struct fv_xform { float m[3][4]; } fv_xform;

FV_HD static inline fv_vec3 fv_v3(float x, float y, float z) { fv_vec3 r = {x, y, z}; return r; }
FV_HD static inline fv_vec3 fv_v3s(float s) { return fv_v3(s, s, s); }
FV_HD static inline fv_vec3 fv_add(fv_vec3 a, fv_vec3 b) { return fv_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
FV_HD static inline fv_vec3 fv_sub(fv_vec3 a, fv_vec3 b) { return fv_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
FV_HD static inline fv_vec3 fv_mul(fv_vec3 a, fv_vec3 b) { return fv_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
FV_HD static inline fv_vec3 fv_scale(fv_vec3 a, float s) { return fv_v3(a.x * s, a.y * s, a.z * s); }
FV_HD static inline fv_vec3 fv_neg(fv_vec3 a) { return fv_v3(-a.x, -a.y, -a.z); }
FV_HD static inline fv_vec3 fv_madd(fv_vec3 a, fv_vec3 b, float s) { return fv_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
FV_HD static inline float fv_dot(fv_vec3 a, fv_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
FV_HD static inline fv_vec3 fv_cross(fv_vec3 a, fv_vec3 b)
{
    return fv_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
FV_HD static inline float fv_length(fv_vec3 a) { return sqrtf(fv_dot(a, a)); }
FV_HD static inline fv_vec3 fv_normalize(fv_vec3 a)
{
    float l = fv_length(a);
    return l > 0.0f ? fv_scale(a, 1.0f / l) : a;
}
/* Plain comparisons rather than fmaxf/fminf: without -ffinite-math-only those stay library calls
 * on hot paths. Like fmaxf, a NaN operand yields the other one. */
FV_HD static inline float fv_maxf(float a, float b) { return a > b || b != b ? a : b; }
FV_HD static inline float fv_minf(float a, float b) { return a < b || b != b ? a : b; }
FV_HD static inline float fv_max3(fv_vec3 a) { return fv_maxf(a.x, fv_maxf(a.y, a.z)); }
FV_HD static inline float fv_min3(fv_vec3 a) { return fv_minf(a.x, fv_minf(a.y, a.z)); }
FV_HD static inline fv_vec3 fv_vmin(fv_vec3 a, fv_vec3 b) { return fv_v3(fv_minf(a.x, b.x), fv_minf(a.y, b.y), fv_minf(a.z, b.z)); }
FV_HD static inline fv_vec3 fv_vmax(fv_vec3 a, fv_vec3 b) { return fv_v3(fv_maxf(a.x, b.x), fv_maxf(a.y, b.y), fv_maxf(a.z, b.z)); }
FV_HD static inline fv_vec3 fv_lerp3(fv_vec3 a, fv_vec3 b, float t) { return fv_add(fv_scale(a, 1.0f - t), fv_scale(b, t)); }
FV_HD static inline float fv_luminance(fv_vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
FV_HD static inline bool fv_is_finite3(fv_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
FV_HD static inline float fv_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
FV_HD static inline float fv_radians(float deg) { return deg * (FV_PI / 180.0f); }
FV_HD static inline float fv_degrees(float rad) { return rad * (180.0f / FV_PI); }

/* Orthonormal basis around a unit normal n (Duff et al. 2017, "Building an orthonormal basis,
 * revisited"): branch-free and continuous except at n.z = -1's sign flip. */
FV_HD static inline void fv_basis(fv_vec3 n, fv_vec3 *t, fv_vec3 *b)
{
    float s = copysignf(1.0f, n.z);
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    *t = fv_v3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    *b = fv_v3(c, s + n.y * n.y * a, -n.y);
}
FV_HD static inline fv_vec3 fv_to_local(fv_vec3 v, fv_vec3 t, fv_vec3 b, fv_vec3 n)
{
    return fv_v3(fv_dot(v, t), fv_dot(v, b), fv_dot(v, n));
}
FV_HD static inline fv_vec3 fv_from_local(fv_vec3 v, fv_vec3 t, fv_vec3 b, fv_vec3 n)
{
    return fv_add(fv_add(fv_scale(t, v.x), fv_scale(b, v.y)), fv_scale(n, v.z));
}

/* ---- affine transforms ---- */
FV_HD static inline fv_xform fv_xform_identity(void)
{
    fv_xform r = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    return r;
}
FV_HD static inline fv_vec3 fv_xform_point(const fv_xform *x, fv_vec3 p)
{
    return fv_v3(x->m[0][0] * p.x + x->m[0][1] * p.y + x->m[0][2] * p.z + x->m[0][3],
                 x->m[1][0] * p.x + x->m[1][1] * p.y + x->m[1][2] * p.z + x->m[1][3],
                 x->m[2][0] * p.x + x->m[2][1] * p.y + x->m[2][2] * p.z + x->m[2][3]);
}
FV_HD static inline fv_vec3 fv_xform_vector(const fv_xform *x, fv_vec3 v)
{
    return fv_v3(x->m[0][0] * v.x + x->m[0][1] * v.y + x->m[0][2] * v.z,
                 x->m[1][0] * v.x + x->m[1][1] * v.y + x->m[1][2] * v.z,
                 x->m[2][0] * v.x + x->m[2][1] * v.y + x->m[2][2] * v.z);
}
/* Normals transform by the inverse transpose; callers pass the inverse and we apply its transpose. */
FV_HD static inline fv_vec3 fv_xform_normal(const fv_xform *inv, fv_vec3 n)
{
    return fv_v3(inv->m[0][0] * n.x + inv->m[1][0] * n.y + inv->m[2][0] * n.z,
                 inv->m[0][1] * n.x + inv->m[1][1] * n.y + inv->m[2][1] * n.z,
                 inv->m[0][2] * n.x + inv->m[1][2] * n.y + inv->m[2][2] * n.z);
}

/* Quaternion from axis (need not be unit) and angle in radians. */
FV_HD static inline fv_quat fv_quat_axis_angle(fv_vec3 axis, float angle)
{
    fv_vec3 a = fv_normalize(axis);
    float s = sinf(0.5f * angle);
    fv_quat q = {a.x * s, a.y * s, a.z * s, cosf(0.5f * angle)};
    return q;
}

/* Hamilton product: rotating by b, then by a. */
FV_HD static inline fv_quat fv_quat_mul(fv_quat a, fv_quat b)
{
    fv_quat r = {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                 a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
    return r;
}

/* Rotation about x, then y, then z (fixed axes), angles in degrees. */
FV_HD static inline fv_quat fv_quat_euler_deg(fv_vec3 deg)
{
    fv_quat qx = fv_quat_axis_angle(fv_v3(1, 0, 0), fv_radians(deg.x));
    fv_quat qy = fv_quat_axis_angle(fv_v3(0, 1, 0), fv_radians(deg.y));
    fv_quat qz = fv_quat_axis_angle(fv_v3(0, 0, 1), fv_radians(deg.z));
    return fv_quat_mul(qz, fv_quat_mul(qy, qx));
}

/* Spherical linear interpolation along the shorter arc. */
FV_HD static inline fv_quat fv_quat_slerp(fv_quat a, fv_quat b, float t)
{
    float d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
    if (d < 0.0f) {
        b.x = -b.x; b.y = -b.y; b.z = -b.z; b.w = -b.w;
        d = -d;
    }
    float wa, wb;
    if (d > 0.9995f) { /* nearly parallel: lerp is accurate and avoids dividing by sin(~0) */
        wa = 1.0f - t;
        wb = t;
    } else {
        float th = acosf(d), s = sinf(th);
        wa = sinf((1.0f - t) * th) / s;
        wb = sinf(t * th) / s;
    }
    fv_quat r = {wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z, wa * a.w + wb * b.w};
    float l = sqrtf(r.x * r.x + r.y * r.y + r.z * r.z + r.w * r.w);
    r.x /= l; r.y /= l; r.z /= l; r.w /= l;
    return r;
}

/* T * R * S: scale first, then rotate, then translate. */
FV_HD static inline fv_xform fv_xform_trs(fv_vec3 t, fv_quat q, fv_vec3 s)
{
    float x = q.x, y = q.y, z = q.z, w = q.w;
    float r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                     {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                     {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    fv_xform m;
    for (int i = 0; i < 3; i++) {
        m.m[i][0] = r[i][0] * s.x;
        m.m[i][1] = r[i][1] * s.y;
        m.m[i][2] = r[i][2] * s.z;
    }
    m.m[0][3] = t.x; m.m[1][3] = t.y; m.m[2][3] = t.z;
    return m;
}

/* Inverse of an affine transform; returns false when the linear part is singular. */
FV_HD static inline bool fv_xform_inverse(const fv_xform *a, fv_xform *out)
{
    const float(*m)[4] = a->m;
    float c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    float c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    float c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    float det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    if (!(fabsf(det) > 1e-20f)) return false;
    float id = 1.0f / det;
    fv_xform r;
    r.m[0][0] = c00 * id;
    r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
    r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
    r.m[1][0] = c01 * id;
    r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
    r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
    r.m[2][0] = c02 * id;
    r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
    r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
    for (int i = 0; i < 3; i++)
        r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
    *out = r;
    return true;
}

#ifdef __cplusplus
}
#endif
#endif
