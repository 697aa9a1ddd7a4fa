/* fovea — kept static photon paths, refreshed near the dynamic objects (see path_store.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "transport/light_path.h"
#include "technique/photon/path_store.h"

#define BLOCK 2048

/* A ray segment of a walk: o + t d for t in (0, t_end); t_end = inf for a ray that left. */
typedef struct seg {
    fv_vec3 o, d;
    float t_end;
} seg;

struct fv_path_store {
    fv_photon_job job;
    bool ready;
    int64_t count;
    fv_photon *ph;       /* every path's photons, path after path */
    int64_t *pstart;     /* count + 1 offsets into ph */
    seg *sg;
    int64_t *sstart;     /* count + 1 offsets into sg */
    float (*u)[5];       /* each path's emission numbers (what a flux scale may depend on) */
    /* The room the arrays above have (paths, photons, segments): grown, never shrunk, so that
     * tracing the paths again (fpm-guided's M_g, when the focus region moves) allocates nothing
     * once it has grown to what a trace needs (docs/threads.md). */
    int64_t cap_count, cap_ph, cap_sg;
    struct blk *fb;      /* the blocks of a trace or a frame, kept with their buffers (grown, never shrunk) */
    int64_t fb_cap;
};

/* What one block of paths produced, and per path how many photons and segments. */
typedef struct blk {
    fv_photon *p;
    int np, capp;
    seg *s;
    int ns, caps;
    int pn[BLOCK], sn[BLOCK];
    float u[BLOCK][5];
    uint64_t rays;
    bool oom, record;
} blk;

static void keep(void *ctx, const fv_hit *h, const fv_material *m, fv_vec3 dir, fv_vec3 flux)
{
    (void)m;
    blk *b = ctx;
    if (b->oom || fv_grow((void **)&b->p, &b->capp, b->np + 1, sizeof *b->p)) {
        b->oom = true;
        return;
    }
    b->p[b->np++] = fv_photon_make(h->p, dir, flux, h->ng);
}

/* Walk i of the job through `set`: fv_light_path_trace's loop, with its segments recorded when
 * b->record (the same random numbers in the same order, so a walk that meets no dynamic object is
 * the walk the whole scene gives). */
static void walk(const fv_photon_job *job, fv_trace_set set, int64_t i, blk *b, float u[5])
{
    fv_rng rng;
    fv_vec3 o, d, flux;
    if (!fv_photon_emit(job, i, &rng, u, &o, &d, &flux)) return;
    for (int depth = 0; depth < job->max_depth; depth++) {
        fv_hit h;
        b->rays++;
        bool hit = fv_scene_intersect(job->scene, set, o, d, INFINITY, &h);
        if (b->record) {
            if (b->oom || fv_grow((void **)&b->s, &b->caps, b->ns + 1, sizeof *b->s)) {
                b->oom = true;
                return;
            }
            b->s[b->ns++] = (seg){o, d, hit ? h.t : INFINITY};
        }
        if (!hit || !fv_light_path_scatter(job->scene, &h, &o, &d, &flux, &rng, keep, b)) return;
    }
}

fv_status fv_path_store_create(fv_path_store **out, fv_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory");
}

/* No paths (the room is kept). */
static void clear(fv_path_store *p)
{
    p->count = 0;
    p->ready = false;
}

void fv_path_store_destroy(fv_path_store *p)
{
    if (!p) return;
    free(p->ph), free(p->pstart), free(p->sg), free(p->sstart), free(p->u);
    for (int64_t k = 0; k < p->fb_cap; k++) free(p->fb[k].p), free(p->fb[k].s);
    free(p->fb);
    free(p);
}

bool fv_path_store_ready(const fv_path_store *p) { return p->ready; }

/* *ptr with room for need elements of size bytes (*cap of them now): replaced by a larger block
 * when short, its contents not kept. 0 on success. */
static int room_for(void **ptr, int64_t *cap, int64_t need, size_t size)
{
    if (need <= *cap) return 0;
    void *q = fv_alloc_array((size_t)need, size);
    if (!q) return -1;
    free(*ptr);
    *ptr = q;
    *cap = need;
    return 0;
}

