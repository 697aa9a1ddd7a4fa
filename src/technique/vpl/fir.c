/* fovea — `fir`: Foveated Instant Radiosity (Wang, Li, Shi, Yan et al.), Alg. 1 frame by frame.
 *
 *   voxelize (Alg. 1: static once at create, dynamic objects every frame)
 *   inject direct light into the voxels (Sec. 3.4)
 *   foveated weights of the voxels (Alg. 2)
 *   update last frame's VPLs (Alg. 4 line 3: follow their object, drop on a changed normal or a low
 *     importance) and their importance now (Alg. 3)
 *   candidates from the fovea (Sec. 3.1, Eq. 1), their importance, resampling by its CDF
 *   selection (Eq. 2, Alg. 4 and 5) against the density grid
 *   radiosity of the valid VPLs (Eq. 3) and their intensity (uniform density)
 *   cube maps: new VPLs' maps, then the oldest, up to `rebuild` of them (Sec. 4.1: 20% per frame)
 *   interleaved deferred shading over tiles_x x tiles_y tiles, a 5x5 box filter, direct light
 *
 * CPU choices, each said in docs/instant-radiosity.md: candidates are placed by an Embree ray (as
 * cheap here as a voxel walk, and it puts the VPL on the surface its cube map must start from);
 * visibility from the VPLs is a depth cube map, rasterised as the paper's shadow maps are when
 * the scene is small and built by casting rays when it is large (cubemap.h); the two eyes of a stereo frame share one VPL set, managed with the left
 * eye's view and gaze (both eyes then see the same light, and the management runs once a frame).
 *
 * All arrays are sized at create (VPLs, candidates, cube maps, voxels) or when the image size
 * changes, so memory does not grow with the frame count.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/stage_time.h"
#include "filter/atrous.h"
#include "scene/light.h"
#include "technique/class.h"
#include "technique/vpl/direct.h"
#include "technique/vpl/fir.h"
#include "technique/vpl/manage.h"
#include "technique/vpl/radiosity.h"
#include "technique/vpl/vpl_shade.h"
#include "technique/vpl/weights.h"

/* index ranges within FV_STREAM_VPL, one per purpose (radiosity.h: ir's walks use 0 .. walks - 1,
 * the injection 5 << 40 on) */
#define FIR_RNG_CANDIDATE ((uint64_t)1 << 40)
#define FIR_RNG_RESAMPLE ((uint64_t)2 << 40)
#define FIR_RNG_ACCEPT ((uint64_t)3 << 40)
#define FIR_RNG_VPL_DIRECT ((uint64_t)4 << 40)

typedef struct fir_vpl {
    fv_vec3 p, n;   /* world, now */
    fv_vec3 lp, ln; /* in its object's space (follows a dynamic object) */
    fv_vec3 albedo;
    float imp;      /* foveated importance (Alg. 3) when last computed */
    int obj;        /* the object it lies on */
    int map;        /* its cube map slot */
    int tile;       /* its interleaved tile */
    int64_t built;  /* frame counter when its map was built; -1 never */
} fir_vpl;

typedef struct build_key {
    int64_t built;
    int index;
} build_key;

enum { FILTER_BOX = 0, FILTER_ATROUS, FILTER_NONE };
static const char *const k_filters[] = {"box", "atrous", "none", NULL};
static const char *const k_visibility[] = {"cube", "rays", NULL};

typedef struct fir_state {
    const fv_scene *scene;
    /* parameters */
    int total, ncand, resolution, ndirs, density_res, density_limit, tiles_x, tiles_y, cube_size, cube_filter, filter,
        area_samples, show, visibility, cube_build;
    float resample, density_c, drop_importance, drop_cos, rebuild, radius, clamp;
    /* scene side */
    fv_voxels *vox;
    size_t ncells;
    float *weight;    /* Alg. 2, per level-0 cell */
    float *scratch;   /* 3 per level-0 cell */
    int *dens_vox;    /* occupied level-0 cells per density cell */
    unsigned char *reached; /* density cells a candidate landed in this frame */
    int *owner, *queue;     /* nearest density cell holding VPLs, and the BFS's queue */
    float *cell_area;       /* the surface area the VPLs of a density cell stand for */
    float area_per_voxel;
    fv_density_grid *grid;
    fv_vpl_dirs dirs;
    bool has_dynamic;
    double last_time;
    bool have_time;
    /* VPLs */
    fir_vpl *vpl, *next;
    int nvpl;
    fir_vpl *cand;
    int ncand_cap, ncand_made;
    bool *cand_ok;
    float *cand_imp;
    int *picked;
    fv_vec3 *old_pos, *cand_pos, *sel_cand_pos;
    float *old_prev, *old_new, *old_u, *sel_cand_imp;
    bool *keep_old, *take_cand;
    int *free_slots, nfree;
    fv_cubemaps *maps;
    int *build_idx;
    struct build_key *build_keys;
    fv_vec3 *build_pos, *build_nrm;
    int64_t frames;     /* frames managed so far */
    int64_t managed_index;
    bool managed;
    /* shading */
    fv_vpl_light *lights;
    int *tile_list, *tile_offset;
    int *tiles;         /* scratch for fv_vpl_assign_tiles */
    fv_vpl_frame vf;
    fv_vec3 *tmp;       /* the box filter's horizontal pass */
    float *fbuf;        /* atrous: rgb, normal, position */
    fv_atrous *atrous;  /* atrous: the filter's scratch, kept from frame to frame */
    fv_scratch room;    /* resampling's CDF and the selection's ranking, kept from frame to frame */
    size_t ntmp;
    /* last management's counts, reported by both eyes */
    int moved_count[FV_MAX_THREADS];
    int reused, fresh, dropped, moved, built_maps, made_candidates, fovea_cells;
} fir_state;

/* ---- create / destroy ---- */

static void fir_destroy(void *state)
{
    fir_state *st = state;
    if (!st) return;
    fv_voxels_destroy(st->vox);
    fv_density_grid_destroy(st->grid);
    fv_cubemaps_destroy(st->maps);
    fv_atrous_destroy(st->atrous);
    fv_scratch_free(&st->room);
    fv_vpl_frame_free(&st->vf);
    void *bufs[] = {st->reached, st->owner, st->queue, st->cell_area, st->weight,   st->scratch,   st->dens_vox,    st->vpl,       st->next,         st->cand,
                    st->cand_ok,  st->cand_imp,  st->picked,      st->old_pos,   st->cand_pos,     st->sel_cand_pos,
                    st->old_prev, st->old_new,   st->old_u,       st->sel_cand_imp, st->keep_old,  st->take_cand,
                    st->free_slots, st->build_idx, st->build_keys, st->build_pos, st->build_nrm, st->lights,       st->tile_list,
                    st->tile_offset, st->tiles,  st->tmp,          st->fbuf};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++) free(bufs[i]);
    free(st);
}

