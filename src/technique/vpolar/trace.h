/* fovea — the trace stage shared by Visual-Polar path tracing and its baselines: one path per
 * sample of a sample space (Foveated Real-Time Path Tracing in Visual-Polar Space, Sec. 3.1: a
 * primary ray, one indirect bounce, a shadow ray from each hit), with the shared path tracing
 * kernel (transport/path.h) and its first-hit features for the denoiser.
 *
 * Launch orders (Sec. 6):
 *  - grid order: samples are taken in tiles of the grid, camera rays eight neighbours at a time as
 *    one packet (coherent: neighbours in the grid are neighbours on the screen);
 *  - random order: the same samples in a random permutation, eight at a time (incoherent packets);
 *  - kill: every pixel of a full-resolution screen grid is launched and a path survives with the
 *    linear fall-off probability (Weier et al. 2016); killed lanes idle in their packet.
 * Every sample draws its random numbers from the frame's camera stream at its grid index (kit.h),
 * so the image does not depend on the order, the packing or the thread count.
 */
#ifndef FV_TECHNIQUE_VPOLAR_TRACE_H
#define FV_TECHNIQUE_VPOLAR_TRACE_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/camera.h"
#include "technique/kit.h"
#include "transport/path.h"
#include "technique/vpolar/space.h"
#include "technique/vpolar/kvp_trace.h"

typedef enum fv_vp_order { FV_VP_ORDER_GRID = 0, FV_VP_ORDER_RANDOM } fv_vp_order;

/* Buffers on the grid's storage (w * h pixels): technique/vpolar/kvp_trace.h's. */
typedef fv_kvp_gbuf fv_vp_gbuf;

typedef struct fv_vp_trace_job {
    const fv_scene *scene;
    fv_path_opts pt;
    fv_camera_basis cam;
    fv_space_view view;
    int screen_w, screen_h;
    fv_vp_order order;
    const uint32_t *perm;  /* random order: the grid's valid pixel indices, permuted */
    long nperm;
    bool skip_offscreen;   /* the cells marked 0 in onscreen are not traced */
    const uint8_t *onscreen; /* per grid cell (fv_space_onscreen_mask); NULL: every cell is on screen */
    bool kill;             /* linear fall-off: survival 1 up to kill_e0, kill_p from kill_e1 on */
    double kill_e0, kill_e1, kill_p, px_per_deg;
    const fv_frame *frame;     /* seed, index, eye, threads */
    fv_kit_progress *progress; /* the trace's phase of the frame */
    fv_kit_counters *counters; /* the caller's block, zeroed (fv_kit_counters_reuse); NULL: none */
} fv_vp_trace_job;

typedef struct fv_vp_trace_result {
    uint64_t rays, paths;
    uint64_t nan_paths;
} fv_vp_trace_result;

/* Linear fall-off (Weier et al. 2016): the probability that a path at screen position (px, py)
 * survives, 1 up to e0 planar degrees from the gaze, p from e1 on, linear between. */
double fv_vp_survival(const fv_space_view *v, float px, float py, double px_per_deg, double e0, double e1, double p);

/* The job as the trace kernels take it (technique/vpolar/kvp_trace.h); its pointers are the job's. */
void fv_vp_trace_kframe(const fv_vp_trace_job *job, fv_kvp_trace_frame *out);

/* Traces every valid sample of job->view's grid into g (every valid cell is written, traced or not;
 * rows beyond a column's height are left as they are). False when cancelled through the progress
 * callback (g is then partly written). */
bool fv_vp_trace(const fv_vp_trace_job *job, const fv_vp_gbuf *g, fv_vp_trace_result *res);

/* A permutation of the grid's valid pixel indices drawn from seed's order stream (for FV_VP_ORDER_RANDOM);
 * *n receives the count. NULL when out of memory. */
uint32_t *fv_vp_random_order(const fv_grid *g, uint64_t seed, long *n);

#endif
