/* fovea — the Visual-Polar family's stages on a device backend (docs/gpu.md): the trace (a grid
 * sample at a time, kernel/vp_trace.h, on the flat scene and its BVH), the φ-mipmaps (a cell of a
 * level at a time), the map to the screen (a pixel at a time, kernel/vp_map.h) and the foveated
 * blur (a pixel of each pass at a time, kernel/vp_blur.h). The portable
 * backend runs each stage over tiles of its grid on the CPU's threads, which is what CI tests
 * against the CPU pipeline. The pipeline (pipeline.c) keeps the buffers and the temporal state
 * either way. The denoiser (filter/svgf.h) runs as kernels too: the reprojection of its history
 * (kernel/vp_reproject.h) and its steps (kernel/svgf.h, a pixel at a time, filter/svgf_kernels.h),
 * its buffers and history kept here between frames.
 *
 * The CUDA backend (device/cuda/vpolar.cu) takes a whole frame instead (fv_vp_device_frames): the
 * stages follow one another on the GPU with no host wait between them, and the grid, SVGF's buffers
 * and history, the mipmaps and the film stay there; a stereo pair's two eyes (a device each) are
 * queued together and waited for once.
 */
#ifndef FV_TECHNIQUE_VPOLAR_DEVICE_H
#define FV_TECHNIQUE_VPOLAR_DEVICE_H

#include "filter/phi_mips.h"
#include "filter/svgf.h"
#include "fovea/device.h"
#include "fovea/film.h"
#include "device/cuda_backend.h"
#include "kernel/vp_map.h"
#include "kernel/vp_reproject.h"
#include "technique/vpolar/trace.h"

typedef struct fv_vp_device fv_vp_device;

/* device: portable or cuda. */
fv_status fv_vp_device_create(const fv_scene *scene, fv_device device, fv_vp_device **out, fv_error *err);
void fv_vp_device_destroy(fv_vp_device *d);

/* True for a backend that renders whole frames (cuda: fv_vp_device_frames); false for one that runs
 * the stages below one at a time (portable). */
bool fv_vp_device_whole_frame(const fv_vp_device *d);
/* Whole frames of `eyes` eyes (1, or 2: a stereo pair, a device, frame, film and result per eye;
 * each f's scene is set here, to its device's flat scene at the frame's time) into out, with one
 * host wait for them all (fv_cuda_vp_render). */
fv_status fv_vp_device_frames(fv_vp_device *const *d, int eyes, fv_cuda_vp_frame *f, const fv_film_views *out, fv_cuda_vp_result *res,
                              fv_error *err);

/* The trace stage: every valid cell of the job's grid into g, as fv_vp_trace (the launch order
 * changes nothing: each sample has its own random stream). *done false: cancelled. */
fv_status fv_vp_device_trace(fv_vp_device *d, const fv_vp_trace_job *job, const fv_vp_gbuf *g, fv_vp_trace_result *res, bool *done,
                             fv_error *err);
/* The denoiser's history coordinates (kernel/vp_reproject.h): every cell of the grid into
 * prev_coord (2 floats a cell). */
void fv_vp_device_reproject(fv_vp_device *d, const fv_kvp_reproject_frame *f, float *prev_coord, int threads);
/* The denoiser's stage (kernel/svgf.h) for grid g with options o: its buffers (allocated here,
 * zeroed, kept between frames) and a fresh history. g's col_h must outlive the stage (until the next
 * setup or release). Errors as fv_svgf_create's. */
fv_status fv_vp_device_svgf_setup(fv_vp_device *d, const fv_grid *g, const fv_svgf_opts *o, fv_error *err);
/* Frees the stage's buffers (before its grid goes). */
void fv_vp_device_svgf_release(fv_vp_device *d);
/* As fv_svgf_set_periphery, for the stage's following frames. */
void fv_vp_device_svgf_periphery(fv_vp_device *d, int x_from, int passes);
/* One frame through the stage, as fv_svgf_filter (the same bits and counters); FV_ERR_INVALID when
 * no stage was set up. */
fv_status fv_vp_device_svgf(fv_vp_device *d, const fv_svgf_frame *fr, int threads, fv_svgf_info *info, fv_error *err);
/* Every level of m from rgb (level 0 a copy), as fv_phi_mips_build. */
void fv_vp_device_mips(fv_vp_device *d, fv_phi_mips *m, const float *rgb, int threads);
/* The map stage: every pixel of the screen. */
void fv_vp_device_map(fv_vp_device *d, const fv_kvp_map_frame *mf, const fv_film_views *out, int threads);
/* The foveated blur (kernel/vp_blur.h): rgb (w x h) in place with the per-pixel sigma, as
 * fv_blur_variable, bit for bit; its scratch image is kept between frames. */
fv_status fv_vp_device_blur(fv_vp_device *d, float *rgb, int w, int h, const float *sigma, int threads, fv_error *err);

#endif
