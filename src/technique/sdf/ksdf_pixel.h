/* fovea — the rays of the sphere-tracing family as kernel code: a pixel of the target level (every
 * target sample sphere-traced from the camera, plain or over-relaxed, technique/sdf/kmarch.h, and shaded
 * with sphere-traced shadows, technique/sdf/ksdf_shade.h) for all four methods, and a ray of a pyramid level
 * below it for ipr and fipr (technique/sdf/kpyr.h holds the pyramid's image steps). The portable
 * backend runs them a cell at a time on the CPU's threads, CUDA one thread a cell (the kernels of
 * technique/sdf/sdf_kernels.h, launched by technique/sdf/sdf_device.c's frame).
 *
 * The target level lays the samples out as the CPU pipeline's target level does (technique/sdf/sdf_pipeline.c): spp 1, 4 or 16 is a regular S x S grid of sub-pixel centres, sample (a, b) of pixel (x, y)
 * through target-grid position (x S + a + 1/2, y S + b + 1/2), rows first; the ray is clipped to the
 * world's box, its hit distance max(eps_abs, eps_k t). The samples' colours are summed in that
 * order through the same non-finite guard, and the first sample's hit fills the auxiliary buffers.
 * The march and the shading are the CPU's own steps, and the world's field is evaluated by the
 * scalar build the CPU's lanes agree with bit for bit, so on a CPU the image is the CPU pipeline's.
 */
#ifndef FV_TECHNIQUE_SDF_KSDF_PIXEL_H
#define FV_TECHNIQUE_SDF_KSDF_PIXEL_H

#include "fovea/camera.h"
#include "fovea/film.h"
#include "kernel/kpath.h"
#include "technique/sdf/kpyr.h"
#include "technique/sdf/ksdf_shade.h"
#include "kernel/ksimt.h"

/* What a frame's pixels share. */
typedef struct fv_ksdf_frame {
    fv_camera_basis cam;
    int S;                  /* samples per pixel along each axis: 1, 2 or 4 */
    float eps_k;            /* hit distance per unit distance: `hit` x a target sample's footprint */
    fv_march_opts march;    /* max_steps, relax (wide unused) */
    fv_sdf_shade_opts shade;
} fv_ksdf_frame;

/* What a pixel cost, summed by the caller (the counters the CPU pipeline reports). */
typedef struct fv_ksdf_counts {
    uint64_t rays;          /* camera rays */
    uint64_t steps;         /* their field evaluations */
    uint64_t exhausted;     /* camera rays stopped by max_steps */
    uint64_t nan;           /* non-finite colours dropped */
    fv_sdf_shade_counts shade;
} fv_ksdf_counts;

/* What a pyramid's frame cost (ipr, fipr), as the CPU pipeline reports it: the sums, each level's
 * camera rays and steps, and fipr's mask, edge and refreshed counts. Host code sums it. */
typedef struct fv_ksdf_pyr_counts {
    fv_ksdf_counts all;
    uint64_t level_rays[FV_PYRAMID_MAX_LEVELS], level_steps[FV_PYRAMID_MAX_LEVELS];
    uint64_t masked, edges, refreshed;
} fv_ksdf_pyr_counts;

/* The camera ray through target-grid position (sx, sy), its range clipped to the world's box (an
 * empty range when it misses the box). */
FV_HD static inline void fv_ksdf_camera_ray(const fv_ksdf_world *w, const fv_ksdf_frame *f, float sx, float sy, fv_march_ray *r)
{
    r->o = f->cam.pos;
    r->d = fv_camera_dir(&f->cam, sx / (float)f->S, sy / (float)f->S);
    if (!fv_ksdf_world_clip(w, r->o, r->d, &r->t0, &r->t1)) r->t0 = 1.0f, r->t1 = 0.0f;
    r->eps = w->eps_abs;
    r->eps_k = f->eps_k;
}

/* Ray (x, y) of pyramid level k below the target (ipr, fipr; Polychronakis et al. 2023, Sec. 3.1):
 * through the centre of its block, starting at the min-filtered depth of level k-1 (Sec. 3.2.4);
 * its depth and steps into the level's buffers. On level L-2, the one the target starts from:
 * fipr's rays that pass 4 does not need are skipped (technique/sdf/kpyr.h, need), those due for a
 * refresh are shaded into the eye's history (stamped with the frame's index), and with
 * shadow_reuse every hit's visibility is kept for the target's samples. The costs are added to *c. */