static fv_status read_params(fir_state *st, fv_params *p, fv_error *err)
{
    double resample, density_c, drop_imp, drop_deg, rebuild, radius, clamp;
    fv_status s;
    if ((s = fv_params_int(p, "vpls", 1000, -2147483647, 1000000, &st->total, err)) != FV_OK) return s;
    if (st->total <= 0) return fv_error_set(err, FV_ERR_INVALID, "parameter vpls=%d: must be at least 1", st->total);
    if ((s = fv_params_int(p, "candidates", 1000, 1, 1000000, &st->ncand, err)) != FV_OK ||
        (s = fv_params_float(p, "resample", 0.1, 0.0, 1.0, &resample, err)) != FV_OK ||
        (s = fv_params_int(p, "resolution", 64, 8, 1024, &st->resolution, err)) != FV_OK ||
        (s = fv_params_int(p, "directions", 32, 1, FV_VPL_MAX_DIRECTIONS, &st->ndirs, err)) != FV_OK ||
        (s = fv_params_int(p, "density_grid", 16, 1, 256, &st->density_res, err)) != FV_OK ||
        (s = fv_params_int(p, "density_limit", 4, 1, 1000000, &st->density_limit, err)) != FV_OK ||
        (s = fv_params_float(p, "density_c", 1.0, 1e-6, 1e6, &density_c, err)) != FV_OK ||
        (s = fv_params_float(p, "drop_importance", 0.01, 0.0, 1.0, &drop_imp, err)) != FV_OK ||
        (s = fv_params_float(p, "drop_normal_deg", 60.0, 0.0, 180.0, &drop_deg, err)) != FV_OK ||
        (s = fv_params_int(p, "tiles_x", 5, 1, 64, &st->tiles_x, err)) != FV_OK ||
        (s = fv_params_int(p, "tiles_y", 5, 1, 64, &st->tiles_y, err)) != FV_OK ||
        (s = fv_params_int(p, "cube_size", 128, -2147483647, 2147483647, &st->cube_size, err)) != FV_OK)
        return s;
    if (st->cube_size < FV_CUBE_MIN_SIZE || st->cube_size > FV_CUBE_MAX_SIZE)
        return fv_error_set(err, FV_ERR_INVALID, "parameter cube_size=%d: out of range [%d, %d]", st->cube_size, FV_CUBE_MIN_SIZE,
                            FV_CUBE_MAX_SIZE);
    if (st->tiles_x * st->tiles_y > st->total)
        return fv_error_set(err, FV_ERR_INVALID,
                            "parameters tiles_x=%d, tiles_y=%d: %d tiles do not divide vpls=%d (each tile needs a VPL)", st->tiles_x,
                            st->tiles_y, st->tiles_x * st->tiles_y, st->total);
    if ((s = fv_params_float(p, "rebuild", 0.2, 0.0, 1.0, &rebuild, err)) != FV_OK ||
        (s = fv_params_choice(p, "cube_filter", 0, fv_cube_filter_names, &st->cube_filter, err)) != FV_OK ||
        (s = fv_params_choice(p, "filter", FILTER_BOX, k_filters, &st->filter, err)) != FV_OK ||
        (s = fv_params_float(p, "radius", 0.25, -1e30, 1e30, &radius, err)) != FV_OK ||
        (s = fv_params_int(p, "area_samples", 16, 1, 4096, &st->area_samples, err)) != FV_OK ||
        (s = fv_params_float(p, "clamp", 0.03, 0.0, 1.0, &clamp, err)) != FV_OK ||
        (s = fv_params_choice(p, "show", 0, fv_vpl_show_names, &st->show, err)) != FV_OK ||
        (s = fv_params_choice(p, "visibility", 0, k_visibility, &st->visibility, err)) != FV_OK ||
        (s = fv_params_choice(p, "cube_build", FV_CUBE_BUILD_AUTO, fv_cube_build_names, &st->cube_build, err)) != FV_OK)
        return s;
    if (!(radius > 0.0 && radius <= 1.0))
        return fv_error_set(err, FV_ERR_INVALID, "parameter radius=%g: outside (0, 1] (a fraction of the image width)", radius);
    st->resample = (float)resample;
    st->density_c = (float)density_c;
    st->drop_importance = (float)drop_imp;
    st->drop_cos = cosf((float)(drop_deg * M_PI / 180.0));
    st->rebuild = (float)rebuild;
    st->radius = (float)radius;
    st->clamp = (float)clamp;
    return FV_OK;
}

/* The occupied level-0 cells of each density cell: the area a density cell's VPLs share. */
/* The occupied voxels per density-grid cell. A step of the team (or one thread outside a region):
 * the cells shared out, each count an atomic increment (the same integers in any order). */
static void count_range(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    fir_state *st = ctx;
    for (int64_t c = b; c < e; c++) {
        fv_voxel vx;
        fv_voxels_cell(st->vox, (int)c, &vx);
        if (!vx.occupied) continue;
        int *slot = &st->dens_vox[fv_density_grid_cell(st->grid, fv_voxels_centre(st->vox, (int)c))];
#pragma omp atomic
        (*slot)++;
    }
}

static void count_density_voxels(fir_state *st)
{
#pragma omp master
    memset(st->dens_vox, 0, (size_t)fv_density_grid_cells(st->grid) * sizeof *st->dens_vox);
#pragma omp barrier
    fv_team_for((int64_t)st->ncells, 4096, count_range, st);
}

