/* fovea — depth cube maps by rasterising triangles (see cube_raster.h for the edge functions,
 * the depth formula and the bounding box rule). */
#include <math.h>
#include <stdlib.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include "core/alloc.h"
#include "scene/query.h"
#include "technique/vpl/cube_raster.h"
#include "technique/vpl/cubemap.h"

typedef struct soup_tri {
    fv_vec3 a, b, c, nrm; /* world corners, nrm = (b - a) x (c - a) */
} soup_tri;

struct fv_tri_soup {
    int count;
    size_t cap; /* triangles tri holds room for: grown, never shrunk (fv_tri_soup_update) */
    soup_tri *tri;
};

fv_status fv_tri_soup_update(fv_tri_soup **io, const fv_scene *s, fv_error *err)
{
    fv_tri_soup *t = *io;
    if (!t && !(t = *io = calloc(1, sizeof *t))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the cube maps' triangles");
    size_t total = 0;
    const int nobj = fv_scene_object_count(s);
    for (int o = 0; o < nobj; o++) total += (size_t)fv_scene_object_triangle_count(s, o);
    t->count = 0;
    if (total > t->cap) {
        soup_tri *tri = fv_alloc_array(total, sizeof *tri);
        if (!tri) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the cube maps' %zu triangles", total);
        free(t->tri);
        t->tri = tri;
        t->cap = total;
    }
    for (int o = 0; o < nobj; o++)
        for (int p = 0, nt = fv_scene_object_triangle_count(s, o); p < nt; p++) {
            soup_tri *q = &t->tri[t->count++];
            fv_scene_triangle(s, o, p, &q->a, &q->b, &q->c);
            q->nrm = fv_cross(fv_sub(q->b, q->a), fv_sub(q->c, q->a));
        }
    return FV_OK;
}

void fv_tri_soup_destroy(fv_tri_soup *t)
{
    if (!t) return;
    free(t->tri);
    free(t);
}

int fv_tri_soup_count(const fv_tri_soup *t) { return t->count; }

/* A vector in face f's frame: (along U, along V, along the axis A) (cubemap.h's convention). */
static inline fv_vec3 in_face(fv_vec3 v, int f)
{
    const int a = f >> 1;
    const float s = (f & 1) ? -1.0f : 1.0f;
    return fv_v3(s * fv_cube_comp(v, (a + 1) % 3), fv_cube_comp(v, (a + 2) % 3), s * fv_cube_comp(v, a));
}

/* The range of face-plane coordinates [lo, hi] (x then y) the triangle with corners p[3] (face
 * frame) can cover; false when it lies wholly behind the face. Corners in front project to
 * (x / z, y / z); an edge crossing z = 0 leaves towards infinity along its crossing point's
 * (x, y), which opens the box on that side. */
static bool face_box(const fv_vec3 p[3], float lo[2], float hi[2])
{
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    bool any = false;
    for (int k = 0; k < 3; k++) {
        const fv_vec3 u = p[k], w = p[(k + 1) % 3];
        if (u.z > 0.0f) {
            const float q[2] = {u.x / u.z, u.y / u.z};
            for (int c = 0; c < 2; c++) lo[c] = fminf(lo[c], q[c]), hi[c] = fmaxf(hi[c], q[c]);
            any = true;
        }
        if ((u.z > 0.0f) != (w.z > 0.0f)) {
            /* the edge's point at z = 0: a direction at infinity in the face plane */
            const float t = u.z / (u.z - w.z);
            const float d[2] = {u.x + t * (w.x - u.x), u.y + t * (w.y - u.y)};
            for (int c = 0; c < 2; c++) {
                if (d[c] > 0.0f) hi[c] = INFINITY;
                if (d[c] < 0.0f) lo[c] = -INFINITY;
            }
        }
    }
    return any;
}

/* Texel indices whose centres 2 (i + 0.5) / n - 1 lie in [lo, hi], clamped to the face. */
static bool texel_range(float lo, float hi, int n, int *i0, int *i1)
{
    const float h = 0.5f * (float)n;
    const float a = fmaxf(-1.0f, lo), b = fminf(1.0f, hi);
    if (!(a <= b)) return false;
    int x0 = (int)ceilf((a + 1.0f) * h - 0.5f), x1 = (int)floorf((b + 1.0f) * h - 0.5f);
    x0 = x0 < 0 ? 0 : x0;
    x1 = x1 > n - 1 ? n - 1 : x1;
    *i0 = x0, *i1 = x1;
    return x0 <= x1;
}

/* The texels [*xa, *xb] of a row, within [x0, x1], where the three edge functions c_k + sx g_k may
 * all be >= 0: the interval the three half-lines leave, solved in sx and widened by a texel on
 * each side so rounding in the solve never drops a texel the exact per-texel test would take. */
static bool row_span(float c0, float g0, float c1, float g1, float c2, float g2, int n, int x0, int x1, int *xa, int *xb)
{
    float lo = -2.0f, hi = 2.0f; /* the face is [-1, 1]: beyond +-2 is as good as infinity */
    const float c[3] = {c0, c1, c2}, g[3] = {g0, g1, g2};
    for (int k = 0; k < 3; k++) {
        if (g[k] > 0.0f) lo = fmaxf(lo, -c[k] / g[k]);
        else if (g[k] < 0.0f) hi = fminf(hi, -c[k] / g[k]);
        else if (c[k] < 0.0f) return false;
    }
    if (!(lo <= hi)) return false;
    const float h = 0.5f * (float)n;
    const int a = (int)floorf((fmaxf(lo, -2.0f) + 1.0f) * h - 0.5f) - 1, b = (int)ceilf((fminf(hi, 2.0f) + 1.0f) * h - 0.5f) + 1;
    *xa = a > x0 ? a : x0;
    *xb = b < x1 ? b : x1;
    return *xa <= *xb;
}

/* One row's texels xa..xb: where all three edge functions are >= 0, the distance along the texel
 * centre's ray, kept if nearer. Four texels at a time with SSE2 where the compiler targets it:
 * the same operations in the same order as the scalar tail (IEEE square root and division are
 * exactly rounded either way), so both give the same bits. */
static void raster_row(float *row, int xa, int xb, float step, float c0, float g0, float c1, float g1, float c2, float g2, float cn,
                       float gn, float sy2, float det)
{
    int x = xa;
#if defined(__SSE2__)
    const __m128 vstep = _mm_set1_ps(step), one = _mm_set1_ps(1.0f), half = _mm_set1_ps(0.5f), zero = _mm_setzero_ps();
    const __m128 vc0 = _mm_set1_ps(c0), vg0 = _mm_set1_ps(g0), vc1 = _mm_set1_ps(c1), vg1 = _mm_set1_ps(g1);
    const __m128 vc2 = _mm_set1_ps(c2), vg2 = _mm_set1_ps(g2), vcn = _mm_set1_ps(cn), vgn = _mm_set1_ps(gn);
    const __m128 vsy2 = _mm_set1_ps(sy2), vdet = _mm_set1_ps(det);
    for (; x + 3 <= xb; x += 4) {
        const __m128 sx = _mm_sub_ps(_mm_mul_ps(_mm_add_ps(_mm_cvtepi32_ps(_mm_setr_epi32(x, x + 1, x + 2, x + 3)), half), vstep), one);
        const __m128 e0 = _mm_add_ps(vc0, _mm_mul_ps(sx, vg0)), e1 = _mm_add_ps(vc1, _mm_mul_ps(sx, vg1));
        const __m128 e2 = _mm_add_ps(vc2, _mm_mul_ps(sx, vg2));
        const __m128 d = _mm_div_ps(_mm_mul_ps(vdet, _mm_sqrt_ps(_mm_add_ps(vsy2, _mm_mul_ps(sx, sx)))), _mm_add_ps(vcn, _mm_mul_ps(sx, vgn)));
        const __m128 old = _mm_loadu_ps(row + x);
        __m128 take = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(e0, zero), _mm_cmpge_ps(e1, zero)), _mm_cmpge_ps(e2, zero));
        take = _mm_and_ps(take, _mm_and_ps(_mm_cmpgt_ps(d, zero), _mm_cmplt_ps(d, old)));
        _mm_storeu_ps(row + x, _mm_or_ps(_mm_and_ps(take, d), _mm_andnot_ps(take, old)));
    }
