/* fovea — deferred shading for the instant-radiosity family (see vpl_shade.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/stage_time.h"
#include "technique/vpl/direct.h"
#include "technique/vpl/vpl_shade.h"

typedef struct direct_job {
    const fv_scene *s;
    const fv_gbuffer *gb;
    const fv_frame *frame;
    int area_samples;
    fv_vec3 *out;
    fv_kit_counters *counters;
} direct_job;

static void direct_tile(void *ctx, const fv_tile *t)
{
    direct_job *j = ctx;
    uint64_t rays = 0;
    const int w = j->gb->width;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++) {
            const size_t pix = (size_t)y * (size_t)w + (size_t)x;
            const fv_gpixel *g = &j->gb->px[pix];
            if (!fv_gpixel_hit(g)) {
                j->out[pix] = fv_v3s(0.0f);
                continue;
            }
            fv_rng rng = fv_kit_rng(j->frame, pix, 0);
            j->out[pix] = fv_vpl_direct_irradiance(j->s, g->p, g->n, g->ng, j->area_samples, &rng, &rays);
        }
    fv_kit_count(j->counters, t->thread, FV_KIT_RAYS, rays);
    fv_kit_count(j->counters, t->thread, FV_VPL_SLOT_DIRECT_RAYS, rays);
}

bool fv_vpl_pass_direct(const fv_scene *s, const fv_gbuffer *gb, const fv_frame *frame, int area_samples, fv_vec3 *direct,
                        fv_kit_counters *counters, fv_kit_progress *prog)
{
    direct_job j = {s, gb, frame, area_samples, direct, counters};
    return fv_parallel_tiles(gb->width, gb->height, frame->threads, direct_tile, &j, fv_kit_progress_fn, prog);
}

bool fv_vpl_pass_direct_team(const fv_scene *s, const fv_gbuffer *gb, const fv_frame *frame, int area_samples, fv_vec3 *direct,
                             fv_kit_counters *counters, fv_team_progress *tp)
{
    direct_job j = {s, gb, frame, area_samples, direct, counters};
    return fv_team_tiles(gb->width, gb->height, direct_tile, &j, tp);
}

typedef struct indirect_job {
    const fv_vpl_gather *g;
    const fv_gbuffer *gb;
    const fv_vpl_tiles *tiles;
    fv_vec3 *sum;
    fv_kit_counters *counters;
} indirect_job;

/* Exact visibility: pixel by pixel, each pixel's shadow rays to its VPLs go eight per packet. */
static void indirect_tile_rays(indirect_job *j, const fv_tile *t)
{
    uint64_t rays = 0, lookups = 0;
    const int w = j->gb->width, nx = j->tiles->nx, ny = j->tiles->ny;
    for (int y = t->y0; y < t->y1; y++)
        for (int x = t->x0; x < t->x1; x++) {
            const size_t pix = (size_t)y * (size_t)w + (size_t)x;
            const fv_gpixel *g = &j->gb->px[pix];
            if (!fv_gpixel_hit(g)) continue;
            const int tile = (x % nx) + nx * (y % ny);
            const int b = j->tiles->offset[tile], e = j->tiles->offset[tile + 1];
            fv_vec3 v = fv_vpl_gather_at(j->g, g->p, g->n, g->ng, j->tiles->list + b, e - b, &rays, &lookups);
            j->sum[pix] = fv_add(j->sum[pix], v);
        }
    fv_kit_count(j->counters, t->thread, FV_KIT_RAYS, rays);
    fv_kit_count(j->counters, t->thread, FV_VPL_SLOT_VPL_RAYS, rays);
}

/* Cube maps: VPL by VPL over the pixels of a block of the screen that see it, so one VPL's map stays
 * in cache while it is read (a 128^2 map is 393 KB, and pixel by pixel every lookup would miss);
 * the order a GPU shades in, one light's shadow map at a time. Blocks are larger than the tile
 * loop's 16^2: a map is loaded once per block, and with 4x4 interleaving a 16^2 tile would give each
 * VPL only 16 pixels to amortise it over. */
#define MAP_BLOCK 64

typedef struct map_job {
    indirect_job *j;
    int bx; /* blocks per row */
} map_job;

