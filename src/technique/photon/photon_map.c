/* fovea — photon maps in a dense, sorted uniform grid (see photon_map.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <omp.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include "core/alloc.h"
#include "core/parallel.h"
#include "core/params_read.h"
#include "fovea/limits.h"
#include "technique/photon/photon_map.h"

void fv_photon_map_init(fv_photon_map *m) { memset(m, 0, sizeof *m); }

void fv_photon_map_free(fv_photon_map *m)
{
    free(m->p);
    free(m->start);
    free(m->scratch);
    free(m->px);
    free(m->key);
    free(m->count);
    memset(m, 0, sizeof *m);
}

void fv_photon_map_clear(fv_photon_map *m)
{
    m->n = 0;
    m->ncells = 0;
}

fv_status fv_photon_map_append(fv_photon_map *m, const fv_photon *ph, int count, fv_error *err)
{
    if (count <= 0) return FV_OK;
    if (m->n > INT32_MAX - count || fv_grow((void **)&m->p, &m->cap, m->n + count, sizeof *m->p))
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory storing %d photons", m->n + count);
    memcpy(m->p + m->n, ph, (size_t)count * sizeof *ph);
    m->n += count;
    m->ncells = 0; /* the grid is stale until the next build */
    return FV_OK;
}

fv_status fv_photon_map_push(fv_photon_map *m, const fv_photon *ph, fv_error *err) { return fv_photon_map_append(m, ph, 1, err); }

/* The cell of coordinate v; clamped so that no position, however far (or NaN), overflows an int. */
static inline int cell_coord(float v, float inv)
{
    float c = floorf(v * inv);
    if (!(c >= -1073741824.0f)) c = -1073741824.0f; /* NaN too */
    if (c > 1073741824.0f) c = 1073741824.0f;
    return (int)c;
}

/* Where the cells c of one axis are stored: c - org, modulo dim on a wrapped axis. */
static inline long long axis_slot(const fv_photon_map *m, int a, long long c)
{
    long long r = c - m->org[a];
    if (m->wrap[a]) {
        r %= m->dim[a];
        if (r < 0) r += m->dim[a];
    }
    return r;
}

static inline uint32_t photon_cell(const fv_photon_map *m, fv_vec3 p)
{
    long long x = axis_slot(m, 0, cell_coord(p.x, m->inv_cell)), y = axis_slot(m, 1, cell_coord(p.y, m->inv_cell)),
              z = axis_slot(m, 2, cell_coord(p.z, m->inv_cell));
    return (uint32_t)((z * m->dim[1] + y) * m->dim[0] + x);
}

/* Room for the sorted copy, the SoA positions (padded: a block may read past the last photon)
 * and the bucket of each photon. */
static fv_status reserve(fv_photon_map *m, fv_error *err)
{
    int n = m->n ? m->n : 1;
    if (m->scratch_cap < n) {
        fv_photon *s = realloc(m->scratch, (size_t)n * sizeof *s);
        if (!s) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building a photon grid");
        m->scratch = s;
        m->scratch_cap = n;
    }
    if (m->key_cap < n) {
        uint32_t *k = realloc(m->key, (size_t)n * sizeof *k);
        if (!k) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building a photon grid");
        m->key = k;
        m->key_cap = n;
    }
    if (m->soa_cap < n) {
        float *a = realloc(m->px, 6 * ((size_t)n + FV_PHOTON_BLOCK) * sizeof *a);
        if (!a) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building a photon grid");
        m->px = a;
        m->soa_cap = n;
    }
    size_t stride = (size_t)m->soa_cap + FV_PHOTON_BLOCK;
    float **arr[6] = {&m->px, &m->py, &m->pz, &m->nx, &m->ny, &m->nz};
    for (int k = 1; k < 6; k++) *arr[k] = m->px + (size_t)k * stride;
    return FV_OK;
}

/* The grid's extent: the cells the photons occupy; axes wrap while there are more than `limit`
 * cells (the memory of the old hashed grid, about two buckets per photon). */
