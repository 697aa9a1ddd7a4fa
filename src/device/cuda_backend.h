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
struct fv_ksdf_world;
struct fv_ksdf_frame;
struct fv_ksdf_counts;
struct fv_ksdf_pyr_counts;
struct fv_kpyr;
struct fv_kpyr_fovea;

/* What a backend asked of the runtime (device/backend.h), counted by the backend's own calls
 * (device/cuda/common.h). */
typedef fv_backend_calls fv_cuda_calls;

/* The sphere-tracing family (kernel/sdf_pixel.h, kernel/sdf_pyramid.h): the GPU's buffers for the
 * world, the films, the pyramid and fipr's history, kept between frames and grown when a frame
 * needs more. Each render takes `eyes` eyes (1, or 2: a stereo pair, f, out and fov one per eye):
 * every eye's kernels are launched on one stream, one after the other with no host wait between
 * them (each eye has its own film on the GPU), and the host waits once, for the films' buffers
 * that are set and the counters; *syncs receives the host waits (1). */
typedef struct fv_cuda_sdf fv_cuda_sdf;
fv_status fv_cuda_sdf_create(fv_cuda_sdf **out, fv_error *err);
/* sdf-gt and sdf-relaxed: copies the world (host memory, the flat form) to the GPU where it changed,
 * renders every pixel of each eye into its film's buffers (host memory), and adds the costs of all
 * eyes to *counts; *kernel_ms the kernels' own time. */
fv_status fv_cuda_sdf_render(fv_cuda_sdf *c, const struct fv_ksdf_world *w, int eyes, const struct fv_ksdf_frame *f, const fv_film_views *out,
                             struct fv_ksdf_counts *counts, double *kernel_ms, int *syncs, fv_error *err);
/* What ipr and fipr ask of a pyramid frame besides its shape: fipr's Sobel threshold (edge),
 * shadow_reuse (level L-2's visibility kept), and fipr's pass 5 (blur: a Gaussian of blur_sigma
 * pixels over the mask's transitions, kernel/sdf_pyramid.h and kernel/vp_blur.h, on the GPU). */
typedef struct fv_cuda_pyr_opts {
    float edge;
    bool shadow_reuse;
    bool blur;
    float blur_sigma;
} fv_cuda_pyr_opts;
/* ipr and fipr: shape gives the pyramid's sizes, levels and min filter (its pointers are not read;
 * every eye has this size); fov (NULL for ipr) fipr's mask and refresh per eye. Every pass is a
 * kernel; the pyramid's buffers and fipr's history (per eye: fov[e].eye_index) stay on the GPU
 * between frames (reallocated only when the size changes), the world is copied only when it
 * changed; the costs of all eyes are added to *counts. */
fv_status fv_cuda_sdf_pyramid_render(fv_cuda_sdf *c, const struct fv_ksdf_world *w, int eyes, const struct fv_ksdf_frame *f, const struct fv_kpyr *shape,
                                     const struct fv_kpyr_fovea *fov, const fv_cuda_pyr_opts *po, const fv_film_views *out,
                                     struct fv_ksdf_pyr_counts *counts, double *kernel_ms, int *syncs, fv_error *err);
void fv_cuda_sdf_destroy(fv_cuda_sdf *c);
void fv_cuda_sdf_calls(const fv_cuda_sdf *c, fv_cuda_calls *out);

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
