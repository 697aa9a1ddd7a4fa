/* fovea — the voxel grid of Foveated Instant Radiosity: voxelization (Alg. 1), the mip pyramid and
 * cone tracing (Sec. 3.4, Eq. 3), ray casting (Alg. 3). See voxels.h for the representation.
 *
 * Limits: the voxelization is one thread's (the pyramid is the team's); a surface voxelization (no solid fill); the pyramid is rebuilt over the box of
 * cells that changed, which for a fast object crossing the scene is most of the grid.
 */
#include "technique/vpl/voxels.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "fovea/stats.h"
#include "core/ray_box.h"

#define FV_VOX_MAX_LEVELS 12   /* 1024 -> 1 takes 11 halvings */

/* What the writers of one cell added up (one accumulator for static, one for dynamic objects). */
typedef struct fv_vox_acc {
    float n[3];    /* sum of unit normals */
    float a[3];    /* sum of albedos */
    float w;       /* number of writes */
    int obj;       /* last writer */
} fv_vox_acc;

struct fv_voxels {
    const fv_scene *scene;
    fv_vec3 org;
    float h;
    int nlevels;
    int dims[FV_VOX_MAX_LEVELS][3];
    size_t ncells;
    fv_vox_acc *stat, *dyn;
    float *rad0;                          /* 3 per level-0 cell */
    uint32_t *touched;                    /* cells with a dynamic write, each once */
    size_t ntouched;
    int dirty_lo[3], dirty_hi[3];         /* the level-0 box the last update changed (the team's) */
    fv_voxel_mip *mip[FV_VOX_MAX_LEVELS]; /* levels >= 1 (mip[0] unused: level 0 is resolved on read) */
};

static size_t cell_index(const fv_voxels *v, int i, int j, int k)
{
    return (size_t)i + (size_t)v->dims[0][0] * ((size_t)j + (size_t)v->dims[0][1] * (size_t)k);
}

static bool occupied0(const fv_voxels *v, size_t c) { return v->stat[c].w > 0.0f || v->dyn[c].w > 0.0f; }

/* ---- voxelization (Alg. 1) ---- */

static void add_write(fv_voxels *v, fv_vox_acc *acc, bool dynamic, size_t c, fv_vec3 n, fv_vec3 albedo, int obj)
{
    fv_vox_acc *x = &acc[c];
    if (dynamic && x->w == 0.0f) v->touched[v->ntouched++] = (uint32_t)c;
    x->n[0] += n.x, x->n[1] += n.y, x->n[2] += n.z;
    x->a[0] += albedo.x, x->a[1] += albedo.y, x->a[2] += albedo.z;
    x->w += 1.0f;
    x->obj = obj;
}

/* The cells [c0, c1] on each axis that a world box [lo, hi] touches, a cell whose face it merely
 * reaches included (the slack is in cell units, larger than the overlap test's). False: none. */
static bool cell_range(const fv_voxels *v, fv_vec3 lo, fv_vec3 hi, int c0[3], int c1[3])
{
    const float l[3] = {lo.x - v->org.x, lo.y - v->org.y, lo.z - v->org.z};
    const float u[3] = {hi.x - v->org.x, hi.y - v->org.y, hi.z - v->org.z};
    for (int a = 0; a < 3; a++) {
        int n = v->dims[0][a];
        float f0 = fv_clampf(l[a] / v->h - 1e-3f, -1.0f, (float)n);
        float f1 = fv_clampf(u[a] / v->h + 1e-3f, -1.0f, (float)n);
        if (!(f0 <= f1)) return false;
        c0[a] = (int)floorf(f0) < 0 ? 0 : (int)floorf(f0);
        c1[a] = (int)floorf(f1) > n - 1 ? n - 1 : (int)floorf(f1);
        if (c0[a] > c1[a]) return false;
    }
    return true;
}

/* Separating axis test of a triangle against the cube of half edge r around the origin (vertices
 * already relative to the cube's centre): the 3 cube normals, the triangle's normal and the 9
 * cross products of cube axes and triangle edges. Touching counts as overlap. */
