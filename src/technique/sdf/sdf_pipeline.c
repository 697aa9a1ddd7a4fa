/* fovea — the render of the sphere-tracing family (sdf_pipeline.h). */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/scratch.h"
#include "core/parallel.h"
#include "core/stage_time.h"
#include "core/rng.h"
#include "filter/blur.h"
#include "technique/sdf/ksdf_pixel.h"
#include "technique/kit.h"
#include "technique/sdf/sdf_pipeline.h"

struct fv_sdf_pipeline {
    const fv_scene *scene;
    fv_sdf_opts o;
    fv_pyramid_history hist[2]; /* fipr's middle level, per eye */
    fv_kpyr k;         /* the pyramid's buffers for the current size (pyramid.h) */
    float *heat;       /* pixels: camera-ray steps per sample */
    uint8_t *level_of; /* pixels */
    float *sigma;      /* fipr pass 5, pixels */
    int pw, ph;        /* the size heat, level_of and sigma have */
    /* every frame's counters, kept (fv_kit_counters_reuse): steps and rays, and per level */
    fv_kit_counters *c, *lsteps, *lrays;
    /* each thread's tile temporaries (rays, hits, shading's), kept from frame to frame */
    fv_scratch room[FV_MAX_THREADS];
    fv_scratch blur_room; /* fipr's pass 5 */
    fv_sdf_world world; /* the scene's fields and lights, refreshed every frame (fv_sdf_world_refresh) */
    struct job *jb;     /* the frame's shared context, made by the first frame, zeroed every frame */
};

static void free_scratch(fv_sdf_pipeline *p)
{
    fv_pyramid_free(&p->k);
    free(p->heat);
    free(p->level_of);
    free(p->sigma);
    p->heat = p->sigma = NULL;
    p->level_of = NULL;
    p->pw = p->ph = 0;
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
    fv_pyramid_history_free(&p->hist[0]);
    fv_pyramid_history_free(&p->hist[1]);
    fv_kit_counters_destroy(p->c);
    fv_kit_counters_destroy(p->lsteps);
    fv_kit_counters_destroy(p->lrays);
    for (int t = 0; t < FV_MAX_THREADS; t++) fv_scratch_free(&p->room[t]);
    fv_scratch_free(&p->blur_room);
    fv_sdf_world_free(&p->world);
    free(p->jb);
    free(p);
}

int fv_sdf_samples_per_axis(int spp) { return spp >= 16 ? 4 : spp >= 4 ? 2 : 1; }

static fv_status ensure_size(fv_sdf_pipeline *p, int w, int h, fv_error *err)
{
    const int S = fv_sdf_samples_per_axis(p->o.spp), L = p->o.levels;
    fv_status s = fv_pyramid_alloc(&p->k, w, h, S, L, p->o.method == FV_SDF_FIPR, p->o.shadow_reuse, err);
    if (s != FV_OK) {
        free_scratch(p);
        return s;
    }
    p->k.min_filter = p->o.min_filter;
    if (p->pw == w && p->ph == h) return FV_OK;
    free(p->heat);
    free(p->level_of);
    free(p->sigma);
    p->sigma = NULL;
    size_t np = (size_t)w * h;
    bool ok = (p->heat = fv_alloc_array(np, sizeof(float))) != NULL;
    ok &= (p->level_of = fv_alloc_array(np, 1)) != NULL;
    if (p->o.method == FV_SDF_FIPR) ok &= (p->sigma = fv_alloc_array(np, sizeof(float))) != NULL;
    if (!ok) {
        free_scratch(p);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d sphere-tracing pyramid at %d spp", w, h, p->o.spp);
    }
    p->pw = w;
    p->ph = h;
    return FV_OK;
}

/* ---- one frame's shared context ---- */

typedef struct job {
    fv_sdf_pipeline *p;
    const fv_frame *frame;
    fv_sdf_world world;
    fv_camera_basis cam;
    fv_film_views out;
    int level;               /* the level of a level pass */
    fv_ksdf_frame kf;        /* what the kernel steps read of the frame (technique/sdf/ksdf_pixel.h) */
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
static void camera_ray(const job *j, float sx, float sy, fv_march_ray *r) { fv_ksdf_camera_ray(&j->world.k, &j->kf, sx, sy, r); }

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
    fv_status s = fv_sdf_shade(&j->world, &p->o.march, &p->o.shade, rays, hits, n, vis_in, NULL, colour, normal, &sc, &p->room[thread], &e);
    if (s != FV_OK) j->status[thread] = s;
    count_shading(j, thread, &sc);
}

