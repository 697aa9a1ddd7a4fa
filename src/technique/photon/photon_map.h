/* fovea — photons and photon maps stored in a sorted uniform grid.
 *
 * Foveated Photon Mapping (Sec. 3) keeps four maps (light/foveated x static/dynamic); a photon
 * has a direction, a signed RGB flux and a position (and the map remembers the surface normal to
 * keep photons from leaking through thin walls). The paper stores maps in sorted uniform grids
 * rather than kd-trees because they rebuild in linear time; so do we: photons are counting-sorted
 * by cell into a dense grid over their bounding box (at most about two cells per photon: axes wrap
 * beyond that), positions, normals and directions are also kept apart (SoA) for the tests, and a
 * query tests the photons of its neighbouring cells a block at a time, one contiguous range per
 * row of cells along x (docs/photon-mapping.md, "The grid and the gather").
 */
#ifndef FV_PHOTON_MAP_H
#define FV_PHOTON_MAP_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/limits.h"
#include "fovea/math.h"
#include "fovea/status.h"

typedef struct fv_photon {
    fv_vec3 pos;
    fv_vec3 dir;   /* unit direction of travel when the photon arrived */
    fv_vec3 flux;  /* signed RGB flux (negative photons cancel light a dynamic object blocks) */
    fv_vec3 n;     /* unit geometric normal, on the side the photon arrived from */
} fv_photon;

/* A photon arriving along dir at a surface of geometric normal ng: its normal is stored on the
 * side it came from, which the gather's facing test compares. */
static inline fv_photon fv_photon_make(fv_vec3 pos, fv_vec3 dir, fv_vec3 flux, fv_vec3 ng)
{
    fv_photon ph = {pos, dir, flux, fv_dot(ng, dir) < 0.0f ? ng : fv_neg(ng)};
    return ph;
}

typedef struct fv_photon_map {
    fv_photon *p;          /* after fv_photon_map_build: sorted by grid cell */
    int n, cap;
    /* grid: cell (i, j, k) covers [i, i + 1) x [j, j + 1) x [k, k + 1) times `cell`; the cells
     * from org to org + dim - 1 are stored densely, x fastest. An axis whose extent would make the
     * grid too big wraps: it keeps dim (>= 7) cells and cell c is stored at (c - org) mod dim, so
     * the up to 7 cells a query spans on it stay distinct. */
    float cell, inv_cell;
    int org[3], dim[3];
    bool wrap[3];
    uint32_t *start;       /* ncells + 1 offsets into p */
    size_t start_cap;      /* room in start, grown, never shrunk */
    uint32_t ncells;       /* 0: not built */
    /* Position and normal of p again, one array per component (SoA), padded by FV_PHOTON_BLOCK:
     * a query tests a block of photons at a time without loading the rest of each. */
    float *px, *py, *pz, *nx, *ny, *nz;
    int soa_cap;
    fv_photon *scratch;
    int scratch_cap;
    uint32_t *key;         /* build scratch: each photon's cell */
    int key_cap;
    uint32_t *count;       /* build scratch: photons per (thread, cell), kept between builds */
    size_t count_cap;
} fv_photon_map;

/* Photons a query tests at once (one pass of the tests over the SoA arrays). */
#define FV_PHOTON_BLOCK 8
/* Index ranges a query may test: a row of up to 7 cells along x is one range (two where x wraps),
 * for each of up to 7 x 7 rows (r up to 3 cells). */
#define FV_PHOTON_MAX_RANGES 98

/* A query in progress: the index ranges of p to test, in the order they are summed, and how far
 * the test has got. */
typedef struct fv_photon_query {
    const fv_photon_map *m;
    fv_vec3 x;
    float r2;
    bool facing;           /* fv_photon_query_facing was called */
    fv_vec3 n;
    int nranges, range;
    uint32_t i;
    uint32_t lo[FV_PHOTON_MAX_RANGES], hi[FV_PHOTON_MAX_RANGES];
} fv_photon_query;