/* The store's n blocks, emptied (their buffers kept), or NULL when out of memory. */
static struct blk *blocks(fv_path_store *p, int64_t n);

typedef struct trace_job {
    fv_path_store *p;
    const fv_photon_job *job;
    blk *b;
} trace_job;

/* Block k of the paths, recorded into its own output. */
static void trace_block(void *ctx, int64_t k)
{
    const trace_job *t = ctx;
    const fv_photon_job *job = t->job;
    blk *o = &t->b[k];
    o->record = true;
    int64_t end = (k + 1) * BLOCK < job->count ? (k + 1) * BLOCK : job->count;
    for (int64_t i = k * BLOCK; i < end; i++) {
        int np = o->np, ns = o->ns;
        walk(job, FV_TRACE_STATIC, i, o, t->p->u[i]);
        o->pn[i - k * BLOCK] = o->np - np;
        o->sn[i - k * BLOCK] = o->ns - ns;
    }
}

fv_status fv_path_store_trace(fv_path_store *p, const fv_photon_job *job, uint64_t *rays, fv_error *err)
{
    clear(p);
    p->job = *job;
    if (job->count <= 0 || fv_scene_light_count(job->scene) == 0) {
        p->ready = true;
        return FV_OK;
    }
    int64_t nblocks = (job->count + BLOCK - 1) / BLOCK;
    blk *b = blocks(p, nblocks);
    const int64_t need = job->count + 1;
    if (b && p->cap_count < need) {
        /* grown together: cap_count is the room all three have */
        int64_t cp = p->cap_count, cs = p->cap_count, cu = p->cap_count;
        if (room_for((void **)&p->pstart, &cp, need, sizeof *p->pstart) == 0 && room_for((void **)&p->sstart, &cs, need, sizeof *p->sstart) == 0 &&
            room_for((void **)&p->u, &cu, need, sizeof *p->u) == 0)
            p->cap_count = need;
    }
    if (!b || p->cap_count < need) {
        clear(p);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory keeping %lld photon paths", (long long)job->count);
    }
    memset(p->u, 0, (size_t)job->count * sizeof *p->u); /* a path that emits nothing keeps zeros */
    trace_job tj = {p, job, b};
    bool stop = !fv_photon_blocks(job, nblocks, trace_block, &tj);
    /* Concatenated in block order: the store does not depend on the thread count. */
    fv_status st = stop ? fv_error_set(err, FV_ERR_CANCELLED, "render cancelled") : FV_OK;
    int64_t tp = 0, ts = 0;
    for (int64_t k = 0; k < nblocks; k++) {
        if (b[k].oom && st == FV_OK) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory keeping photon paths");
        tp += b[k].np, ts += b[k].ns;
    }
    if (st == FV_OK && (room_for((void **)&p->ph, &p->cap_ph, tp + 1, sizeof *p->ph) || room_for((void **)&p->sg, &p->cap_sg, ts + 1, sizeof *p->sg)))
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory keeping photon paths");
    int64_t op = 0, os = 0;
    for (int64_t k = 0; k < nblocks; k++) {
        if (st == FV_OK) {
            if (b[k].np) memcpy(p->ph + op, b[k].p, (size_t)b[k].np * sizeof *p->ph);
            if (b[k].ns) memcpy(p->sg + os, b[k].s, (size_t)b[k].ns * sizeof *p->sg);
            int64_t first = k * BLOCK, end = (k + 1) * BLOCK < job->count ? (k + 1) * BLOCK : job->count;
            for (int64_t i = first; i < end; i++) {
                p->pstart[i] = op, p->sstart[i] = os;
                op += b[k].pn[i - first], os += b[k].sn[i - first];
            }
        }
        if (rays) *rays += b[k].rays;
    }
    if (st != FV_OK) {
        clear(p);
        return st;
    }
    p->pstart[job->count] = op, p->sstart[job->count] = os;
    p->count = job->count;
    p->ready = true;
    return FV_OK;
}

/* Whether segment s passes within r of c (conservatively: its line's closest approach inside the
 * segment's extent, or an end point inside the sphere). */