/* ---- a lower level: every ray (or, for fipr's middle level, those `need` asks for) ---- */

/* Shades (colour NULL: visibility only) a compacted batch of a level's rays, counting the cost;
 * with shadow_reuse the visibility lands in p->k.vis at the rays' indices. */
static void shade_level(job *j, int thread, fv_march_ray *rays, fv_march_hit *hits, const int *at, int n, fv_vec3 *colour)
{
    fv_sdf_pipeline *p = j->p;
    if (n == 0) return;
    fv_sdf_shade_counts sc = {0, 0, 0};
    fv_error e;
    fv_scratch *room = &p->room[thread];
    const size_t mark = fv_scratch_mark(room);
    uint32_t *bits = p->k.vis ? fv_scratch_take(room, (size_t)n, sizeof *bits) : NULL;
    fv_status s = p->k.vis && !bits ? FV_ERR_NOMEM
                                   : fv_sdf_shade(&j->world, &p->o.march, &p->o.shade, rays, hits, n, NULL, bits, colour, NULL, &sc, room, &e);
    if (s != FV_OK) j->status[thread] = s;
    if (bits && s == FV_OK)
        for (int r = 0; r < n; r++) p->k.vis[at[r]] = bits[r];
    fv_scratch_release(room, mark);
    count_shading(j, thread, &sc);
}

static void level_tile(void *ctx, const fv_tile *tile)
{
    job *j = ctx;
    fv_sdf_pipeline *p = j->p;
    const int k = j->level;
    const fv_pyramid_level *lv = &p->k.lv[k];
    const bool below_target = k == p->o.levels - 2;
    const int cap = (tile->x1 - tile->x0) * (tile->y1 - tile->y0);
    fv_scratch *room = &p->room[tile->thread];
    fv_scratch_begin(room);
    fv_march_ray *rays = fv_scratch_take(room, (size_t)cap, sizeof *rays), *vrays = fv_scratch_take(room, (size_t)cap, sizeof *vrays);
    fv_march_hit *hits = fv_scratch_take(room, (size_t)cap, sizeof *hits), *vhits = fv_scratch_take(room, (size_t)cap, sizeof *vhits);
    int *at = fv_scratch_take(room, (size_t)cap, sizeof *at), *vat = fv_scratch_take_zero(room, (size_t)cap, sizeof *vat);
    fv_vec3 *colour = p->k.need ? fv_scratch_take(room, (size_t)cap, sizeof *colour) : NULL;
    if (!rays || !vrays || !hits || !vhits || !at || !vat || (p->k.need && !colour)) {
        j->status[tile->thread] = FV_ERR_NOMEM;
        goto done;
    }
    int n = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++) {
            size_t i = (size_t)y * lv->w + x;
            if (p->k.need && below_target && !p->k.need[i]) {
                p->k.depth[k][i] = 0.0f; /* not read: no mask pixel starts from it */
                p->k.steps[k][i] = 0;
                if (p->k.vis) p->k.vis[i] = FV_SDF_VIS_UNKNOWN;
                continue;
            }
            float sx, sy;
            fv_pyramid_centre(lv, p->k.sw, p->k.sh, x, y, &sx, &sy);
            camera_ray(j, sx, sy, &rays[n]);
            if (k > 0) rays[n].t0 = fmaxf(rays[n].t0, fv_kpyr_start(p->k.depth[k - 1], &p->k.lv[k - 1], x >> 1, y >> 1, p->o.min_filter));
            at[n++] = (int)i;
        }
    trace(j, tile->thread, k, rays, hits, n, NULL, NULL, NULL);
    /* Below the target: fipr's rays due for a refresh are shaded (colour kept in its history);
     * with shadow_reuse the others get their visibility only. */
    int ns = 0, nv = 0;
    for (int r = 0; r < n; r++) {
        p->k.depth[k][at[r]] = hits[r].hit ? hits[r].t : INFINITY;
        p->k.steps[k][at[r]] = hits[r].steps;
        if (!below_target) continue;
        if (p->k.need && p->k.need[at[r]] == 2) {
            rays[ns] = rays[r];
            hits[ns] = hits[r];
            at[ns++] = at[r];
        } else if (p->k.vis) {
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
        float *dst = &p->k.hist_color[3 * (size_t)at[r]];
        dst[0] = c.x, dst[1] = c.y, dst[2] = c.z;
        p->k.hist_stamp[at[r]] = j->frame->index;
    }
    fv_kit_count(j->c, tile->thread, FV_KIT_NAN, bad);
done:; /* the temporaries stay in the thread's room until its next tile */
}

