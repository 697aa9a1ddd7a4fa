/* fovea — depth cube maps for VPL visibility (Foveated Instant Radiosity Sec. 3.4; see cubemap.h
 * for the face convention, the hemisphere rule and the bias rule).
 *
 * A face is traced row by row in packets of eight neighbouring texels: the rays share the VPL as
 * origin and fan out by less than a texel each, the coherent case Embree's packet traversal is
 * made for. The last packet of a row idles its lanes past the edge, as does a lane whose texel lies
 * behind the VPL. Each map is traced on one thread in a fixed order, so its depths are the same
 * whatever the thread count.
 */
#include <math.h>
#include <stdlib.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "scene/query.h"
#include "technique/vpl/cube_raster.h"
#include "technique/vpl/cubemap.h"

typedef struct fv_cube_meta {
    fv_vec3 centre; /* where the rays started */
    float eps;      /* the scene's ray offset, the constant of the bias */
} fv_cube_meta;

struct fv_cubemaps {
    int count, n;
    fv_cube_build how;
    size_t texels;      /* per map: 6 n^2 */
    float *depth;       /* count x texels */
    fv_cube_meta *meta; /* count */
    fv_tri_soup *soup;  /* rasterised builds: the frame's triangles, kept and refreshed (soup_for) */
};

fv_status fv_cubemaps_create(int count, int face_size, fv_cubemaps **out, fv_error *err)
{
    if (!out) return fv_error_set(err, FV_ERR_INVALID, "cube maps: no output handle");
    *out = NULL;
    if (count < 1) return fv_error_set(err, FV_ERR_INVALID, "vpls %d: need at least 1 cube map", count);
    if (face_size < FV_CUBE_MIN_SIZE || face_size > FV_CUBE_MAX_SIZE)
        return fv_error_set(err, FV_ERR_INVALID, "cube_size %d: must be in [%d, %d]", face_size, FV_CUBE_MIN_SIZE,
                            FV_CUBE_MAX_SIZE);
    fv_cubemaps *m = calloc(1, sizeof *m);
    if (!m) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for %d cube maps", count);
    m->count = count;
    m->n = face_size;
    m->texels = (size_t)6 * (size_t)face_size * (size_t)face_size;
    m->meta = fv_calloc_array((size_t)count, sizeof *m->meta);
    m->depth = m->texels <= SIZE_MAX / (size_t)count ? fv_alloc_array(m->texels * (size_t)count, sizeof(float)) : NULL;
    if (!m->meta || !m->depth) {
        fv_cubemaps_destroy(m);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for %d cube maps of %d^2 (vpls x cube_size)", count,
                            face_size);
    }
    /* An unbuilt map reads as all visible: no occluder has been seen yet. */
    for (size_t k = 0, all = m->texels * (size_t)count; k < all; k++) m->depth[k] = INFINITY;
    *out = m;
    return FV_OK;
}

fv_status fv_vpl_cubemaps_create(int count, int face_size, fv_cubemaps **out, fv_error *err)
{
    fv_status s = fv_cubemaps_create(count, face_size, out, err);
    if (s != FV_ERR_NOMEM) return s;
    const double gb = 6.0 * face_size * (double)face_size * sizeof(float) * count / 1e9;
    return fv_error_set(err, FV_ERR_INVALID, "parameters vpls=%d, cube_size=%d: the cube maps need %.1f GB, more than can be allocated (lower either)",
                        count, face_size, gb);
}

void fv_cubemaps_destroy(fv_cubemaps *m)
{
    if (!m) return;
    free(m->depth);
    free(m->meta);
    fv_tri_soup_destroy(m->soup);
    free(m);
}

int fv_cubemaps_count(const fv_cubemaps *m) { return m->count; }
int fv_cubemaps_face_size(const fv_cubemaps *m) { return m->n; }
fv_vec3 fv_cubemaps_centre(const fv_cubemaps *m, int i) { return m->meta[i].centre; }
const float *fv_cubemaps_depths(const fv_cubemaps *m, int i) { return m->depth + (size_t)i * m->texels; }

const char *const fv_cube_build_names[] = {"auto", "raster", "rays", NULL};
const char *const fv_cube_filter_names[] = {"nearest", "pcf", NULL};

void fv_cubemaps_set_build(fv_cubemaps *m, fv_cube_build how) { m->how = how; }

