/* fovea — light photon tracing (PT_s, full) and dynamic-object photon tracing (PT_d) with the
 * light-space direction maps (see photon_trace.h). */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "scene/light.h"
#include "technique/photon/photon_trace.h"
#include "transport/light_path.h"

#define BLOCK 2048

/* Photons of one block of emitted photons, gathered by one thread. */
typedef struct block_out {
    fv_photon *p;
    int n, cap;
    uint64_t rays;
    bool oom;
} block_out;

struct fv_photon_room {
    block_out *blocks;
    int64_t cap; /* blocks held, each with its photon buffer */
};

fv_photon_room *fv_photon_room_create(void) { return calloc(1, sizeof(fv_photon_room)); }

void fv_photon_room_destroy(fv_photon_room *r)
{
    if (!r) return;
    for (int64_t b = 0; b < r->cap; b++) free(r->blocks[b].p);
    free(r->blocks);
    free(r);
}

/* nblocks empty blocks from the room (grown to hold them; each block keeps its buffer), or NULL
 * when out of memory. */
static block_out *room_blocks(fv_photon_room *r, int64_t nblocks)
{
    if (nblocks > r->cap) {
        block_out *nb = realloc(r->blocks, (size_t)nblocks * sizeof *nb);
        if (!nb) return NULL;
        memset(nb + r->cap, 0, (size_t)(nblocks - r->cap) * sizeof *nb);
        r->blocks = nb;
        r->cap = nblocks;
    }
    for (int64_t b = 0; b < nblocks; b++) {
        r->blocks[b].n = 0;
        r->blocks[b].rays = 0;
        r->blocks[b].oom = false;
    }
    return r->blocks;
}

/* The light path's visit: a photon is stored at every diffuse or glossy vertex. */
static void deposit(void *ctx, const fv_hit *h, const fv_material *m, fv_vec3 dir, fv_vec3 flux)
{
    (void)m; /* a photon keeps its flux; the gather applies the receiving BSDF, at the gather's point */
    block_out *b = ctx;
    if (b->oom) return;
    if (fv_grow((void **)&b->p, &b->cap, b->n + 1, sizeof *b->p)) {
        b->oom = true;
        return;
    }
    b->p[b->n++] = fv_photon_make(h->p, dir, flux, h->ng);
}

/* ---- running blocks of photons in parallel, deterministically ---- */

typedef struct run_ctx {
    const fv_photon_job *job;
    fv_trace_set set;
    const fv_dyn_dirs *dirs;
    block_out *blocks;
} run_ctx;

typedef void (*photon_fn)(const run_ctx *c, int64_t i, block_out *out);

bool fv_photon_blocks(const fv_photon_job *job, int64_t nblocks, fv_photon_block_fn fn, void *ctx)
{
    int64_t done = 0;
    int stop = 0;
    fv_region_begin();
    #pragma omp parallel for schedule(dynamic, 1) num_threads(fv_thread_count(job->threads))
    for (int64_t b = 0; b < nblocks; b++) {
        int halt;
        #pragma omp atomic read
        halt = stop;
        if (halt) continue;
        fn(ctx, b);
        int64_t d;
        #pragma omp atomic capture
        d = ++done;
        /* Progress from one thread only, so the callback never runs concurrently with itself. */
        if (job->progress && omp_get_thread_num() == 0 && !fv_kit_progress_fn(job->progress, (double)d / nblocks)) {
            #pragma omp atomic write
            stop = 1;
        }
    }
    fv_region_end();
    return !stop;
}

typedef struct block_job {
    run_ctx *c;
    photon_fn fn;
} block_job;

static void run_block(void *ctx, int64_t b)
{
    block_job *j = ctx;
    const fv_photon_job *job = j->c->job;
    int64_t end = (b + 1) * BLOCK < job->count ? (b + 1) * BLOCK : job->count;
    for (int64_t i = b * BLOCK; i < end; i++) j->fn(j->c, i, &j->c->blocks[b]);
}

