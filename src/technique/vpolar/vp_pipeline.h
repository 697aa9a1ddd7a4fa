/* fovea — the frame pipeline of Visual-Polar path tracing (Foveated Real-Time Path Tracing in
 * Visual-Polar Space, Fig. 2) for one eye, shared by `vpolar` and every baseline it is compared
 * with; they differ only in their sample space and launch:
 *
 *   trace (Sec. 3.1)  ->  denoise in the sample space (SVGF, Sec. 3.3)  ->  mip along φ and map
 *   to the screen (Sec. 3.4)  ->  foveated blur (Sec. 3.5)
 *
 * The pipeline keeps its temporal state (the denoiser's history, last frame's camera and sample
 * space view) between frames and rebuilds its buffers when the film size changes. Stage times go
 * to fv_stats as "trace", "denoise", "mip", "map", "blur".
 */
#ifndef FV_TECHNIQUE_VPOLAR_VP_PIPELINE_H
#define FV_TECHNIQUE_VPOLAR_VP_PIPELINE_H

#include <stdbool.h>
#include "filter/svgf.h"
#include "fovea/device.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/stats.h"
#include "technique/vpolar/vp_device.h"
#include "technique/vpolar/space.h"
#include "technique/vpolar/trace.h"

typedef struct fv_vp_opts {
    fv_space_opts space;
    fv_path_opts pt;            /* spp paths per grid sample, max_depth = 1 + bounces */
    fv_vp_order order;
    bool skip_offscreen;
    bool kill;                 /* linear fall-off launch (screen grid only) */
    double kill_e0, kill_e1, kill_p;
    bool denoise;
    fv_svgf_opts svgf;
    bool blur;
    double blur_sigma;         /* at 1280 pixels wide; scaled with the width (Sec. 3.5: 6.8) */
    double blur_fovea_deg, blur_ramp_deg;
    bool blur_follows_space;   /* Visual-Polar: the blur's fovea stretches with the space (Sec. 3.2) */
    int periphery_passes;      /* SVGF passes beyond periphery_deg (fv_svgf_set_periphery); >= the
                                  iterations: every pass everywhere */
    double periphery_deg;      /* where the periphery's fewer passes start (blur_ramp_deg by default),
                                  stretched with the space like the blur's profile */
    fv_device device;          /* cpu: the CPU's own stages; portable, cuda: the device frame (vp_device.h) */
} fv_vp_opts;

typedef struct fv_vp_pipeline fv_vp_pipeline;

/* dev: the device the frames run on when o->device is not cpu (shared by a method's pipelines, so a
 * stereo pair's eyes are queued together; it must outlive the pipeline), else NULL. */
fv_status fv_vp_pipeline_create(const fv_scene *scene, const fv_vp_opts *o, fv_vp_device *dev, fv_vp_pipeline **out, fv_error *err);
void fv_vp_pipeline_destroy(fv_vp_pipeline *p);

/* Renders one eye of a frame (its camera and gaze; its previous camera, NULL: no history). */
fv_status fv_vp_pipeline_render(fv_vp_pipeline *p, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
/* Renders both eyes of a stereo frame, p[e] eye e's pipeline (frames[e] into films[e]): the images,
 * counters and histories of fv_vp_pipeline_render called for eye 0 then eye 1. On a device (both
 * pipelines on the same one) both eyes are queued before one host wait; on the CPU the two calls. */
fv_status fv_vp_pipeline_render_pair(fv_vp_pipeline *const *p, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err);
/* The same split in two (technique/class.h's submit and collect): `eyes` frames (1, or a pair as
 * above) queued on the device with their read-back and no host wait, *in_flight true; then
 * fv_vp_pipeline_collect with the same pipelines delivers them into the films and stats they were
 * submitted with, in the order submitted. On the CPU, for a pair not on one device, and after a
 * cancel or a failure, the frame is rendered (or ended) now and *in_flight is false. */
fv_status fv_vp_pipeline_submit(fv_vp_pipeline *const *p, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, bool *in_flight,
                                fv_error *err);
fv_status fv_vp_pipeline_collect(fv_vp_pipeline *const *p, int eyes, fv_error *err);

/* The last frame's sample space, its view (where the gaze was), the sample-space image (denoised
 * when denoising is on) and the display's pixels per degree, for pictures of the space itself
 * (docs/results.md). NULL before the first frame. */
const fv_space *fv_vp_pipeline_space(const fv_vp_pipeline *p, fv_space_view *view, const float **image, double *px_per_deg);

#endif