/* ---- the target level, per film tile ---- */

/* Camera-ray steps per sample of pixel (x, y) from the levels below the target: each lower ray's
 * steps shared among the target samples it stands for, so the map sums to the frame's steps. */
static float lower_steps(const fv_sdf_pipeline *p, int x, int y, int *top_level)
{
    const int S = p->k.S, L = p->o.levels;
    float sum = 0.0f;
    *top_level = 0;
    for (int b = 0; b < S; b++)
        for (int a = 0; a < S; a++)
            for (int k = 0; k + 1 < L; k++) {
                const fv_pyramid_level *lv = &p->k.lv[k];
                int i = (x * S + a) / lv->f, jj = (y * S + b) / lv->f;
                uint16_t s = p->k.steps[k][(size_t)jj * lv->w + i];
                sum += (float)s / (float)(lv->f * lv->f);
                if (s > 0 && k > *top_level) *top_level = k;
            }
    return sum / (float)(S * S);
}

static void target_tile(void *ctx, const fv_tile *tile)
{
    job *j = ctx;
    fv_sdf_pipeline *p = j->p;
    const int S = p->k.S, L = p->o.levels, w = p->k.w;
    const int npix = (tile->x1 - tile->x0) * (tile->y1 - tile->y0), cap = npix * S * S;
    fv_scratch *room = &p->room[tile->thread];
    fv_scratch_begin(room);
    fv_march_ray *rays = fv_scratch_take(room, (size_t)cap, sizeof *rays);
    fv_march_hit *hits = fv_scratch_take(room, (size_t)cap, sizeof *hits);
    fv_vec3 *colour = fv_scratch_take(room, (size_t)cap, sizeof *colour), *normal = fv_scratch_take(room, (size_t)cap, sizeof *normal);
    int *first = fv_scratch_take(room, (size_t)npix, sizeof *first);
    uint32_t *known = p->k.vis ? fv_scratch_take(room, (size_t)cap, sizeof *known) : NULL;
    if (!rays || !hits || !colour || !normal || !first || (p->k.vis && !known)) {
        j->status[tile->thread] = FV_ERR_NOMEM;
        goto done;
    }
    const bool diagnostics = p->o.show == FV_SDF_SHOW_STEPS || p->o.show == FV_SDF_SHOW_LEVEL;
    int n = 0, q = 0;
    for (int y = tile->y0; y < tile->y1; y++)
        for (int x = tile->x0; x < tile->x1; x++, q++) {
            size_t pix = (size_t)y * w + x;
            if (p->k.mask && !p->k.mask[pix]) {
                first[q] = -1;
                continue;
            }
            first[q] = n;
            for (int b = 0; b < S; b++)
                for (int a = 0; a < S; a++) {
                    int sx = x * S + a, sy = y * S + b;
                    camera_ray(j, (float)sx + 0.5f, (float)sy + 0.5f, &rays[n]);
                    if (L > 1) rays[n].t0 = fmaxf(rays[n].t0, fv_kpyr_start(p->k.depth[L - 2], &p->k.lv[L - 2], sx >> 1, sy >> 1, p->o.min_filter));
                    if (known) known[n] = fv_kpyr_agreed_vis(&p->k, sx >> 1, sy >> 1);
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
                c = fv_kpyr_reconstruct(&p->k, x, y);
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
done:; /* the temporaries stay in the thread's room until its next tile */
}

/* ---- fipr's passes 2 and 3, and what pass 4 must trace of the middle level ---- */

void fv_sdf_fovea_of(const fv_frame *f, const fv_sdf_opts *o, int w, int h, fv_kpyr_fovea *out)
{
    memset(out, 0, sizeof *out);
    fv_eye_model def;
    out->eye = *fv_frame_eye_model(f, w, h, &def);
    out->gaze = f->gaze;
    /* a fovea widened to the whole screen (a missing gaze under `widen`): every pixel is traced
     * at the target level, as ipr traces it, whatever fovea_deg says */
    out->whole = fv_frame_fovea_covers(f, &out->eye, w, h);
    out->seed = f->seed;
    out->eye_index = f->eye;
    out->index = f->index;
    out->fovea_deg = o->fovea_deg;
    out->outer_deg = o->outer_deg;
    out->refresh = o->refresh;
}

/* Passes 2 and 3 and the refresh: fills edge, mask and need (technique/sdf/kpyr.h's steps);
 * returns the number of mask pixels. */
static uint64_t build_mask(job *j, uint64_t *edge_pixels, uint64_t *refreshed)
{
    fv_sdf_pipeline *p = j->p;
    const fv_frame *f = j->frame;
    fv_kpyr *k = &p->k;
    const int w = k->w, h = k->h;
    const fv_pyramid_level *low = &k->lv[0], *mid = &k->lv[k->L - 2];
    fv_pyramid_sobel(k->depth[0], low->w, low->h, p->o.edge, k->edge);
    fv_kpyr_fovea fov;
    fv_sdf_fovea_of(f, &p->o, w, h, &fov);
    uint64_t masked = 0, edges = 0, fresh = 0;
    /* Both loops run in one parallel region (the mask was a serial 56 ms of a frame at 720x800,
     * issue 29); need gathers from the mask (fv_kpyr_need_cell), so no two threads write one cell. */
    fv_region_begin();
    #pragma omp parallel num_threads(fv_thread_count(f->threads))
    {
        #pragma omp for schedule(static) reduction(+ : masked, edges)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                uint8_t m = fv_kpyr_mask_pixel(k, &fov, x, y);
                k->mask[(size_t)y * w + x] = m;
                edges += fv_kpyr_edge_of_pixel(k, x, y) != 0;
                masked += m;
            }
        #pragma omp for schedule(static) reduction(+ : fresh)
        for (int v = 0; v < mid->h; v++)
            for (int u = 0; u < mid->w; u++) {
                uint8_t need = fv_kpyr_need_cell(k, &fov, u, v);
                k->need[(size_t)v * mid->w + u] = need;
                fresh += need == 2;
            }
    }
    fv_region_end();
    *edge_pixels = edges;
    *refreshed = fresh;
    return masked;
}

/* Pass 5: sigma = blur_sigma on the transitions, 0 elsewhere, which fv_blur_variable leaves
 * untouched. */
fv_status fv_sdf_blur_transitions(float *rgb, const uint8_t *mask, float *sigma, int w, int h, float blur_sigma, int threads, fv_scratch *room,
                                  fv_error *err)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) sigma[(size_t)y * w + x] = fv_kpyr_blur_sigma(mask, w, h, x, y, blur_sigma);
    return room ? fv_blur_variable_in(rgb, w, h, sigma, threads, room, err) : fv_blur_variable(rgb, w, h, sigma, threads, err);
}