static fv_status fir_create(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err)
{
    (void)log;
    fir_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    fv_status s = read_params(st, params, err);
    if (s != FV_OK) goto fail;
    if ((s = fv_voxels_create(scene, st->resolution, &st->vox, err)) != FV_OK) goto fail;
    if (st->filter == FILTER_ATROUS && (s = fv_atrous_create(&st->atrous, err)) != FV_OK) goto fail;
    int dims[3];
    fv_voxels_dims(st->vox, 0, dims);
    st->ncells = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    fv_vec3 lo, hi;
    fv_scene_bounds(scene, &lo, &hi);
    if ((s = fv_density_grid_create(lo, hi, st->density_res, &st->grid, err)) != FV_OK) goto fail;
    /* visibility=rays reads no map: none is made */
    if (st->visibility == 0 && (s = fv_vpl_cubemaps_create(st->total, st->cube_size, &st->maps, err)) != FV_OK) goto fail;
    if (st->maps) fv_cubemaps_set_build(st->maps, (fv_cube_build)st->cube_build);
    fv_vpl_dirs_make(st->ndirs, &st->dirs);
    for (int o = 0, n = fv_scene_object_count(scene); o < n; o++) st->has_dynamic |= fv_scene_object_dynamic(scene, o);
    const int N = st->total;
    st->ncand_cap = st->ncand > 2 * N ? st->ncand : 2 * N;
    const size_t C = (size_t)st->ncand_cap;
    st->weight = fv_calloc_array(st->ncells, sizeof *st->weight);
    st->scratch = fv_calloc_array(3 * st->ncells, sizeof *st->scratch);
    const size_t D = (size_t)fv_density_grid_cells(st->grid);
    st->dens_vox = fv_calloc_array(D, sizeof *st->dens_vox);
    st->reached = fv_calloc_array(D, sizeof *st->reached);
    st->owner = fv_calloc_array(D, sizeof *st->owner);
    st->queue = fv_calloc_array(D, sizeof *st->queue);
    st->cell_area = fv_calloc_array(D, sizeof *st->cell_area);
    st->vpl = fv_calloc_array((size_t)N, sizeof *st->vpl);
    st->next = fv_calloc_array((size_t)N, sizeof *st->next);
    st->cand = fv_calloc_array(C, sizeof *st->cand);
    st->cand_ok = fv_calloc_array(C, sizeof *st->cand_ok);
    st->cand_imp = fv_calloc_array(C, sizeof *st->cand_imp);
    st->picked = fv_calloc_array(C, sizeof *st->picked);
    st->old_pos = fv_calloc_array((size_t)N, sizeof *st->old_pos);
    st->cand_pos = fv_calloc_array(C, sizeof *st->cand_pos);
    st->sel_cand_pos = fv_calloc_array(C, sizeof *st->sel_cand_pos);
    st->old_prev = fv_calloc_array((size_t)N, sizeof *st->old_prev);
    st->old_new = fv_calloc_array((size_t)N, sizeof *st->old_new);
    st->old_u = fv_calloc_array((size_t)N, sizeof *st->old_u);
    st->sel_cand_imp = fv_calloc_array(C, sizeof *st->sel_cand_imp);
    st->keep_old = fv_calloc_array((size_t)N, sizeof *st->keep_old);
    st->take_cand = fv_calloc_array(C, sizeof *st->take_cand);
    st->free_slots = fv_calloc_array((size_t)N, sizeof *st->free_slots);
    st->build_idx = fv_calloc_array((size_t)N, sizeof *st->build_idx);
    st->build_keys = fv_calloc_array((size_t)N, sizeof *st->build_keys);
    st->build_pos = fv_calloc_array((size_t)N, sizeof *st->build_pos);
    st->build_nrm = fv_calloc_array((size_t)N, sizeof *st->build_nrm);
    st->lights = fv_calloc_array((size_t)N, sizeof *st->lights);
    st->tiles = fv_calloc_array((size_t)N, sizeof *st->tiles);
    st->tile_list = fv_calloc_array((size_t)N, sizeof *st->tile_list);
    st->tile_offset = fv_calloc_array((size_t)(st->tiles_x * st->tiles_y + 1), sizeof *st->tile_offset);
    if (!st->weight || !st->scratch || !st->dens_vox || !st->reached || !st->owner || !st->queue || !st->cell_area || !st->vpl || !st->next || !st->cand || !st->cand_ok || !st->cand_imp ||
        !st->picked || !st->old_pos || !st->cand_pos || !st->sel_cand_pos || !st->old_prev || !st->old_new || !st->old_u ||
        !st->sel_cand_imp || !st->keep_old || !st->take_cand || !st->free_slots || !st->build_idx || !st->build_keys || !st->build_pos ||
        !st->build_nrm || !st->lights || !st->tiles || !st->tile_list || !st->tile_offset) {
        s = fv_error_set(err, FV_ERR_NOMEM, "out of memory for %d VPLs and a %dx%dx%d voxel grid", N, dims[0], dims[1], dims[2]);
        goto fail;
    }
    for (int i = 0; i < N; i++) st->free_slots[i] = N - 1 - i; /* pop from the end: slot 0 first */
    st->nfree = N;
    st->area_per_voxel = fv_vpl_area_per_voxel(st->vox, scene);
    count_density_voxels(st);
    *state = st;
    return FV_OK;
fail:
    fir_destroy(st);
    return s;
}

/* The filters' scratch, sized with the image. */
static fv_status fir_reserve(fir_state *st, fv_error *err)
{
    const size_t n = st->vf.npix;
    if (n == st->ntmp) return FV_OK;
    free(st->tmp);
    free(st->fbuf);
    st->tmp = malloc(n * sizeof *st->tmp);
    st->fbuf = st->filter == FILTER_ATROUS ? malloc(9 * n * sizeof *st->fbuf) : NULL;
    st->ntmp = st->tmp && (st->filter != FILTER_ATROUS || st->fbuf) ? n : 0;
    if (!st->ntmp) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d frame", st->vf.cam.width, st->vf.cam.height);
    return FV_OK;
}

/* ---- a VPL and its object ---- */

static void object_maps(const fv_scene *s, int obj, fv_xform *w2l, fv_xform *l2w)
{
    fv_scene_object_world_to_local(s, obj, w2l);
    if (!fv_xform_inverse(w2l, l2w)) *l2w = fv_xform_identity();
}

void fv_fir_follow(const fv_scene *s, int obj, fv_vec3 lp, fv_vec3 ln, fv_vec3 *p, fv_vec3 *n)
{
    fv_xform w2l, l2w;
    object_maps(s, obj, &w2l, &l2w);
    *p = fv_xform_point(&l2w, lp);
    *n = fv_normalize(fv_xform_vector(&l2w, ln));
}

/* A new VPL at hit h (normal turned towards dir's origin side). */
static void vpl_from_hit(const fv_scene *s, const fv_hit *h, fv_vec3 dir, fir_vpl *v)
{
    memset(v, 0, sizeof *v);
    v->p = h->p;
    v->n = fv_dot(h->ng, dir) < 0.0f ? h->ng : fv_neg(h->ng);
    fv_material mbuf;
    v->albedo = fv_hit_material(s, h, &mbuf)->albedo;
    v->obj = h->obj;
    v->map = -1;
    v->tile = -1;
    v->built = -1;
    if (fv_scene_object_dynamic(s, h->obj)) {
        fv_xform w2l, l2w;
        object_maps(s, h->obj, &w2l, &l2w);
        v->lp = fv_xform_point(&w2l, v->p);
        v->ln = fv_normalize(fv_xform_vector(&w2l, v->n));
    } else {
        v->lp = v->p;
        v->ln = v->n;
    }
}

