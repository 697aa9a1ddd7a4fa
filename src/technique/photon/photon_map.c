/* fovea — photon maps in a hashed, sorted uniform grid (see photon_map.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "technique/photon/photon_map.h"

void fv_photon_map_init(fv_photon_map *m) { memset(m, 0, sizeof *m); }

void fv_photon_map_free(fv_photon_map *m)
{
    free(m->p);
    free(m->start);
    free(m->scratch);
    memset(m, 0, sizeof *m);
}

void fv_photon_map_clear(fv_photon_map *m)
{
    m->n = 0;
    m->nbuckets = 0;
}

fv_status fv_photon_map_append(fv_photon_map *m, const fv_photon *ph, int count, fv_error *err)
{
    if (count <= 0) return FV_OK;
    if (m->n > INT32_MAX - count || fv_grow((void **)&m->p, &m->cap, m->n + count, sizeof *m->p))
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory storing %d photons", m->n + count);
    memcpy(m->p + m->n, ph, (size_t)count * sizeof *ph);
    m->n += count;
    m->nbuckets = 0; /* the grid is stale until the next build */
    return FV_OK;
}

fv_status fv_photon_map_push(fv_photon_map *m, const fv_photon *ph, fv_error *err) { return fv_photon_map_append(m, ph, 1, err); }

static inline int cell_coord(float v, float inv) { return (int)floorf(v * inv); }

static inline uint32_t cell_hash(int x, int y, int z, uint32_t mask)
{
    uint32_t h = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)z * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return h & mask;
}

fv_status fv_photon_map_build(fv_photon_map *m, float cell, fv_error *err)
{
    if (!(cell > 0.0f) || !isfinite(cell)) return fv_error_set(err, FV_ERR_INVALID, "photon grid: cell size %g must be positive", cell);
    m->cell = cell;
    m->inv_cell = 1.0f / cell;
    /* About two buckets per photon keeps chains short; at least 1024. */
    uint32_t nb = 1024;
    while (nb < (uint32_t)m->n * 2u && nb < (1u << 26)) nb <<= 1;
    uint32_t *start = realloc(m->start, ((size_t)nb + 1) * sizeof *start);
    if (!start) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building a photon grid");
    m->start = start;
    if (m->scratch_cap < m->n) {
        fv_photon *s = realloc(m->scratch, (size_t)(m->n ? m->n : 1) * sizeof *s);
        if (!s) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building a photon grid");
        m->scratch = s;
        m->scratch_cap = m->n;
    }
    m->mask = nb - 1;
    m->nbuckets = nb;
    memset(start, 0, ((size_t)nb + 1) * sizeof *start);
    /* Counting sort by bucket: count, prefix sum, scatter. */
    for (int i = 0; i < m->n; i++) {
        const fv_vec3 p = m->p[i].pos;
        start[cell_hash(cell_coord(p.x, m->inv_cell), cell_coord(p.y, m->inv_cell), cell_coord(p.z, m->inv_cell), m->mask) + 1]++;
    }
    for (uint32_t b = 0; b < nb; b++) start[b + 1] += start[b];
    for (int i = 0; i < m->n; i++) {
        const fv_vec3 p = m->p[i].pos;
        uint32_t b = cell_hash(cell_coord(p.x, m->inv_cell), cell_coord(p.y, m->inv_cell), cell_coord(p.z, m->inv_cell), m->mask);
        m->scratch[start[b]++] = m->p[i];
    }
    /* start[b] now holds the end of bucket b: shift back to the starts. */
    for (uint32_t b = nb; b > 0; b--) start[b] = start[b - 1];
    start[0] = 0;
    fv_photon *t = m->p;
    int tc = m->cap;
    m->p = m->scratch;
    m->cap = m->scratch_cap;
    m->scratch = t;
    m->scratch_cap = tc;
    return FV_OK;
}

/* Visits every bucket holding cells that overlap the box [x - r, x + r]^3 once (two cells hashed
 * to one bucket must not count its photons twice), calling visit on each photon within r. */
#define MAX_CELLS 343 /* 7^3: r up to 3 cells */
typedef bool (*bucket_fn)(void *ctx, const fv_photon *ph, uint32_t index, float d2);

static void visit_box(const fv_photon_map *m, fv_vec3 x, float r, bucket_fn fn, void *ctx)
{
    int lo[3], hi[3];
    const float c[3] = {x.x, x.y, x.z};
    for (int a = 0; a < 3; a++) {
        lo[a] = cell_coord(c[a] - r, m->inv_cell);
        hi[a] = cell_coord(c[a] + r, m->inv_cell);
        if (hi[a] - lo[a] > 6) hi[a] = lo[a] + 6; /* callers keep r <= 3 cells */
    }
    uint32_t seen[MAX_CELLS];
    int nseen = 0;
    float r2 = r * r;
    for (int z = lo[2]; z <= hi[2]; z++)
        for (int y = lo[1]; y <= hi[1]; y++)
            for (int xx = lo[0]; xx <= hi[0]; xx++) {
                uint32_t b = cell_hash(xx, y, z, m->mask);
                bool dup = false;
                for (int j = 0; j < nseen && !dup; j++) dup = seen[j] == b;
                if (dup) continue;
                seen[nseen++] = b;
                for (uint32_t i = m->start[b]; i < m->start[b + 1]; i++) {
                    fv_vec3 d = fv_sub(m->p[i].pos, x);
                    float d2 = fv_dot(d, d);
                    if (d2 <= r2 && !fn(ctx, &m->p[i], i, d2)) return;
                }
            }
}

typedef struct query_ctx {
    fv_photon_fn fn;
    void *ctx;
} query_ctx;

static bool query_visit(void *ctx, const fv_photon *ph, uint32_t index, float d2)
{
    (void)index;
    query_ctx *q = ctx;
    q->fn(q->ctx, ph, d2);
    return true;
}

void fv_photon_map_query(const fv_photon_map *m, fv_vec3 x, float r, fv_photon_fn fn, void *ctx)
{
    if (m->nbuckets == 0 || m->n == 0) return;
    query_ctx q = {fn, ctx};
    visit_box(m, x, r, query_visit, &q);
}

typedef struct nearest_ctx {
    fv_vec3 n;
    float best;
    int index;
} nearest_ctx;

static bool nearest_visit(void *ctx, const fv_photon *ph, uint32_t index, float d2)
{
    nearest_ctx *c = ctx;
    if (d2 < c->best && fv_dot(ph->n, c->n) > 0.5f) {
        c->best = d2;
        c->index = (int)index;
    }
    return true;
}

int fv_photon_map_nearest(const fv_photon_map *m, fv_vec3 x, fv_vec3 n, float r, float *d2_out)
{
    if (m->nbuckets == 0 || m->n == 0) return -1;
    /* The nearest photon is usually close: look within a small radius first; a hit there is the
     * nearest overall because every photon within that radius was examined. */
    nearest_ctx c = {n, INFINITY, -1};
    float r0 = fminf(r, 0.25f * m->cell);
    visit_box(m, x, r0, nearest_visit, &c);
    if (c.index < 0 && r > r0) {
        c.best = INFINITY;
        visit_box(m, x, r, nearest_visit, &c);
    }
    if (d2_out) *d2_out = c.best;
    return c.index;
}

float fv_photon_radius_eq8(fv_vec3 lo, fv_vec3 hi, int width, int height)
{
    fv_vec3 e = fv_sub(hi, lo);
    return (e.x + e.y + e.z) / 3.0f / ((width + height) / 2.0f) * 20.0f;
}
