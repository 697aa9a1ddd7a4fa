/* fovea — photon guiding towards the focus region's gather discs (see guide.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "scene/light.h"
#include "technique/photon/guide.h"
#include "transport/light_path.h"

/* ---- the cell set: open addressing on packed cell coordinates ---- */

#define EMPTY UINT64_MAX
#define COORD_BIAS (1 << 20) /* 21 bits per axis: +-1M cells, far beyond any gather grid */

struct fv_focus_cells {
    float cell, inv_cell;
    uint64_t *key;
    int cap, n; /* cap: a power of two, kept at least twice n */
};

fv_status fv_focus_cells_create(fv_focus_cells **out, fv_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_focus_cells_reset(*out, 1.0f);
    return FV_OK;
}

void fv_focus_cells_destroy(fv_focus_cells *f)
{
    if (!f) return;
    free(f->key);
    free(f);
}

void fv_focus_cells_reset(fv_focus_cells *f, float cell)
{
    f->cell = cell > 0.0f && isfinite(cell) ? cell : 1.0f;
    f->inv_cell = 1.0f / f->cell;
    f->n = 0;
    if (f->key)
        for (int i = 0; i < f->cap; i++) f->key[i] = EMPTY;
}

static int coord(float v, float inv_cell)
{
    float c = floorf(v * inv_cell);
    /* NaN and far-away points share the outermost cell: never a valid focus cell in practice. */
    if (!(c > -(float)(COORD_BIAS - 1))) return -(COORD_BIAS - 1);
    if (c > (float)(COORD_BIAS - 1)) return COORD_BIAS - 1;
    return (int)c;
}

static uint64_t pack(int x, int y, int z)
{
    return ((uint64_t)(x + COORD_BIAS) << 42) | ((uint64_t)(y + COORD_BIAS) << 21) | (uint64_t)(z + COORD_BIAS);
}

static int slot_of(const fv_focus_cells *f, uint64_t k)
{
    uint32_t mask = (uint32_t)f->cap - 1, i = (uint32_t)(fv_hash64(k) & mask);
    while (f->key[i] != EMPTY && f->key[i] != k) i = (i + 1) & mask;
    return (int)i;
}

static fv_status grow(fv_focus_cells *f, fv_error *err)
{
    int cap = f->cap ? 2 * f->cap : 1024;
    uint64_t *old = f->key, *key = fv_alloc_array((size_t)cap, sizeof *key);
    if (!key) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the focus cells");
    for (int i = 0; i < cap; i++) key[i] = EMPTY;
    int old_cap = f->cap;
    f->key = key;
    f->cap = cap;
    for (int i = 0; i < old_cap; i++)
        if (old[i] != EMPTY) f->key[slot_of(f, old[i])] = old[i];
    free(old);
    return FV_OK;
}

fv_status fv_focus_cells_add(fv_focus_cells *f, fv_vec3 x, float r, fv_error *err)
{
    int lo[3] = {coord(x.x - r, f->inv_cell), coord(x.y - r, f->inv_cell), coord(x.z - r, f->inv_cell)};
    int hi[3] = {coord(x.x + r, f->inv_cell), coord(x.y + r, f->inv_cell), coord(x.z + r, f->inv_cell)};
    for (int a = 0; a < 3; a++)
        if (hi[a] > lo[a] + 1) hi[a] = lo[a] + 1; /* r <= cell: two cells per axis at most */
    for (int i = lo[0]; i <= hi[0]; i++)
        for (int j = lo[1]; j <= hi[1]; j++)
            for (int k = lo[2]; k <= hi[2]; k++) {
                if (2 * (f->n + 1) > f->cap) {
                    fv_status s = grow(f, err);
                    if (s != FV_OK) return s;
                }
                uint64_t key = pack(i, j, k);
                int slot = slot_of(f, key);
                if (f->key[slot] == EMPTY) {
                    f->key[slot] = key;
                    f->n++;
                }
            }
    return FV_OK;
}

