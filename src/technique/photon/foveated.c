/* fovea — foveated photon tracing (PT_f) and temporal photon management (see foveated.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "kernel/kbsdf.h"
#include "technique/photon/foveated.h"

struct fv_foveated {
    int w, h, n, max_depth;
    uint8_t *focus, *focus_prev, *claimed;
    int *fbm, *fbm_prev;
    int32_t *fbp, *fbp_prev;       /* w * h * n path ids, -1 for an empty slot */
    /* Pool of static paths: path i owns pool[i * max_depth ..], len[i] photons (0: free). */
    fv_fov_photon *pool;
    uint8_t *len;
    int cap, *free_ids, nfree, live;
    fv_photon_map fs, fd;
    bool has_prev;
    /* Scratch kept from frame to frame, so that a warmed-up frame allocates nothing
     * (docs/threads.md): manage's source pixels (w * h), and trace's tasks and their paths
     * (task_cap of each, grown, never shrunk). */
    int *src;
    int *task_px;
    struct path_out *res;
    long task_cap;
};

fv_status fv_foveated_create(int w, int h, int n, int max_depth, fv_foveated **out, fv_error *err)
{
    if (n < 1 || n > 64) return fv_error_set(err, FV_ERR_INVALID, "foveated photons: paths per pixel %d must be in [1, 64]", n);
    if (max_depth < 1 || max_depth > FV_FOV_MAX_DEPTH)
        return fv_error_set(err, FV_ERR_INVALID, "foveated photons: max depth %d must be in [1, %d]", max_depth, FV_FOV_MAX_DEPTH);
    fv_foveated *f = calloc(1, sizeof *f);
    if (!f) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    size_t np = (size_t)w * h;
    f->w = w;
    f->h = h;
    f->n = n;
    f->max_depth = max_depth;
    f->focus = calloc(np, 1);
    f->focus_prev = calloc(np, 1);
    f->claimed = calloc(np, 1);
    f->fbm = calloc(np, sizeof(int));
    f->fbm_prev = calloc(np, sizeof(int));
    f->fbp = fv_alloc_array(np * (size_t)n, sizeof(int32_t));
    f->fbp_prev = fv_alloc_array(np * (size_t)n, sizeof(int32_t));
    f->src = fv_alloc_array(np, sizeof(int));
    fv_photon_map_init(&f->fs);
    fv_photon_map_init(&f->fd);
    if (!f->focus || !f->focus_prev || !f->claimed || !f->fbm || !f->fbm_prev || !f->fbp || !f->fbp_prev || !f->src) {
        fv_foveated_destroy(f);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the foveated photon buffers of %dx%d", w, h);
    }
    memset(f->fbp, 0xff, np * (size_t)n * sizeof(int32_t));
    memset(f->fbp_prev, 0xff, np * (size_t)n * sizeof(int32_t));
    *out = f;
    return FV_OK;
}

void fv_foveated_destroy(fv_foveated *f)
{
    if (!f) return;
    free(f->focus);
    free(f->focus_prev);
    free(f->claimed);
    free(f->fbm);
    free(f->fbm_prev);
    free(f->fbp);
    free(f->fbp_prev);
    free(f->pool);
    free(f->len);
    free(f->free_ids);
    free(f->src);
    free(f->task_px);
    free(f->res);
    fv_photon_map_free(&f->fs);
    fv_photon_map_free(&f->fd);
    free(f);
}

const fv_photon_map *fv_foveated_static_map(const fv_foveated *f) { return &f->fs; }
const fv_photon_map *fv_foveated_dynamic_map(const fv_foveated *f) { return &f->fd; }

void fv_foveated_pool(const fv_foveated *f, int *live, int *capacity)
{
    *live = f->live;
    *capacity = f->cap;
}

static void free_path(fv_foveated *f, int32_t id)
{
    if (id < 0 || id >= f->cap || f->len[id] == 0) return;
    f->len[id] = 0;
    f->free_ids[f->nfree++] = id;
    f->live--;
}

