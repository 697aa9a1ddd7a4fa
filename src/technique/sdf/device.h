/* fovea — the sphere-tracing family on the device backends (docs/gpu.md): `sdf-gt` and
 * `sdf-relaxed` (the target pixel of kernel/sdf_pixel.h), `ipr` and `fipr` (its pyramid passes:
 * the level rays of kernel/sdf_pixel.h, the Sobel edges, mask and refresh of kernel/sdf_pyramid.h,
 * then the target pixel), run by the portable backend (each pass over tiles of its grid on the
 * CPU's threads, what CI tests against the CPU pipeline) or by CUDA (device/cuda/sdf.cu, a kernel
 * per pass). The world is built on the host each frame, as the CPU pipeline builds it
 * (technique/sdf/world.h), and read in its flat form. fipr's pass 5 (blur=true) is kernels too:
 * the transitions' sigma (kernel/sdf_pyramid.h) and the blur's two passes (kernel/vp_blur.h).
 * A stereo frame can be rendered as a pair: the world built once, and on CUDA both eyes' kernels
 * launched before the one host wait.
 */
#ifndef FV_SDF_DEVICE_H
#define FV_SDF_DEVICE_H

#include "fovea/device.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/stats.h"
#include "technique/sdf/pipeline.h"

typedef struct fv_sdf_device fv_sdf_device;

/* o: the method's options (show=image); device portable or cuda. */
fv_status fv_sdf_device_create(const fv_scene *scene, const fv_sdf_opts *o, fv_device device, fv_sdf_device **out, fv_error *err);
/* Renders one eye of one frame, reporting the CPU pipeline's counters. */
fv_status fv_sdf_device_render(fv_sdf_device *d, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
/* Renders both eyes of a stereo frame (frames[0] the left, frames[1] the right; the technique
 * class's render_pair): the same images and counters as two calls of fv_sdf_device_render, with
 * one host wait on CUDA ("host_syncs" 1 for the pair). */
fv_status fv_sdf_device_render_pair(fv_sdf_device *d, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err);
void fv_sdf_device_destroy(fv_sdf_device *d);

#endif