static fv_status run_blocks(run_ctx *c, photon_fn fn, fv_photon_map *out, uint64_t *rays, fv_error *err)
{
    const fv_photon_job *job = c->job;
    int64_t nblocks = (job->count + BLOCK - 1) / BLOCK;
    c->blocks = job->room ? room_blocks(job->room, nblocks) : fv_calloc_array((size_t)nblocks, sizeof *c->blocks);
    if (!c->blocks) return fv_error_set(err, FV_ERR_NOMEM, "out of memory tracing %lld photons", (long long)job->count);
    block_job bj = {c, fn};
    bool stop = !fv_photon_blocks(job, nblocks, run_block, &bj);
    fv_status st = stop ? fv_error_set(err, FV_ERR_CANCELLED, "render cancelled") : FV_OK;
    for (int64_t b = 0; b < nblocks; b++) {
        if (c->blocks[b].oom && st == FV_OK) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory storing photons");
        if (st == FV_OK) st = fv_photon_map_append(out, c->blocks[b].p, c->blocks[b].n, err);
        if (rays) *rays += c->blocks[b].rays;
        if (!job->room) free(c->blocks[b].p);
    }
    if (!job->room) free(c->blocks);
    c->blocks = NULL;
    return st;
}

static fv_rng photon_rng(const fv_photon_job *job, int64_t i, uint64_t sub)
{
    return fv_rng_stream(job->seed, FV_STREAM_PHOTONS(job->stream), (uint64_t)i, sub, (uint64_t)job->frame);
}

bool fv_photon_emit(const fv_photon_job *job, int64_t i, fv_rng *rng, float u[5], fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux)
{
    *rng = photon_rng(job, i, 0);
    if (!job->warp) {
        /* fv_light_path_emit's five numbers, kept for the caller */
        for (int k = 0; k < 5; k++) u[k] = fv_rng_next(rng);
        return fv_light_path_emit_u(job->scene, u, job->count, o, d, flux);
    }
    float q = job->warp(job->warp_ctx, rng, u);
    if (!(q > 0.0f) || !fv_light_path_emit_u(job->scene, u, job->count, o, d, flux)) return false;
    *flux = fv_scale(*flux, 1.0f / q);
    return true;
}

static void light_photon(const run_ctx *c, int64_t i, block_out *out)
{
    const fv_photon_job *job = c->job;
    fv_rng rng;
    float u[5];
    fv_vec3 o, d, flux;
    if (!fv_photon_emit(job, i, &rng, u, &o, &d, &flux)) return;
    fv_light_path_trace(job->scene, c->set, o, d, flux, 0, job->max_depth, &rng, deposit, out, &out->rays);
}

fv_status fv_photon_trace_lights(const fv_photon_job *job, fv_trace_set set, fv_photon_map *out, uint64_t *rays, fv_error *err)
{
    if (job->count <= 0 || fv_scene_light_count(job->scene) == 0) return FV_OK;
    run_ctx c = {job, set, NULL, NULL};
    return run_blocks(&c, light_photon, out, rays, err);
}

/* ---- directions towards the dynamic objects (the paper's light cube map) ---- */

typedef struct dyn_sphere {
    fv_vec3 c;
    float r;
} dyn_sphere;

struct fv_dyn_dirs {
    dyn_sphere *sph;
    int n, cap;
};

fv_status fv_dyn_dirs_create(fv_dyn_dirs **out, fv_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
}

void fv_dyn_dirs_destroy(fv_dyn_dirs *d)
{
    if (!d) return;
    free(d->sph);
    free(d);
}

int fv_dyn_dirs_count(const fv_dyn_dirs *d) { return d->n; }

void fv_dyn_dirs_sphere(const fv_dyn_dirs *d, int k, fv_vec3 *c, float *r)
{
    *c = d->sph[k].c;
    *r = d->sph[k].r;
}

fv_status fv_dyn_dirs_build(fv_dyn_dirs *d, const fv_scene *s, fv_error *err)
{
    d->n = 0;
    for (int i = 0; i < fv_scene_object_count(s); i++) {
        if (!fv_scene_object_dynamic(s, i)) continue;
        /* The bounding sphere of the object's box at the current time. */
        fv_vec3 lo, hi;
        fv_scene_object_bounds(s, i, &lo, &hi);
        if (fv_grow((void **)&d->sph, &d->cap, d->n + 1, sizeof *d->sph)) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        d->sph[d->n].c = fv_scale(fv_add(lo, hi), 0.5f);
        d->sph[d->n].r = 0.5f * fv_length(fv_sub(hi, lo)) * 1.001f + fv_scene_ray_eps(s);
        d->n++;
    }
    return FV_OK;
}

/* Cosine of the half-angle of the cone sphere k subtends from x; -1 when x is inside it. */
static float cone_cos(const dyn_sphere *k, fv_vec3 x, fv_vec3 *axis)
{
    fv_vec3 v = fv_sub(k->c, x);
    float d2 = fv_dot(v, v);
    if (d2 <= k->r * k->r) {
        *axis = fv_v3(0, 0, 1);
        return -1.0f;
    }
    float d = sqrtf(d2);
    *axis = fv_scale(v, 1.0f / d);
    return sqrtf(fv_maxf(0.0f, 1.0f - k->r * k->r / d2));
}