bool fv_focus_cells_contains(const fv_focus_cells *f, fv_vec3 p)
{
    if (f->n == 0) return false;
    uint64_t k = pack(coord(p.x, f->inv_cell), coord(p.y, f->inv_cell), coord(p.z, f->inv_cell));
    return f->key[slot_of(f, k)] == k;
}

int fv_focus_cells_count(const fv_focus_cells *f) { return f->n; }
float fv_focus_cells_cell(const fv_focus_cells *f) { return f->cell; }

double fv_focus_cells_overlap(const fv_focus_cells *a, const fv_focus_cells *b)
{
    if (a->n == 0) return 1.0;
    if (a->cell != b->cell || b->n == 0) return 0.0;
    int both = 0;
    for (int i = 0; i < a->cap; i++)
        if (a->key[i] != EMPTY && b->key[slot_of(b, a->key[i])] == a->key[i]) both++;
    return (double)both / a->n;
}

/* ---- the guide ---- */

/* Cells of q: the light-pick number in up to LIGHT_BINS bins, the two direction numbers in
 * DIR_BINS x DIR_BINS. With 300k photons a frame, 40% guided and an eighth of those as pilot,
 * a cornell-sized scene puts some 30 pilot photons in each of 8 x 12 x 12 cells. */
#define LIGHT_BINS 8
#define DIR_BINS 12

struct fv_photon_guide {
    const fv_scene *scene;
    double alpha;
    int lbins, ncells;
    double cdf[LIGHT_BINS * DIR_BINS * DIR_BINS + 1];
    float q[LIGHT_BINS * DIR_BINS * DIR_BINS]; /* density relative to uniform numbers */
    uint64_t w[LIGHT_BINS * DIR_BINS * DIR_BINS]; /* learn's pilot sums per cell: the guide's, so learning allocates nothing */
    double focus_share;
};

fv_status fv_photon_guide_create(double alpha, fv_photon_guide **out, fv_error *err)
{
    if (!(alpha >= 0.0 && alpha < 1.0)) return fv_error_set(err, FV_ERR_INVALID, "guide alpha %g outside [0, 1)", alpha);
    fv_photon_guide *g = calloc(1, sizeof *g);
    if (!g) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    g->alpha = alpha;
    *out = g;
    return FV_OK;
}

void fv_photon_guide_destroy(fv_photon_guide *g) { free(g); }

double fv_photon_guide_focus_share(const fv_photon_guide *g) { return g->focus_share; }

static float below_one(float v) { return v < 0x1.fffffep-1f ? v : 0x1.fffffep-1f; }

/* The cell of q that numbers u fall in. */
static int cell_of(const fv_photon_guide *g, const float u[5])
{
    int b = (int)(u[0] * g->lbins), k = fv_light_emission_dir_dims(g->scene, u[0]);
    int i = (int)(u[k] * DIR_BINS), j = (int)(u[k + 1] * DIR_BINS);
    b = b < g->lbins ? b : g->lbins - 1;
    i = i < DIR_BINS ? i : DIR_BINS - 1;
    j = j < DIR_BINS ? j : DIR_BINS - 1;
    return (b * DIR_BINS + i) * DIR_BINS + j;
}

/* q from per-cell weights (NULL or all zero: uniform): alpha of the probability in proportion to
 * the weights, the rest spread evenly. */
static void build(fv_photon_guide *g, const uint64_t *w)
{
    double total = 0.0;
    for (int c = 0; c < g->ncells && w; c++) total += (double)w[c];
    double a = total > 0.0 ? g->alpha : 0.0;
    g->cdf[0] = 0.0;
    for (int c = 0; c < g->ncells; c++) {
        double p = (1.0 - a) / g->ncells + (total > 0.0 ? a * (double)w[c] / total : 0.0);
        g->q[c] = (float)(p * g->ncells);
        g->cdf[c + 1] = g->cdf[c] + p;
    }
    g->cdf[g->ncells] = 1.0;
}