static bool tri_overlaps_cube(fv_vec3 p0, fv_vec3 p1, fv_vec3 p2, float r)
{
    if (fv_minf(p0.x, fv_minf(p1.x, p2.x)) > r || fv_maxf(p0.x, fv_maxf(p1.x, p2.x)) < -r) return false;
    if (fv_minf(p0.y, fv_minf(p1.y, p2.y)) > r || fv_maxf(p0.y, fv_maxf(p1.y, p2.y)) < -r) return false;
    if (fv_minf(p0.z, fv_minf(p1.z, p2.z)) > r || fv_maxf(p0.z, fv_maxf(p1.z, p2.z)) < -r) return false;
    const fv_vec3 e[3] = {fv_sub(p1, p0), fv_sub(p2, p1), fv_sub(p0, p2)};
    fv_vec3 axes[10];
    axes[0] = fv_cross(e[0], e[1]);
    const fv_vec3 unit[3] = {fv_v3(1, 0, 0), fv_v3(0, 1, 0), fv_v3(0, 0, 1)};
    for (int k = 0; k < 3; k++)
        for (int m = 0; m < 3; m++) axes[1 + 3 * k + m] = fv_cross(unit[k], e[m]);
    for (int q = 0; q < 10; q++) {
        fv_vec3 ax = axes[q];
        float d0 = fv_dot(ax, p0), d1 = fv_dot(ax, p1), d2 = fv_dot(ax, p2);
        float rad = r * (fabsf(ax.x) + fabsf(ax.y) + fabsf(ax.z));
        if (fv_minf(d0, fv_minf(d1, d2)) > rad || fv_maxf(d0, fv_maxf(d1, d2)) < -rad) return false;
    }
    return true;
}

/* The albedo of material mat on triangle prim of object obj: a textured one's at the triangle's
 * centroid (a cell is coarser than a texel; SDF objects have no texture coordinates). */
static fv_vec3 material_albedo(const fv_scene *s, int mat, int obj, int prim)
{
    fv_material mbuf;
    const fv_material *m = fv_scene_material(s, mat);
    return m ? fv_material_at(s, mat, obj, prim, 1.0f / 3.0f, 1.0f / 3.0f, &mbuf)->albedo : fv_v3s(0.0f);
}

static fv_vec3 unit_or_zero(fv_vec3 n)
{
    float l = fv_length(n);
    return l > 0.0f && isfinite(l) ? fv_scale(n, 1.0f / l) : fv_v3s(0.0f);
}

static void voxelize_mesh(fv_voxels *v, int obj, fv_vox_acc *acc, bool dynamic)
{
    const fv_scene *s = v->scene;
    /* A hair over half an edge, so rounding never loses a cell a face lies on. */
    const float r = 0.5f * v->h * (1.0f + 1e-5f);
    for (int p = 0, nt = fv_scene_object_triangle_count(s, obj); p < nt; p++) {
        fv_vec3 a, b, c;
        fv_scene_triangle(s, obj, p, &a, &b, &c);
        int c0[3], c1[3];
        if (!cell_range(v, fv_vmin(a, fv_vmin(b, c)), fv_vmax(a, fv_vmax(b, c)), c0, c1)) continue;
        fv_vec3 n = unit_or_zero(fv_cross(fv_sub(b, a), fv_sub(c, a)));
        fv_vec3 albedo = material_albedo(s, fv_scene_triangle_material(s, obj, p), obj, p);
        for (int k = c0[2]; k <= c1[2]; k++)
            for (int j = c0[1]; j <= c1[1]; j++)
                for (int i = c0[0]; i <= c1[0]; i++) {
                    fv_vec3 ctr = fv_add(v->org, fv_v3(((float)i + 0.5f) * v->h, ((float)j + 0.5f) * v->h, ((float)k + 0.5f) * v->h));
                    if (tri_overlaps_cube(fv_sub(a, ctr), fv_sub(b, ctr), fv_sub(c, ctr), r))
                        add_write(v, acc, dynamic, cell_index(v, i, j, k), n, albedo, obj);
                }
    }
}

