/* fovea — light photon tracing (PT_s, full) and dynamic-object photon tracing (PT_d) with the
 * light-space direction maps (see photon_trace.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "scene/bsdf.h"
#include "scene/light.h"
#include "technique/photon/photon_trace.h"

#define BLOCK 2048

/* Photons of one block of emitted photons, gathered by one thread. */
typedef struct block_out {
    fv_photon *p;
    int n, cap;
    uint64_t rays;
    bool oom;
} block_out;

static void deposit(block_out *b, fv_vec3 pos, fv_vec3 dir, fv_vec3 flux, fv_vec3 ng)
{
    if (b->oom) return;
    if (fv_grow((void **)&b->p, &b->cap, b->n + 1, sizeof *b->p)) {
        b->oom = true;
        return;
    }
    fv_photon *ph = &b->p[b->n++];
    ph->pos = pos;
    ph->dir = dir;
    ph->flux = flux;
    ph->n = fv_dot(ng, dir) < 0.0f ? ng : fv_neg(ng); /* the side the photon came from */
}

/* Stores the photon at hit h if the surface is diffuse or glossy, then scatters it: returns false
 * when the path ends (absorbed, Russian roulette, no valid direction). */
static bool store_and_scatter(const fv_scene *s, const fv_hit *h, fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux, fv_rng *rng, block_out *out)
{
    const fv_material *m = &s->mats[h->mat];
    if (fv_bsdf_is_smooth(m)) deposit(out, h->p, *d, *flux, h->ng);
    fv_vec3 wo = fv_neg(*d);
    fv_shading sh;
    fv_shading_make(m, h->ng, h->ns, wo, &sh);
    fv_bsdf_sample bs;
    float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
    if (!fv_bsdf_sample_dir(m, sh.wo, FV_TRANSPORT_IMPORTANCE, u0, u1, u2, &bs)) return false;
    fv_vec3 wi = fv_shading_to_world(&sh, bs.wi);
    bool reflect = bs.wi.z * sh.wo.z > 0.0f;
    if ((fv_dot(wi, h->ng) * fv_dot(wo, h->ng) > 0.0f) != reflect) return false;
    /* Russian roulette on the change of power: the surviving photon keeps about the flux it had. */
    fv_vec3 nf = fv_mul(*flux, bs.weight);
    float before = fv_max3(fv_vmax(*flux, fv_neg(*flux))), after = fv_max3(fv_vmax(nf, fv_neg(nf)));
    float q = before > 0.0f ? fv_minf(1.0f, after / before) : 0.0f;
    if (!(fv_rng_next(rng) < q)) return false;
    *flux = fv_scale(nf, 1.0f / q);
    *o = fv_offset_point(s, h->p, h->ng, wi);
    *d = wi;
    return true;
}

/* Follows a photon from o along d; `depth` bounces are already behind it. */
static void trace_path(const fv_scene *s, fv_trace_set set, fv_vec3 o, fv_vec3 d, fv_vec3 flux, int depth, int max_depth, fv_rng *rng,
                       block_out *out)
{
    for (; depth < max_depth; depth++) {
        fv_hit h;
        out->rays++;
        if (!fv_scene_intersect(s, set, o, d, INFINITY, &h)) return;
        if (!store_and_scatter(s, &h, &o, &d, &flux, rng, out)) return;
    }
}

/* ---- running blocks of photons in parallel, deterministically ---- */

typedef struct run_ctx {
    const fv_photon_job *job;
    fv_trace_set set;
    const fv_dyn_dirs *dirs;
    block_out *blocks;
} run_ctx;

typedef void (*photon_fn)(const run_ctx *c, int64_t i, block_out *out);

static fv_status run_blocks(run_ctx *c, photon_fn fn, fv_photon_map *out, uint64_t *rays, fv_error *err)
{
    const fv_photon_job *job = c->job;
    int64_t nblocks = (job->count + BLOCK - 1) / BLOCK;
    c->blocks = fv_calloc_array((size_t)nblocks, sizeof *c->blocks);
    if (!c->blocks) return fv_error_set(err, FV_ERR_NOMEM, "out of memory tracing %lld photons", (long long)job->count);
    int nthreads = fv_thread_count(job->threads);
    #pragma omp parallel for schedule(dynamic, 1) num_threads(nthreads)
    for (int64_t b = 0; b < nblocks; b++) {
        int64_t end = (b + 1) * BLOCK < job->count ? (b + 1) * BLOCK : job->count;
        for (int64_t i = b * BLOCK; i < end; i++) fn(c, i, &c->blocks[b]);
    }
    fv_status st = FV_OK;
    for (int64_t b = 0; b < nblocks; b++) {
        if (c->blocks[b].oom && st == FV_OK) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory storing photons");
        if (st == FV_OK) st = fv_photon_map_append(out, c->blocks[b].p, c->blocks[b].n, err);
        if (rays) *rays += c->blocks[b].rays;
        free(c->blocks[b].p);
    }
    free(c->blocks);
    c->blocks = NULL;
    return st;
}

