/* fovea — the render of the sphere-tracing family (pipeline.h). */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/parallel.h"
#include "core/stage_time.h"
#include "core/rng.h"
#include "filter/blur.h"
#include "technique/kit.h"
#include "technique/sdf/pipeline.h"

/* fipr's middle level kept between frames, per eye: the colours the pixels outside the mask are
 * reconstructed from, and the frame each was last shaded in (refreshed every 1, 2 or 4 frames). */
typedef struct eye_history {
    int sw, sh;      /* the target grid it belongs to; another size starts afresh */
    float *color;    /* 3 per middle-level ray */
    int *stamp;      /* frame index of the last shading, INT_MIN: never */
} eye_history;

struct fv_sdf_pipeline {
    const fv_scene *scene;
    fv_sdf_opts o;
    eye_history hist[2];
    /* scratch for the current size */
    int w, h, S, sw, sh;
    fv_pyramid_level lv[FV_PYRAMID_MAX_LEVELS];
    float *depth[FV_PYRAMID_MAX_LEVELS];     /* levels 0 .. L-2: where each ray stopped, +inf: missed */
    uint16_t *steps[FV_PYRAMID_MAX_LEVELS];  /* levels 0 .. L-2 */
    uint8_t *need;     /* fipr, middle level: 0 skip, 1 depth only, 2 depth and colour */
    uint8_t *edge;     /* fipr, level 0 */
    uint8_t *mask;     /* fipr, pixels: 1 traced at the target level */
    float *heat;       /* pixels: camera-ray steps per sample */
    uint8_t *level_of; /* pixels */
    float *sigma;      /* fipr pass 5, pixels */
    uint32_t *vis;     /* shadow_reuse: which lights reach each hit of level L-2 (shade.h) */
};

static void free_scratch(fv_sdf_pipeline *p)
{
    for (int k = 0; k < FV_PYRAMID_MAX_LEVELS; k++) {
        free(p->depth[k]);
        free(p->steps[k]);
        p->depth[k] = NULL;
        p->steps[k] = NULL;
    }
    free(p->need);
    free(p->edge);
    free(p->mask);
    free(p->heat);
    free(p->level_of);
    free(p->sigma);
    free(p->vis);
    p->vis = NULL;
    p->need = p->edge = p->mask = p->level_of = NULL;
    p->heat = p->sigma = NULL;
    p->w = p->h = 0;
}

static void free_history(eye_history *h)
{
    free(h->color);
    free(h->stamp);
    memset(h, 0, sizeof *h);
}

fv_status fv_sdf_pipeline_create(const fv_scene *scene, const fv_sdf_opts *o, fv_sdf_pipeline **out, fv_error *err)
{
    fv_sdf_pipeline *p = calloc(1, sizeof *p);
    if (!p) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    p->scene = scene;
    p->o = *o;
    *out = p;
    return FV_OK;
}

void fv_sdf_pipeline_destroy(fv_sdf_pipeline *p)
{
    if (!p) return;
    free_scratch(p);
    free_history(&p->hist[0]);
    free_history(&p->hist[1]);
    free(p);
}

static int samples_per_axis(int spp) { return spp >= 16 ? 4 : spp >= 4 ? 2 : 1; }

static fv_status ensure_size(fv_sdf_pipeline *p, int w, int h, fv_error *err)
{
    const int S = samples_per_axis(p->o.spp), L = p->o.levels;
    if (p->w == w && p->h == h && p->S == S) return FV_OK;
    free_scratch(p);
    p->S = S;
    p->sw = w * S;
    p->sh = h * S;
    fv_pyramid_levels(p->sw, p->sh, L, p->lv);
    bool ok = true;
    for (int k = 0; k + 1 < L; k++) {
        size_t n = (size_t)p->lv[k].w * p->lv[k].h;
        ok &= (p->depth[k] = fv_alloc_array(n, sizeof(float))) != NULL;
        ok &= (p->steps[k] = fv_calloc_array(n, sizeof(uint16_t))) != NULL;
    }
    if (p->o.shadow_reuse && L > 1) ok &= (p->vis = fv_alloc_array((size_t)p->lv[L - 2].w * p->lv[L - 2].h, sizeof(uint32_t))) != NULL;
    size_t np = (size_t)w * h;
    ok &= (p->heat = fv_alloc_array(np, sizeof(float))) != NULL;
    ok &= (p->level_of = fv_alloc_array(np, 1)) != NULL;
    if (p->o.method == FV_SDF_FIPR) {
        const fv_pyramid_level *mid = &p->lv[L - 2];
        ok &= (p->need = fv_alloc_array((size_t)mid->w * mid->h, 1)) != NULL;
        ok &= (p->edge = fv_alloc_array((size_t)p->lv[0].w * p->lv[0].h, 1)) != NULL;
        ok &= (p->mask = fv_alloc_array(np, 1)) != NULL;
        ok &= (p->sigma = fv_alloc_array(np, sizeof(float))) != NULL;
    }
    if (!ok) {
        free_scratch(p);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d sphere-tracing pyramid at %d spp", w, h, p->o.spp);
    }
    p->w = w;
    p->h = h;
    return FV_OK;
}