static void grid_extent(fv_photon_map *m, int nt)
{
    int lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    const int n = m->n;
    fv_region_begin();
    #pragma omp parallel num_threads(nt)
    {
        int l[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, h[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
        #pragma omp for schedule(static) nowait
        for (int i = 0; i < n; i++) {
            const int c[3] = {cell_coord(m->p[i].pos.x, m->inv_cell), cell_coord(m->p[i].pos.y, m->inv_cell),
                              cell_coord(m->p[i].pos.z, m->inv_cell)};
            for (int a = 0; a < 3; a++) {
                if (c[a] < l[a]) l[a] = c[a];
                if (c[a] > h[a]) h[a] = c[a];
            }
        }
        #pragma omp critical
        for (int a = 0; a < 3; a++) {
            if (l[a] < lo[a]) lo[a] = l[a];
            if (h[a] > hi[a]) hi[a] = h[a];
        }
    }
    fv_region_end();
    long long d[3];
    for (int a = 0; a < 3; a++) {
        if (n == 0) lo[a] = hi[a] = 0;
        m->org[a] = lo[a];
        d[a] = (long long)hi[a] - lo[a] + 1;
        m->wrap[a] = false;
    }
    const long long limit = n < 512 ? 1024 : n < (1 << 25) ? 2LL * n : 1LL << 26;
    while (d[0] * d[1] * d[2] > limit) {
        int a = d[0] >= d[1] && d[0] >= d[2] ? 0 : d[1] >= d[2] ? 1 : 2;
        if (d[a] <= 7) break;
        d[a] = d[a] / 2 > 7 ? d[a] / 2 : 7;
        m->wrap[a] = true;
    }
    for (int a = 0; a < 3; a++) m->dim[a] = (int)d[a];
}

fv_status fv_photon_map_build_mt(fv_photon_map *m, float cell, int threads, fv_error *err)
{
    if (!(cell > 0.0f) || !isfinite(cell)) return fv_error_set(err, FV_ERR_INVALID, "photon grid: cell size %g must be positive", cell);
    m->cell = cell;
    m->inv_cell = 1.0f / cell;
    m->ncells = 0;
    int nt = fv_thread_count(threads);
    if (nt > 1 && m->n < 65536) nt = 1; /* not worth waking threads */
    grid_extent(m, nt);
    const uint32_t nc = (uint32_t)m->dim[0] * (uint32_t)m->dim[1] * (uint32_t)m->dim[2];
    /* grown, never shrunk: a build of a grid no larger than before allocates nothing */
    if ((size_t)nc + 1 > m->start_cap) {
        uint32_t *start = realloc(m->start, ((size_t)nc + 1) * sizeof *start);
        if (!start) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building a photon grid");
        m->start = start;
        m->start_cap = (size_t)nc + 1;
    }
    fv_status rc = reserve(m, err);
    if (rc != FV_OK) return rc;
    /* A stable counting sort by cell, in parallel: each thread counts the cells of its own
     * contiguous share of the photons, every (cell, thread) pair gets its offset in cell-major,
     * thread-minor order, and each thread scatters its share in order. So the photons of a cell
     * stay in the order they were stored, whatever the thread count. */
    /* The counts live in the map, grown, never shrunk: after the first frames a build allocates
     * nothing (a fresh calloc of cells x threads was tens of MB a frame at 16 threads), and the
     * threads zero their own rows. */
    const size_t need = (size_t)nc * (size_t)nt;
    if (need > m->count_cap) {
        uint32_t *c = fv_alloc_array(need, sizeof *c);
        if (!c) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building a photon grid");
        free(m->count);
        m->count = c;
        m->count_cap = need;
    }
    uint32_t *count = m->count, *start = m->start;
    const int n = m->n;
    /* per thread: the running offset where its block of cells starts (the scan's second level) */
    uint32_t block_sum[FV_MAX_THREADS + 1];
    fv_region_begin();
    #pragma omp parallel num_threads(nt)
    {
        const int t = omp_get_thread_num(), T = omp_get_num_threads();
        const int i0 = (int)((int64_t)n * t / T), i1 = (int)((int64_t)n * (t + 1) / T);
        uint32_t *cnt = count + (size_t)t * nc;
        memset(cnt, 0, (size_t)nc * sizeof *cnt);
        for (int i = i0; i < i1; i++) cnt[m->key[i] = photon_cell(m, m->p[i].pos)]++;
        #pragma omp barrier
        /* The exclusive scan over (cell, thread) in cell-major, thread-minor order, in parallel:
         * each thread sums its own block of cells, one thread scans the T block sums, and each
         * thread then writes its block's offsets from its block's start. Integer sums: the same
         * offsets as one serial scan (which was O(cells x threads) on one thread). */
        const uint32_t b0 = (uint32_t)((uint64_t)nc * t / T), b1 = (uint32_t)((uint64_t)nc * (t + 1) / T);
        uint32_t local = 0;
        for (uint32_t b = b0; b < b1; b++)
            for (int k = 0; k < T; k++) local += count[(size_t)k * nc + b];
        block_sum[t + 1] = local;
        #pragma omp barrier
        #pragma omp single
        {
            block_sum[0] = 0;
            for (int k = 1; k <= T; k++) block_sum[k] += block_sum[k - 1];
            start[nc] = block_sum[T];
        }
        uint32_t sum = block_sum[t];
        for (uint32_t b = b0; b < b1; b++) {
            start[b] = sum;
            for (int k = 0; k < T; k++) {
                uint32_t c = count[(size_t)k * nc + b];
                count[(size_t)k * nc + b] = sum;
                sum += c;
            }
        }
        #pragma omp barrier
        for (int i = i0; i < i1; i++) m->scratch[cnt[m->key[i]]++] = m->p[i];
        #pragma omp barrier
        /* The SoA copies from the sorted records: sequential reads and writes (scattering seven
         * arrays at once would miss the cache seven times per photon). */
        #pragma omp for schedule(static)
        for (int d = 0; d < n; d++) {
            const fv_photon *ph = &m->scratch[d];
            m->px[d] = ph->pos.x;
            m->py[d] = ph->pos.y;
            m->pz[d] = ph->pos.z;
            m->nx[d] = ph->n.x;
            m->ny[d] = ph->n.y;
            m->nz[d] = ph->n.z;
        }
    }
    fv_region_end();
    /* Padding far away: a block reading past the last photon never accepts it. */
    for (int k = 0; k < FV_PHOTON_BLOCK; k++) {
        m->px[n + k] = m->py[n + k] = m->pz[n + k] = INFINITY;
        m->nx[n + k] = m->ny[n + k] = m->nz[n + k] = 0.0f;
    }
    fv_photon *tp = m->p;
    int tc = m->cap;
    m->p = m->scratch;
    m->cap = m->scratch_cap;
    m->scratch = tp;
    m->scratch_cap = tc;
    m->ncells = nc;
    return FV_OK;
}

fv_status fv_photon_map_build(fv_photon_map *m, float cell, fv_error *err) { return fv_photon_map_build_mt(m, cell, 0, err); }

/* The slots of the cells lo..hi of axis a that the grid holds, in order; their count. */
static int axis_slots(const fv_photon_map *m, int a, int lo, int hi, int *out)
{
    int k = 0;
    for (long long c = lo; c <= hi; c++) {
        long long r = axis_slot(m, a, c);
        if (r >= 0 && r < m->dim[a]) out[k++] = (int)r;
    }
    return k;
}

/* The ranges of p to test: the cells overlapping the box [x - r, x + r]^3, z then y then x, a row
 * of consecutive slots along x being one contiguous range of p. */
void fv_photon_query_begin(fv_photon_query *q, const fv_photon_map *m, fv_vec3 x, float r)
{
    q->m = m;
    q->x = x;
    q->r2 = r * r;
    q->facing = false;
    q->nranges = 0;
    q->range = 0;
    q->i = 0;
    if (m->ncells == 0 || m->n == 0) return;
    int lo[3], hi[3];
    const float c[3] = {x.x, x.y, x.z};
    for (int a = 0; a < 3; a++) {
        lo[a] = cell_coord(c[a] - r, m->inv_cell);
        hi[a] = cell_coord(c[a] + r, m->inv_cell);
        if (hi[a] - lo[a] > 6) hi[a] = lo[a] + 6; /* callers keep r <= 3 cells */
    }
    int sx[7], sy[7], sz[7];
    const int nx = axis_slots(m, 0, lo[0], hi[0], sx), ny = axis_slots(m, 1, lo[1], hi[1], sy), nz = axis_slots(m, 2, lo[2], hi[2], sz);
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++) {
            const uint32_t row = ((uint32_t)sz[k] * (uint32_t)m->dim[1] + (uint32_t)sy[j]) * (uint32_t)m->dim[0];
            for (int i = 0; i < nx;) {
                int e = i + 1;
                while (e < nx && sx[e] == sx[e - 1] + 1) e++; /* a run of consecutive slots */
                const uint32_t b = m->start[row + (uint32_t)sx[i]], f = m->start[row + (uint32_t)sx[e - 1] + 1];
                if (b < f) {
                    q->lo[q->nranges] = b;
                    q->hi[q->nranges++] = f;
                }
                i = e;
            }
        }
    if (q->nranges > 0) q->i = q->lo[0];
}

void fv_photon_query_facing(fv_photon_query *q, fv_vec3 n)
{
    q->facing = true;
    q->n = n;
}

/* Bit k set when photon i + k passes the query: d2 <= r2, and with q->facing !(n . N <= 0.5), the
 * comparisons of the scalar gather, NaN included. The arithmetic is
 * the scalar one too, (a x b x + a y b y) + a z b z, so the same photons pass whichever branch
 * compiles; SSE2 (every x86-64) tests four at a time. */
static inline unsigned block_mask(const fv_photon_map *m, const fv_photon_query *q, uint32_t i)
{
    const float x = q->x.x, y = q->x.y, z = q->x.z, r2 = q->r2;
    const float *X = m->px + i, *Y = m->py + i, *Z = m->pz + i;
#if defined(__SSE2__)
    const __m128 vx = _mm_set1_ps(x), vy = _mm_set1_ps(y), vz = _mm_set1_ps(z), vr = _mm_set1_ps(r2);
    unsigned mask = 0;
    for (int k = 0; k < FV_PHOTON_BLOCK; k += 4) {
        __m128 dx = _mm_sub_ps(_mm_loadu_ps(X + k), vx), dy = _mm_sub_ps(_mm_loadu_ps(Y + k), vy), dz = _mm_sub_ps(_mm_loadu_ps(Z + k), vz);
        __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        mask |= (unsigned)_mm_movemask_ps(_mm_cmple_ps(d2, vr)) << k;
    }
    if (q->facing && mask) {
        const __m128 Nx = _mm_set1_ps(q->n.x), Ny = _mm_set1_ps(q->n.y), Nz = _mm_set1_ps(q->n.z);
        const __m128 half = _mm_set1_ps(0.5f);
        unsigned face = 0;
        for (int k = 0; k < FV_PHOTON_BLOCK; k += 4) {
            __m128 nd = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(m->nx + i + k), Nx), _mm_mul_ps(_mm_loadu_ps(m->ny + i + k), Ny)),
                                   _mm_mul_ps(_mm_loadu_ps(m->nz + i + k), Nz));
            face |= (unsigned)_mm_movemask_ps(_mm_cmpnle_ps(nd, half)) << k;
        }
        mask &= face;
    }
    return mask;
