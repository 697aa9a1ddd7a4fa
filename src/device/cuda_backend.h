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

#ifdef __cplusplus
}
#endif
#endif