static void voxelize_sdf(fv_voxels *v, int obj, fv_vox_acc *acc, bool dynamic)
{
    const fv_scene *s = v->scene;
    const fv_sdf *sdf = fv_scene_object_sdf(s, obj);
    fv_xform w2l;
    fv_scene_object_world_to_local(s, obj, &w2l);
    /* Local units per world unit: animation scales uniformly, so one column's length is the
     * factor that turns a local distance back into a world one. */
    float k_loc = fv_length(fv_xform_vector(&w2l, fv_v3(1, 0, 0)));
    const float half_diag = 0.5f * v->h * sqrtf(3.0f);
    fv_vec3 lo, hi;
    fv_scene_object_bounds(s, obj, &lo, &hi);
    int c0[3], c1[3];
    if (!cell_range(v, fv_sub(lo, fv_v3s(half_diag)), fv_add(hi, fv_v3s(half_diag)), c0, c1)) return;
    for (int k = c0[2]; k <= c1[2]; k++)
        for (int j = c0[1]; j <= c1[1]; j++)
            for (int i = c0[0]; i <= c1[0]; i++) {
                fv_vec3 ctr = fv_add(v->org, fv_v3(((float)i + 0.5f) * v->h, ((float)j + 0.5f) * v->h, ((float)k + 0.5f) * v->h));
                fv_vec3 p = fv_xform_point(&w2l, ctr);
                int mat = 0;
                float d = fv_sdf_distance(sdf, p, &mat) / k_loc;
                if (!(fabsf(d) <= half_diag)) continue;
                /* The gradient over half a cell: the normal of the surface the cell holds. */
                fv_vec3 n = unit_or_zero(fv_xform_normal(&w2l, fv_sdf_normal(sdf, p, 0.5f * v->h * k_loc)));
                add_write(v, acc, dynamic, cell_index(v, i, j, k), n, material_albedo(s, mat, obj, 0), obj);
            }
}

static void voxelize_object(fv_voxels *v, int obj, fv_vox_acc *acc, bool dynamic)
{
    if (fv_scene_object_kind(v->scene, obj) == FV_OBJECT_SDF) voxelize_sdf(v, obj, acc, dynamic);
    else voxelize_mesh(v, obj, acc, dynamic);
}

/* ---- level 0 as read ---- */

/* A cell's writers combined: the static accumulator alone when no dynamic object wrote there, so
 * the static state reads back bit for bit once the dynamic writes are gone. */
static void resolve(const fv_voxels *v, size_t c, fv_voxel *out)
{
    memset(out, 0, sizeof *out);
    out->object = -1;
    const fv_vox_acc *s = &v->stat[c], *d = &v->dyn[c];
    fv_vox_acc x;
    if (d->w == 0.0f) x = *s;
    else if (s->w == 0.0f) x = *d;
    else {
        for (int q = 0; q < 3; q++) x.n[q] = s->n[q] + d->n[q], x.a[q] = s->a[q] + d->a[q];
        x.w = s->w + d->w;
        x.obj = d->obj;
    }
    if (x.w == 0.0f) return;
    out->occupied = 1;
    out->object = x.obj;
    out->normal = unit_or_zero(fv_v3(x.n[0], x.n[1], x.n[2]));
    out->albedo = fv_scale(fv_v3(x.a[0], x.a[1], x.a[2]), 1.0f / x.w);
}

static fv_vec3 rad0_at(const fv_voxels *v, size_t c) { return fv_v3(v->rad0[3 * c], v->rad0[3 * c + 1], v->rad0[3 * c + 2]); }

static bool in_level(const fv_voxels *v, int l, int i, int j, int k)
{
    return i >= 0 && j >= 0 && k >= 0 && i < v->dims[l][0] && j < v->dims[l][1] && k < v->dims[l][2];
}

static fv_voxel_mip *mip_at(const fv_voxels *v, int l, int i, int j, int k)
{
    return &v->mip[l][(size_t)i + (size_t)v->dims[l][0] * ((size_t)j + (size_t)v->dims[l][1] * (size_t)k)];
}

void fv_voxels_mip_cell(const fv_voxels *v, int level, int i, int j, int k, fv_voxel_mip *out)
{
    memset(out, 0, sizeof *out);
    if (level < 0 || level >= v->nlevels || !in_level(v, level, i, j, k)) return;
    if (level > 0) {
        *out = *mip_at(v, level, i, j, k);
        return;
    }
    size_t c = cell_index(v, i, j, k);
    fv_voxel x;
    resolve(v, c, &x);
    if (!x.occupied) return;
    out->occupancy = 1.0f;
    out->albedo = x.albedo;
    out->normal = x.normal;
    out->radiance = rad0_at(v, c);
}

/* ---- the pyramid ---- */

/* One parent of level l (l >= 1): the mean of its 8 children, those outside the grid counting
 * empty; geometry and radiance, or radiance alone. */