#else
    unsigned mask = 0;
    for (int k = 0; k < FV_PHOTON_BLOCK; k++) {
        float dx = X[k] - x, dy = Y[k] - y, dz = Z[k] - z;
        bool pass = dx * dx + dy * dy + dz * dz <= r2;
        if (q->facing)
            pass = pass && !(m->nx[i + k] * q->n.x + m->ny[i + k] * q->n.y + m->nz[i + k] * q->n.z <= 0.5f);
        mask |= (unsigned)pass << k;
    }
    return mask;
#endif
}

int fv_photon_query_next(fv_photon_query *q, uint32_t *restrict idx, int cap)
{
    const fv_photon_map *m = q->m;
    int n = 0, range = q->range;
    uint32_t i = q->i;
    while (range < q->nranges) {
        const uint32_t end = q->hi[range];
        while (i < end) {
            if (n + FV_PHOTON_BLOCK > cap) goto full;
            const uint32_t len = end - i < FV_PHOTON_BLOCK ? end - i : FV_PHOTON_BLOCK;
            unsigned pass = block_mask(m, q, i) & ((1u << len) - 1u);
            while (pass) { /* the passing photons, in order */
                idx[n++] = i + (uint32_t)__builtin_ctz(pass);
                pass &= pass - 1u;
            }
            i += len;
        }
        if (++range < q->nranges) i = q->lo[range];
    }
full:
    q->range = range;
    q->i = i;
    return n;
}

