/* fovea — the trace stage of Visual-Polar path tracing and its baselines (see trace.h). */
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "technique/vpolar/trace.h"

typedef struct trace_ctx {
    const fv_vp_trace_job *job;
    fv_kvp_trace_frame kf;
    const fv_vp_gbuf *g;
    const fv_grid *grid;
    fv_kit_counters *counters; /* rays, NaN, paths (FV_KIT_USER0) */
} trace_ctx;

double fv_vp_survival(const fv_space_view *v, float px, float py, double px_per_deg, double e0, double e1, double p)
{
    const fv_kvp_view kv = fv_space_kview(v);
    return fv_kvp_survival(&kv, px, py, px_per_deg, e0, e1, p);
}

void fv_vp_trace_kframe(const fv_vp_trace_job *job, fv_kvp_trace_frame *out)
{
    memset(out, 0, sizeof *out);
    const fv_space *sp = job->view.space;
    out->space = *fv_space_kernel(sp);
    out->view = fv_space_kview(&job->view);
    out->col_h = fv_space_grid(sp)->col_h;
    out->cam = job->cam;
    out->pt = job->pt;
    out->seed = job->frame->seed;
    out->eye = job->frame->eye;
    out->index = job->frame->index;
    out->onscreen = job->skip_offscreen ? job->onscreen : NULL;
    out->kill = job->kill;
    out->kill_e0 = job->kill_e0, out->kill_e1 = job->kill_e1, out->kill_p = job->kill_p;
    out->px_per_deg = job->px_per_deg;
}

/* Traces up to eight samples (grid pixel indices, -1 for an empty lane) as one camera packet: each
 * placed and stored by the kernel's steps (technique/vpolar/kvp_trace.h), the camera rays through Embree. */
static void trace_packet(trace_ctx *c, const long *pix, int thread)
{
    const fv_vp_trace_job *j = c->job;
    const fv_vp_gbuf *g = c->g;
    fv_vec3 dir[8];
    fv_rng rng[8];
    bool active[8];
    fv_hit hits[8];
    bool ok[8];
    int nactive = 0;
    for (int k = 0; k < 8; k++) {
        active[k] = false;
        dir[k] = j->cam.forward;
        if (pix[k] < 0) continue;
        long i = pix[k];
        bool go = fv_kvp_sample_ray(&c->kf, i, &rng[k], &dir[k]);
        g->sampled[i] = go;
        if (!go) {
            fv_kvp_store_miss(g, i);
            continue;
        }
        active[k] = true;
        nactive++;
    }
    if (!nactive) return;
    fv_scene_intersect8_active(j->scene, j->cam.pos, dir, active, hits, ok);
    uint64_t rays = 0, bad = 0;
    for (int k = 0; k < 8; k++) {
        if (!active[k]) continue;
        long i = pix[k];
        fv_path_first_hit first;
        memset(&first, 0, sizeof first);
        fv_vec3 L = fv_kit_guard(fv_path_trace_from(j->scene, &j->pt, j->cam.pos, dir[k], &hits[k], ok[k], &rng[k], &first, &rays), &bad);
        /* spp > 1: more paths through the same camera ray (its hit is shared), averaged. */
        for (int n = 1; n < j->pt.spp; n++)
            L = fv_add(L, fv_kit_guard(fv_path_trace_from(j->scene, &j->pt, j->cam.pos, dir[k], &hits[k], ok[k], &rng[k], NULL, &rays), &bad));
        if (j->pt.spp > 1) L = fv_scale(L, 1.0f / (float)j->pt.spp);
        fv_kvp_store_sample(g, i, L, &first);
    }
    fv_kit_count(c->counters, thread, FV_KIT_RAYS, rays);
    fv_kit_count(c->counters, thread, FV_KIT_USER0, (uint64_t)nactive);
    fv_kit_count(c->counters, thread, FV_KIT_NAN, bad);
}

static void grid_tile(void *ctx, const fv_tile *t)
{
    trace_ctx *c = ctx;
    const int w = c->grid->w;
    for (int y = t->y0; y < t->y1; y++)
        for (int x0 = t->x0; x0 < t->x1; x0 += 8) {
            long pix[8];
            for (int k = 0; k < 8; k++) {
                int x = x0 + k;
                pix[k] = x < t->x1 && fv_grid_valid(c->grid, x, y) ? (long)y * w + x : -1;
            }
            trace_packet(c, pix, t->thread);
        }
}

static void random_range(void *ctx, int64_t b, int64_t e, int thread)
{
    trace_ctx *c = ctx;
    for (int64_t i = b; i < e; i += 8) {
        long pix[8];
        for (int k = 0; k < 8; k++) pix[k] = i + k < e ? (long)c->job->perm[i + k] : -1;
        trace_packet(c, pix, thread);
    }
}

bool fv_vp_trace(const fv_vp_trace_job *job, const fv_vp_gbuf *g, fv_vp_trace_result *res)
{
    trace_ctx ctx, *c = &ctx;
    memset(res, 0, sizeof *res);
    memset(c, 0, sizeof *c);
    if (!(c->counters = job->counters)) return true; /* the caller checks res->paths against the grid */
    c->job = job;
    c->g = g;
    c->grid = fv_space_grid(job->view.space);
    fv_vp_trace_kframe(job, &c->kf);
    const fv_grid *grid = c->grid;
    bool done = true;
    if (job->order == FV_VP_ORDER_RANDOM && job->perm)
        done = fv_parallel_for_progress(job->nperm, 4096, job->frame->threads, random_range, c, fv_kit_progress_fn, job->progress);
    else
        done = fv_parallel_tiles(grid->w, grid->h, job->frame->threads, grid_tile, c, fv_kit_progress_fn, job->progress);
    res->rays = fv_kit_sum(c->counters, FV_KIT_RAYS);
    res->paths = fv_kit_sum(c->counters, FV_KIT_USER0);
    res->nan_paths = fv_kit_sum(c->counters, FV_KIT_NAN);
    return done;
}

uint32_t *fv_vp_random_order(const fv_grid *g, uint64_t seed, long *n)
{
    long count = 0;
    for (int x = 0; x < g->w; x++) count += fv_grid_col_h(g, x);
    uint32_t *p = fv_alloc_array((size_t)count, sizeof(uint32_t));
    if (!p) return NULL;
    long k = 0;
    for (int y = 0; y < g->h; y++)
        for (int x = 0; x < g->w; x++)
            if (fv_grid_valid(g, x, y)) p[k++] = (uint32_t)((long)y * g->w + x);
    /* Fisher-Yates with the counter-based generator. */
    fv_rng r = fv_rng_stream(seed, FV_STREAM_ORDER, 0, 0, 0);
    for (long i = count - 1; i > 0; i--) {
        uint64_t hi = fv_rng_u32(&r);
        uint64_t lo = fv_rng_u32(&r);
        long j = (long)((hi << 32 | lo) % (uint64_t)(i + 1));
        uint32_t t = p[i];
        p[i] = p[j];
        p[j] = t;
    }
    *n = count;
    return p;
}