static void build_parent(fv_voxels *v, int l, int i, int j, int k, bool geometry)
{
    fv_voxel_mip sum;
    memset(&sum, 0, sizeof sum);
    for (int q = 0; q < 8; q++) {
        fv_voxel_mip ch;
        fv_voxels_mip_cell(v, l - 1, 2 * i + (q & 1), 2 * j + (q >> 1 & 1), 2 * k + (q >> 2), &ch);
        /* Already premultiplied (level 0: an occupied cell's values times 1). */
        sum.occupancy += ch.occupancy;
        sum.albedo = fv_add(sum.albedo, ch.albedo);
        sum.normal = fv_add(sum.normal, ch.normal);
        sum.radiance = fv_add(sum.radiance, ch.radiance);
    }
    fv_voxel_mip *m = mip_at(v, l, i, j, k);
    m->radiance = fv_scale(sum.radiance, 0.125f);
    if (!geometry) return;
    m->occupancy = sum.occupancy * 0.125f;
    m->albedo = fv_scale(sum.albedo, 0.125f);
    m->normal = fv_scale(sum.normal, 0.125f);
}

/* The parents of one level's box, shared out by rows (j, k). */
typedef struct mip_level_job {
    fv_voxels *v;
    int l, lo[3], hi[3];
    bool geometry;
} mip_level_job;

static void mip_rows(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    const mip_level_job *m = ctx;
    const int64_t ny = m->hi[1] - m->lo[1] + 1;
    for (int64_t r = b; r < e; r++) {
        const int j = m->lo[1] + (int)(r % ny), k = m->lo[2] + (int)(r / ny);
        for (int i = m->lo[0]; i <= m->hi[0]; i++) build_parent(m->v, m->l, i, j, k, m->geometry);
    }
}

/* Rebuilds levels 1.. over the parents of level-0 cells lo..hi (inclusive). A step of the calling
 * team (fv_team_for; a team of one outside a region): every parent of a level is independent of the
 * others, and the loop's barrier finishes a level before the next reads it, so any thread count
 * gives the same bits. */
static void build_mips(fv_voxels *v, const int lo0[3], const int hi0[3], bool geometry)
{
    mip_level_job m = {v, 0, {lo0[0], lo0[1], lo0[2]}, {hi0[0], hi0[1], hi0[2]}, geometry};
    for (int l = 1; l < v->nlevels; l++) {
        bool empty = false;
        for (int a = 0; a < 3; a++) {
            m.lo[a] >>= 1;
            m.hi[a] >>= 1;
            if (m.hi[a] > v->dims[l][a] - 1) m.hi[a] = v->dims[l][a] - 1;
            empty = empty || m.hi[a] < m.lo[a];
        }
        m.l = l;
        const int64_t rows = empty ? 0 : (int64_t)(m.hi[1] - m.lo[1] + 1) * (m.hi[2] - m.lo[2] + 1);
        fv_team_for(rows, 4, mip_rows, &m);
    }
}

static void build_all(fv_voxels *v, bool geometry)
{
    const int lo[3] = {0, 0, 0}, hi[3] = {v->dims[0][0] - 1, v->dims[0][1] - 1, v->dims[0][2] - 1};
    build_mips(v, lo, hi, geometry);
}

void fv_voxels_build_radiance(fv_voxels *v) { build_all(v, false); }

/* ---- create, update, destroy ---- */

static void extend_box(const fv_voxels *v, size_t c, int lo[3], int hi[3])
{
    int ijk[3] = {(int)(c % (size_t)v->dims[0][0]), (int)(c / (size_t)v->dims[0][0] % (size_t)v->dims[0][1]),
                  (int)(c / ((size_t)v->dims[0][0] * (size_t)v->dims[0][1]))};
    for (int a = 0; a < 3; a++) {
        if (ijk[a] < lo[a]) lo[a] = ijk[a];
        if (ijk[a] > hi[a]) hi[a] = ijk[a];
    }
}