bool fv_cube_build_rasterises(fv_cube_build how, const fv_scene *s)
{
    if (how != FV_CUBE_BUILD_AUTO) return how == FV_CUBE_BUILD_RASTER && fv_scene_sdf_object_count(s) == 0;
    return fv_scene_sdf_object_count(s) == 0 && fv_scene_triangle_count(s) <= FV_CUBE_RASTER_MAX_TRIANGLES;
}

/* Texel (x, y) of face f faces the VPL's lit side: its centre direction (not unit, the sign is
 * what matters) has a positive cosine with the normal. Rays and rasteriser share this rule. The
 * direction is fv_cube_dir's, component by component (its other terms add exact zeros), so the
 * dot product is computed in fv_dot's order without building vectors. */
static inline bool texel_in_front(fv_vec3 nrm, int f, int x, int y, float inv)
{
    const int a = f >> 1;
    const float s = (f & 1) ? -1.0f : 1.0f;
    float d[3];
    d[a] = s;
    d[(a + 1) % 3] = s * (2.0f * (((float)x + 0.5f) * inv) - 1.0f);
    d[(a + 2) % 3] = 2.0f * (((float)y + 0.5f) * inv) - 1.0f;
    return nrm.x * d[0] + nrm.y * d[1] + nrm.z * d[2] > 0.0f;
}

/* Traces one face of one map from o; with a normal, texels not in front of it store 0. */
static void trace_face(const fv_scene *s, int n, int f, fv_vec3 o, const fv_vec3 *nrm, float *out)
{
    const float inv = 1.0f / (float)n;
    fv_vec3 dirs[8];
    bool active[8], ok[8];
    fv_hit hits[8];
    for (int y = 0; y < n; y++) {
        const float v = ((float)y + 0.5f) * inv;
        for (int x0 = 0; x0 < n; x0 += 8) {
            for (int k = 0; k < 8; k++) {
                const int x = x0 + k;
                dirs[k] = fv_normalize(fv_cube_dir(f, ((float)(x < n ? x : n - 1) + 0.5f) * inv, v));
                active[k] = x < n && (!nrm || texel_in_front(*nrm, f, x, y, inv));
            }
            fv_scene_intersect8_active(s, o, dirs, active, hits, ok);
            /* Unit directions: a hit's t is its distance from o. */
            for (int k = 0; k < 8 && x0 + k < n; k++)
                out[(size_t)y * n + x0 + k] = !active[k] ? 0.0f : (ok[k] ? hits[k].t : INFINITY);
        }
    }
}

/* A face with no direction in front of the normal: every direction of the face is
 * A + s U + t V with |s|, |t| <= 1, so the largest cosine with n is at a corner. */
static bool face_behind(int f, fv_vec3 nrm)
{
    fv_vec3 A, U, V;
    fv_cube_face_axes(f, &A, &U, &V);
    return fv_dot(nrm, A) + fabsf(fv_dot(nrm, U)) + fabsf(fv_dot(nrm, V)) <= 0.0f;
}

/* Row y of face f: texels behind the normal store 0 (texel_in_front's rule, texel by texel). Along
 * a row the cosine is linear in x, so only the texels within two of its zero crossing are
 * evaluated; the rest take the sign of the line, which is far from zero there. */
static void clear_behind(fv_vec3 nrm, int f, int y, int n, float inv, float *row)
{
    const int a = f >> 1;
    const float s = (f & 1) ? -1.0f : 1.0f;
    const float c = fv_cube_comp(nrm, a) * s + fv_cube_comp(nrm, (a + 2) % 3) * (2.0f * (((float)y + 0.5f) * inv) - 1.0f);
    const float g = fv_cube_comp(nrm, (a + 1) % 3) * s; /* cosine = c + g sx */
    if (!(fabsf(g) > 1e-6f * (fabsf(c) + 1e-30f))) {
        for (int x = 0; x < n; x++)
            if (!texel_in_front(nrm, f, x, y, inv)) row[x] = 0.0f;
        return;
    }
    /* sx = 2 (x + 0.5) / n - 1 = -c / g at the crossing */
    const float xc = (-c / g + 1.0f) * 0.5f * (float)n - 0.5f;
    const int lo = xc < -4.0f ? -4 : xc > (float)n + 4.0f ? n + 4 : (int)floorf(xc) - 2;
    const int hi = lo + 5;
    for (int x = 0; x < n; x++) {
        bool front;
        if (x >= lo && x <= hi) front = texel_in_front(nrm, f, x, y, inv);
        else front = (g > 0.0f) == (x > hi); /* right of the crossing: the sign of g */
        if (!front) row[x] = 0.0f;
    }
}

