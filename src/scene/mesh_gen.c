/* fovea — triangle-mesh builder and procedural shapes (see mesh_gen.h for the contract).
 * Shapes are wound counter-clockwise seen from the side their normal faces, which is the side the
 * scene treats as the front (one-sided emission leaves from it).
 */
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "scene/mesh_gen.h"

#define MESHBUF_MAX (INT32_MAX / 4)

void fv_meshbuf_init(fv_meshbuf *mb) { memset(mb, 0, sizeof *mb); }

void fv_meshbuf_free(fv_meshbuf *mb)
{
    free(mb->pos);
    free(mb->nrm);
    free(mb->uv);
    free(mb->idx);
    free(mb->mat);
    memset(mb, 0, sizeof *mb);
}

void fv_meshbuf_clear(fv_meshbuf *mb)
{
    mb->nv = mb->nt = 0;
    mb->smooth = false;
}

/* Grows two parallel arrays together. Both start from the same capacity and double the same way,
 * so they stay the same length; if only the first grows, the recorded capacity is unchanged and
 * the extra memory is merely unused. */
static bool grow_pair(void **a, size_t sa, void **b, size_t sb, int *cap, int need)
{
    if (need <= *cap) return true;
    if (need > MESHBUF_MAX) return false;
    int ca = *cap, cb = *cap;
    if (fv_grow(a, &ca, need, sa) != 0 || fv_grow(b, &cb, need, sb) != 0) return false;
    *cap = ca < cb ? ca : cb;
    return true;
}

int fv_meshbuf_vertex_uv(fv_meshbuf *mb, fv_vec3 p, fv_vec3 n, fv_vec2 uv)
{
    if (mb->oom) return -1;
    if (!grow_pair((void **)&mb->pos, sizeof *mb->pos, (void **)&mb->nrm, sizeof *mb->nrm, &mb->capv, mb->nv + 1) ||
        fv_grow((void **)&mb->uv, &mb->capuv, mb->nv + 1, sizeof *mb->uv) != 0) {
        mb->oom = true;
        return -1;
    }
    mb->pos[mb->nv] = p;
    mb->nrm[mb->nv] = n;
    mb->uv[mb->nv] = uv;
    return mb->nv++;
}

int fv_meshbuf_vertex(fv_meshbuf *mb, fv_vec3 p, fv_vec3 n) { return fv_meshbuf_vertex_uv(mb, p, n, (fv_vec2){0.0f, 0.0f}); }

void fv_meshbuf_tri(fv_meshbuf *mb, int a, int b, int c, int mat)
{
    /* A negative index means the vertex could not be stored: oom is already set. */
    if (mb->oom || a < 0 || b < 0 || c < 0) return;
    if (!grow_pair((void **)&mb->idx, 3 * sizeof *mb->idx, (void **)&mb->mat, sizeof *mb->mat, &mb->capt, mb->nt + 1)) {
        mb->oom = true;
        return;
    }
    uint32_t *t = mb->idx + 3 * (size_t)mb->nt;
    t[0] = (uint32_t)a;
    t[1] = (uint32_t)b;
    t[2] = (uint32_t)c;
    mb->mat[mb->nt++] = mat;
}

fv_status fv_meshbuf_check(const fv_meshbuf *mb, const char *name, fv_error *err)
{
    if (mb->oom) return fv_error_set(err, FV_ERR_NOMEM, "out of memory while generating mesh '%s'", name);
    return FV_OK;
}

void fv_meshbuf_desc(const fv_meshbuf *mb, const char *name, fv_mesh_desc *out)
{
    memset(out, 0, sizeof *out);
    out->name = name;
    out->positions = mb->pos;
    out->vertex_count = mb->nv;
    out->normals = mb->smooth ? mb->nrm : NULL;
    out->indices = mb->idx;
    out->triangle_count = mb->nt;
    out->materials = mb->mat;
    out->material = mb->nt > 0 ? mb->mat[0] : 0;
    out->uvs = mb->uv;
}

fv_status fv_meshbuf_add(const fv_meshbuf *mb, fv_scene *scene, const char *name, const fv_log *log, int *object_id,
                         fv_error *err)
{
    fv_status st = fv_meshbuf_check(mb, name, err);
    if (st != FV_OK) return st;
    fv_mesh_desc d;
    fv_meshbuf_desc(mb, name, &d);
    return fv_scene_add_mesh(scene, &d, log, object_id, err);
}

void fv_mesh_quad(fv_meshbuf *mb, fv_vec3 p0, fv_vec3 p1, fv_vec3 p2, fv_vec3 p3, int mat)
{
    /* The diagonal p0-p2 splits the quad; both halves share its normal when it is planar. */
    fv_vec3 n = fv_normalize(fv_cross(fv_sub(p1, p0), fv_sub(p2, p0)));
    int a = fv_meshbuf_vertex_uv(mb, p0, n, (fv_vec2){0, 0}), b = fv_meshbuf_vertex_uv(mb, p1, n, (fv_vec2){1, 0});
    int c = fv_meshbuf_vertex_uv(mb, p2, n, (fv_vec2){1, 1}), d = fv_meshbuf_vertex_uv(mb, p3, n, (fv_vec2){0, 1});
    fv_meshbuf_tri(mb, a, b, c, mat);
    fv_meshbuf_tri(mb, a, c, d, mat);
}

static fv_vec3 axis_point(int axis, float c, float u, float v)
{
    switch (axis) {
    case 0: return fv_v3(c, u, v);
    case 1: return fv_v3(v, c, u);
    default: return fv_v3(u, v, c);
    }
}