FV_HD static inline void fv_ksdf_level_cell(const fv_ksdf_world *w, const fv_ksdf_frame *f, const fv_kpyr *py, int k, int x, int y, int index,
                                            fv_ksdf_counts *c)
{
    const fv_pyramid_level *lv = &py->lv[k];
    const size_t i = (size_t)y * (size_t)lv->w + (size_t)x;
    const bool below_target = k == py->L - 2;
    if (py->need && below_target && !py->need[i]) {
        py->depth[k][i] = 0.0f; /* not read: no mask pixel starts from it */
        py->steps[k][i] = 0;
        if (py->vis) py->vis[i] = FV_SDF_VIS_UNKNOWN;
        return;
    }
    float sx, sy;
    fv_kpyr_centre(lv, py->sw, py->sh, x, y, &sx, &sy);
    fv_march_ray r;
    fv_march_hit h;
    fv_ksdf_camera_ray(w, f, sx, sy, &r);
    FV_SIMT_STEP(FV_SIMT_SAMPLE);
    if (k > 0) r.t0 = fmaxf(r.t0, fv_kpyr_start(py->depth[k - 1], &py->lv[k - 1], x >> 1, y >> 1, py->min_filter != 0));
    fv_kmarch_one(w, f->march.max_steps, f->march.relax, &r, false, &h);
    c->rays++;
    c->steps += h.steps;
    c->exhausted += h.exhausted;
    py->depth[k][i] = h.hit ? h.t : INFINITY;
    py->steps[k][i] = h.steps;
    if (!below_target) return;
    const bool colour = py->need && py->need[i] == 2;
    if (!colour && !py->vis) return;
    fv_vec3 nrm;
    uint32_t vis;
    fv_vec3 col = fv_ksdf_shade_vis(w, &f->march, &f->shade, &r, &h, FV_SDF_VIS_UNKNOWN, py->vis ? &vis : NULL, &c->shade, &nrm);
    if (py->vis) py->vis[i] = vis;
    if (!colour) return;
    col = fv_path_guard(col, &c->nan);
    py->hist_color[3 * i] = col.x;
    py->hist_color[3 * i + 1] = col.y;
    py->hist_color[3 * i + 2] = col.z;
    py->hist_stamp[i] = index;
}

/* Pixel (x, y) of the target level: its colour into out's colour, the first sample's hit into its
 * auxiliary buffers, the costs added to *c. py: NULL for sdf-gt and sdf-relaxed (every sample from
 * the camera); ipr and fipr's pyramid otherwise: each sample starts at the min-filtered depth of
 * level L-2, with shadow_reuse it takes the lights its parent's 3x3 agree on, and a pixel outside
 * fipr's mask is reconstructed from the middle level's kept colours instead (no hit). */
FV_HD static inline void fv_ksdf_target_pixel(const fv_ksdf_world *w, const fv_ksdf_frame *f, const fv_kpyr *py, int x, int y,
                                              const fv_film_views *out, fv_ksdf_counts *c)
{
    const int S = f->S;
    const size_t pix = (size_t)y * (size_t)f->cam.width + (size_t)x;
    if (py && py->mask && !py->mask[pix]) {
        fv_vec3 v = fv_kpyr_reconstruct(py, x, y);
        fv_film_store_first_hit(out, pix, false, 0.0f, fv_v3s(0.0f), fv_v3s(0.0f), fv_v3s(0.0f), 0);
        out->color[3 * pix] = v.x;
        out->color[3 * pix + 1] = v.y;
        out->color[3 * pix + 2] = v.z;
        return;
    }
    const bool pyramid = py && py->L > 1;
    fv_vec3 sum = fv_v3s(0.0f);
    for (int b = 0; b < S; b++)
        for (int a = 0; a < S; a++) {
            FV_SIMT_STEP(FV_SIMT_SAMPLE);
            fv_march_ray r;
            fv_march_hit h;
            const int sx = x * S + a, sy = y * S + b;
            fv_ksdf_camera_ray(w, f, (float)sx + 0.5f, (float)sy + 0.5f, &r);
            uint32_t known = FV_SDF_VIS_UNKNOWN;
            if (pyramid) {
                r.t0 = fmaxf(r.t0, fv_kpyr_start(py->depth[py->L - 2], &py->lv[py->L - 2], sx >> 1, sy >> 1, py->min_filter != 0));
                if (py->vis) known = fv_kpyr_agreed_vis(py, sx >> 1, sy >> 1);
            }
            fv_kmarch_one(w, f->march.max_steps, f->march.relax, &r, false, &h);
            c->rays++;
            c->steps += h.steps;
            c->exhausted += h.exhausted;
            fv_vec3 nrm;
            fv_vec3 col = fv_ksdf_shade_vis(w, &f->march, &f->shade, &r, &h, known, NULL, &c->shade, &nrm);
            sum = fv_add(sum, fv_path_guard(col, &c->nan));
            if (a == 0 && b == 0) {
                fv_vec3 hp = fv_madd(r.o, r.d, h.t);
                fv_vec3 alb = h.hit ? fv_ksdf_material(w, h.mat)->albedo : fv_v3s(0.0f);
                fv_film_store_first_hit(out, pix, h.hit, h.t, hp, nrm, alb, 0);
            }
        }
    fv_vec3 v = fv_path_guard(fv_scale(sum, 1.0f / (float)(S * S)), &c->nan);
    out->color[3 * pix] = v.x;
    out->color[3 * pix + 1] = v.y;
    out->color[3 * pix + 2] = v.z;
}

/* Pixel (x, y) of sdf-gt or sdf-relaxed: the target level without a pyramid. */
FV_HD static inline void fv_ksdf_pixel(const fv_ksdf_world *w, const fv_ksdf_frame *f, int x, int y, const fv_film_views *out,
                                       fv_ksdf_counts *c)
{
    fv_ksdf_target_pixel(w, f, NULL, x, y, out, c);
}

#endif