static fv_status ensure_history(fv_sdf_pipeline *p, int eye, int index, fv_error *err)
{
    eye_history *hs = &p->hist[eye];
    const fv_pyramid_level *mid = &p->lv[p->o.levels - 2];
    size_t n = (size_t)mid->w * mid->h;
    if (hs->sw != p->sw || hs->sh != p->sh || !hs->color) {
        free_history(hs);
        hs->color = fv_calloc_array(n * 3, sizeof(float));
        hs->stamp = fv_alloc_array(n, sizeof(int));
        if (!hs->color || !hs->stamp) {
            free_history(hs);
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory for fipr's history");
        }
        hs->sw = p->sw;
        hs->sh = p->sh;
        index = 0;
    }
    /* a sequence's first frame starts without history */
    if (index == 0)
        for (size_t i = 0; i < n; i++) hs->stamp[i] = INT_MIN;
    return FV_OK;
}

/* ---- one frame's shared context ---- */

typedef struct job {
    fv_sdf_pipeline *p;
    const fv_frame *frame;
    fv_sdf_world world;
    fv_camera_basis cam;
    fv_film_views out;
    float foot;              /* a target sample's angular footprint per unit distance */
    int level;               /* the level of a level pass */
    eye_history *hist;
    fv_kit_counters *c;      /* RAYS (all rays), NAN, USER0 steps, USER1 shadow steps, USER2 normal evals, USER3 exhausted, USER4 shadow rays */
    fv_kit_counters *lsteps; /* per level: steps */
    fv_kit_counters *lrays;  /* per level: rays */
    fv_status status[FV_MAX_THREADS];
} job;

enum { C_STEPS = FV_KIT_USER0, C_SHADOW = FV_KIT_USER1, C_NORMAL = FV_KIT_USER2, C_EXHAUSTED = FV_KIT_USER3, C_SHADOW_RAYS = FV_KIT_USER4 };

/* What shading cost on this thread. */
static void count_shading(job *j, int thread, const fv_sdf_shade_counts *sc)
{
    fv_kit_count(j->c, thread, C_SHADOW, sc->shadow_steps);
    fv_kit_count(j->c, thread, C_NORMAL, sc->normal_evals);
    fv_kit_count(j->c, thread, C_SHADOW_RAYS, sc->shadow_rays);
}

/* The camera ray through target-grid position (sx, sy), its range clipped to the world's box. */
static void camera_ray(const job *j, float sx, float sy, float eps_k, fv_march_ray *r)
{
    const int S = j->p->S;
    r->o = j->cam.pos;
    r->d = fv_camera_dir(&j->cam, sx / (float)S, sy / (float)S);
    if (!fv_sdf_world_clip(&j->world, r->o, r->d, &r->t0, &r->t1)) r->t0 = 1.0f, r->t1 = 0.0f;
    r->eps = j->world.eps_abs;
    r->eps_k = eps_k;
}