static void show(job *j)
{
    fv_sdf_pipeline *p = j->p;
    const int S = p->k.S;
    for (int y = 0; y < p->k.h; y++)
        for (int x = 0; x < p->k.w; x++) {
            size_t pix = (size_t)y * p->k.w + x;
            fv_vec3 c;
            switch (p->o.show) {
            case FV_SDF_SHOW_STEPS: c = fv_pyramid_heat(p->heat[pix]); break;
            case FV_SDF_SHOW_LEVEL: c = fv_pyramid_level_colour(p->level_of[pix], p->o.levels); break;
            case FV_SDF_SHOW_MASK: c = fv_v3s(p->k.mask[pix] ? 1.0f : 0.0f); break;
            case FV_SDF_SHOW_EDGES: {
                const fv_pyramid_level *low = &p->k.lv[0];
                int li = (x * S + S / 2) / low->f, lj = (y * S + S / 2) / low->f;
                c = fv_v3s(p->k.edge[(size_t)lj * low->w + li] ? 1.0f : 0.0f);
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
/* The most a tile takes from its thread's room: a level tile's arrays (level_tile, shade_level) or
 * a target tile's (target_tile), with the shading of every ray. Reserved in every thread's room
 * before the passes, since which thread meets the largest tile depends on the schedule. */
static size_t tile_room_bound(const fv_sdf_pipeline *p)
{
    const size_t lc = (size_t)FV_TILE_SIZE * FV_TILE_SIZE, tc = lc * (size_t)p->k.S * (size_t)p->k.S;
    const size_t level = 2 * fv_scratch_bytes(lc, sizeof(fv_march_ray)) + 2 * fv_scratch_bytes(lc, sizeof(fv_march_hit)) +
                         2 * fv_scratch_bytes(lc, sizeof(int)) + fv_scratch_bytes(lc, sizeof(fv_vec3)) + fv_scratch_bytes(lc, sizeof(uint32_t)) +
                         fv_sdf_shade_room_bound((int)lc);
    const size_t target = fv_scratch_bytes(tc, sizeof(fv_march_ray)) + fv_scratch_bytes(tc, sizeof(fv_march_hit)) +
                          2 * fv_scratch_bytes(tc, sizeof(fv_vec3)) + fv_scratch_bytes(lc, sizeof(int)) + fv_scratch_bytes(tc, sizeof(uint32_t)) +
                          fv_sdf_shade_room_bound((int)tc);
    return level > target ? level : target;
}

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
    if (!p->jb && !(p->jb = malloc(sizeof *p->jb))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    job *j = p->jb;
    memset(j, 0, sizeof *j);
    fv_status s = fv_frame_camera(frame->camera, film, &j->cam, err);
    if (s == FV_OK) s = fv_sdf_world_refresh(&p->world, p->scene, err);
    j->world = p->world; /* a view of the pipeline's world: its arrays stay the pipeline's */
    if (s == FV_OK) s = ensure_size(p, j->cam.width, j->cam.height, err);
    if (s == FV_OK)
        for (int t = 0, nt = fv_thread_count(frame->threads); t < nt; t++) fv_scratch_reserve(&p->room[t], tile_room_bound(p));
    const fv_sdf_method m = p->o.method;
    const int L = p->o.levels;
    if (s == FV_OK && m == FV_SDF_FIPR) s = fv_pyramid_history_attach(&p->hist[frame->eye], &p->k, frame->index, err);
    j->c = fv_kit_counters_reuse(&p->c);
    j->lsteps = fv_kit_counters_reuse(&p->lsteps);
    j->lrays = fv_kit_counters_reuse(&p->lrays);
    if (s == FV_OK && (!j->c || !j->lsteps || !j->lrays)) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    if (s != FV_OK) goto done;
    j->p = p;
    j->frame = frame;
    j->out = fv_film_views_of(film);
    j->kf.cam = j->cam;
    j->kf.S = p->k.S;
    /* the hit distance per unit distance: `hit` x a target sample's angular footprint */
    j->kf.eps_k = p->o.hit * (2.0f * j->cam.tan_half_x / (float)(j->cam.width * p->k.S));
    j->kf.march = p->o.march;
    j->kf.shade = p->o.shade;

    /* progress: each pass's share of the rays a full pyramid would trace */
    double total = 0.0, base = 0.0;
    for (int k = 0; k < L; k++) total += (double)p->k.lv[k].w * p->k.lv[k].h;
    fv_kit_progress prog = {0};
    char stage[32];
    const int full_below = m == FV_SDF_FIPR ? L - 2 : L - 1; /* levels traced whole before the special ones */
    for (int k = 0; k < full_below && s == FV_OK; k++) {
        double span = (double)p->k.lv[k].w * p->k.lv[k].h / total;
        j->level = k;
        snprintf(stage, sizeof stage, "level%d", k);
        s = run_pass(j, p->k.lv[k].w, p->k.lv[k].h, level_tile, &prog, base, span, stats, stage, err);
        base += span;
    }
    uint64_t masked = 0, edges = 0, refreshed = 0;
    if (s == FV_OK && m == FV_SDF_FIPR) {
        fv_stage_clock t0 = fv_stage_clock_now();
        masked = build_mask(j, &edges, &refreshed);
        fv_stage_stop(stats, "mask", t0);
        double span = (double)p->k.lv[L - 2].w * p->k.lv[L - 2].h / total;
        j->level = L - 2;
        s = run_pass(j, p->k.lv[L - 2].w, p->k.lv[L - 2].h, level_tile, &prog, base, span, stats, "middle", err);
        base += span;
    }
    if (s == FV_OK) s = run_pass(j, p->k.w, p->k.h, target_tile, &prog, base, 1.0 - base, stats, "target", err);
    if (s == FV_OK && m == FV_SDF_FIPR && p->o.blur) {
        fv_stage_clock t0 = fv_stage_clock_now();
        s = fv_sdf_blur_transitions(j->out.color, p->k.mask, p->sigma, p->k.w, p->k.h, p->o.blur_sigma, frame->threads, &p->blur_room, err);
        fv_stage_stop(stats, "blur", t0);
    }
    if (s != FV_OK) goto done;
    show(j);

    fv_kit_report(j->c, stats);
    fv_stats_add_count(stats, "samples", (double)p->k.w * p->k.h * p->o.spp);
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
    return s;
}