void fv_voxels_update_dynamic(fv_voxels *v)
{
    /* The voxelization by one thread (a cell's writes add up in the objects' triangle order, which
     * keeps it bit for bit), its time reported as the region's serial part; the box of changed
     * cells is the team's, published by the barrier. */
#pragma omp master
    {
        const double t0 = fv_time_ms();
        int lo[3] = {INT_MAX, INT_MAX, INT_MAX}, hi[3] = {-1, -1, -1};
        for (size_t q = 0; q < v->ntouched; q++) {
            extend_box(v, v->touched[q], lo, hi);
            memset(&v->dyn[v->touched[q]], 0, sizeof v->dyn[0]);
        }
        v->ntouched = 0;
        for (int o = 0, n = fv_scene_object_count(v->scene); o < n; o++)
            if (fv_scene_object_dynamic(v->scene, o)) voxelize_object(v, o, v->dyn, true);
        for (size_t q = 0; q < v->ntouched; q++) extend_box(v, v->touched[q], lo, hi);
        memcpy(v->dirty_lo, lo, sizeof lo);
        memcpy(v->dirty_hi, hi, sizeof hi);
        fv_region_serial(fv_time_ms() - t0);
    }
#pragma omp barrier
    if (v->dirty_hi[0] >= 0) build_mips(v, v->dirty_lo, v->dirty_hi, true);
}

int fv_voxels_dynamic_cells(const fv_voxels *v) { return (int)v->ntouched; }

fv_status fv_voxels_create(const fv_scene *scene, int resolution, fv_voxels **out, fv_error *err)
{
    *out = NULL;
    if (resolution < 8 || resolution > 1024)
        return fv_error_set(err, FV_ERR_INVALID, "voxels: resolution %d outside [8, 1024]", resolution);
    fv_vec3 lo, hi;
    fv_scene_bounds(scene, &lo, &hi);
    fv_vec3 ext = fv_sub(hi, lo);
    float longest = fv_max3(ext);
    if (!(longest > 0.0f) || !isfinite(longest))
        return fv_error_set(err, FV_ERR_INVALID, "voxels: the scene has no extent to voxelize (not committed?)");

    fv_voxels *v = calloc(1, sizeof *v);
    if (!v) return fv_error_set(err, FV_ERR_NOMEM, "voxels: out of memory");
    v->scene = scene;
    v->org = lo;
    v->h = longest / (float)resolution;
    const float e[3] = {ext.x, ext.y, ext.z};
    for (int a = 0; a < 3; a++) {
        /* The slack keeps the longest axis at exactly `resolution` despite rounding. */
        int n = (int)ceilf(e[a] / v->h - 1e-3f);
        v->dims[0][a] = n < 1 ? 1 : (n > resolution ? resolution : n);
    }
    v->nlevels = 1;
    while (v->nlevels < FV_VOX_MAX_LEVELS) {
        const int *d = v->dims[v->nlevels - 1];
        if (d[0] == 1 && d[1] == 1 && d[2] == 1) break;
        for (int a = 0; a < 3; a++) v->dims[v->nlevels][a] = (d[a] + 1) / 2;
        v->nlevels++;
    }
    v->ncells = (size_t)v->dims[0][0] * (size_t)v->dims[0][1] * (size_t)v->dims[0][2];
    v->stat = fv_calloc_array(v->ncells, sizeof *v->stat);
    v->dyn = fv_calloc_array(v->ncells, sizeof *v->dyn);
    v->rad0 = fv_calloc_array(v->ncells, 3 * sizeof *v->rad0);
    v->touched = fv_alloc_array(v->ncells, sizeof *v->touched);
    bool ok = v->stat && v->dyn && v->rad0 && v->touched;
    for (int l = 1; l < v->nlevels && ok; l++) {
        v->mip[l] = fv_calloc_array((size_t)v->dims[l][0] * (size_t)v->dims[l][1] * (size_t)v->dims[l][2], sizeof *v->mip[l]);
        ok = v->mip[l] != NULL;
    }
    if (!ok) {
        const int d0 = v->dims[0][0], d1 = v->dims[0][1], d2 = v->dims[0][2];
        fv_voxels_destroy(v);
        return fv_error_set(err, FV_ERR_NOMEM, "voxels: out of memory for a %dx%dx%d grid", d0, d1, d2);
    }

    /* Alg. 1 line 1: the static part once; line 4's dynamic part at the current time. */
    for (int o = 0, n = fv_scene_object_count(scene); o < n; o++)
        if (!fv_scene_object_dynamic(scene, o)) voxelize_object(v, o, v->stat, false);
    for (int o = 0, n = fv_scene_object_count(scene); o < n; o++)
        if (fv_scene_object_dynamic(scene, o)) voxelize_object(v, o, v->dyn, true);
    build_all(v, true);
    *out = v;
    return FV_OK;
}

void fv_voxels_destroy(fv_voxels *v)
{
    if (!v) return;
    free(v->stat);
    free(v->dyn);
    free(v->rad0);
    free(v->touched);
    for (int l = 1; l < FV_VOX_MAX_LEVELS; l++) free(v->mip[l]);
    free(v);
}