static fv_status alloc_path(fv_foveated *f, int32_t *id, fv_error *err)
{
    if (f->nfree == 0) {
        int nc = f->cap ? 2 * f->cap : 1024;
        fv_fov_photon *pool = realloc(f->pool, (size_t)nc * f->max_depth * sizeof *pool);
        if (pool) f->pool = pool;
        uint8_t *len = pool ? realloc(f->len, (size_t)nc) : NULL;
        if (len) f->len = len;
        int *fr = len ? realloc(f->free_ids, (size_t)nc * sizeof(int)) : NULL;
        if (!fr) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for %d foveated photon paths", nc);
        f->free_ids = fr;
        for (int i = nc - 1; i >= f->cap; i--) {
            f->len[i] = 0;
            f->free_ids[f->nfree++] = i;
        }
        f->cap = nc;
    }
    *id = f->free_ids[--f->nfree];
    f->live++;
    return FV_OK;
}

static void focus_mask(const fv_eye_model *eye, fv_gaze g, uint8_t *mask, int w, int h)
{
    double rt = fv_eye_transition_radius_px(eye);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) mask[(size_t)y * w + x] = fv_eye_gaze_dist_px(eye, g, x + 0.5, y + 0.5) <= rt;
}

fv_status fv_foveated_manage(fv_foveated *f, const fv_scene *s, const fv_camera *cam, const fv_camera *prev, const fv_eye_model *eye,
                             fv_gaze gaze, int threads, fv_fov_stats *st, fv_error *err)
{
    size_t np = (size_t)f->w * f->h;
    int n = f->n;
    /* Alg. 2 lines 1-4: keep last frame's fbm, fbp and focus; start this frame's afresh. */
    int *tm = f->fbm_prev;
    f->fbm_prev = f->fbm;
    f->fbm = tm;
    int32_t *tp = f->fbp_prev;
    f->fbp_prev = f->fbp;
    f->fbp = tp;
    uint8_t *tf = f->focus_prev;
    f->focus_prev = f->focus;
    f->focus = tf;
    focus_mask(eye, gaze, f->focus, f->w, f->h);
    memset(f->fbp, 0xff, np * (size_t)n * sizeof(int32_t));
    for (size_t i = 0; i < np; i++) f->fbm[i] = f->focus[i] ? n : 0;
    memset(f->claimed, 0, np);
    fv_camera_basis cb, pb;
    fv_status rc = fv_camera_basis_make(cam, &cb, err);
    if (rc != FV_OK) return rc;
    bool have_prev = f->has_prev && prev && fv_camera_basis_make(prev, &pb, err) == FV_OK;
    /* Lines 5-7, one row per task: back-project each focus pixel with V, project with V'. */
    int *src = f->src;
    int nthreads = fv_thread_count(threads);
    fv_region_begin();
    #pragma omp parallel for schedule(dynamic, 4) num_threads(nthreads)
    for (int y = 0; y < f->h; y++)
        for (int x = 0; x < f->w; x++) {
            size_t i = (size_t)y * f->w + x;
            src[i] = -1;
            if (!f->focus[i]) continue;
            fv_hit hit;
            fv_vec3 d = fv_camera_dir(&cb, x + 0.5f, y + 0.5f);
            if (!have_prev || !fv_scene_intersect(s, FV_TRACE_ALL, cb.pos, d, INFINITY, &hit)) continue;
            float px, py;
            if ( !fv_camera_project(&pb, hit.p, &px, &py) || px < 0 || py < 0 || px >= f->w || py >= f->h) continue;
            int q = (int)py * f->w + (int)px;
            bool ok = !fv_scene_object_dynamic(s, hit.obj) && fv_bsdf_is_smooth(fv_scene_material(s, hit.mat));
            src[i] = ok ? q : -2 - q; /* -2 - q: v is not on a static diffuse surface */
        }
    fv_region_end();
    /* Lines 8-12. Each previous pixel's paths go to at most one current pixel (the first to claim
     * it, in pixel order). */
    for (size_t i = 0; i < np; i++) {
        if (src[i] == -1) continue;
        int q = src[i] >= 0 ? src[i] : -2 - src[i];
        if (!f->focus_prev[q] || f->claimed[q]) continue;
        f->claimed[q] = 1;
        if (src[i] >= 0) {
            int k = 0;
            for (int j = 0; j < n; j++) {
                int32_t id = f->fbp_prev[(size_t)q * n + j];
                if (id >= 0) f->fbp[i * n + k++] = id;
            }
            f->fbm[i] = n - k;
            if (st) st->paths_reused += k;
        } else {
            for (int j = 0; j < n; j++) {
                int32_t id = f->fbp_prev[(size_t)q * n + j];
                if (id >= 0 && st) st->paths_deleted++;
                free_path(f, id);
                f->fbp_prev[(size_t)q * n + j] = -1;
            }
        }
    }
    /* Paths of previous pixels no current pixel took over have left the focus region (or are
     * hidden now): delete them so the maps do not grow. */
    for (size_t q = 0; q < np; q++) {
        if (f->claimed[q]) continue;
        for (int j = 0; j < n; j++) {
            int32_t id = f->fbp_prev[q * n + j];
            if (id >= 0 && st) st->paths_deleted++;
            free_path(f, id);
            f->fbp_prev[q * n + j] = -1;
        }
    }
    f->has_prev = true;
    return FV_OK;
}