void fv_photon_map_init(fv_photon_map *m);
void fv_photon_map_free(fv_photon_map *m);
void fv_photon_map_clear(fv_photon_map *m);
/* Appends (not thread-safe; see fv_photon_map_append_many). */
fv_status fv_photon_map_push(fv_photon_map *m, const fv_photon *ph, fv_error *err);
fv_status fv_photon_map_append(fv_photon_map *m, const fv_photon *ph, int count, fv_error *err);
/* Sorts the photons into the grid of cell size `cell` (queries may reach up to 3 cells; about the
 * gather radius is best). O(n), on up to `threads` threads (fv_thread_count; fv_photon_map_build:
 * all); the result does not depend on the thread count. */
fv_status fv_photon_map_build_mt(fv_photon_map *m, float cell, int threads, fv_error *err);
fv_status fv_photon_map_build(fv_photon_map *m, float cell, fv_error *err);

/* Every photon within radius r (r <= 3 cells) of x, in a fixed order (the order sums over them
 * are taken in), without callbacks:
 *     fv_photon_query q;  uint32_t idx[64];  int k;
 *     fv_photon_query_begin(&q, m, x, r);
 *     while ((k = fv_photon_query_next(&q, idx, 64)) > 0) ... m->p[idx[j]] for j < k ...
 * next fills idx with up to cap (>= FV_PHOTON_BLOCK) indices into m->p and returns how many; 0 once
 * all are found. */
void fv_photon_query_begin(fv_photon_query *q, const fv_photon_map *m, fv_vec3 x, float r);
int fv_photon_query_next(fv_photon_query *q, uint32_t *restrict idx, int cap);
/* After begin: keep only the photons on a surface facing like n (n_photon . n > 0.5), the gather's
 * test against light leaking through thin walls and around corners, made a block at a time.
 * Where a photon came from is not tested: on a flat surface it always arrived from above (it is
 * stored on the side it came from), and on a curved one the photons arriving from below the
 * query's tangent plane belong to the flux density the disc averages (rejecting them made a unit
 * sphere r^2 / 8 too dark; docs/photon-mapping.md, "The normal test"). */
void fv_photon_query_facing(fv_photon_query *q, fv_vec3 n);

/* Calls fn for every photon within radius r (r <= 3 cell) of x. */
typedef void (*fv_photon_fn)(void *ctx, const fv_photon *ph, float d2);
void fv_photon_map_query(const fv_photon_map *m, fv_vec3 x, float r, fv_photon_fn fn, void *ctx);
/* Index of the nearest photon within r (r <= 3 cell) of x whose normal agrees with n
 * (dot > 0.5); -1 when none. *d2 gets its squared distance. */
int fv_photon_map_nearest(const fv_photon_map *m, fv_vec3 x, fv_vec3 n, float r, float *d2);

/* The gather radius of Foveated Photon Mapping Eq. 8: the mean extent of the scene's bounding
 * box over the mean image side, times 20. */
float fv_photon_radius_eq8(fv_vec3 lo, fv_vec3 hi, int width, int height);
/* The "radius" parameter of a photon method: 0 (left out) means Eq. 8 at the render's size; given,
 * it must be > 0, else FV_ERR_INVALID naming the value and `what` ("gather radius", ...). */
struct fv_params;
fv_status fv_photon_read_radius(struct fv_params *p, const char *what, double *radius, fv_error *err);
/* The scene the photon family's benchmarks render (class.h, bench_scene): the paper's Cornell box
 * with its moving objects. */
#define FV_PHOTON_BENCH_SCENE "cornell-fpm"

/* Its entry in a class's parameter table (technique/class.h), with the method's own help. */
#define FV_PHOTON_RADIUS_PARAM(h)                                                                                    \
    {.key = "radius", .type = FV_PARAM_FLOAT, .def_note = "Eq. 8", .min = 0.0, .min_open = true, .max = FV_COORD_MAX, \
     .help = (h)}

#endif