/* Marches and (when colour is not NULL) shades n rays, counting what they cost on this thread. */
static void trace(job *j, int thread, int level, fv_march_ray *rays, fv_march_hit *hits, int n, const uint32_t *vis_in, fv_vec3 *colour,
                  fv_vec3 *normal)
{
    fv_sdf_pipeline *p = j->p;
    fv_march(&j->world, &p->o.march, rays, hits, n, false);
    uint64_t steps = 0, exhausted = 0;
    for (int i = 0; i < n; i++) steps += hits[i].steps, exhausted += hits[i].exhausted;
    fv_kit_count(j->c, thread, C_STEPS, steps);
    fv_kit_count(j->c, thread, C_EXHAUSTED, exhausted);
    fv_kit_count(j->c, thread, FV_KIT_RAYS, (uint64_t)n);
    fv_kit_count(j->lsteps, thread, level, steps);
    fv_kit_count(j->lrays, thread, level, (uint64_t)n);
    if (!colour) return;
    fv_sdf_shade_counts sc = {0, 0, 0};
    fv_error e;
    fv_status s = fv_sdf_shade(&j->world, &p->o.march, &p->o.shade, rays, hits, n, vis_in, NULL, colour, normal, &sc, &e);
    if (s != FV_OK) j->status[thread] = s;
    count_shading(j, thread, &sc);
}

/* ---- a lower level: every ray (or, for fipr's middle level, those `need` asks for) ---- */

/* Shades (colour NULL: visibility only) a compacted batch of a level's rays, counting the cost;
 * with shadow_reuse the visibility lands in p->vis at the rays' indices. */
static void shade_level(job *j, int thread, fv_march_ray *rays, fv_march_hit *hits, const int *at, int n, fv_vec3 *colour)
{
    fv_sdf_pipeline *p = j->p;
    if (n == 0) return;
    fv_sdf_shade_counts sc = {0, 0, 0};
    fv_error e;
    uint32_t *bits = p->vis ? malloc((size_t)n * sizeof *bits) : NULL;
    fv_status s = p->vis && !bits ? FV_ERR_NOMEM
                                   : fv_sdf_shade(&j->world, &p->o.march, &p->o.shade, rays, hits, n, NULL, bits, colour, NULL, &sc, &e);
    if (s != FV_OK) j->status[thread] = s;
    if (bits && s == FV_OK)
        for (int r = 0; r < n; r++) p->vis[at[r]] = bits[r];
    free(bits);
    count_shading(j, thread, &sc);
}

static void level_tile(void *ctx, const fv_tile *tile)
{
    job *j = ctx;
    fv_sdf_pipeline *p = j->p;
    const int k = j->level;
    const fv_pyramid_level *lv = &p->lv[k];
    const bool below_target = k == p->o.levels - 2;
    const int cap = (tile->x1 - tile->x0) * (tile->y1 - tile->y0);
    fv_march_ray *rays = malloc((size_t)cap * sizeof *rays), *vrays = malloc((size_t)cap * sizeof *vrays);
    fv_march_hit *hits = malloc((size_t)cap * sizeof *hits), *vhits = malloc((size_t)cap * sizeof *vhits);
    int *at = malloc((size_t)cap * sizeof *at), *vat = calloc((size_t)cap, sizeof *vat);
    fv_vec3 *colour = p->need ? malloc((size_t)cap * sizeof *colour) : NULL;
    if (!rays || !vrays || !hits || !vhits || !at || !vat || (p->need && !colour)) {
        j->status[tile->thread] = FV_ERR_NOMEM;
        goto done;
    }
    const float eps_k = p->o.hit * j->foot;
    int n = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++) {
            size_t i = (size_t)y * lv->w + x;
            if (p->need && below_target && !p->need[i]) {
                p->depth[k][i] = 0.0f; /* not read: no mask pixel starts from it */
                p->steps[k][i] = 0;
                if (p->vis) p->vis[i] = FV_SDF_VIS_UNKNOWN;
                continue;
            }
            float sx, sy;
            fv_pyramid_centre(lv, p->sw, p->sh, x, y, &sx, &sy);
            camera_ray(j, sx, sy, eps_k, &rays[n]);
            if (k > 0) rays[n].t0 = fmaxf(rays[n].t0, fv_pyramid_start(p->depth[k - 1], &p->lv[k - 1], x >> 1, y >> 1, p->o.min_filter));
            at[n++] = (int)i;
        }
    trace(j, tile->thread, k, rays, hits, n, NULL, NULL, NULL);
    /* Below the target: fipr's rays due for a refresh are shaded (colour kept in its history);
     * with shadow_reuse the others get their visibility only. */
    int ns = 0, nv = 0;
    for (int r = 0; r < n; r++) {
        p->depth[k][at[r]] = hits[r].hit ? hits[r].t : INFINITY;
        p->steps[k][at[r]] = hits[r].steps;
        if (!below_target) continue;
        if (p->need && p->need[at[r]] == 2) {
            rays[ns] = rays[r];
            hits[ns] = hits[r];
            at[ns++] = at[r];
        } else if (p->vis) {
            vrays[nv] = rays[r];
            vhits[nv] = hits[r];
            vat[nv++] = at[r];
        }
    }
    shade_level(j, tile->thread, vrays, vhits, vat, nv, NULL);
    shade_level(j, tile->thread, rays, hits, at, ns, colour);
    uint64_t bad = 0;
    for (int r = 0; r < ns; r++) {
        fv_vec3 c = fv_kit_guard(colour[r], &bad);
        float *dst = &j->hist->color[3 * (size_t)at[r]];
        dst[0] = c.x, dst[1] = c.y, dst[2] = c.z;
        j->hist->stamp[at[r]] = j->frame->index;
    }
    fv_kit_count(j->c, tile->thread, FV_KIT_NAN, bad);