#endif
    for (; x <= xb; x++) {
        const float sx = ((float)x + 0.5f) * step - 1.0f;
        const float e0 = c0 + sx * g0, e1 = c1 + sx * g1, e2 = c2 + sx * g2;
        if (!(e0 >= 0.0f && e1 >= 0.0f && e2 >= 0.0f)) continue;
        const float d = det * sqrtf(sy2 + sx * sx) / (cn + sx * gn);
        /* the rounding of a nearly edge-on triangle can flip the denominator: keep only a
         * distance in front */
        if (d > 0.0f && d < row[x]) row[x] = d;
    }
}

void fv_cube_raster(const fv_tri_soup *t, fv_vec3 o, int n, unsigned face_mask, float *faces)
{
    const float step = 2.0f / (float)n;
    for (int i = 0; i < t->count; i++) {
        const soup_tri *q = &t->tri[i];
        const fv_vec3 pa = fv_sub(q->a, o), pb = fv_sub(q->b, o), pc = fv_sub(q->c, o);
        const float det = fv_dot(q->nrm, pa);
        /* o on the triangle's plane: the rays graze it and see nothing of it */
        if (!(fabsf(det) > 0.0f)) continue;
        const float sg = det > 0.0f ? 1.0f : -1.0f;
        const fv_vec3 e[3] = {fv_scale(fv_cross(pa, pb), sg), fv_scale(fv_cross(pb, pc), sg), fv_scale(fv_cross(pc, pa), sg)};
        for (int f = 0; f < 6; f++) {
            if (!(face_mask & (1u << f))) continue;
            const fv_vec3 p[3] = {in_face(pa, f), in_face(pb, f), in_face(pc, f)};
            float lo[2], hi[2];
            int x0, x1, y0, y1;
            if (!face_box(p, lo, hi) || !texel_range(lo[0], hi[0], n, &x0, &x1) || !texel_range(lo[1], hi[1], n, &y0, &y1))
                continue;
            /* each function g(sx, sy) = g.z + sx g.x + sy g.y over the face */
            const fv_vec3 g0 = in_face(e[0], f), g1 = in_face(e[1], f), g2 = in_face(e[2], f), gn = in_face(q->nrm, f);
            float *out = faces + (size_t)f * n * n;
            for (int y = y0; y <= y1; y++) {
                const float sy = ((float)y + 0.5f) * step - 1.0f;
                const float c0 = g0.z + sy * g0.y, c1 = g1.z + sy * g1.y, c2 = g2.z + sy * g2.y, cn = gn.z + sy * gn.y;
                int xa, xb;
                if (!row_span(c0, g0.x, c1, g1.x, c2, g2.x, n, x0, x1, &xa, &xb)) continue;
                raster_row(out + (size_t)y * n, xa, xb, step, c0, g0.x, c1, g1.x, c2, g2.x, cn, gn.x, 1.0f + sy * sy, det);
            }
        }
    }
}
