/* fovea — the Visual-Polar family's frame on a device backend (device/backend.h), written once for
 * the portable backend and CUDA (docs/gpu.md; Foveated Real-Time Path Tracing in Visual-Polar
 * Space, Fig. 2): a frame of one eye is the kernels of technique/vpolar/vpolar_kernels.h queued in
 * this order,
 *
 *   the tables that follow the gaze, where it moved (Sec. 3.2: the on-screen mask, the radial
 *   table) -> trace (Sec. 3.1) -> the history's coordinates, SVGF's steps (Sec. 3.3) -> φ-mipmaps
 *   (Sec. 3.4) -> map to the screen (Sec. 3.4) -> foveated blur (Sec. 3.5) -> the film's and
 *   counters' read-back,
 *
 * and the host waits once for every eye it was given (a stereo pair: both eyes queued, then one
 * wait). The CPU's own stages (Embree, vectorised filters) stay in vp_pipeline.c.
 *
 * What stays on the device between frames: the sample grid, the history's coordinates, SVGF's
 * buffers and history, the φ-mipmaps, the blur's sigma and scratch image, the film's buffers, and
 * the tables that follow the gaze. Those are computed there (technique/vpolar/kvp_tables.h, the functions the
 * CPU's space.c and vp_pipeline.c run), each only when what it depends on changed: the on-screen mask
 * and the radial table when the view moved; the radial table has two buffers, used in turn, since
 * the reprojection reads the previous frame's while the map reads this one's (one serves both
 * while the gaze stays). What the host builds per screen size (column heights, the mipmaps' shape,
 * the blur's kernels) goes through mirrors (fv_mirror: pinned, copied only when its bytes changed),
 * so a steady frame uploads nothing however the gaze moves. The film and counters come back into
 * pinned memory. So after a sequence's first frame nothing is allocated and the host waits once a
 * frame.
 */
#ifndef FV_TECHNIQUE_VPOLAR_DEVICE_H
#define FV_TECHNIQUE_VPOLAR_DEVICE_H

#include <stdbool.h>
#include "device/backend.h"
#include "filter/grid.h"
#include "filter/svgf.h"
#include "fovea/device.h"
#include "fovea/film.h"
#include "fovea/scene.h"
#include "filter/kblur.h"
#include "technique/vpolar/kvp_map.h"
#include "technique/vpolar/kvp_reproject.h"
#include "technique/vpolar/kvp_tables.h"
#include "technique/vpolar/kvp_trace.h"

/* The backend and the flat scene on it, shared by a method's pipelines (both eyes, and
 * cartesian-full's when the fovea covers the screen), so a stereo pair has one queue and one wait. */
typedef struct fv_vp_device fv_vp_device;

/* device: portable or cuda. */
fv_status fv_vp_device_create(const fv_scene *scene, fv_device device, fv_vp_device **out, fv_error *err);
void fv_vp_device_destroy(fv_vp_device *d);
fv_device fv_vp_device_kind(const fv_vp_device *d);

/* One pipeline's buffers and history on d. */
typedef struct fv_vp_device_eye fv_vp_device_eye;
fv_status fv_vp_device_eye_create(fv_vp_device *d, fv_vp_device_eye **out, fv_error *err);
void fv_vp_device_eye_destroy(fv_vp_device_eye *e);
/* The sample-space image of the last frame (denoised when denoising is on) where the host can read
 * it (portable: device memory is host memory), else NULL. */
const float *fv_vp_device_eye_image(const fv_vp_device_eye *e);

