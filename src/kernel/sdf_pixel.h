/* fovea — one pixel of `sdf-gt` and `sdf-relaxed` as kernel code: every target sample of the pixel
 * sphere-traced from the camera (plain or over-relaxed, kernel/sdf_march.h) and shaded with
 * sphere-traced shadows (kernel/sdf_shade.h). The portable backend runs it a pixel at a time on the
 * CPU's threads (technique/sdf/device.c), CUDA one thread a pixel (device/cuda/sdf.cu).
 *
 * It lays the samples out as the CPU pipeline's target level does (technique/sdf/pipeline.c, one
 * level): spp 1, 4 or 16 is a regular S x S grid of sub-pixel centres, sample (a, b) of pixel (x, y)
 * through target-grid position (x S + a + 1/2, y S + b + 1/2), rows first; the ray is clipped to the
 * world's box, its hit distance max(eps_abs, eps_k t). The samples' colours are summed in that
 * order through the same non-finite guard, and the first sample's hit fills the auxiliary buffers.
 * The march and the shading are the CPU's own steps, and the world's field is evaluated by the
 * scalar build the CPU's lanes agree with bit for bit, so on a CPU the image is the CPU pipeline's.
 */
#ifndef FV_KERNEL_SDF_PIXEL_H
#define FV_KERNEL_SDF_PIXEL_H

#include "fovea/camera.h"
#include "fovea/film.h"
#include "kernel/path.h"
#include "kernel/sdf_shade.h"

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

/* Pixel (x, y): its colour into out's colour, the first sample's hit into its auxiliary buffers,
 * the costs added to *c. */
FV_HD static inline void fv_ksdf_pixel(const fv_ksdf_world *w, const fv_ksdf_frame *f, int x, int y, const fv_film_views *out,
                                       fv_ksdf_counts *c)
{
    const int S = f->S;
    const size_t pix = (size_t)y * (size_t)f->cam.width + (size_t)x;
    fv_vec3 sum = fv_v3s(0.0f);
    for (int b = 0; b < S; b++)
        for (int a = 0; a < S; a++) {
            fv_march_ray r;
            fv_march_hit h;
            fv_ksdf_camera_ray(w, f, (float)(x * S + a) + 0.5f, (float)(y * S + b) + 0.5f, &r);
            fv_kmarch_one(w, f->march.max_steps, f->march.relax, &r, false, &h);
            c->rays++;
            c->steps += h.steps;
            c->exhausted += h.exhausted;
            fv_vec3 nrm;
            fv_vec3 col = fv_ksdf_shade_one(w, &f->march, &f->shade, &r, &h, &c->shade, &nrm);
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

#endif