static void indirect_blocks_maps(void *ctx, int64_t b0, int64_t b1, int thread)
{
    map_job *mj = ctx;
    indirect_job *j = mj->j;
    const int w = j->gb->width, h = j->gb->height, nx = j->tiles->nx, ny = j->tiles->ny;
    int pix[MAP_BLOCK * MAP_BLOCK];
    fv_vec3 acc[MAP_BLOCK * MAP_BLOCK];
    uint64_t lookups = 0;
    for (int64_t b = b0; b < b1; b++) {
        const int x0 = (int)(b % mj->bx) * MAP_BLOCK, y0 = (int)(b / mj->bx) * MAP_BLOCK;
        const int x1 = x0 + MAP_BLOCK < w ? x0 + MAP_BLOCK : w, y1 = y0 + MAP_BLOCK < h ? y0 + MAP_BLOCK : h;
        for (int cy = 0; cy < ny; cy++)
            for (int cx = 0; cx < nx; cx++) {
                /* the pixels of this block in interleave class (cx, cy) */
                int np = 0;
                for (int y = y0 + ((cy - y0 % ny) + ny) % ny; y < y1; y += ny)
                    for (int x = x0 + ((cx - x0 % nx) + nx) % nx; x < x1; x += nx) {
                        const size_t p = (size_t)y * (size_t)w + (size_t)x;
                        if (!fv_gpixel_hit(&j->gb->px[p])) continue;
                        pix[np] = (int)p;
                        acc[np] = fv_v3s(0.0f);
                        np++;
                    }
                if (!np) continue;
                const int tile = cx + nx * cy;
                for (int k = j->tiles->offset[tile]; k < j->tiles->offset[tile + 1]; k++) {
                    const fv_vpl_light *v = &j->g->vpls[j->tiles->list[k]];
                    for (int i = 0; i < np; i++) {
                        const fv_gpixel *g = &j->gb->px[pix[i]];
                        fv_vec3 c;
                        if (!fv_vpl_term(j->g, v, g->p, g->n, &c)) continue;
                        lookups++;
                        const float vis = fv_cubemaps_visibility(j->g->maps, v->map, g->p, j->g->filter);
                        if (vis > 0.0f) acc[i] = fv_madd(acc[i], c, vis);
                    }
                }
                for (int i = 0; i < np; i++) j->sum[pix[i]] = fv_add(j->sum[pix[i]], acc[i]);
            }
    }
    /* the kit's counters are per thread: no lock, the same sum whatever thread counted */
    fv_kit_count(j->counters, thread, FV_VPL_SLOT_LOOKUPS, lookups);
}

static void indirect_tile(void *ctx, const fv_tile *t) { indirect_tile_rays(ctx, t); }

bool fv_vpl_pass_indirect(const fv_vpl_gather *g, const fv_gbuffer *gb, const fv_vpl_tiles *tiles, int threads,
                          fv_vec3 *sum, fv_kit_counters *counters, fv_kit_progress *prog)
{
    indirect_job j = {g, gb, tiles, sum, counters};
    if (!g->maps) return fv_parallel_tiles(gb->width, gb->height, threads, indirect_tile, &j, fv_kit_progress_fn, prog);
    map_job mj = {&j, (gb->width + MAP_BLOCK - 1) / MAP_BLOCK};
    const int64_t blocks = (int64_t)mj.bx * ((gb->height + MAP_BLOCK - 1) / MAP_BLOCK);
    return fv_parallel_for_progress(blocks, 1, threads, indirect_blocks_maps, &mj, fv_kit_progress_fn, prog);
}

bool fv_vpl_pass_indirect_team(const fv_vpl_gather *g, const fv_gbuffer *gb, const fv_vpl_tiles *tiles, fv_vec3 *sum,
                               fv_kit_counters *counters, fv_team_progress *tp)
{
    indirect_job j = {g, gb, tiles, sum, counters};
    if (!g->maps) return fv_team_tiles(gb->width, gb->height, indirect_tile, &j, tp);
    map_job mj = {&j, (gb->width + MAP_BLOCK - 1) / MAP_BLOCK};
    const int64_t blocks = (int64_t)mj.bx * ((gb->height + MAP_BLOCK - 1) / MAP_BLOCK);
    return fv_team_for_progress(blocks, 1, indirect_blocks_maps, &mj, tp);
}