static fv_rng photon_rng(const fv_photon_job *job, int64_t i, uint64_t sub)
{
    return fv_rng_make(job->seed ^ (job->stream * 0x9e3779b97f4a7c15ULL), (uint64_t)i, sub, (uint64_t)job->frame);
}

static void light_photon(const run_ctx *c, int64_t i, block_out *out)
{
    const fv_photon_job *job = c->job;
    fv_rng rng = photon_rng(job, i, 0);
    float u[5];
    for (int k = 0; k < 5; k++) u[k] = fv_rng_next(&rng);
    fv_vec3 o, d, power, n;
    if (!fv_light_sample_emission(job->scene, u, &o, &d, &power, &n)) return;
    if (fv_dot(n, n) > 0.0f) o = fv_offset_point(job->scene, o, n, d);
    trace_path(job->scene, c->set, o, d, fv_scale(power, 1.0f / (float)job->count), 0, job->max_depth, &rng, out);
}

fv_status fv_photon_trace_lights(const fv_photon_job *job, fv_trace_set set, fv_photon_map *out, uint64_t *rays, fv_error *err)
{
    if (job->count <= 0 || job->scene->nlights == 0) return FV_OK;
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

fv_status fv_dyn_dirs_build(fv_dyn_dirs *d, const fv_scene *s, fv_error *err)
{
    d->n = 0;
    for (int i = 0; i < s->nobj; i++) {
        const fv_object *o = &s->objs[i];
        if (!o->dynamic) continue;
        /* The bounding sphere of the object's box, moved to the current time. */
        fv_vec3 lo = fv_v3s(INFINITY), hi = fv_v3s(-INFINITY);
        for (int k = 0; k < 8; k++) {
            fv_vec3 p = fv_v3(k & 1 ? o->hi.x : o->lo.x, k & 2 ? o->hi.y : o->lo.y, k & 4 ? o->hi.z : o->lo.z);
            p = fv_xform_point(&o->xf, p);
            lo = fv_vmin(lo, p);
            hi = fv_vmax(hi, p);
        }
        if (fv_grow((void **)&d->sph, &d->cap, d->n + 1, sizeof *d->sph)) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        d->sph[d->n].c = fv_scale(fv_add(lo, hi), 0.5f);
        d->sph[d->n].r = 0.5f * fv_length(fv_sub(hi, lo)) * 1.001f + s->eps;
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
    if (d->n == 0 || s->nlights == 0) return false;
    float u = fv_rng_next(rng);
    int lo = 0, hi = s->nlights - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (s->light_cdf[mid + 1] <= u) lo = mid + 1;
        else hi = mid;
    }
    const fv_light *l = &s->lights[lo];
    float pmf_l = s->light_cdf[lo + 1] - s->light_cdf[lo];
    if (!(pmf_l > 0.0f)) return false;
    if (l->kind == 0) {
        *o = l->desc.pos;
    } else {
        fv_vec3 a, b, c;
        fv_scene_triangle(s, l->obj, l->prim, &a, &b, &c);
        float su = sqrtf(fv_rng_next(rng)), u1 = fv_rng_next(rng), ba = 1.0f - su, bb = u1 * su;
        *o = fv_add(fv_add(fv_scale(a, ba), fv_scale(b, bb)), fv_scale(c, 1.0f - ba - bb));
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
    if (l->kind == 0) {
        *power = fv_scale(fv_light_delta_intensity(l, *dir), 1.0f / (pmf_l * pdf_w));
    } else {
        float c = fv_dot(l->n, *dir);
        if (!(c > 0.0f || (l->two_sided && c < 0.0f))) return false;
        *power = fv_scale(l->emission, fabsf(c) * l->area / (pmf_l * pdf_w));
        *o = fv_offset_point(s, *o, l->n, *dir);
    }
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
    if (!fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h) || !s->objs[h.obj].dynamic) return;
    /* Negative photon: straight through the object, then on as the static map's photon would. */
    fv_rng neg = photon_rng(job, i, 3);
    trace_path(s, FV_TRACE_STATIC, h.p, d, fv_neg(flux), 0, job->max_depth, &neg, out);
    /* Positive photon: the object's own material decides. */
    fv_vec3 po = o, pd = d, pf = flux;
    if (store_and_scatter(s, &h, &po, &pd, &pf, &rng, out)) trace_path(s, FV_TRACE_ALL, po, pd, pf, 1, job->max_depth, &rng, out);
}

fv_status fv_photon_trace_dynamic(const fv_photon_job *job, const fv_dyn_dirs *dirs, fv_photon_map *out, uint64_t *rays, fv_error *err)
{
    if (job->count <= 0 || !dirs || dirs->n == 0) return FV_OK;
    run_ctx c = {job, FV_TRACE_ALL, dirs, NULL};
    return run_blocks(&c, dynamic_photon, out, rays, err);
}