done:
    free(rays);
    free(vrays);
    free(hits);
    free(vhits);
    free(at);
    free(vat);
    free(colour);
}

/* ---- the target level, per film tile ---- */

/* Reconstruction of a pixel outside fipr's mask: its samples read the middle level bilinearly. */
static fv_vec3 reconstruct(const job *j, int x, int y)
{
    const fv_sdf_pipeline *p = j->p;
    const fv_pyramid_level *mid = &p->lv[p->o.levels - 2];
    const int S = p->S;
    const float *col = j->hist->color;
    fv_vec3 sum = fv_v3s(0.0f);
    for (int b = 0; b < S; b++)
        for (int a = 0; a < S; a++) {
            /* the sample's centre in the middle level's ray coordinates (ray i at 2i + 1) */
            float u = ((float)(x * S + a) + 0.5f) / (float)mid->f - 0.5f, v = ((float)(y * S + b) + 0.5f) / (float)mid->f - 0.5f;
            int i0 = (int)floorf(u), j0 = (int)floorf(v);
            float fu = u - (float)i0, fv = v - (float)j0;
            int i1 = i0 + 1, j1 = j0 + 1;
            i0 = i0 < 0 ? 0 : i0 >= mid->w ? mid->w - 1 : i0;
            i1 = i1 < 0 ? 0 : i1 >= mid->w ? mid->w - 1 : i1;
            j0 = j0 < 0 ? 0 : j0 >= mid->h ? mid->h - 1 : j0;
            j1 = j1 < 0 ? 0 : j1 >= mid->h ? mid->h - 1 : j1;
            const float *c00 = &col[3 * ((size_t)j0 * mid->w + i0)], *c10 = &col[3 * ((size_t)j0 * mid->w + i1)];
            const float *c01 = &col[3 * ((size_t)j1 * mid->w + i0)], *c11 = &col[3 * ((size_t)j1 * mid->w + i1)];
            float w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
            sum.x += w00 * c00[0] + w10 * c10[0] + w01 * c01[0] + w11 * c11[0];
            sum.y += w00 * c00[1] + w10 * c10[1] + w01 * c01[1] + w11 * c11[1];
            sum.z += w00 * c00[2] + w10 * c10[2] + w01 * c01[2] + w11 * c11[2];
        }
    return fv_scale(sum, 1.0f / (float)(S * S));
}

/* Camera-ray steps per sample of pixel (x, y) from the levels below the target: each lower ray's
 * steps shared among the target samples it stands for, so the map sums to the frame's steps. */
static float lower_steps(const fv_sdf_pipeline *p, int x, int y, int *top_level)
{
    const int S = p->S, L = p->o.levels;
    float sum = 0.0f;
    *top_level = 0;
    for (int b = 0; b < S; b++)
        for (int a = 0; a < S; a++)
            for (int k = 0; k + 1 < L; k++) {
                const fv_pyramid_level *lv = &p->lv[k];
                int i = (x * S + a) / lv->f, jj = (y * S + b) / lv->f;
                uint16_t s = p->steps[k][(size_t)jj * lv->w + i];
                sum += (float)s / (float)(lv->f * lv->f);
                if (s > 0 && k > *top_level) *top_level = k;
            }
    return sum / (float)(S * S);
}