/* The level-0 voxel under world point p; false outside the grid. */
static bool voxel_at(const fv_voxels *vox, fv_vec3 p, fv_voxel *out)
{
    const fv_vec3 o = fv_voxels_origin(vox);
    const float h = fv_voxels_cell_size(vox);
    const float fx = (p.x - o.x) / h, fy = (p.y - o.y) / h, fz = (p.z - o.z) / h;
    if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f)) return false;
    const int c = fv_voxels_index(vox, (int)fx, (int)fy, (int)fz);
    if (c < 0) return false;
    fv_voxels_cell(vox, c, out);
    return true;
}

/* ---- the management of one frame (eye 0) ---- */

typedef struct par_ctx {
    fir_state *st;
    const fv_frame *frame;
    const fv_camera_basis *cam;
    float gx, gy, R;
    bool whole; /* the frame's fovea covers the screen (fv_frame_fovea_covers): candidates from all of it */
    uint64_t rays[FV_MAX_THREADS];
} par_ctx;

/* Sec. 3.1: candidate j from a uniform point of the foveal disc (Eq. 1), or of the screen when the
 * fovea covers it, and one cosine-distributed bounce from the surface seen there. */
static void candidates_range(void *ctx, int64_t b, int64_t e, int thread)
{
    par_ctx *c = ctx;
    fir_state *st = c->st;
    const fv_scene *s = st->scene;
    for (int64_t j = b; j < e; j++) {
        st->cand_ok[j] = false;
        fv_rng rng = fv_rng_stream(c->frame->seed, FV_STREAM_VPL, FIR_RNG_CANDIDATE + (uint64_t)j, 0, (uint64_t)c->frame->index);
        float dx, dy;
        const float u = fv_rng_next(&rng), v = fv_rng_next(&rng);
        fv_vpl_polar_sample(u, v, &dx, &dy);
        float px = c->gx + c->R * dx, py = c->gy + c->R * dy;
        if (c->whole) px = u * (float)st->vf.gb.width, py = v * (float)st->vf.gb.height;
        if (!(px >= 0.0f && py >= 0.0f && px < (float)st->vf.gb.width && py < (float)st->vf.gb.height)) continue;
        const fv_gpixel *g = &st->vf.gb.px[(size_t)py * (size_t)st->vf.gb.width + (size_t)px];
        if (!fv_gpixel_hit(g)) continue;
        fv_vec3 t, bb;
        fv_basis(g->n, &t, &bb);
        const float u0 = fv_rng_next(&rng), u1 = fv_rng_next(&rng);
        const float r = sqrtf(u0), phi = 2.0f * (float)M_PI * u1;
        const fv_vec3 d = fv_from_local(fv_v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u0))), t, bb, g->n);
        fv_hit h;
        c->rays[thread]++;
        if (!fv_scene_intersect(s, FV_TRACE_ALL, fv_offset_point(s, g->p, g->ng, d), d, INFINITY, &h)) continue;
        vpl_from_hit(s, &h, d, &st->cand[j]);
        st->cand_ok[j] = true;
    }
}

static void cand_importance_range(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    fir_state *st = ((par_ctx *)ctx)->st;
    for (int64_t j = b; j < e; j++)
        st->cand_imp[j] = fv_vpl_importance(st->vox, st->weight, &st->dirs, st->cand[j].p, st->cand[j].n);
}

/* Alg. 4 line 3 for VPL i: follow its object, check the voxel it now lies in, importance now. */
static void update_range(void *ctx, int64_t b, int64_t e, int thread)
{
    fir_state *st = ((par_ctx *)ctx)->st;
    for (int64_t i = b; i < e; i++) {
        fir_vpl *v = &st->vpl[i];
        if (v->obj >= 0 && fv_scene_object_dynamic(st->scene, v->obj)) {
            fv_vec3 p, n;
            fv_fir_follow(st->scene, v->obj, v->lp, v->ln, &p, &n);
            if (fv_length(fv_sub(p, v->p)) > 0.0f) {
                v->built = -2; /* moved: its map is stale */
                st->moved_count[thread]++;
            }
            v->p = p;
            v->n = n;
        }
        fv_voxel vx;
        /* the voxel's normal is as wound, the VPL's faces the side it was found from: compare the
         * lines, not the sides (a wall wound away from the room would drop every VPL on it) */
        bool keep = voxel_at(st->vox, v->p, &vx) && vx.occupied && fabsf(fv_dot(vx.normal, v->n)) >= st->drop_cos * fv_length(vx.normal);
        float imp = keep ? fv_vpl_importance(st->vox, st->weight, &st->dirs, v->p, v->n) : 0.0f;
        if (keep && imp < st->drop_importance) keep = false;
        st->old_new[i] = keep ? imp : -1.0f; /* -1: dropped by the update */
    }
}

/* The density cells the valid VPLs lie in, and their six face neighbours: the surfaces the VPLs
 * stand for. The VPLs are where the candidates from the fovea landed and were kept, so this is the
 * region one bounce from the fovea reaches; a neighbour fills the holes a thousand VPLs leave
 * between the cells they hold on a surface they all reach. Measured on the fovea's indirect light
 * against pt (cornell; furnace; 128x128, frame 4): the VPLs' own cells only, 82% and 80% of the
 * truth; with the six neighbours 109% and 97%; with all 26, 122% on cornell (corners add cells of
 * surfaces that do not face the fovea). It depends on the VPLs alone, so a still scene keeps it
 * (E' = 0); the frame's candidates instead would change it every frame. */