/* ---- tracing one path ---- */

typedef struct path_out {
    int len;
    bool dynamic;
    fv_fov_photon ph[FV_FOV_MAX_DEPTH];
} path_out;

typedef struct trace_ctx {
    const fv_scene *s;
    const fv_camera_basis *cb;
    const fv_photon_map *ls, *ld;
    float radius;
    int max_depth;
    uint64_t seed;
    int frame;
} trace_ctx;

/* The nearest light photon to x on a surface facing n, from M_ls or M_ld, or NULL. */
static const fv_photon *nearest_light(const trace_ctx *c, fv_vec3 x, fv_vec3 n, int32_t *idx, uint8_t *map)
{
    float d_ls = INFINITY, d_ld = INFINITY;
    int a = fv_photon_map_nearest(c->ls, x, n, c->radius, &d_ls);
    int b = fv_photon_map_nearest(c->ld, x, n, c->radius, &d_ld);
    if (a < 0 && b < 0) return NULL;
    if (b >= 0 && (a < 0 || d_ld < d_ls)) {
        *idx = b;
        *map = 1;
        return &c->ld->p[b];
    }
    *idx = a;
    *map = 0;
    return &c->ls->p[a];
}

static void trace_path(const trace_ctx *c, int px, int py, int attempt, path_out *out)
{
    const fv_scene *s = c->s;
    out->len = 0;
    out->dynamic = false;
    fv_rng rng = fv_rng_stream(c->seed, FV_STREAM_FOVEATED, (uint64_t)py * c->cb->width + px, (uint64_t)attempt, (uint64_t)c->frame);
    fv_vec3 o = c->cb->pos, d = fv_camera_dir(c->cb, px + fv_rng_next(&rng), py + fv_rng_next(&rng));
    fv_vec3 chain = fv_v3s(1.0f);             /* mirror/glass weights since the last vertex */
    fv_vec3 chains[FV_FOV_MAX_DEPTH], transfer[FV_FOV_MAX_DEPTH], dout[FV_FOV_MAX_DEPTH];
    const fv_photon *last_q = NULL;
    bool ended = false;
    for (int depth = 0; depth < c->max_depth; depth++) {
        fv_hit h;
        if (!fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h)) {
            ended = true;
            break;
        }
        fv_material mbuf;
        const fv_material *m = fv_hit_material(s, &h, &mbuf);
        if (out->len > 0 && fv_max3(m->emission) > 0.0f) { /* reached the light: the last photon holds direct light */
            ended = true;
            break;
        }
        if (fv_scene_object_dynamic(s, h.obj)) out->dynamic = true;
        fv_shading sh;
        fv_shading_make(m, h.ng, h.ns, fv_neg(d), &sh);
        fv_vec3 ng = sh.ng;
        if (!fv_bsdf_is_smooth(m)) {
            /* Mirrors and glass: the laws of reflection and refraction (Sec. 3.1). */
            fv_bsdf_sample bs;
            float u0 = fv_rng_next(&rng), u1 = fv_rng_next(&rng), u2 = fv_rng_next(&rng);
            if (!fv_bsdf_sample_dir(m, sh.wo, FV_TRANSPORT_IMPORTANCE, u0, u1, u2, &bs)) {
                ended = true;
                break;
            }
            fv_vec3 wi = fv_shading_to_world(&sh, bs.wi);
            chain = fv_mul(chain, bs.weight);
            o = fv_offset_point(s, h.p, h.ng, wi);
            d = wi;
            continue;
        }
        int32_t qi;
        uint8_t qm;
        const fv_photon *q = nearest_light(c, h.p, ng, &qi, &qm);
        if (!q || fv_luminance(q->flux) <= 0.0f) { /* no light here, or a negative photon: stop */
            ended = true;
            break;
        }
        if (qm == 1) out->dynamic = true;
        int k = out->len++;
        fv_fov_photon *fp = &out->ph[k];
        fp->p.pos = h.p;
        fp->p.n = ng;
        fp->nearl = qi;
        fp->nearl_map = qm;
        chains[k] = chain;
        chain = fv_v3s(1.0f);
        /* The flux a photon keeps when a diffuse or glossy surface reflects it. */
        transfer[k] = fv_vmin(fv_add(m->albedo, m->type == FV_MAT_GLOSSY ? m->specular : fv_v3s(0.0f)), fv_v3s(1.0f));
        last_q = q;
        float survive = fv_minf(0.95f, fv_max3(transfer[k]));
        if (!(fv_rng_next(&rng) < survive)) {
            dout[k] = fv_neg(q->dir);
            ended = true;
            break;
        }
        fv_vec3 nd = fv_neg(q->dir); /* towards where the nearest light photon's light came from */
        dout[k] = nd;
        if (fv_dot(nd, ng) <= 0.0f) {
            ended = true;
            break;
        }
        o = fv_offset_point(s, h.p, h.ng, nd);
        d = nd;
    }
    /* A path still going at the maximum depth is removed whole (Sec. 3.1). */
    if (!ended || out->len == 0) {
        out->len = 0;
        return;
    }
    /* Flux: the last photon takes its nearest light photon's, the others receive it along the path. */
    int k = out->len - 1;
    out->ph[k].p.flux = last_q->flux;
    out->ph[k].p.dir = last_q->dir;
    out->ph[k].nextf = -1;
    for (int i = k - 1; i >= 0; i--) {
        out->ph[i].p.flux = fv_mul(fv_mul(out->ph[i + 1].p.flux, transfer[i + 1]), chains[i + 1]);
        out->ph[i].p.dir = fv_neg(dout[i]);
        out->ph[i].nextf = i + 1;
    }
}

