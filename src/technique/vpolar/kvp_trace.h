/* fovea — the trace stage of Visual-Polar path tracing (Sec. 3.1) as kernel code: where one grid
 * sample's camera ray goes (its jitter inside the cell, the sample space's map to the screen, the
 * off-screen skip and linear fall-off's kill), what it stores, and the whole sample traced on the
 * flat scene with pt's path kernel (kernel/kpt.h).
 *
 * The CPU trace (technique/vpolar/trace.c) places every sample and stores every result with these
 * functions, and traces its camera rays eight at a time through Embree; the portable backend
 * (technique/vpolar/vp_device.c) and CUDA trace a sample at a time with fv_kvp_trace_sample. Both
 * draw the same random numbers from the same streams, so they agree sample by sample up to where
 * the traversals' last bits differ (test_device_pt says where that is).
 */
#ifndef FV_TECHNIQUE_VPOLAR_KVP_TRACE_H
#define FV_TECHNIQUE_VPOLAR_KVP_TRACE_H

#include <stdbool.h>
#include <stdint.h>
#include "core/rng.h"
#include "fovea/camera.h"
#include "kernel/keye.h"
#include "kernel/kpath.h"
#include "kernel/kpt.h"
#include "technique/vpolar/kvp_space.h"

/* One eye of one frame of the trace stage. */
typedef struct fv_kvp_trace_frame {
    fv_kvp_space space;
    fv_kvp_view view;
    const int *col_h;          /* the grid's column heights, NULL: every column gh rows */
    fv_camera_basis cam;
    fv_path_opts pt;
    uint64_t seed;
    int eye, index;            /* the frame's eye and index in its sequence */
    const uint8_t *onscreen;   /* skip the cells marked 0 (NULL: trace every cell) */
    int kill;                  /* linear fall-off: survival 1 up to kill_e0, kill_p from kill_e1 on */
    double kill_e0, kill_e1, kill_p, px_per_deg;
} fv_kvp_trace_frame;

/* Linear fall-off (Weier et al. 2016): the probability that a path at screen position (px, py)
 * survives (fv_vp_survival). */
FV_HD static inline double fv_kvp_survival(const fv_kvp_view *v, float px, float py, double px_per_deg, double e0, double e1, double p)
{
    float dx = px - v->gx, dy = py - v->gy;
    return fv_kacuity_linear(sqrt((double)dx * dx + (double)dy * dy) / px_per_deg, e0, e1, p);
}

/* Grid cell i's camera ray: its random stream (*rng, left after the jitter), its direction, and
 * whether a path goes (false: skipped off screen or killed). */
FV_HD static inline bool fv_kvp_sample_ray(const fv_kvp_trace_frame *f, long i, fv_rng *rng, fv_vec3 *dir)
{
    const int w = f->space.gw;
    const int x = (int)(i % w), y = (int)(i / w);
    *rng = fv_rng_stream(f->seed, FV_STREAM_CAMERA, (uint64_t)i * 2 + (uint64_t)f->eye, 0, (uint64_t)f->index);
    /* Jitter inside the grid cell: the temporal accumulation of the denoiser then integrates over
     * the cell instead of converging to one aliased point. */
    float X = (float)x + fv_rng_next(rng);
    float V = ((float)y + fv_rng_next(rng)) / (float)(f->col_h ? f->col_h[x] : f->space.gh);
    float px, py;
    fv_kvp_to_screen(&f->space, &f->view, X, V, &px, &py);
    *dir = f->cam.forward;
    bool go = !(f->onscreen && !f->onscreen[i]);
    if (go && f->kill) {
        fv_rng kr = fv_rng_stream(f->seed, FV_STREAM_KILL, (uint64_t)i * 2 + (uint64_t)f->eye, 0, (uint64_t)f->index);
        go = fv_rng_next(&kr) < (float)fv_kvp_survival(&f->view, px, py, f->px_per_deg, f->kill_e0, f->kill_e1, f->kill_p);
    }
    if (go) *dir = fv_camera_dir(&f->cam, px, py);
    return go;
}

/* No surface at cell i: black, no features, depth +inf. */
FV_HD static inline void fv_kvp_store_miss(const fv_kvp_gbuf *g, long i)
{
    for (int c = 0; c < 3; c++) g->color[3 * i + c] = g->albedo[3 * i + c] = g->reflectance[3 * i + c] = 0.0f;
    for (int c = 0; c < 3; c++) g->normal[3 * i + c] = g->position[3 * i + c] = 0.0f;
    g->depth[i] = INFINITY;
    g->id[i] = 0;
}

/* Cell i's estimate L and its first hit. */
FV_HD static inline void fv_kvp_store_sample(const fv_kvp_gbuf *g, long i, fv_vec3 L, const fv_path_first_hit *first)
{
    if (!first->hit) fv_kvp_store_miss(g, i);
    g->color[3 * i] = L.x, g->color[3 * i + 1] = L.y, g->color[3 * i + 2] = L.z;
    if (!first->hit) return;
    g->albedo[3 * i] = first->albedo.x, g->albedo[3 * i + 1] = first->albedo.y, g->albedo[3 * i + 2] = first->albedo.z;
    g->reflectance[3 * i] = first->reflectance.x, g->reflectance[3 * i + 1] = first->reflectance.y,
    g->reflectance[3 * i + 2] = first->reflectance.z;
    g->normal[3 * i] = first->n.x, g->normal[3 * i + 1] = first->n.y, g->normal[3 * i + 2] = first->n.z;
    g->position[3 * i] = first->p.x, g->position[3 * i + 1] = first->p.y, g->position[3 * i + 2] = first->p.z;
    g->depth[i] = first->t;
    g->id[i] = (uint32_t)first->obj + 1u;
}

/* The trace's costs, per thread or per block. */
typedef struct fv_kvp_trace_counts {
    uint64_t rays, paths, nan_paths;
} fv_kvp_trace_counts;

/* Grid cell i (a valid cell) traced on the flat scene with pt's path kernel: spp paths through its
 * camera ray, averaged, the first one's first hit kept. */
FV_HD static inline void fv_kvp_trace_sample(const fv_kscene *s, const fv_kvp_trace_frame *f, const fv_kvp_gbuf *g, long i,
                                             fv_kvp_trace_counts *c)
{
    fv_rng rng;
    fv_vec3 dir;
    const bool go = fv_kvp_sample_ray(f, i, &rng, &dir);
    g->sampled[i] = go;
    if (!go) {
        fv_kvp_store_miss(g, i);
        return;
    }
    fv_path_first_hit first;
    first.hit = false;
    first.t = 0.0f;
    first.p = first.n = first.albedo = first.reflectance = fv_v3s(0.0f);
    first.obj = 0;
    FV_SIMT_STEP(FV_SIMT_SAMPLE);
    fv_vec3 L = fv_path_guard(fv_kpath_trace_from(s, &f->pt, f->cam.pos, dir, NULL, false, &rng, &first, &c->rays), &c->nan_paths);
    /* spp > 1: more paths through the same camera ray, averaged. */
    for (int n = 1; n < f->pt.spp; n++) {
        FV_SIMT_STEP(FV_SIMT_SAMPLE);
        L = fv_add(L, fv_path_guard(fv_kpath_trace_from(s, &f->pt, f->cam.pos, dir, NULL, false, &rng, NULL, &c->rays), &c->nan_paths));
    }
    if (f->pt.spp > 1) L = fv_scale(L, 1.0f / (float)f->pt.spp);
    fv_kvp_store_sample(g, i, L, &first);
    c->paths++;
}

#endif