static void mark_reached(fir_state *st)
{
    int dims[3];
    fv_density_grid_dims(st->grid, dims);
    memset(st->reached, 0, (size_t)fv_density_grid_cells(st->grid));
    for (int i = 0; i < st->nvpl; i++) {
        const int c = fv_density_grid_cell(st->grid, st->vpl[i].p);
        const int x = c % dims[0], y = (c / dims[0]) % dims[1], z = c / (dims[0] * dims[1]);
        const int nb[7][3] = {{x, y, z}, {x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z}, {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
        for (int k = 0; k < 7; k++) {
            const int X = nb[k][0], Y = nb[k][1], Z = nb[k][2];
            if (X < 0 || Y < 0 || Z < 0 || X >= dims[0] || Y >= dims[1] || Z >= dims[2]) continue;
            st->reached[X + dims[0] * (Y + dims[1] * Z)] = 1;
        }
    }
}

/* The area the VPLs of each density cell stand for (Sec. 3.4, "uniform density"; radiosity.h): a
 * cell's own surface, plus that of the reached cells (mark_reached) no VPL took, each given to the
 * nearest cell holding VPLs (a breadth-first search over the grid from all of them at once).
 * Surfaces farther from the VPLs do not light the fovea by the candidates' construction and stand
 * for nothing; without the neighbours, a density cell that no VPL took would lose its light, and
 * every region would come out darker the fewer VPLs it has. */
static void vpl_cell_areas(fir_state *st)
{
    int dims[3];
    fv_density_grid_dims(st->grid, dims);
    const int D = dims[0] * dims[1] * dims[2];
    int head = 0, tail = 0;
    for (int c = 0; c < D; c++) {
        st->cell_area[c] = 0.0f;
        st->owner[c] = -1;
        if (fv_density_grid_count_cell(st->grid, c) > 0) {
            st->owner[c] = c;
            st->queue[tail++] = c;
        }
    }
    while (head < tail) {
        const int c = st->queue[head++];
        const int x = c % dims[0], y = (c / dims[0]) % dims[1], z = c / (dims[0] * dims[1]);
        const int nb[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z}, {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
        for (int k = 0; k < 6; k++) {
            if (nb[k][0] < 0 || nb[k][1] < 0 || nb[k][2] < 0 || nb[k][0] >= dims[0] || nb[k][1] >= dims[1] || nb[k][2] >= dims[2])
                continue;
            const int q = nb[k][0] + dims[0] * (nb[k][1] + dims[1] * nb[k][2]);
            if (st->owner[q] >= 0) continue;
            st->owner[q] = st->owner[c];
            st->queue[tail++] = q;
        }
    }
    for (int c = 0; c < D; c++) {
        const bool own = fv_density_grid_count_cell(st->grid, c) > 0;
        if ((own || st->reached[c]) && st->owner[c] >= 0)
            st->cell_area[st->owner[c]] += (float)st->dens_vox[c] * st->area_per_voxel;
    }
}

/* Radiosity (Eq. 3) and power of VPL i of the new set. */
static void radiosity_range(void *ctx, int64_t b, int64_t e, int thread)
{
    par_ctx *c = ctx;
    fir_state *st = c->st;
    for (int64_t i = b; i < e; i++) {
        const fir_vpl *v = &st->vpl[i];
        fv_rng rng = fv_rng_stream(c->frame->seed, FV_STREAM_VPL, FIR_RNG_VPL_DIRECT + (uint64_t)i, 0, (uint64_t)c->frame->index);
        fv_vec3 ed = fv_vpl_direct_irradiance(st->scene, v->p, v->n, v->n, st->area_samples, &rng, &c->rays[thread]);
        fv_vec3 ec = fv_vpl_cone_irradiance(st->vox, v->p, v->n);
        const int nc = fv_density_grid_count(st->grid, v->p);
        const float area = st->cell_area[fv_density_grid_cell(st->grid, v->p)] / (float)(nc > 0 ? nc : 1);
        fv_vpl_light *l = &st->lights[i];
        l->p = v->p;
        l->n = v->n;
        l->power = fv_scale(fv_mul(v->albedo, fv_add(ed, ec)), area / (float)M_PI);

        l->map = v->map;
    }
}

/* Cube maps are rebuilt in this order: never built (-1) and moved (-2) first, then the oldest; ties
 * by index, so the order does not depend on the sort. */
static int cmp_build_key(const void *a, const void *b)
{
    const build_key *x = a, *y = b;
    if (x->built != y->built) return x->built < y->built ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

/* The management's serial steps, done by one thread between the parallel ones (manage). */

/* After the update (Alg. 4 line 3): the moved count, the dropped VPLs' maps freed and the kept
 * ones packed; returns how many candidates to bounce (Sec. 3.1), *n_old the VPLs kept and *need
 * the VPLs to resample. */
static int manage_after_update(fir_state *st, int *n_old_out, int *need_out)
{
    st->moved = 0;
    for (int t = 0; t < FV_MAX_THREADS; t++) st->moved += st->moved_count[t];
    int n_old = 0;
    st->dropped = 0;
    for (int i = 0; i < st->nvpl; i++) {
        if (st->old_new[i] < 0.0f) {
            st->free_slots[st->nfree++] = st->vpl[i].map;
            st->dropped++;
            continue;
        }
        st->vpl[n_old] = st->vpl[i];
        st->old_new[n_old] = st->old_new[i];
        n_old++;
    }
    /* Sec. 3.1: candidates, their importance (Alg. 3), resampling by its CDF */
    int need = (int)ceilf(st->resample * (float)st->total);
    if (st->total - n_old > need) need = st->total - n_old;
    int m = st->ncand > 2 * need ? st->ncand : 2 * need;
    if (m > st->ncand_cap) m = st->ncand_cap;
    *n_old_out = n_old;
    *need_out = need;
    return m;
}

/* After the candidates' importance: resampling, the selection (Eq. 2, Alg. 4 and 5), the new set,
 * its tiles and the areas its VPLs stand for; returns the new set's size. */
static int manage_select(fir_state *st, const fv_frame *frame, int made, int n_old, int need)
{
    /* a candidate the update would drop next frame is not worth a VPL (nor a cube map) */
    for (int j = 0; j < made; j++)
        if (st->cand_imp[j] < st->drop_importance) st->cand_imp[j] = 0.0f;
    fv_rng rr = fv_rng_stream(frame->seed, FV_STREAM_VPL, FIR_RNG_RESAMPLE, 0, (uint64_t)frame->index);
    const int npick = fv_vpl_resample_in(st->cand_imp, made, need, &rr, st->picked, &st->room);
    for (int k = 0; k < npick; k++) {
        st->sel_cand_pos[k] = st->cand[st->picked[k]].p;
        st->sel_cand_imp[k] = st->cand_imp[st->picked[k]];
    }
    /* Eq. 2, Alg. 4 and 5 */
    for (int i = 0; i < n_old; i++) {
        st->old_pos[i] = st->vpl[i].p;
        st->old_prev[i] = st->vpl[i].imp;
        fv_rng ra = fv_rng_stream(frame->seed, FV_STREAM_VPL, FIR_RNG_ACCEPT + (uint64_t)i, 0, (uint64_t)frame->index);
        st->old_u[i] = fv_rng_next(&ra);
    }
    fv_vpl_select_in in = {n_old, st->old_pos, st->old_prev, st->old_new, st->old_u, npick, st->sel_cand_pos, st->sel_cand_imp};
    fv_vpl_select_opts opt = {st->total, st->density_limit, st->density_c, &st->room};
    fv_density_grid_clear(st->grid);
    int kept_reused = 0, kept_left = 0;
    fv_vpl_select(&in, &opt, st->grid, st->keep_old, st->take_cand, &kept_reused, &kept_left);
    int n = 0;
    for (int i = 0; i < n_old; i++) {
        if (!st->keep_old[i]) {
            st->free_slots[st->nfree++] = st->vpl[i].map;
            st->dropped++;
            continue;
        }
        st->next[n] = st->vpl[i];
        st->next[n].imp = st->old_new[i];
        n++;
    }
    st->reused = n;
    for (int k = 0; k < npick; k++) {
        if (!st->take_cand[k]) continue;
        st->next[n] = st->cand[st->picked[k]];
        st->next[n].imp = st->sel_cand_imp[k];
        st->next[n].map = st->free_slots[--st->nfree];
        n++;
    }
    st->fresh = n - st->reused;
    fir_vpl *sw = st->vpl;
    st->vpl = st->next;
    st->next = sw;
    st->nvpl = n;
    /* Sec. 3.4: old VPLs keep their tile, new ones balance the tiles */
    for (int i = 0; i < n; i++) st->tiles[i] = st->vpl[i].tile;
    fv_vpl_assign_tiles(st->tiles, n, st->tiles_x * st->tiles_y);
    for (int i = 0; i < n; i++) st->vpl[i].tile = st->tiles[i];
    /* the density of the final set, for the VPLs' area */
    fv_density_grid_clear(st->grid);
    for (int i = 0; i < n; i++) fv_density_grid_add(st->grid, st->vpl[i].p, 1);
    mark_reached(st);
    vpl_cell_areas(st);
    return n;
}

static fv_status manage(fir_state *st, const fv_frame *frame, const fv_camera_basis *cam, fv_stats *stats, uint64_t *rays,
                        fv_error *err)
{
    const fv_scene *s = st->scene;
    const int threads = frame->threads;
    par_ctx pc;
    memset(&pc, 0, sizeof pc);
    pc.st = st;
    pc.frame = frame;
    pc.cam = cam;
    pc.gx = frame->gaze.x * (float)cam->width;
    pc.gy = frame->gaze.y * (float)cam->height;
    /* The foveal radius is the paper's fraction of the width (`radius`), unless the frame's eye
     * model has a fovea covering the whole screen (a missing gaze under `widen`, docs/gaze.md):
     * then every visible voxel has acuity 1 and candidates come from the whole screen. */
    fv_eye_model def;
    const fv_eye_model *eye = fv_frame_eye_model(frame, cam->width, cam->height, &def);
    pc.whole = fv_frame_fovea_covers(frame, eye, cam->width, cam->height);
    pc.R = pc.whole ? (float)fv_eye_fovea_radius_px(eye) : st->radius * (float)cam->width;

    /* Alg. 1 line 4: the dynamic objects at this frame's time; light injected when anything moved. */
    const double now = fv_scene_time(s);
    const bool moved = !st->have_time || now != st->last_time;
    const bool inject = !st->have_time || (moved && (st->has_dynamic || fv_scene_lights_move(s)));
    st->have_time = true;
    st->last_time = now;
    memset(st->moved_count, 0, sizeof st->moved_count);
    st->fovea_cells = 0;
    uint64_t inject_rays = 0;
    int n = 0, m = 0, made = 0, n_old = 0, need = 0;
    fv_stage_clock c0, c1, c2, c3, c4;
    /* One parallel region from the voxels to the VPLs' radiosity (docs/threads.md): each parallel
     * step is a work-sharing loop of the team (fv_team_for, its barrier orders it before the next),
     * each serial step (the management's bookkeeping between them) is done by the thread that opened
     * the region (`master`, so its time counts as serial in --stats) while the others wait at the
     * barrier after it. Every step reads and writes what it did as separate regions. */
    c0 = fv_stage_clock_now();
    fv_region_begin();
#pragma omp parallel num_threads(fv_thread_count(threads))
    {
        if (st->has_dynamic && moved) {
            fv_voxels_update_dynamic(st->vox);
            count_density_voxels(st);
        }
#pragma omp master
        c1 = fv_stage_clock_now();
        if (inject) fv_vpl_inject_team(st->vox, s, frame->seed, (uint64_t)frame->index, st->area_samples, st->scratch, &inject_rays);
#pragma omp master
        c2 = fv_stage_clock_now();
        /* Alg. 2 (no barrier needed before it: the injection's last one ordered everything) */
        fv_vpl_foveated_weights_team(st->vox, cam, &st->vf.gb, pc.gx, pc.gy, pc.R, st->weight, &st->fovea_cells);
        /* Alg. 4 line 3 */
        fv_team_for(st->nvpl, 16, update_range, &pc);
#pragma omp master
        {
            const double ts = fv_time_ms();
            m = manage_after_update(st, &n_old, &need);
            fv_region_serial(fv_time_ms() - ts);
        }
#pragma omp barrier
        fv_team_for(m, 16, candidates_range, &pc);
#pragma omp master
        {
            const double ts = fv_time_ms();
            made = 0;
            for (int j = 0; j < m; j++)
                if (st->cand_ok[j]) st->cand[made++] = st->cand[j];
            st->made_candidates = made;
            fv_region_serial(fv_time_ms() - ts);
        }
#pragma omp barrier
        fv_team_for(made, 8, cand_importance_range, &pc);
#pragma omp master
        {
            const double ts = fv_time_ms();
            n = manage_select(st, frame, made, n_old, need);
            fv_region_serial(fv_time_ms() - ts);
            c3 = fv_stage_clock_now();
        }
#pragma omp barrier
        /* Eq. 3 */
        fv_team_for(n, 8, radiosity_range, &pc);
    }
    fv_region_end();
    c4 = fv_stage_clock_now();
    *rays += inject_rays;

    /* cube maps: every VPL without one, then moved ones and the oldest, up to rebuild x n */
    int budget = st->visibility == 0 ? (int)ceilf(st->rebuild * (float)n) : 0;
    build_key *keys = st->build_keys;
    for (int i = 0; i < n; i++) keys[i] = (build_key){st->vpl[i].built, i};
    qsort(keys, (size_t)n, sizeof *keys, cmp_build_key);
    int must = 0;
    while (st->visibility == 0 && must < n && keys[must].built < 0) must++;
    int nb = budget > must ? budget : must;
    if (nb > n) nb = n;
    for (int k = 0; k < nb; k++) {
        fir_vpl *v = &st->vpl[keys[k].index];
        st->build_pos[k] = v->p;
        st->build_nrm[k] = v->n;
        st->build_idx[k] = v->map;
        v->built = st->frames;
    }
    fv_status status = st->maps ? fv_cubemaps_build_many(st->maps, s, st->build_idx, st->build_pos, st->build_nrm, nb, threads, err) : FV_OK;
    st->built_maps = nb;
    fv_stage_clock c5 = fv_stage_clock_now();
    st->frames++;

    for (int t = 0; t < FV_MAX_THREADS; t++) *rays += pc.rays[t];
    fv_stage_add(stats, "voxelize", c0, c1);
    fv_stage_add(stats, "inject", c1, c2);
    fv_stage_add(stats, "vpl_generation", c2, c3);
    fv_stage_add(stats, "radiosity", c3, c4);
    fv_stage_add(stats, "cube_maps", c4, c5);
    return status;
}

/* ---- shading ---- */

/* The tiles' VPL lists (CSR). */
static void build_tile_lists(fir_state *st)
{
    const int T = st->tiles_x * st->tiles_y;
    memset(st->tile_offset, 0, (size_t)(T + 1) * sizeof *st->tile_offset);
    for (int i = 0; i < st->nvpl; i++) st->tile_offset[st->vpl[i].tile + 1]++;
    for (int t = 0; t < T; t++) st->tile_offset[t + 1] += st->tile_offset[t];
    int *fill = st->tiles; /* reused as cursors */
    for (int t = 0; t < T; t++) fill[t] = st->tile_offset[t];
    for (int i = 0; i < st->nvpl; i++) st->tile_list[fill[st->vpl[i].tile]++] = i;
}

/* Each pixel saw the VPLs of its tile only: an unbiased estimate of the whole set's light is its
 * sum times n / n_tile (Sec. 3.4, interleaved sampling). */
static void scale_tiles(fir_state *st)
{
    const int w = st->vf.gb.width, h = st->vf.gb.height, nx = st->tiles_x;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const int t = (x % nx) + nx * (y % st->tiles_y);
            const int cnt = st->tile_offset[t + 1] - st->tile_offset[t];
            const size_t p = (size_t)y * (size_t)w + (size_t)x;
            st->vf.indirect[p] = cnt > 0 ? fv_scale(st->vf.indirect[p], (float)st->nvpl / (float)cnt) : fv_v3s(0.0f);
        }
}

/* The 5x5 box of Sec. 3.4 over the pixels that hit, as two 1D passes of sums and counts. */
static void box5(fir_state *st)
{
    const int w = st->vf.gb.width, h = st->vf.gb.height;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            fv_vec3 s = fv_v3s(0.0f);
            for (int k = -2; k <= 2; k++) {
                const int xx = x + k;
                if (xx < 0 || xx >= w) continue;
                const size_t q = (size_t)y * (size_t)w + (size_t)xx;
                if (fv_gpixel_hit(&st->vf.gb.px[q])) s = fv_add(s, st->vf.indirect[q]);
            }
            st->tmp[(size_t)y * (size_t)w + (size_t)x] = s;
        }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const size_t p = (size_t)y * (size_t)w + (size_t)x;
            if (!fv_gpixel_hit(&st->vf.gb.px[p])) continue;
            fv_vec3 s = fv_v3s(0.0f);
            int n = 0;
            for (int k = -2; k <= 2; k++) {
                const int yy = y + k;
                if (yy < 0 || yy >= h) continue;
                s = fv_add(s, st->tmp[(size_t)yy * (size_t)w + (size_t)x]);
                for (int l = -2; l <= 2; l++) {
                    const int xx = x + l;
                    if (xx >= 0 && xx < w && fv_gpixel_hit(&st->vf.gb.px[(size_t)yy * (size_t)w + (size_t)xx])) n++;
                }
            }
            st->vf.indirect[p] = fv_scale(s, 1.0f / (float)n);
        }
}

static fv_status filter_indirect(fir_state *st, int threads, fv_error *err)
{
    if (st->filter == FILTER_BOX) {
        box5(st);
        return FV_OK;
    }
    if (st->filter == FILTER_NONE) return FV_OK;
    const size_t n = st->vf.npix;
    float *rgb = st->fbuf, *nrm = st->fbuf + 3 * n, *pos = st->fbuf + 6 * n;
    for (size_t i = 0; i < n; i++) {
        const fv_gpixel *g = &st->vf.gb.px[i];
        const fv_vec3 zero = fv_v3s(0.0f);
        const fv_vec3 nn = fv_gpixel_hit(g) ? g->n : zero, pp = fv_gpixel_hit(g) ? g->p : zero;
        rgb[3 * i] = st->vf.indirect[i].x, rgb[3 * i + 1] = st->vf.indirect[i].y, rgb[3 * i + 2] = st->vf.indirect[i].z;
        nrm[3 * i] = nn.x, nrm[3 * i + 1] = nn.y, nrm[3 * i + 2] = nn.z;
        pos[3 * i] = pp.x, pos[3 * i + 1] = pp.y, pos[3 * i + 2] = pp.z;
    }
    fv_atrous_opts o;
    fv_atrous_opts_default(&o);
    o.sigma_position = INFINITY;
    o.threads = threads;
    o.workspace = st->atrous;
    fv_status s = fv_atrous_filter(rgb, nrm, NULL, st->vf.gb.width, st->vf.gb.height, &o, err);
    if (s != FV_OK) return s;
    for (size_t i = 0; i < n; i++) st->vf.indirect[i] = fv_v3(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
    return FV_OK;
}

static fv_status fir_render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    fir_state *st = state;
    const fv_scene *s = st->scene;
    fv_vpl_frame *vf = &st->vf;
    fv_status status = fv_vpl_frame_begin(vf, s, frame, film, stats, err);
    if (status == FV_OK) status = fir_reserve(st, err);
    bool ok = true;

    /* One VPL set per frame index, managed with the view and gaze of the first eye rendered (the left
     * one, or the only one). A frame rendered again after a cancel keeps the set its first attempt
     * made, so it comes out as if it had not been interrupted. */
    if (status == FV_OK && (!st->managed || st->managed_index != frame->index)) {
        status = manage(st, frame, &vf->cam, stats, &vf->rays, err);
        st->managed = status == FV_OK;
        st->managed_index = frame->index;
    }
    if (status == FV_OK) {
        fv_stage_clock t1 = fv_stage_clock_now();
        build_tile_lists(st);
        fv_vpl_gather g = {s, st->lights, st->visibility == 0 ? st->maps : NULL, (fv_cube_filter)st->cube_filter, 0.0f};
        const float c = fv_vpl_clamp_distance(s, st->clamp);
        g.clamp2 = c * c;
        fv_vpl_tiles tiles = {st->tiles_x, st->tiles_y, st->tile_list, st->tile_offset};
        fv_kit_phase(&vf->prog, frame, 0.0, 0.8);
        ok = fv_vpl_pass_indirect(&g, &vf->gb, &tiles, frame->threads, vf->indirect, vf->counters, &vf->prog);
        if (ok) {
            scale_tiles(st);
            status = filter_indirect(st, frame->threads, err);
        }
        fv_stage_clock t2 = fv_stage_clock_now();
        fv_stage_add(stats, "shading", t1, t2);
        fv_kit_phase(&vf->prog, frame, 0.8, 0.2);
        if (ok && status == FV_OK) ok = fv_vpl_pass_direct(s, &vf->gb, frame, st->area_samples, vf->direct, vf->counters, &vf->prog);
        fv_stage_stop(stats, "direct", t2);
    }
    if (status == FV_OK && ok) {
        fv_stats_add_count(stats, "valid_vpls", st->nvpl);
        fv_stats_add_count(stats, "reused_vpls", st->reused);
        fv_stats_add_count(stats, "new_vpls", st->fresh);
        fv_stats_add_count(stats, "dropped_vpls", st->dropped);
        fv_stats_add_count(stats, "moved_vpls", st->moved);
        fv_stats_add_count(stats, "cube_maps_built", st->built_maps);
        fv_stats_add_count(stats, "candidates", st->made_candidates);
        fv_stats_add_count(stats, "fovea_voxels", st->fovea_cells);
    }
    return fv_vpl_frame_end(vf, (fv_vpl_show)st->show, ok, status, stats, err);
}

static const fv_param_info k_params[] = {
    FV_PARAM_INT("vpls", "1000", 1, 1000000, "TOTALNUMBER, valid VPLs (Sec. 4.1)"),
    FV_PARAM_INT("candidates", "1000", 1, 1000000, "VPL candidates bounced from the fovea per frame (Sec. 3.1)"),
    FV_PARAM_FLOAT("resample", "0.1", 0.0, 1.0, "fraction of vpls resampled from the candidates per frame (Sec. 4.1)"),
    FV_PARAM_INT("resolution", "64", 8, 1024, "voxels along the scene's longest axis (Alg. 1)"),
    FV_PARAM_INT("directions", "32", 1, FV_VPL_MAX_DIRECTIONS, "fixed directions cast per VPL for its importance (Alg. 3)"),
    FV_PARAM_INT("density_grid", "16", 1, 256, "density-grid cells along the longest axis (Alg. 5)"),
    FV_PARAM_INT("density_limit", "4", 1, 1000000, "DENSITYLIMIT, VPLs a density cell may take (Alg. 5)"),
    FV_PARAM_FLOAT("density_c", "1", 1e-6, 1e6, "C in the score Imp + 1/(vd + C) (Alg. 5)"),
    FV_PARAM_FLOAT("drop_importance", "0.01", 0.0, 1.0, "an old VPL below this importance is dropped (Sec. 3.3)"),
    FV_PARAM_FLOAT("drop_normal_deg", "60", 0.0, 180.0, "an old VPL whose voxel normal turned more than this is dropped (Sec. 3.3)"),
    FV_PARAM_INT("tiles_x", "5", 1, 64, "interleaved-sampling tiles across (Sec. 3.4; 5x5 so the 5x5 box sees each tile once)"),
    FV_PARAM_INT("tiles_y", "5", 1, 64, "interleaved-sampling tiles down; tiles_x * tiles_y <= vpls"),
    FV_PARAM_INT("cube_size", "128", FV_CUBE_MIN_SIZE, FV_CUBE_MAX_SIZE, "texels per cube-map face edge of a VPL's depth map (Sec. 4.1)"),
    FV_PARAM_FLOAT("rebuild", "0.2", 0.0, 1.0, "fraction of the VPLs' cube maps rebuilt per frame, new VPLs' always (Sec. 4.1)"),
    FV_CUBE_FILTER_PARAM("cube-map lookup"),
    FV_CUBE_BUILD_PARAM,
    FV_PARAM_CHOICE("filter", "box", k_filters, "filter of the interleaved indirect light (Sec. 3.4: a 5x5 box)"),
    {.key = "radius", .type = FV_PARAM_FLOAT, .def = "0.25", .min = 0.0, .min_open = true, .max = 1.0,
     .help = "foveal radius as a fraction of the image width (Sec. 4.1)"},
    FV_VPL_AREA_SAMPLES_PARAM,
    FV_VPL_CLAMP_PARAM,
    FV_PARAM_CHOICE("visibility", "cube", k_visibility, "VPL visibility from the cube maps (the paper) or exact shadow rays (no maps built)"),
    FV_VPL_SHOW_PARAM,
};

const fv_technique_class fv_technique_fir = {
    .name = "fir",
    .summary = "Foveated Instant Radiosity: VPLs chosen and reused by foveated importance, interleaved shading",
    .family = FV_FAMILY_VPL,
    .baseline = "ir", /* the paper's IR, 2000 VPLs with exact visibility (Tables 1-2) */
    FV_CLASS_PARAMS(k_params),
    .main = {"vpls", {FV_VPL_STEPS}, false},
    .create = fir_create,
    .render = fir_render,
    .destroy = fir_destroy,
    .foveated = true,
    /* VPLs survive from frame to frame while they stay important (the management of manage.c), so
     * a block of an MPI-split sequence starts 8 frames early (docs/distributed.md measures what
     * remains) */
    .warmup_frames = 8,
    /* a still's first frame picks its VPLs without the management's history: its error is 1.15x
     * that of the frames after it (cornell-fir at 128x128), one frame later they have converged */
    .still_warmup_frames = 1,
    /* furnace: emitted 0.5 + direct 0.25 + the VPLs' two bounces 0.1875 = 0.9375; a first frame
     * measures 0.892: its few hundred VPLs' cells and their neighbours cover less of the sphere
     * than a full set's (0.546 of 0.5625 for the VPL term after three frames) */
    .test_params = "vpls=64,candidates=64,resolution=16,cube_size=16,area_samples=2,directions=8",
    .furnace_params = "vpls=1000,resolution=32,cube_size=32,area_samples=16",
    .furnace_radiance = 0.9375,
    .furnace_tolerance = 0.08,
    .spp_instead = FV_VPL_SPP_INSTEAD,
    .bench_scene = FV_VPL_BENCH_SCENE,
};