void fv_vpl_compose(const fv_gbuffer *gb, const fv_vec3 *direct, const fv_vec3 *indirect, bool emitted, float *rgb,
                    uint64_t *dropped)
{
    const size_t n = (size_t)gb->width * (size_t)gb->height;
    for (size_t i = 0; i < n; i++) {
        const fv_gpixel *g = &gb->px[i];
        fv_vec3 L = fv_v3s(0.0f);
        if (fv_gpixel_hit(g)) {
            fv_vec3 e = fv_v3s(0.0f);
            if (direct) e = direct[i];
            if (indirect) e = fv_add(e, indirect[i]);
            L = fv_scale(fv_mul(g->albedo, e), 1.0f / (float)M_PI);
            if (emitted) L = fv_add(L, g->emit);
        } else if (emitted) {
            L = g->emit;
        }
        L = fv_kit_guard(L, dropped);
        rgb[3 * i] = L.x;
        rgb[3 * i + 1] = L.y;
        rgb[3 * i + 2] = L.z;
    }
}

const char *const fv_vpl_show_names[] = {"all", "direct", "indirect", NULL};

fv_status fv_vpl_frame_begin(fv_vpl_frame *vf, const fv_scene *s, const fv_frame *frame, fv_film *film, fv_stats *stats,
                             fv_error *err)
{
    fv_status st = fv_frame_camera(frame->camera, film, &vf->cam, err);
    if (st != FV_OK) return st;
    const int w = vf->cam.width, h = vf->cam.height;
    if ((st = fv_gbuffer_reserve(&vf->gb, w, h, err)) != FV_OK) return st;
    const size_t n = (size_t)w * (size_t)h;
    if (n != vf->npix) {
        free(vf->direct);
        free(vf->indirect);
        vf->direct = malloc(n * sizeof *vf->direct);
        vf->indirect = malloc(n * sizeof *vf->indirect);
        vf->npix = vf->direct && vf->indirect ? n : 0;
        if (!vf->npix) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d frame", w, h);
    }
    if (!fv_kit_counters_reuse(&vf->counters)) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    vf->out = fv_film_views_of(film);
    memset(&vf->prog, 0, sizeof vf->prog);
    vf->rays = 0;
    fv_stage_clock t0 = fv_stage_clock_now();
    fv_gbuffer_trace(&vf->gb, s, &vf->cam, &vf->out, frame->threads, &vf->rays);
    fv_stage_stop(stats, "gbuffer", t0);
    memset(vf->indirect, 0, n * sizeof *vf->indirect);
    return FV_OK;
}

fv_status fv_vpl_frame_end(fv_vpl_frame *vf, fv_vpl_show show, bool ok, fv_status status, fv_stats *stats, fv_error *err)
{
    if (status == FV_OK && ok) {
        uint64_t bad = 0;
        fv_stage_clock t0 = fv_stage_clock_now();
        fv_vpl_compose(&vf->gb, show == FV_VPL_SHOW_INDIRECT ? NULL : vf->direct, show == FV_VPL_SHOW_DIRECT ? NULL : vf->indirect,
                       show == FV_VPL_SHOW_ALL, vf->out.color, &bad);
        fv_stage_stop(stats, "compose", t0);
        fv_kit_count(vf->counters, 0, FV_KIT_NAN, bad);
        fv_kit_count(vf->counters, 0, FV_KIT_RAYS, vf->rays);
        fv_kit_report(vf->counters, stats);
        fv_stats_add_count(stats, "vpl_shadow_rays", (double)fv_kit_sum(vf->counters, FV_VPL_SLOT_VPL_RAYS));
        fv_stats_add_count(stats, "cube_lookups", (double)fv_kit_sum(vf->counters, FV_VPL_SLOT_LOOKUPS));
        fv_stats_add_count(stats, "direct_rays", (double)fv_kit_sum(vf->counters, FV_VPL_SLOT_DIRECT_RAYS));
    }
    if (status != FV_OK) return status;
    return ok ? fv_kit_phase_end(&vf->prog, err) : fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
}

void fv_vpl_frame_free(fv_vpl_frame *vf)
{
    fv_gbuffer_free(&vf->gb);
    free(vf->direct);
    free(vf->indirect);
    fv_kit_counters_destroy(vf->counters);
    memset(vf, 0, sizeof *vf);
}
