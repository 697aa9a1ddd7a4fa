/* fovea — the first-hit buffer (see gbuffer.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "scene/light.h"
#include "technique/vpl/gbuffer.h"

fv_status fv_gbuffer_reserve(fv_gbuffer *g, int width, int height, fv_error *err)
{
    if (g->px && g->width == width && g->height == height) return FV_OK;
    free(g->px);
    g->px = malloc((size_t)width * (size_t)height * sizeof *g->px);
    if (!g->px) {
        g->width = g->height = 0;
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d first-hit buffer", width, height);
    }
    g->width = width;
    g->height = height;
    return FV_OK;
}

void fv_gbuffer_free(fv_gbuffer *g)
{
    free(g->px);
    memset(g, 0, sizeof *g);
}

typedef struct gb_job {
    fv_gbuffer *g;
    const fv_scene *s;
    const fv_camera_basis *cam;
    const fv_film_views *out;
    uint64_t rays[FV_MAX_THREADS];
} gb_job;

static void gb_fill(const fv_scene *s, fv_vec3 d, const fv_hit *h, bool ok, fv_gpixel *g)
{
    if (!ok) {
        memset(g, 0, sizeof *g);
        g->t = INFINITY;
        g->obj = -1;
        g->emit = fv_light_env_radiance(s, d); /* the environment, if any, seen past everything */
        return;
    }
    fv_material mbuf;
    const fv_material *m = fv_hit_material(s, h, &mbuf);
    const fv_vec3 wo = fv_neg(d);
    g->p = h->p;
    g->t = h->t;
    g->obj = h->obj;
    g->ng = fv_dot(h->ng, wo) >= 0.0f ? h->ng : fv_neg(h->ng);
    g->n = fv_dot(h->ns, g->ng) >= 0.0f ? h->ns : fv_neg(h->ns);
    g->albedo = m->albedo;
    g->emit = fv_light_emitted(s, m, h->ng, wo);
}

static void gb_tile(void *ctx, const fv_tile *tile)
{
    gb_job *j = ctx;
    const int w = j->cam->width;
    for (int y = tile->y0; y < tile->y1; y++) {
        for (int x0 = tile->x0; x0 < tile->x1; x0 += 8) {
            const int n = tile->x1 - x0 < 8 ? tile->x1 - x0 : 8;
            fv_vec3 dir[8];
            fv_hit hits[8];
            bool ok[8];
            for (int k = 0; k < n; k++) dir[k] = fv_camera_dir(j->cam, (float)(x0 + k) + 0.5f, (float)y + 0.5f);
            fv_scene_intersect8(j->s, j->cam->pos, dir, n, hits, ok);
            j->rays[tile->thread] += (uint64_t)n;
            for (int k = 0; k < n; k++) {
                const size_t pix = (size_t)y * (size_t)w + (size_t)(x0 + k);
                fv_gpixel *g = &j->g->px[pix];
                gb_fill(j->s, dir[k], &hits[k], ok[k], g);
                fv_film_store_first_hit(j->out, pix, ok[k], g->t, g->p, g->n, g->albedo, g->obj);
            }
        }
    }
}

void fv_gbuffer_trace(fv_gbuffer *g, const fv_scene *s, const fv_camera_basis *cam, const fv_film_views *out, int threads,
                      uint64_t *rays)
{
    fv_film_views none;
    memset(&none, 0, sizeof none);
    gb_job j; /* 2 KiB of counters: one per thread, summed after */
    memset(&j, 0, sizeof j);
    j.g = g;
    j.s = s;
    j.cam = cam;
    j.out = out ? out : &none;
    fv_parallel_tiles(cam->width, cam->height, threads, gb_tile, &j, NULL, NULL);
    for (int t = 0; t < FV_MAX_THREADS; t++) *rays += j.rays[t];
}