static inline float photon_d2(const fv_photon_map *m, uint32_t i, fv_vec3 x)
{
    float dx = m->px[i] - x.x, dy = m->py[i] - x.y, dz = m->pz[i] - x.z;
    return dx * dx + dy * dy + dz * dz;
}

void fv_photon_map_query(const fv_photon_map *m, fv_vec3 x, float r, fv_photon_fn fn, void *ctx)
{
    fv_photon_query q;
    uint32_t idx[64];
    int k;
    fv_photon_query_begin(&q, m, x, r);
    while ((k = fv_photon_query_next(&q, idx, 64)) > 0)
        for (int j = 0; j < k; j++) fn(ctx, &m->p[idx[j]], photon_d2(m, idx[j], x));
}

/* The nearest photon in query order (ties: the first met). */
static int nearest_within(const fv_photon_map *m, fv_vec3 x, fv_vec3 n, float r, float *best)
{
    fv_photon_query q;
    uint32_t idx[64];
    int k, index = -1;
    *best = INFINITY;
    fv_photon_query_begin(&q, m, x, r);
    while ((k = fv_photon_query_next(&q, idx, 64)) > 0)
        for (int j = 0; j < k; j++) {
            float d2 = photon_d2(m, idx[j], x);
            if (d2 < *best && fv_dot(m->p[idx[j]].n, n) > 0.5f) {
                *best = d2;
                index = (int)idx[j];
            }
        }
    return index;
}