void fv_mesh_axis_quad(fv_meshbuf *mb, int axis, float c, float lo_u, float lo_v, float hi_u, float hi_v, int facing,
                       int mat)
{
    /* (u, v, axis) is a right-handed frame, so lo -> +u -> hi winds towards +axis. */
    fv_vec3 p0 = axis_point(axis, c, lo_u, lo_v), p1 = axis_point(axis, c, hi_u, lo_v);
    fv_vec3 p2 = axis_point(axis, c, hi_u, hi_v), p3 = axis_point(axis, c, lo_u, hi_v);
    if (facing > 0)
        fv_mesh_quad(mb, p0, p1, p2, p3, mat);
    else
        fv_mesh_quad(mb, p0, p3, p2, p1, mat);
}

void fv_mesh_grid(fv_meshbuf *mb, fv_vec3 o, fv_vec3 eu, fv_vec3 ev, int nu, int nv, int mat)
{
    if (nu < 1) nu = 1;
    if (nv < 1) nv = 1;
    fv_vec3 n = fv_normalize(fv_cross(eu, ev));
    int base = mb->nv;
    for (int j = 0; j <= nv; j++)
        for (int i = 0; i <= nu; i++) {
            fv_vec3 p = fv_add(o, fv_add(fv_scale(eu, (float)i / (float)nu), fv_scale(ev, (float)j / (float)nv)));
            if (fv_meshbuf_vertex_uv(mb, p, n, (fv_vec2){(float)i / (float)nu, (float)j / (float)nv}) < 0) return;
        }
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            int a = base + j * (nu + 1) + i, b = a + 1, c = a + nu + 2, d = a + nu + 1;
            fv_meshbuf_tri(mb, a, b, c, mat);
            fv_meshbuf_tri(mb, a, c, d, mat);
        }
}

static void box_faces(fv_meshbuf *mb, fv_vec3 c, fv_vec3 h, float yaw_deg, bool bottom, int mat)
{
    float s = sinf(fv_radians(yaw_deg)), co = cosf(fv_radians(yaw_deg));
    fv_vec3 p[8];
    for (int k = 0; k < 8; k++) {
        fv_vec3 l = fv_v3(k & 1 ? h.x : -h.x, k & 2 ? h.y : -h.y, k & 4 ? h.z : -h.z);
        /* Rotation about +y by yaw (right-handed). */
        p[k] = fv_add(c, fv_v3(co * l.x + s * l.z, l.y, -s * l.x + co * l.z));
    }
    /* Corner k has bit 0 = +x, bit 1 = +y, bit 2 = +z. Faces counter-clockwise seen from outside:
     * -x, +x, +y, -z, +z, then -y (the bottom). */
    static const int f[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}};
    int nf = bottom ? 6 : 5;
    for (int i = 0; i < nf; i++) fv_mesh_quad(mb, p[f[i][0]], p[f[i][1]], p[f[i][2]], p[f[i][3]], mat);
}

void fv_mesh_box(fv_meshbuf *mb, fv_vec3 center, fv_vec3 half, float yaw_deg, int mat)
{
    box_faces(mb, center, half, yaw_deg, true, mat);
}

void fv_mesh_box_open(fv_meshbuf *mb, fv_vec3 center, fv_vec3 half, float yaw_deg, int mat)
{
    box_faces(mb, center, half, yaw_deg, false, mat);
}

int fv_mesh_sphere_triangles(int seg_u, int seg_v)
{
    if (seg_u < 3) seg_u = 3;
    if (seg_v < 2) seg_v = 2;
    return 2 * seg_u * (seg_v - 1);
}

void fv_mesh_sphere(fv_meshbuf *mb, fv_vec3 c, float r, int su, int sv, bool inward, int mat)
{
    if (su < 3) su = 3;
    if (sv < 2) sv = 2;
    int base = mb->nv;
    float sign = inward ? -1.0f : 1.0f;
    /* Rows from the north pole (theta = 0, +y) to the south pole; the seam column is duplicated
     * so every row has su + 1 vertices (the pole rows are degenerate rings of one point). */
    for (int j = 0; j <= sv; j++) {
        float th = FV_PI * (float)j / (float)sv;
        float st = j == 0 || j == sv ? 0.0f : sinf(th), ct = j == 0 ? 1.0f : (j == sv ? -1.0f : cosf(th));
        for (int i = 0; i <= su; i++) {
            float ph = 2.0f * FV_PI * (float)(i % su) / (float)su;
            fv_vec3 n = fv_v3(st * cosf(ph), ct, st * sinf(ph));
            fv_vec2 uv = {(float)i / (float)su, 1.0f - (float)j / (float)sv};
            if (fv_meshbuf_vertex_uv(mb, fv_madd(c, n, r), fv_scale(n, sign), uv) < 0) return;
        }
    }
    for (int j = 0; j < sv; j++)
        for (int i = 0; i < su; i++) {
            int a = base + j * (su + 1) + i, b = a + 1, d = a + su + 1, e = d + 1;
            /* Outward winding is a b d / b e d; the pole rows keep only their non-degenerate half. */
            if (j > 0) {
                if (inward)
                    fv_meshbuf_tri(mb, a, d, b, mat);
                else
                    fv_meshbuf_tri(mb, a, b, d, mat);
            }
            if (j < sv - 1) {
                if (inward)
                    fv_meshbuf_tri(mb, b, d, e, mat);
                else
                    fv_meshbuf_tri(mb, b, e, d, mat);
            }
        }
    mb->smooth = true;
}
