/* fovea — the sphere-tracing family's render: one pipeline for sdf-gt, sdf-relaxed, ipr and fipr,
 * which differ only where the papers differ.
 *
 *   sdf-gt       every target sample sphere-traced from the camera (the paper's ground truth);
 *   sdf-relaxed  the same with over-relaxed steps (Keinert et al. 2014);
 *   ipr          the inverted pyramid (Polychronakis et al. 2023, Sec. 3.1): level k starts its
 *                rays at the 3x3 minimum of the depths found one level down (Sec. 3.2.4);
 *   fipr         the five passes of Sec. 3.2 (Fig. 5): 1 the tip's depth; 2 its Sobel edges;
 *                3 the binary foveation mask (Eq. 1 raised to 1 on edges, xi < p); 4 the middle
 *                level, shaded for the pixels outside the mask (refreshed every 1, 2 or 4 frames,
 *                kept in between) and the target level for the mask's pixels only, the others
 *                reconstructed from the middle level; 5 an optional Gaussian blur of the
 *                transitions guided by the mask.
 *
 * Everything is on the sample grid (spp 1, 4, 16: 1, 2, 4 samples per pixel along each axis);
 * samples are at the centres of a regular sub-pixel grid, so the images are deterministic and
 * sdf-gt, ipr and fipr trace the same target rays. docs/sdf-tracing.md says more.
 */
#ifndef FV_TECHNIQUE_SDF_SDF_PIPELINE_H
#define FV_TECHNIQUE_SDF_SDF_PIPELINE_H

#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/stats.h"
#include "technique/sdf/march.h"
#include "technique/sdf/pyramid.h"
#include "technique/sdf/sdf_shade.h"

typedef enum fv_sdf_method { FV_SDF_GT = 0, FV_SDF_RELAXED, FV_SDF_IPR, FV_SDF_FIPR } fv_sdf_method;

typedef enum fv_sdf_show {
    FV_SDF_SHOW_IMAGE = 0,
    FV_SDF_SHOW_STEPS,  /* camera-ray steps per sample, the lower levels' share included (Fig. 4) */
    FV_SDF_SHOW_LEVEL,  /* the level each pixel's value came from */
    FV_SDF_SHOW_MASK,   /* fipr: the binary foveation mask (white: traced at the target level) */
    FV_SDF_SHOW_EDGES   /* fipr: pass 2's edges, upscaled */
} fv_sdf_show;

typedef struct fv_sdf_opts {
    fv_sdf_method method;
    int spp;             /* 1, 4 or 16 */
    int levels;          /* pyramid levels (1 for the two baselines) */
    bool min_filter;     /* Sec. 3.2.4; off only to measure what it buys */
    fv_march_opts march;
    float hit;           /* hit distance as a fraction of the ray's footprint */
    fv_sdf_shade_opts shade;
    bool shadow_reuse;   /* ours, for a CPU (ipr, fipr): shadows from the level below where it agrees */
    fv_sdf_show show;
    /* fipr */
    float fovea_deg, outer_deg; /* zones of the mask (Sec. 3.2.3) */
    float edge;          /* Sobel threshold relative to depth */
    int refresh;         /* frames between refreshes of the pixels outside the mask: 1, 2, 4 */
    bool blur;           /* pass 5 */
    float blur_sigma;    /* pixels */
} fv_sdf_opts;

typedef struct fv_sdf_pipeline fv_sdf_pipeline;

fv_status fv_sdf_pipeline_create(const fv_scene *scene, const fv_sdf_opts *o, fv_sdf_pipeline **out, fv_error *err);
fv_status fv_sdf_pipeline_render(fv_sdf_pipeline *p, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
void fv_sdf_pipeline_destroy(fv_sdf_pipeline *p);

/* What the CPU pipeline and the device backends (sdf_device.h) share of a frame: */
/* samples per pixel along each axis for spp 1, 4, 16; */
int fv_sdf_samples_per_axis(int spp);
/* what fipr's mask and refresh read of the frame (technique/sdf/kpyr.h) for a w x h film; */
void fv_sdf_fovea_of(const fv_frame *f, const fv_sdf_opts *o, int w, int h, fv_kpyr_fovea *out);
/* pass 5: the transitions of mask (w x h) blurred in rgb with sigma blur_sigma (sigma: w x h
 * scratch), by filter/blur.h, its temporaries from room (a kept arena; NULL: for the call). */
fv_status fv_sdf_blur_transitions(float *rgb, const uint8_t *mask, float *sigma, int w, int h, float blur_sigma, int threads, fv_scratch *room,
                                  fv_error *err);

#endif