/* ---- small getters and setters ---- */

void fv_voxels_dims(const fv_voxels *v, int level, int dims[3])
{
    bool ok = level >= 0 && level < v->nlevels;
    for (int a = 0; a < 3; a++) dims[a] = ok ? v->dims[level][a] : 0;
}

int fv_voxels_levels(const fv_voxels *v) { return v->nlevels; }
float fv_voxels_cell_size(const fv_voxels *v) { return v->h; }
fv_vec3 fv_voxels_origin(const fv_voxels *v) { return v->org; }

int fv_voxels_index(const fv_voxels *v, int i, int j, int k) { return in_level(v, 0, i, j, k) ? (int)cell_index(v, i, j, k) : -1; }

fv_vec3 fv_voxels_centre(const fv_voxels *v, int cell)
{
    const size_t c = (size_t)cell, nx = (size_t)v->dims[0][0], ny = (size_t)v->dims[0][1];
    const size_t i = c % nx, j = (c / nx) % ny, k = c / (nx * ny);
    return fv_v3(v->org.x + ((float)i + 0.5f) * v->h, v->org.y + ((float)j + 0.5f) * v->h, v->org.z + ((float)k + 0.5f) * v->h);
}

void fv_voxels_cell(const fv_voxels *v, int cell, fv_voxel *out) { resolve(v, (size_t)cell, out); }

void fv_voxels_set_radiance(fv_voxels *v, int cell, fv_vec3 radiance)
{
    v->rad0[3 * (size_t)cell] = radiance.x;
    v->rad0[3 * (size_t)cell + 1] = radiance.y;
    v->rad0[3 * (size_t)cell + 2] = radiance.z;
}

fv_vec3 fv_voxels_radiance(const fv_voxels *v, int cell) { return rad0_at(v, (size_t)cell); }

/* ---- ray casting through level 0 (Alg. 3) ---- */

bool fv_voxels_cast(const fv_voxels *v, fv_vec3 origin, fv_vec3 dir, float tmax, fv_voxel_hit *hit)
{
    const int *n = v->dims[0];
    fv_vec3 glo = v->org, ghi = fv_add(v->org, fv_v3((float)n[0] * v->h, (float)n[1] * v->h, (float)n[2] * v->h));
    float t0 = 0.0f, t1 = tmax;
    if (!fv_ray_box_clip(origin, dir, glo, ghi, &t0, &t1)) return false;
    const float o[3] = {origin.x - v->org.x, origin.y - v->org.y, origin.z - v->org.z};
    const float d[3] = {dir.x, dir.y, dir.z};
    int c[3], step[3];
    float tnext[3], tdelta[3];
    for (int a = 0; a < 3; a++) {
        /* The cell holding the entry point; rounding at the grid's faces clamps inside. */
        float u = (o[a] + d[a] * t0) / v->h;
        int ci = (int)floorf(fv_clampf(u, 0.0f, (float)n[a]));
        c[a] = ci > n[a] - 1 ? n[a] - 1 : ci;
        if (d[a] > 0.0f) {
            step[a] = 1;
            tnext[a] = ((float)(c[a] + 1) * v->h - o[a]) / d[a];
            tdelta[a] = v->h / d[a];
        } else if (d[a] < 0.0f) {
            step[a] = -1;
            tnext[a] = ((float)c[a] * v->h - o[a]) / d[a];
            tdelta[a] = -v->h / d[a];
        } else {
            step[a] = 0;
            tnext[a] = INFINITY;
            tdelta[a] = INFINITY;
        }
    }
    float t = t0;
    for (;;) {
        size_t idx = cell_index(v, c[0], c[1], c[2]);
        if (occupied0(v, idx)) {
            hit->cell = (int)idx;
            for (int a = 0; a < 3; a++) hit->ijk[a] = c[a];
            hit->t = t;
            resolve(v, idx, &hit->v);
            return true;
        }
        int a = tnext[0] < tnext[1] ? (tnext[0] < tnext[2] ? 0 : 2) : (tnext[1] < tnext[2] ? 1 : 2);
        if (!(tnext[a] <= t1)) return false;
        t = tnext[a];
        c[a] += step[a];
        if (c[a] < 0 || c[a] >= n[a]) return false;
        tnext[a] += tdelta[a];
    }
}