/* shadow_reuse (ours): the lights a target sample sees, taken from the level below when its parent
 * (pi, pj) and the parent's eight neighbours all hit and all see the same lights, or unknown (the
 * sample traces its own shadow rays) where they differ: a shadow's edge, a silhouette. */
static uint32_t agreed_visibility(const fv_sdf_pipeline *p, int pi, int pj)
{
    const fv_pyramid_level *lv = &p->lv[p->o.levels - 2];
    uint32_t v = p->vis[(size_t)pj * lv->w + pi];
    if (v == FV_SDF_VIS_UNKNOWN) return v;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            int x = pi + dx, y = pj + dy;
            if (x < 0 || x >= lv->w || y < 0 || y >= lv->h) continue;
            if (p->vis[(size_t)y * lv->w + x] != v) return FV_SDF_VIS_UNKNOWN;
        }
    return v;
}

static void target_tile(void *ctx, const fv_tile *tile)
{
    job *j = ctx;
    fv_sdf_pipeline *p = j->p;
    const int S = p->S, L = p->o.levels, w = p->w;
    const int npix = (tile->x1 - tile->x0) * (tile->y1 - tile->y0), cap = npix * S * S;
    fv_march_ray *rays = malloc((size_t)cap * sizeof *rays);
    fv_march_hit *hits = malloc((size_t)cap * sizeof *hits);
    fv_vec3 *colour = malloc((size_t)cap * sizeof *colour), *normal = malloc((size_t)cap * sizeof *normal);
    int *first = malloc((size_t)npix * sizeof *first);
    uint32_t *known = p->vis ? malloc((size_t)cap * sizeof *known) : NULL;
    if (!rays || !hits || !colour || !normal || !first || (p->vis && !known)) {
        j->status[tile->thread] = FV_ERR_NOMEM;
        goto done;
    }
    const float eps_k = p->o.hit * j->foot;
    const bool diagnostics = p->o.show == FV_SDF_SHOW_STEPS || p->o.show == FV_SDF_SHOW_LEVEL;
    int n = 0, q = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++, q++) {
            size_t pix = (size_t)y * w + x;
            if (p->mask && !p->mask[pix]) {
                first[q] = -1;
                continue;
            }
            first[q] = n;
            for (int b = 0; b < S; b++)
                for (int a = 0; a < S; a++) {
                    int sx = x * S + a, sy = y * S + b;
                    camera_ray(j, (float)sx + 0.5f, (float)sy + 0.5f, eps_k, &rays[n]);
                    if (L > 1) rays[n].t0 = fmaxf(rays[n].t0, fv_pyramid_start(p->depth[L - 2], &p->lv[L - 2], sx >> 1, sy >> 1, p->o.min_filter));
                    if (known) known[n] = agreed_visibility(p, sx >> 1, sy >> 1);
                    n++;
                }
        }
    trace(j, tile->thread, L - 1, rays, hits, n, known, colour, normal);
    uint64_t bad = 0;
    q = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++, q++) {
            size_t pix = (size_t)y * w + x;
            int top = 0;
            /* the lower levels' share only feeds show=steps and show=level */
            float share = L > 1 && diagnostics ? lower_steps(p, x, y, &top) : 0.0f;
            fv_vec3 c;
            if (first[q] < 0) {
                c = reconstruct(j, x, y);
                p->heat[pix] = share;
                p->level_of[pix] = (uint8_t)(L - 2);
                fv_film_store_first_hit(&j->out, pix, false, 0.0f, fv_v3s(0.0f), fv_v3s(0.0f), fv_v3s(0.0f), 0);
            } else {
                int r0 = first[q];
                fv_vec3 sum = fv_v3s(0.0f);
                float steps = 0.0f;
                bool marched = false;
                for (int s = 0; s < S * S; s++) {
                    sum = fv_add(sum, fv_kit_guard(colour[r0 + s], &bad));
                    steps += (float)hits[r0 + s].steps;
                    marched |= hits[r0 + s].steps > 0;
                }
                c = fv_kit_guard(fv_scale(sum, 1.0f / (float)(S * S)), &bad);
                p->heat[pix] = share + steps / (float)(S * S);
                p->level_of[pix] = (uint8_t)(marched ? L - 1 : top);
                const fv_march_hit *h0 = &hits[r0];
                fv_vec3 hp = fv_madd(rays[r0].o, rays[r0].d, h0->t);
                fv_vec3 alb = h0->hit ? fv_scene_material(p->scene, h0->mat)->albedo : fv_v3s(0.0f);
                fv_film_store_first_hit(&j->out, pix, h0->hit, h0->t, hp, normal[r0], alb, 0);
            }
            j->out.color[3 * pix] = c.x;
            j->out.color[3 * pix + 1] = c.y;
            j->out.color[3 * pix + 2] = c.z;
        }
    fv_kit_count(j->c, tile->thread, FV_KIT_NAN, bad);