/* One frame of one eye, every pointer host memory (the device's copies are the eye's). */
typedef struct fv_vp_device_frame {
    int fresh;                     /* 1: a new grid (the pipeline's setup): its buffers start as "no
                                      surface, not sampled" and the denoiser without history */
    int threads;                   /* the portable backend's CPU threads (fv_thread_count's rule) */
    fv_launch_progress progress;   /* the trace's (portable), fn NULL: none */
    /* 0. the tables that follow the gaze, computed on the device (technique/vpolar/kvp_tables.h).
     *    onscreen 1: a polar grid's on-screen mask (the cells some pixel within onscreen_reach of
     *    the screen sees) at the map's view, which the reprojection and the denoiser read, and the
     *    trace too when trace_skip (offscreen=skip); radial: the radial table the map reads (its
     *    table ignored; n the map's nlut, step 1 / the map's inv_step) */
    int onscreen, trace_skip;
    float onscreen_reach;
    fv_kvp_radial radial;
    /* 1. the trace (col_h: gw heights or NULL; its g and onscreen ignored) */
    fv_kvp_trace_frame trace;
    /* 2. the denoiser (SVGF on grid, with col_h the trace's). history: the previous frame of this
     *    sequence ran on this eye, its camera and view in reproject (whose prev_lut, g and onscreen
     *    are ignored: the previous frame's radial table and the mask are the device's) */
    int denoise;
    fv_grid grid;
    fv_svgf_opts svgf;
    int periph_x, periph_passes;   /* fv_svgf_set_periphery's (w, iterations: every pass everywhere) */
    int history;
    fv_kvp_reproject_frame reproject;
    /* 3. the φ-mipmaps (mips 0: none, a Cartesian grid the screen's size): the chain's shape (rows,
     *    rowsf, inv_src: w entries each; img ignored) and each level's rows of storage */
    int mips;
    fv_kphi_mips mip_shape;
    int mip_h[FV_KPHI_MAX_LEVELS];
    /* 4. the map (sigma non-NULL: the blur follows; lut, col_h, g and mips ignored: the radial
     *    table is radial's, on the device) */
    fv_kvp_map_frame map;
    /* 5. the blur (blur 0: none): its kernels (off: nq ints, k: nk floats) up to a bound on every
     *    pixel's sigma that holds for every gaze (the kernels follow the screen's size only) */
    int blur;
    fv_kblur_table blur_table;
    size_t blur_nk;
} fv_vp_device_frame;

typedef struct fv_vp_device_result {
    uint64_t rays, paths, nan_paths;
    double history_fraction;   /* the denoiser's (fv_svgf_info) */
    double stage_ms[5];        /* trace, denoise, mip, map, blur (between the backend's marks) */
    double kernel_ms;          /* the eye's stages, first to last */
    bool done;                 /* the eye ran; false: its trace (or an earlier eye's) was cancelled
                                  (portable), and nothing of it after the trace ran */
} fv_vp_device_result;

/* Queues `eyes` frames (1, or 2: a stereo pair; an eye, frame, film and result each, the eyes
 * distinct and on d) with their read-back into the next of two staging slots (device/film_device.h),
 * the scene brought to the frame's time once, and no host wait: *in_flight true, and
 * fv_vp_device_collect delivers them into the films (host memory: colour and the auxiliary buffers
 * that are set; a display-only film, fv_film_set_display, receives its colour as RGBA8 converted on
 * the device instead of floats). After a cancel (portable) or a failure the frame is waited for at once and not in
 * flight: res then holds the eyes that ran (done). *calls receives what the submit asked of the
 * backend. */
fv_status fv_vp_device_submit(fv_vp_device *d, fv_vp_device_eye *const *eye, int eyes, const fv_vp_device_frame *f, fv_film *const *films,
                              fv_vp_device_result *res, fv_backend_calls *calls, bool *in_flight, fv_error *err);
/* The oldest frame in flight: waited for (its fence: a frame queued after it runs on), each eye's
 * film and result delivered (res: as many as it had eyes); *calls: what the collect asked. */
fv_status fv_vp_device_collect(fv_vp_device *d, fv_vp_device_result *res, fv_backend_calls *calls, fv_error *err);
int fv_vp_device_in_flight(const fv_vp_device *d);

#endif