int fv_photon_map_nearest(const fv_photon_map *m, fv_vec3 x, fv_vec3 n, float r, float *d2_out)
{
    if (m->ncells == 0 || m->n == 0) return -1;
    /* The nearest photon is usually close: look within a small radius first; a hit there is the
     * nearest overall because every photon within that radius was examined. */
    float best;
    float r0 = fminf(r, 0.25f * m->cell);
    int index = nearest_within(m, x, n, r0, &best);
    if (index < 0 && r > r0) index = nearest_within(m, x, n, r, &best);
    if (d2_out) *d2_out = best;
    return index;
}

float fv_photon_radius_eq8(fv_vec3 lo, fv_vec3 hi, int width, int height)
{
    fv_vec3 e = fv_sub(hi, lo);
    return (e.x + e.y + e.z) / 3.0f / ((width + height) / 2.0f) * 20.0f;
}

fv_status fv_photon_read_radius(struct fv_params *p, const char *what, double *radius, fv_error *err)
{
    /* A gather radius is a distance in the scene: bounded like every coordinate (fovea/limits.h). */
    fv_status s = fv_params_float(p, "radius", 0.0, 0.0, FV_COORD_MAX, radius, err);
    if (s != FV_OK || !fv_params_has(p, "radius") || *radius > 0.0) return s;
    const char *v = "";
    for (int i = 0; i < fv_params_count(p); i++)
        if (strcmp(fv_params_key(p, i), "radius") == 0) v = fv_params_value(p, i);
    return fv_error_set(err, FV_ERR_INVALID, "parameter radius=%s: the %s must be > 0 (leave it out for Eq. 8)", v, what);
}