static bool meets(const seg *s, fv_vec3 c, float r)
{
    fv_vec3 v = fv_sub(c, s->o);
    float dd = fv_dot(s->d, s->d), t = fv_dot(v, s->d) / dd;
    if (t < 0.0f) t = 0.0f;
    if (t > s->t_end) t = s->t_end;
    fv_vec3 q = fv_sub(v, fv_scale(s->d, t));
    return fv_dot(q, q) <= r * r;
}

/* The blocks and their photon and segment buffers are the store's, kept from frame to frame: once
 * they have grown to what a frame (or a trace) needs, it allocates nothing (docs/threads.md). */
static blk *blocks(fv_path_store *p, int64_t n)
{
    if (n > p->fb_cap) {
        blk *nb = realloc(p->fb, (size_t)n * sizeof *nb);
        if (!nb) return NULL;
        memset(nb + p->fb_cap, 0, ((size_t)(n - p->fb_cap)) * sizeof *nb);
        p->fb = nb;
        p->fb_cap = n;
    }
    for (int64_t k = 0; k < n; k++) p->fb[k].np = p->fb[k].ns = 0, p->fb[k].rays = 0, p->fb[k].oom = p->fb[k].record = false;
    return p->fb;
}

fv_status fv_path_store_frame(fv_path_store *p, const fv_dyn_dirs *dirs, fv_path_scale_fn scale, const void *scale_ctx,
                              int threads, fv_photon_map *out, int64_t *retraced, uint64_t *rays, fv_error *err)
{
    *retraced = 0;
    const int nsph = dirs ? fv_dyn_dirs_count(dirs) : 0;
    if (nsph == 0 && !scale) return fv_photon_map_append(out, p->ph, (int)(p->count ? p->pstart[p->count] : 0), err);
    enum { MAXS = 64 };
    fv_vec3 c[MAXS];
    float r[MAXS];
    const int n = nsph < MAXS ? nsph : MAXS;
    for (int k = 0; k < n; k++) fv_dyn_dirs_sphere(dirs, k, &c[k], &r[k]);
    int64_t nblocks = (p->count + BLOCK - 1) / BLOCK;
    blk *b = blocks(p, nblocks + 1);
    if (!b) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    int64_t again = 0;
    fv_region_begin();
    #pragma omp parallel for schedule(dynamic, 1) reduction(+ : again) num_threads(fv_thread_count(threads))
    for (int64_t k = 0; k < nblocks; k++) {
        blk *o = &b[k];
        int64_t end = (k + 1) * BLOCK < p->count ? (k + 1) * BLOCK : p->count;
        for (int64_t i = k * BLOCK; i < end; i++) {
            bool hit = nsph > MAXS; /* more objects than we test: retrace everything */
            for (int64_t j = p->sstart[i]; j < p->sstart[i + 1] && !hit; j++)
                for (int q = 0; q < n && !hit; q++) hit = meets(&p->sg[j], c[q], r[q]);
            int first = o->np;
            if (hit) {
                float u[5];
                walk(&p->job, FV_TRACE_ALL, i, o, u);
                again++;
            } else {
                int m = (int)(p->pstart[i + 1] - p->pstart[i]);
                if (m == 0) continue; /* a path that stored nothing (nor may o->p exist yet) */
                if (o->oom || fv_grow((void **)&o->p, &o->capp, o->np + m, sizeof *o->p)) {
                    o->oom = true;
                    continue;
                }
                if (m > 0) memcpy(o->p + o->np, p->ph + p->pstart[i], (size_t)m * sizeof *o->p); /* o->p may still be NULL */
                o->np += m;
            }
            if (scale && o->np > first) {
                float f = scale(scale_ctx, p->u[i]);
                for (int j = first; j < o->np; j++) o->p[j].flux = fv_scale(o->p[j].flux, f);
            }
        }
    }
    fv_region_end();
    fv_status st = FV_OK;
    for (int64_t k = 0; k < nblocks; k++) {
        if (b[k].oom && st == FV_OK) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory for this frame's photons");
        if (st == FV_OK) st = fv_photon_map_append(out, b[k].p, b[k].np, err);
        if (rays) *rays += b[k].rays;
    }
    *retraced = again;
    return st;
}
