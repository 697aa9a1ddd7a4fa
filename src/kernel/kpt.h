/* fovea — `pt` as a device kernel: one pixel's camera paths on the flat scene (kernel/kscene.h),
 * run by the portable backend on the CPU (technique/pt/pt.c) and by the CUDA backend
 * (technique/pt/pt_kernels.cu), one thread a pixel.
 *
 * The estimator is kernel/kpath_impl.h, the CPU pt's own source, with the flat scene's traversal
 * (kernel/ktraverse.h) answering the ray queries; the pixel draws the same random numbers as the
 * CPU pt (same stream, jitter, then the path), so the three agree sample by sample up to where
 * the traversals' last bits differ.
 */
#ifndef FV_KERNEL_KPT_H
#define FV_KERNEL_KPT_H

#include <math.h>
#include "core/rng.h"
#include "fovea/camera.h"
#include "fovea/film.h"
#include "kernel/kbsdf.h"
#include "kernel/klight.h"
#include "kernel/kmaterial.h"
#include "kernel/kpath.h"
#include "kernel/ksimt.h"
#include "kernel/ktraverse.h"

#define FV_PATH_FN fv_kpath_trace_from
#define FV_PATH_QUAL FV_HD static inline
#define FV_PATH_SCENE fv_kscene
#define FV_PATH_INTERSECT(s, o, d, h) fv_kscene_intersect(s, o, d, INFINITY, h)
#define FV_PATH_MATERIAL(s, h, buf) fv_kscene_material_at(s, h, buf)
#define FV_PATH_LIGHTS(s) (&(s)->lights)
#define FV_PATH_LIGHT_OF(s, h) ((s)->tri_light[(s)->objs[(h)->obj].first_tri + (h)->prim])
#define FV_PATH_VISIBLE(s, p, ng, q) fv_kscene_visible(s, p, ng, q)
#define FV_PATH_OFFSET(s, p, ng, d) fv_kscene_offset_point(s, p, ng, d)
#include "kernel/kpath_impl.h"

/* Pixel (x, y): opt.spp jittered camera paths averaged into out's colour, the first sample's first
 * hit into its auxiliary buffers; *rays and *dropped (non-finite estimates) are increased. */
FV_HD static inline void fv_kpt_pixel(const fv_kscene *s, const fv_kpt_frame *f, int x, int y, const fv_film_views *out, uint64_t *rays,
                                      uint64_t *dropped)
{
    const size_t pix = (size_t)y * (size_t)f->cam.width + (size_t)x;
    fv_vec3 sum = fv_v3s(0.0f);
    fv_path_first_hit first;
    first.hit = false;
    first.t = 0.0f;
    first.p = first.n = first.albedo = first.reflectance = fv_v3s(0.0f);
    first.obj = 0;
    for (int k = 0; k < f->opt.spp; k++) {
        FV_SIMT_STEP(FV_SIMT_SAMPLE);
        fv_rng rng = fv_rng_stream(f->seed, FV_STREAM_CAMERA, (uint64_t)pix * 2 + (uint64_t)f->eye, (uint64_t)k, (uint64_t)f->frame);
        float jx = fv_rng_next(&rng), jy = fv_rng_next(&rng);
        fv_vec3 d = fv_camera_dir(&f->cam, (float)x + jx, (float)y + jy);
        fv_vec3 L = fv_kpath_trace_from(s, &f->opt, f->cam.pos, d, NULL, false, &rng, k == 0 ? &first : NULL, rays);
        sum = fv_add(sum, fv_path_guard(L, dropped));
    }
    /* finite samples can still sum past the float range */
    fv_vec3 v = fv_path_guard(fv_scale(sum, 1.0f / (float)f->opt.spp), dropped);
    out->color[3 * pix] = v.x;
    out->color[3 * pix + 1] = v.y;
    out->color[3 * pix + 2] = v.z;
    fv_film_store_first_hit(out, pix, first.hit, first.t, first.p, first.n, first.albedo, first.obj);
}

#endif