void fv_photon_guide_reset(fv_photon_guide *g, const fv_scene *s)
{
    g->scene = s;
    int n = fv_scene_light_count(s);
    g->lbins = n < 1 ? 1 : n < LIGHT_BINS ? n : LIGHT_BINS;
    g->ncells = g->lbins * DIR_BINS * DIR_BINS;
    g->focus_share = 0.0;
    build(g, NULL);
}

float fv_photon_guide_density(const fv_photon_guide *g, const float u[5]) { return g->q[cell_of(g, u)]; }

float fv_photon_guide_warp(const void *ctx, fv_rng *rng, float u[5])
{
    const fv_photon_guide *g = ctx;
    double x = fv_rng_next(rng);
    int lo = 0, hi = g->ncells - 1;
    while (lo < hi) { /* the first cell whose cdf[c + 1] exceeds x */
        int mid = (lo + hi) / 2;
        if (g->cdf[mid + 1] <= x) lo = mid + 1;
        else hi = mid;
    }
    int b = lo / (DIR_BINS * DIR_BINS), i = lo / DIR_BINS % DIR_BINS, j = lo % DIR_BINS;
    for (int k = 0; k < 5; k++) u[k] = fv_rng_next(rng);
    u[0] = below_one(((float)b + u[0]) / (float)g->lbins);
    int k = fv_light_emission_dir_dims(g->scene, u[0]);
    u[k] = below_one(((float)i + u[k]) / DIR_BINS);
    u[k + 1] = below_one(((float)j + u[k + 1]) / DIR_BINS);
    return g->q[lo];
}

/* ---- learning from pilot photons ---- */

typedef struct pilot_walk {
    const fv_focus_cells *focus;
    uint32_t in, all;
} pilot_walk;

static void pilot_visit(void *ctx, const fv_hit *h, const fv_material *m, fv_vec3 dir, fv_vec3 flux)
{
    (void)m, (void)dir, (void)flux;
    pilot_walk *w = ctx;
    w->all++;
    w->in += fv_focus_cells_contains(w->focus, h->p);
}

fv_status fv_photon_guide_learn(fv_photon_guide *g, const fv_photon_job *job, fv_trace_set set, const fv_focus_cells *focus,
                                uint64_t *rays, fv_error *err)
{
    fv_photon_guide_reset(g, job->scene);
    if (job->count <= 0 || fv_scene_light_count(job->scene) == 0 || fv_focus_cells_count(focus) == 0) return FV_OK;
    (void)err;
    uint64_t *w = g->w;
    memset(w, 0, (size_t)g->ncells * sizeof *w);
    uint64_t in = 0, all = 0, nrays = 0;
    /* Integer sums: the same q whatever the thread count or schedule. */
    fv_region_begin();
    #pragma omp parallel for schedule(dynamic, 256) reduction(+ : in, all, nrays) num_threads(fv_thread_count(job->threads))
    for (int64_t i = 0; i < job->count; i++) {
        fv_rng rng = fv_rng_stream(job->seed, FV_STREAM_PHOTONS(job->stream), (uint64_t)i, 4, (uint64_t)job->frame);
        float u[5];
        for (int k = 0; k < 5; k++) u[k] = fv_rng_next(&rng);
        fv_vec3 o, d, flux;
        if (!fv_light_path_emit_u(job->scene, u, job->count, &o, &d, &flux)) continue;
        pilot_walk pw = {focus, 0, 0};
        fv_light_path_trace(job->scene, set, o, d, flux, 0, job->max_depth, &rng, pilot_visit, &pw, &nrays);
        if (pw.in) {
            int c = cell_of(g, u);
            #pragma omp atomic
            w[c] += pw.in;
        }
        in += pw.in;
        all += pw.all;
    }
    fv_region_end();
    build(g, w);
    g->focus_share = all > 0 ? (double)in / (double)all : 0.0;
    if (rays) *rays += nrays;
    return FV_OK;
}