done:
    free(known);
    free(rays);
    free(hits);
    free(colour);
    free(normal);
    free(first);
}

/* ---- fipr's passes 2 and 3, and what pass 4 must trace of the middle level ---- */

static int imin(int a, int b) { return a < b ? a : b; }
static int imax(int a, int b) { return a > b ? a : b; }
/* Floor and ceiling of a / b for b > 0 and any sign of a (C's division truncates towards 0). */
static int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
static int ceil_div(int a, int b) { return -floor_div(-a, b); }

/* Returns the number of mask pixels; fills edge, mask and need. */
static uint64_t build_mask(job *j, uint64_t *edge_pixels, uint64_t *refreshed)
{
    fv_sdf_pipeline *p = j->p;
    const fv_frame *f = j->frame;
    const int S = p->S, L = p->o.levels, w = p->w, h = p->h;
    const fv_pyramid_level *low = &p->lv[0], *mid = &p->lv[L - 2];
    fv_pyramid_sobel(p->depth[0], low->w, low->h, p->o.edge, p->edge);
    fv_eye_model def;
    const fv_eye_model *eye = fv_frame_eye_model(f, w, h, &def);
    /* a fovea widened to the whole screen (a missing gaze under `widen`): every pixel is traced
     * at the target level, as ipr traces it, whatever fovea_deg says */
    const bool whole = fv_frame_fovea_covers(f, eye, w, h);
    uint64_t masked = 0, edges = 0, fresh = 0;
    const int R = p->o.refresh, now = f->index;
    /* Both loops run in one parallel region (the mask was a serial 56 ms of a frame at 720x800,
     * issue 29). The middle-level rays a mask pixel needs are gathered, not scattered, so that no
     * two threads write one cell: pixel x's samples (x*S + a) >> 1, a in [0, S), span the rays
     * [(x*S) >> 1, (x*S + S - 1) >> 1], and the min filter reads those +-1; so ray u is needed by
     * the pixels x with x*S <= 2u + 3 and x*S + S - 1 >= 2u - 2 (the same in y), and is needed
     * when any of them is in the mask: the same set the scatter marked. */
    fv_region_begin();
    #pragma omp parallel num_threads(fv_thread_count(f->threads))
    {
        #pragma omp for schedule(static) reduction(+ : masked, edges)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t pix = (size_t)y * w + x;
                /* the tip's ray whose block holds the pixel's centre (pass 2's upscaling) */
                int li = (x * S + S / 2) / low->f, lj = (y * S + S / 2) / low->f;
                bool e = p->edge[(size_t)lj * low->w + li] != 0;
                double ecc = fv_eye_eccentricity_deg(eye, f->gaze, x, y);
                double prob = whole ? 1.0 : fv_pyramid_probability(ecc, p->o.fovea_deg, p->o.outer_deg, e);
                fv_rng rng = fv_rng_stream(f->seed, FV_STREAM_MASK, pix * 2 + (uint64_t)f->eye, 0, (uint64_t)f->index);
                bool m = prob >= 1.0 || (prob > 0.0 && fv_rng_next(&rng) < prob);
                p->mask[pix] = m;
                edges += e;
                masked += m;
            }
        /* Refresh: ray (i, j) of the middle level is shaded when its phase comes round (a 2x2
         * interleave for 1/4, a checkerboard for 1/2), so each frame refreshes an even share, and
         * whenever it has never been shaded. */
        #pragma omp for schedule(static) reduction(+ : fresh)
        for (int v = 0; v < mid->h; v++) {
            const int y0 = imax(0, ceil_div(2 * v - 1 - S, S)), y1 = imin(h - 1, floor_div(2 * v + 3, S));
            for (int u = 0; u < mid->w; u++) {
                size_t i = (size_t)v * mid->w + u;
                int phase = R == 4 ? (u & 1) + 2 * (v & 1) : R == 2 ? (u + v) & 1 : 0;
                bool due = j->hist->stamp[i] == INT_MIN || ((now % R) + R) % R == phase;
                if (due) {
                    p->need[i] = 2, fresh++;
                    continue;
                }
                const int x0 = imax(0, ceil_div(2 * u - 1 - S, S)), x1 = imin(w - 1, floor_div(2 * u + 3, S));
                uint8_t need = 0;
                for (int y = y0; y <= y1 && !need; y++)
                    for (int x = x0; x <= x1; x++)
                        if (p->mask[(size_t)y * w + x]) {
                            need = 1;
                            break;
                        }
                p->need[i] = need;
            }
        }
    }
    fv_region_end();
    *edge_pixels = edges;
    *refreshed = fresh;
    return masked;
}