/* ---- cone tracing through the pyramid (Sec. 3.4) ---- */

/* Occupancy and premultiplied radiance of one level at world point p, trilinear between the eight
 * nearest cell centres (cells outside the grid empty). */
static void sample_level(const fv_voxels *v, int l, fv_vec3 p, float *occ, fv_vec3 *rad)
{
    float hl = ldexpf(v->h, l);
    const float u[3] = {(p.x - v->org.x) / hl - 0.5f, (p.y - v->org.y) / hl - 0.5f, (p.z - v->org.z) / hl - 0.5f};
    int b[3];
    float f[3];
    for (int a = 0; a < 3; a++) {
        float fl = floorf(u[a]);
        b[a] = (int)fl;
        f[a] = u[a] - fl;
    }
    *occ = 0.0f;
    *rad = fv_v3s(0.0f);
    for (int q = 0; q < 8; q++) {
        int dx = q & 1, dy = q >> 1 & 1, dz = q >> 2;
        float w = (dx ? f[0] : 1.0f - f[0]) * (dy ? f[1] : 1.0f - f[1]) * (dz ? f[2] : 1.0f - f[2]);
        if (w == 0.0f) continue;
        int i = b[0] + dx, j = b[1] + dy, k = b[2] + dz;
        if (!in_level(v, l, i, j, k)) continue;
        if (l == 0) {
            size_t c = cell_index(v, i, j, k);
            if (!occupied0(v, c)) continue;
            *occ += w;
            *rad = fv_madd(*rad, rad0_at(v, c), w);
        } else {
            const fv_voxel_mip *m = mip_at(v, l, i, j, k);
            *occ += w * m->occupancy;
            *rad = fv_madd(*rad, m->radiance, w);
        }
    }
}

float fv_voxels_cone(const fv_voxels *v, fv_vec3 origin, fv_vec3 dir, float aperture_tan, float tmax, fv_vec3 *radiance)
{
    *radiance = fv_v3s(0.0f);
    float len = fv_length(dir);
    if (!(len > 0.0f)) return 0.0f;
    dir = fv_scale(dir, 1.0f / len);
    const int *n = v->dims[0];
    fv_vec3 ghi = fv_add(v->org, fv_v3((float)n[0] * v->h, (float)n[1] * v->h, (float)n[2] * v->h));
    float t = 0.0f, tend = tmax;
    if (!fv_ray_box_clip(origin, dir, v->org, ghi, &t, &tend)) return 0.0f;
    float alpha = 0.0f;
    fv_vec3 acc = fv_v3s(0.0f);
    const float top = (float)(v->nlevels - 1);
    while (t < tend && alpha < 0.995f) {
        float diam = fv_maxf(v->h, 2.0f * t * aperture_tan);
        /* The level whose cells are as wide as the cone here, blended with the next one. */
        float lvl = fv_clampf(log2f(diam / v->h), 0.0f, top);
        int l0 = (int)lvl;
        float fl = lvl - (float)l0;
        fv_vec3 p = fv_madd(origin, dir, t);
        float occ, occ1 = 0.0f;
        fv_vec3 rad, rad1 = fv_v3s(0.0f);
        sample_level(v, l0, p, &occ, &rad);
        if (fl > 0.0f && l0 + 1 < v->nlevels) sample_level(v, l0 + 1, p, &occ1, &rad1);
        occ = occ * (1.0f - fl) + occ1 * fl;
        rad = fv_lerp3(rad, rad1, fl);
        float step = 0.5f * diam;
        if (occ > 0.0f) {
            /* Surface voxels: a sheet one level-0 cell thick fills 2^-l of a level-l cell's volume
             * but covers all of it across, so the cone sees the occupancy times 2^l (at most 1) as
             * its coverage (without this a thin wall lets most of a wide cone through, and the
             * cone-traced bounce lost more than half its light in the furnace). The coverage is
             * that of one cell crossed; a step of another length sees 1 - (1 - cov)^(step / cell).
             * Radiance keeps its ratio to occupancy. */
            const float cov = fv_minf(1.0f, occ * exp2f(lvl));
            float a = 1.0f - powf(fv_maxf(0.0f, 1.0f - cov), step / (v->h * exp2f(lvl)));
            acc = fv_madd(acc, rad, (1.0f - alpha) * a / occ);
            alpha += (1.0f - alpha) * a;
        }
        t += step;
    }
    *radiance = acc;
    return alpha;
}