fv_status fv_foveated_trace(fv_foveated *f, const fv_scene *s, const fv_camera *cam, const fv_photon_map *m_ls, const fv_photon_map *m_ld,
                            float radius, float cell, uint64_t seed, int frame, int threads, fv_fov_stats *st, fv_error *err)
{
    fv_camera_basis cb;
    fv_status rc = fv_camera_basis_make(cam, &cb, err);
    if (rc != FV_OK) return rc;
    size_t np = (size_t)f->w * f->h;
    if (!f->has_prev) { /* first frame: the focus mask was set by fv_foveated_manage */
        for (size_t i = 0; i < np; i++) f->fbm[i] = f->focus[i] ? f->n : 0;
        f->has_prev = true;
    }
    /* The tasks: (pixel, attempt) for every path a pixel still needs. */
    long ntasks = 0;
    for (size_t i = 0; i < np; i++) ntasks += f->fbm[i] > 0 ? f->fbm[i] : 0;
    if (ntasks > f->task_cap) {
        int *tp = fv_alloc_array((size_t)ntasks, sizeof(int));
        path_out *r = fv_alloc_array((size_t)ntasks, sizeof *r);
        if (!tp || !r) {
            free(tp);
            free(r);
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory tracing %ld foveated photon paths", ntasks);
        }
        free(f->task_px);
        free(f->res);
        f->task_px = tp;
        f->res = r;
        f->task_cap = ntasks;
    }
    int *task_px = f->task_px;
    path_out *res = f->res;
    long t = 0;
    for (size_t i = 0; i < np; i++)
        for (int k = 0; k < f->fbm[i]; k++) task_px[t++] = (int)i;
    trace_ctx c = {s, &cb, m_ls, m_ld, radius, f->max_depth, seed, frame};
    int nthreads = fv_thread_count(threads);
    fv_region_begin();
    #pragma omp parallel for schedule(dynamic, 64) num_threads(nthreads)
    for (long j = 0; j < ntasks; j++) {
        int px = task_px[j] % f->w, py = task_px[j] / f->w;
        /* The random stream of a path: its pixel, its task number and the frame. */
        trace_path(&c, px, py, (int)j, &res[j]);
    }
    fv_region_end();
    /* Merge in task order (deterministic): static paths into the pool and fbp, dynamic ones
     * into M_fd. */
    fv_photon_map_clear(&f->fd);
    rc = FV_OK;
    for (long j = 0; j < ntasks && rc == FV_OK; j++) {
        path_out *p = &res[j];
        size_t i = (size_t)task_px[j];
        if (st) st->paths_traced++;
        if (p->len == 0) {
            if (st) st->paths_failed++;
            continue;
        }
        if (p->dynamic) {
            for (int k = 0; k < p->len && rc == FV_OK; k++) rc = fv_photon_map_push(&f->fd, &p->ph[k].p, err);
            if (st) st->paths_dynamic++, st->photons_dynamic += p->len;
            continue;
        }
        int32_t id = -1;
        if ((rc = alloc_path(f, &id, err)) != FV_OK) break;
        fv_fov_photon *dst = &f->pool[(size_t)id * f->max_depth];
        for (int k = 0; k < p->len; k++) {
            dst[k] = p->ph[k];
            if (dst[k].nextf >= 0) dst[k].nextf = id * f->max_depth + dst[k].nextf;
        }
        f->len[id] = (uint8_t)p->len;
        for (int k = 0; k < f->n; k++)
            if (f->fbp[i * f->n + k] < 0) {
                f->fbp[i * f->n + k] = id;
                break;
            }
        if (st) st->paths_stored_static++;
    }
    if (rc != FV_OK) return rc;
    /* What each pixel still lacks: paths that turned out dynamic or failed are traced again next
     * frame. */
    for (size_t i = 0; i < np; i++) {
        if (!f->focus[i]) {
            f->fbm[i] = 0;
            continue;
        }
        int k = 0;
        for (int j = 0; j < f->n; j++) k += f->fbp[i * f->n + j] >= 0;
        f->fbm[i] = f->n - k;
    }
    /* M_fs from the live paths, then both grids (linear-time rebuilds). */
    fv_photon_map_clear(&f->fs);
    for (int id = 0; id < f->cap && rc == FV_OK; id++)
        for (int k = 0; k < f->len[id] && rc == FV_OK; k++) rc = fv_photon_map_push(&f->fs, &f->pool[(size_t)id * f->max_depth + k].p, err);
    if (st) st->photons_static = f->fs.n;
    if (rc == FV_OK) rc = fv_photon_map_build_mt(&f->fs, cell, threads, err);
    if (rc == FV_OK) rc = fv_photon_map_build_mt(&f->fd, cell, threads, err);
    return rc;
}

double fv_foveated_eta(const float *light, const float *fov, const uint8_t *mask, size_t n)
{
    double l = 0.0, f = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (!mask[i]) continue;
        if (light[i] > 0.0f) l += light[i];
        if (fov[i] > 0.0f) f += fov[i];
    }
    return f > 0.0 && l > 0.0 ? l / (l + f) : 1.0;
}