/* Pass 5: sigma = blur_sigma on the transitions (pixels whose 5x5 neighbourhood holds both mask
 * and other pixels), 0 elsewhere, which fv_blur_variable leaves untouched. */
static fv_status blur_transitions(job *j, fv_error *err)
{
    fv_sdf_pipeline *p = j->p;
    const int w = p->w, h = p->h;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int seen[2] = {0, 0};
            for (int dy = -2; dy <= 2; dy++)
                for (int dx = -2; dx <= 2; dx++) {
                    int u = x + dx, v = y + dy;
                    if (u >= 0 && u < w && v >= 0 && v < h) seen[p->mask[(size_t)v * w + u] ? 1 : 0] = 1;
                }
            p->sigma[(size_t)y * w + x] = seen[0] && seen[1] ? p->o.blur_sigma : 0.0f;
        }
    return fv_blur_variable(j->out.color, w, h, p->sigma, j->frame->threads, err);
}

static void show(job *j)
{
    fv_sdf_pipeline *p = j->p;
    const int S = p->S;
    for (int y = 0; y < p->h; y++)
        for (int x = 0; x < p->w; x++) {
            size_t pix = (size_t)y * p->w + x;
            fv_vec3 c;
            switch (p->o.show) {
            case FV_SDF_SHOW_STEPS: c = fv_pyramid_heat(p->heat[pix]); break;
            case FV_SDF_SHOW_LEVEL: c = fv_pyramid_level_colour(p->level_of[pix], p->o.levels); break;
            case FV_SDF_SHOW_MASK: c = fv_v3s(p->mask[pix] ? 1.0f : 0.0f); break;
            case FV_SDF_SHOW_EDGES: {
                const fv_pyramid_level *low = &p->lv[0];
                int li = (x * S + S / 2) / low->f, lj = (y * S + S / 2) / low->f;
                c = fv_v3s(p->edge[(size_t)lj * low->w + li] ? 1.0f : 0.0f);
                break;
            }
            default: return;
            }
            j->out.color[3 * pix] = c.x;
            j->out.color[3 * pix + 1] = c.y;
            j->out.color[3 * pix + 2] = c.z;
        }
}

static fv_status first_error(const job *j, int threads, fv_error *err)
{
    for (int t = 0; t < threads; t++)
        if (j->status[t] != FV_OK) return fv_error_set(err, j->status[t], "out of memory while sphere tracing");
    return FV_OK;
}

/* One pass over a grid, as a phase of the frame's progress. */
static fv_status run_pass(job *j, int gw, int gh, fv_tile_fn fn, fv_kit_progress *prog, double base, double span, fv_stats *stats,
                          const char *stage, fv_error *err)
{
    fv_kit_phase(prog, j->frame, base, span);
    fv_stage_clock t0 = fv_stage_clock_now();
    fv_parallel_tiles(gw, gh, j->frame->threads, fn, j, fv_kit_progress_fn, prog);
    fv_stage_stop(stats, stage, t0);
    fv_status s = fv_kit_phase_end(prog, err);
    return s != FV_OK ? s : first_error(j, fv_thread_count(j->frame->threads), err);
}