/* Map i by rasterising soup: the faces in front of the normal start at +inf, take the nearest
 * triangle of each texel, and texels behind the normal store 0 as trace_face's do. */
static void raster_one(fv_cubemaps *m, const fv_tri_soup *soup, int i, fv_vec3 o, const fv_vec3 *nrm)
{
    const int n = m->n;
    const size_t face = (size_t)n * (size_t)n;
    float *d = m->depth + (size_t)i * m->texels;
    unsigned mask = 0;
    for (int f = 0; f < 6; f++) {
        const bool behind = nrm && face_behind(f, *nrm);
        for (size_t k = 0; k < face; k++) d[f * face + k] = behind ? 0.0f : INFINITY;
        if (!behind) mask |= 1u << f;
    }
    fv_cube_raster(soup, o, n, mask, d);
    if (!nrm) return;
    const float inv = 1.0f / (float)n;
    for (int f = 0; f < 6; f++)
        if (mask & (1u << f))
            for (int y = 0; y < n; y++) clear_behind(*nrm, f, y, n, inv, d + f * face + (size_t)y * n);
}

/* soup NULL: by rays. */
static void build_one(fv_cubemaps *m, const fv_scene *s, const fv_tri_soup *soup, int i, fv_vec3 p, const fv_vec3 *nrm)
{
    /* Off the VPL's own surface, on its lit side, so the rays do not find the surface they leave. */
    const fv_vec3 o = nrm ? fv_offset_point(s, p, *nrm, *nrm) : p;
    m->meta[i].centre = o;
    m->meta[i].eps = fv_scene_ray_eps(s);
    if (soup) {
        raster_one(m, soup, i, o, nrm);
        return;
    }
    const size_t face = (size_t)m->n * (size_t)m->n;
    float *d = m->depth + (size_t)i * m->texels;
    for (int f = 0; f < 6; f++) {
        if (nrm && face_behind(f, *nrm)) {
            for (size_t k = 0; k < face; k++) d[f * face + k] = 0.0f;
            continue;
        }
        trace_face(s, m->n, f, o, nrm, d + f * face);
    }
}

/* The triangles to rasterise when this pool rasterises in scene s, else NULL (*soup): the pool's
 * own soup, refreshed to the scene's current time (its room grown, never shrunk). */
static fv_status soup_for(fv_cubemaps *m, const fv_scene *s, fv_tri_soup **soup, fv_error *err)
{
    *soup = NULL;
    if (!fv_cube_build_rasterises(m->how, s)) return FV_OK;
    fv_status st = fv_tri_soup_update(&m->soup, s, err);
    if (st == FV_OK) *soup = m->soup;
    return st;
}

fv_status fv_cubemaps_build(fv_cubemaps *m, const fv_scene *s, int i, fv_vec3 p, const fv_vec3 *n, fv_error *err)
{
    if (i < 0 || i >= m->count)
        return fv_error_set(err, FV_ERR_INVALID, "cube map %d: not in [0, %d) (vpls)", i, m->count);
    if (!fv_is_finite3(p) || (n && !fv_is_finite3(*n)))
        return fv_error_set(err, FV_ERR_INVALID, "cube map %d: VPL position or normal is not finite", i);
    fv_tri_soup *soup;
    fv_status st = soup_for(m, s, &soup, err);
    if (st != FV_OK) return st;
    build_one(m, s, soup, i, p, n);
    return FV_OK;
}

typedef struct build_job {
    fv_cubemaps *m;
    const fv_scene *s;
    const fv_tri_soup *soup;
    const int *idx;
    const fv_vec3 *pos, *nrm;
} build_job;

static void build_range(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    const build_job *j = ctx;
    for (int64_t k = b; k < e; k++) build_one(j->m, j->s, j->soup, j->idx[k], j->pos[k], j->nrm ? &j->nrm[k] : NULL);
}

fv_status fv_cubemaps_check(const fv_cubemaps *m, const int *indices, const fv_vec3 *positions, const fv_vec3 *normals,
                            int count, fv_error *err)
{
    for (int k = 0; k < count; k++) {
        if (indices[k] < 0 || indices[k] >= m->count)
            return fv_error_set(err, FV_ERR_INVALID, "cube map %d: not in [0, %d) (vpls)", indices[k], m->count);
        if (!fv_is_finite3(positions[k]) || (normals && !fv_is_finite3(normals[k])))
            return fv_error_set(err, FV_ERR_INVALID, "cube map %d: VPL position or normal is not finite", indices[k]);
    }
    return FV_OK;
}