/* Samples origin, direction and the power of a PT_d photon (to be divided by the photon count):
 * a light by power, a point on it, one dynamic object by the solid angle of its bounding sphere
 * seen from that point, and a direction uniform in that cone. The direction's density sums the
 * cones of every object that contains it, so overlapping objects are not counted twice. */
static bool dyn_sample(const fv_scene *s, const fv_dyn_dirs *d, fv_rng *rng, fv_vec3 *o, fv_vec3 *dir, fv_vec3 *power)
{
    fv_light_point lp;
    if (d->n == 0 || !fv_light_pick_point(s, rng, &lp)) return false;
    float pmf_l = lp.pmf;
    *o = lp.p;
    if (lp.directional) { /* parallel light from its disc: no cone to aim */
        *dir = lp.n;
        return fv_light_point_power(s, &lp, *dir, pmf_l, power) && fv_max3(*power) > 0.0f;
    }
    enum { MAXO = 64 };
    float cosm[MAXO], omega[MAXO], total = 0.0f;
    fv_vec3 axis[MAXO];
    int n = d->n < MAXO ? d->n : MAXO;
    for (int k = 0; k < n; k++) {
        cosm[k] = cone_cos(&d->sph[k], *o, &axis[k]);
        omega[k] = 2.0f * FV_PI * (1.0f - cosm[k]);
        total += omega[k];
    }
    if (!(total > 0.0f)) return false;
    float pick = fv_rng_next(rng) * total;
    int k = 0;
    while (k + 1 < n && pick >= omega[k]) pick -= omega[k++];
    /* Uniform direction in the cone around axis[k]. */
    float ct = 1.0f - fv_rng_next(rng) * (1.0f - cosm[k]), st = sqrtf(fv_maxf(0.0f, 1.0f - ct * ct)), ph = 2.0f * FV_PI * fv_rng_next(rng);
    fv_vec3 t, bt;
    fv_basis(axis[k], &t, &bt);
    *dir = fv_normalize(fv_from_local(fv_v3(st * cosf(ph), st * sinf(ph), ct), t, bt, axis[k]));
    float pdf_w = 0.0f;
    for (int j = 0; j < n; j++)
        if (cosm[j] <= -1.0f || fv_dot(*dir, axis[j]) >= cosm[j]) pdf_w += (omega[j] / total) / omega[j];
    if (!(pdf_w > 0.0f)) return false;
    if (!fv_light_point_power(s, &lp, *dir, pmf_l * pdf_w, power)) return false;
    if (!lp.delta) *o = fv_offset_point(s, *o, lp.n, *dir);
    return fv_max3(*power) > 0.0f;
}

static void dynamic_photon(const run_ctx *c, int64_t i, block_out *out)
{
    const fv_photon_job *job = c->job;
    const fv_scene *s = job->scene;
    fv_rng rng = photon_rng(job, i, 2);
    fv_vec3 o, d, power;
    if (!dyn_sample(s, c->dirs, &rng, &o, &d, &power)) return;
    fv_vec3 flux = fv_scale(power, 1.0f / (float)job->count);
    fv_hit h;
    out->rays++;
    if (!fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h) || !fv_scene_object_dynamic(s, h.obj)) return;
    /* Negative photon: straight through the object, then on as the static map's photon would. */
    fv_rng neg = photon_rng(job, i, 3);
    fv_light_path_trace(s, FV_TRACE_STATIC, h.p, d, fv_neg(flux), 0, job->max_depth, &neg, deposit, out, &out->rays);
    /* Positive photon: the object's own material decides. */
    fv_vec3 po = o, pd = d, pf = flux;
    if (fv_light_path_scatter(s, &h, &po, &pd, &pf, &rng, deposit, out))
        fv_light_path_trace(s, FV_TRACE_ALL, po, pd, pf, 1, job->max_depth, &rng, deposit, out, &out->rays);
}

fv_status fv_photon_trace_dynamic(const fv_photon_job *job, const fv_dyn_dirs *dirs, fv_photon_map *out, uint64_t *rays, fv_error *err)
{
    if (job->count <= 0 || !dirs || dirs->n == 0) return FV_OK;
    run_ctx c = {job, FV_TRACE_ALL, dirs, NULL};
    return run_blocks(&c, dynamic_photon, out, rays, err);
}