fv_status fv_sdf_pipeline_render(fv_sdf_pipeline *p, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    job *j = calloc(1, sizeof *j);
    if (!j) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_status s = fv_frame_camera(frame->camera, film, &j->cam, err);
    if (s == FV_OK) s = fv_sdf_world_build(&j->world, p->scene, err);
    if (s == FV_OK) s = ensure_size(p, j->cam.width, j->cam.height, err);
    const fv_sdf_method m = p->o.method;
    const int L = p->o.levels;
    if (s == FV_OK && m == FV_SDF_FIPR) s = ensure_history(p, frame->eye, frame->index, err);
    j->c = fv_kit_counters_create();
    j->lsteps = fv_kit_counters_create();
    j->lrays = fv_kit_counters_create();
    if (s == FV_OK && (!j->c || !j->lsteps || !j->lrays)) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (s != FV_OK) goto done;
    j->p = p;
    j->frame = frame;
    j->out = fv_film_views_of(film);
    j->foot = 2.0f * j->cam.tan_half_x / (float)(j->cam.width * p->S);
    j->hist = m == FV_SDF_FIPR ? &p->hist[frame->eye] : NULL;

    /* progress: each pass's share of the rays a full pyramid would trace */
    double total = 0.0, base = 0.0;
    for (int k = 0; k < L; k++) total += (double)p->lv[k].w * p->lv[k].h;
    fv_kit_progress prog = {0};
    char stage[32];
    const int full_below = m == FV_SDF_FIPR ? L - 2 : L - 1; /* levels traced whole before the special ones */
    for (int k = 0; k < full_below && s == FV_OK; k++) {
        double span = (double)p->lv[k].w * p->lv[k].h / total;
        j->level = k;
        snprintf(stage, sizeof stage, "level%d", k);
        s = run_pass(j, p->lv[k].w, p->lv[k].h, level_tile, &prog, base, span, stats, stage, err);
        base += span;
    }
    uint64_t masked = 0, edges = 0, refreshed = 0;
    if (s == FV_OK && m == FV_SDF_FIPR) {
        fv_stage_clock t0 = fv_stage_clock_now();
        masked = build_mask(j, &edges, &refreshed);
        fv_stage_stop(stats, "mask", t0);
        double span = (double)p->lv[L - 2].w * p->lv[L - 2].h / total;
        j->level = L - 2;
        s = run_pass(j, p->lv[L - 2].w, p->lv[L - 2].h, level_tile, &prog, base, span, stats, "middle", err);
        base += span;
    }
    if (s == FV_OK) s = run_pass(j, p->w, p->h, target_tile, &prog, base, 1.0 - base, stats, "target", err);
    if (s == FV_OK && m == FV_SDF_FIPR && p->o.blur) {
        fv_stage_clock t0 = fv_stage_clock_now();
        s = blur_transitions(j, err);
        fv_stage_stop(stats, "blur", t0);
    }
    if (s != FV_OK) goto done;
    show(j);

    fv_kit_report(j->c, stats);
    fv_stats_add_count(stats, "samples", (double)p->w * p->h * p->o.spp);
    fv_stats_add_count(stats, "steps", (double)fv_kit_sum(j->c, C_STEPS));
    fv_stats_add_count(stats, "shadow_steps", (double)fv_kit_sum(j->c, C_SHADOW));
    fv_stats_add_count(stats, "normal_evals", (double)fv_kit_sum(j->c, C_NORMAL));
    fv_stats_add_count(stats, "exhausted_rays", (double)fv_kit_sum(j->c, C_EXHAUSTED));
    fv_stats_add_count(stats, "shadow_rays", (double)fv_kit_sum(j->c, C_SHADOW_RAYS));
    for (int k = 0; k < L; k++) {
        snprintf(stage, sizeof stage, "rays_level%d", k);
        fv_stats_add_count(stats, stage, (double)fv_kit_sum(j->lrays, k));
        snprintf(stage, sizeof stage, "steps_level%d", k);
        fv_stats_add_count(stats, stage, (double)fv_kit_sum(j->lsteps, k));
    }
    if (m == FV_SDF_FIPR) {
        fv_stats_add_count(stats, "mask_pixels", (double)masked);
        fv_stats_add_count(stats, "edge_pixels", (double)edges);
        fv_stats_add_count(stats, "refreshed_pixels", (double)refreshed);
    }
done:
    fv_sdf_world_free(&j->world);
    fv_kit_counters_destroy(j->c);
    fv_kit_counters_destroy(j->lsteps);
    fv_kit_counters_destroy(j->lrays);
    free(j);
    return s;
}