fv_status fv_cubemaps_prepare(fv_cubemaps *m, const fv_scene *s, fv_tri_soup **soup, fv_error *err)
{
    return soup_for(m, s, soup, err);
}

void fv_cubemaps_build_team(fv_cubemaps *m, const fv_scene *s, const fv_tri_soup *soup, const int *indices,
                            const fv_vec3 *positions, const fv_vec3 *normals, int count)
{
    build_job j = {m, s, soup, indices, positions, normals};
    /* One map per chunk: a map is the unit of work and is written by one thread only. */
    fv_team_for(count, 1, build_range, &j);
}

fv_status fv_cubemaps_build_many(fv_cubemaps *m, const fv_scene *s, const int *indices, const fv_vec3 *positions,
                                 const fv_vec3 *normals, int count, int threads, fv_error *err)
{
    fv_status st = fv_cubemaps_check(m, indices, positions, normals, count, err);
    if (st != FV_OK || count == 0) return st;
    fv_tri_soup *soup;
    if ((st = soup_for(m, s, &soup, err)) != FV_OK) return st;
    build_job j = {m, s, soup, indices, positions, normals};
    fv_parallel_for(count, 1, threads, build_range, &j);
    return FV_OK;
}

/* ---- lookup ---- */

/* The depth of texel (x, y) of face f, where x or y may be one step past the face's edge: the
 * texel centre's direction is mapped again, landing on the neighbouring face. */
static float tap(const fv_cubemaps *m, const float *d, int f, int x, int y)
{
    const int n = m->n;
    if (x < 0 || y < 0 || x >= n || y >= n) {
        float u, v;
        f = fv_cube_face_of(fv_cube_dir(f, ((float)x + 0.5f) / (float)n, ((float)y + 0.5f) / (float)n), &u, &v);
        x = (int)(u * (float)n);
        y = (int)(v * (float)n);
        x = x < n ? x : n - 1;
        y = y < n ? y : n - 1;
    }
    return d[((size_t)f * n + y) * n + x];
}

float fv_cubemaps_visibility(const fv_cubemaps *m, int i, fv_vec3 q, fv_cube_filter filter)
{
    const fv_cube_meta *mt = &m->meta[i];
    const fv_vec3 dq = fv_sub(q, mt->centre);
    const float r = fv_length(dq);
    if (!isfinite(r)) return 0.0f;
    if (!(r > 2.0f * mt->eps)) return 1.0f;
    const float *d = fv_cubemaps_depths(m, i);
    const int n = m->n;
    float u, v;
    const int f = fv_cube_face_of(dq, &u, &v);
    const float width = 2.0f * r / (float)n; /* bounds one texel's width at distance r */
    if (filter == FV_CUBE_NEAREST) {
        int x = (int)(u * (float)n), y = (int)(v * (float)n);
        x = x < n ? x : n - 1;
        y = y < n ? y : n - 1;
        return r <= d[((size_t)f * n + y) * n + x] + FV_CUBE_BIAS_TEXELS * width + mt->eps ? 1.0f : 0.0f;
    }
    /* 2x2: the four texel centres around q, weighted bilinearly; each tap is up to 1.41 texels from
     * q instead of 0.71, hence twice the bias. */
    const float bias = 2.0f * FV_CUBE_BIAS_TEXELS * width + mt->eps;
    const float fx = u * (float)n - 0.5f, fy = v * (float)n - 0.5f;
    const int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
    const float wx = fx - (float)x0, wy = fy - (float)y0;
    float vis = 0.0f;
    for (int k = 0; k < 4; k++) {
        const int dx = k & 1, dy = k >> 1;
        const float w = (dx ? wx : 1.0f - wx) * (dy ? wy : 1.0f - wy);
        if (w > 0.0f && r <= tap(m, d, f, x0 + dx, y0 + dy) + bias) vis += w;
    }
    return fv_clampf(vis, 0.0f, 1.0f);
}

bool fv_cubemaps_visible(const fv_cubemaps *m, int i, fv_vec3 q)
{
    return fv_cubemaps_visibility(m, i, q, FV_CUBE_NEAREST) > 0.5f;
}
