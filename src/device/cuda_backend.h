/* fovea — the sphere tracers' and the Visual-Polar family's CUDA frames as the rest of the library
 * sees them (pt's frame is already written once over device/backend.h; these two follow): plain C
 * declarations, no CUDA header (device/cuda/sdf.cu and vpolar.cu implement them with nvcc). In a build without CUDA
 * (FOVEA_HAVE_CUDA undefined) device/cuda_stub.c answers instead: "built without CUDA".
 */
#ifndef FV_DEVICE_CUDA_BACKEND_H
#define FV_DEVICE_CUDA_BACKEND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "device/backend.h"
#include "fovea/camera.h"
#include "fovea/film.h"
#include "filter/svgf.h"
#include "fovea/status.h"
#include "kernel/path.h"
#include "kernel/vp_blur.h"
#include "kernel/vp_map.h"
#include "kernel/vp_reproject.h"
#include "kernel/vp_trace.h"

#ifdef __cplusplus
extern "C" {
#endif

struct fv_kscene;

/* What a backend asked of the runtime (device/backend.h), counted by the backend's own calls
 * (device/cuda/common.h). */
typedef fv_backend_calls fv_cuda_calls;

/* The Visual-Polar family (vpolar, cartesian, cartesian-full, linear-falloff, log-polar; technique/
 * vpolar/pipeline.c): a whole frame of one eye on the GPU. The sample grid's buffers, the history's
 * coordinates, the φ-mipmaps, the radial table, the blur's sigma and scratch image and the film stay
 * on the GPU between frames (reallocated only when a size changes); what the host builds per size or
 * per gaze (column heights, the on-screen mask, the mipmaps' shape, the radial table, the blur's
 * kernels) is copied only when its bytes changed. */
typedef struct fv_cuda_vp fv_cuda_vp;
/* Copies the flat scene (host memory) to the GPU. */
fv_status fv_cuda_vp_create(const struct fv_kscene *host, fv_cuda_vp **out, fv_error *err);
void fv_cuda_vp_destroy(fv_cuda_vp *c);
void fv_cuda_vp_calls(const fv_cuda_vp *c, fv_cuda_calls *out);

/* One frame of one eye, every pointer host memory (the GPU's copies are the backend's). */
typedef struct fv_cuda_vp_frame {
    const struct fv_kscene *scene; /* at the frame's time: what moved is copied */
    const uint8_t *onscreen;       /* a polar grid's cells any pixel sees (gw * gh flags), NULL: none;
                                      the trace's and the reprojection's onscreen are this or NULL */
    /* 1. the trace: its space, view, camera, paths and launch (col_h: gw heights or NULL; the g
     *    buffers are ignored) */
    fv_kvp_trace_frame trace;
    /* 2. the denoiser (denoise 1: SVGF, kernel/svgf.h, with these options; its buffers and history
     *    live on the GPU, created with the grid). history 1: the previous frame of this sequence
     *    was rendered by this backend and its camera and view are in reproject; its radial table is
     *    the one the previous frame mapped with, kept on the GPU (prev_lut is ignored). The
     *    denoiser's active cells are onscreen; sampled holes only with kill (linear fall-off). */
    int denoise;
    fv_svgf_opts svgf;
    int periph_x, periph_passes;   /* fv_svgf_set_periphery's (w, iterations: every pass everywhere) */
    int history;
    fv_kvp_reproject_frame reproject;
    /* 3. the φ-mipmaps (mips 0: none, a Cartesian grid the screen's size): the chain's shape (rows,
     *    rowsf, inv_src host arrays of w entries each; img ignored) and each level's rows of storage */
    int mips;
    fv_kphi_mips mip_shape;
    int mip_h[FV_KPHI_MAX_LEVELS];
    /* 4. the map (lut: nlut entries of three floats; col_h as above; sigma non-NULL: the blur follows,
     *    its sigma written on the GPU; g and mips ignored) */
    fv_kvp_map_frame map;
    /* 5. the blur (blur 0: none): its kernels (off: nq ints, k: nk floats) up to a bound on every
     *    pixel's sigma */
    int blur;
    fv_kblur_table blur_table;
    size_t blur_nk;
} fv_cuda_vp_frame;

typedef struct fv_cuda_vp_result {
    uint64_t rays, paths, nan_paths;
    double history_fraction;   /* the denoiser's (fv_svgf_info) */
    double kernel_ms;          /* the frame's launches, first to last (events) */
    double stage_ms[5];        /* trace, denoise, mip, map, blur (events) */
    int syncs;                 /* host waits in the frame: 1 (the end; 0 for a pair's eye 1) */
    fv_cuda_calls calls;       /* what the eye's backend asked of the runtime in the frame */
} fv_cuda_vp_result;

/* Renders `eyes` frames (1, or 2: a stereo pair, one backend, frame, film and result per eye, each
 * eye's buffers and history its own backend's): every stage a kernel (or a sequence of kernels) on
 * the eye's stream with no host wait between them, every eye's frame queued before the host waits
 * once (eye 1's stream is joined to eye 0's by an event, and eye 0's is synchronized); the host
 * receives each eye's film buffers that are set (colour, and the auxiliary ones asked for) and
 * counts. The one wait is res[0].syncs (1); res[1].syncs is 0. */
fv_status fv_cuda_vp_render(fv_cuda_vp *const *c, int eyes, const fv_cuda_vp_frame *f, const fv_film_views *out, fv_cuda_vp_result *res,
                            fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
