/* fovea — the sphere-tracing family on the device backends (docs/gpu.md): `sdf-gt` and
 * `sdf-relaxed` (the target pixel of technique/sdf/ksdf_pixel.h), `ipr` and `fipr` (its pyramid
 * passes: the level rays of ksdf_pixel.h, the Sobel edges, mask and refresh of kpyr.h, then the
 * target pixel). The frame is written once (sdf_device.c) over the device backend
 * (device/backend.h), a kernel per pass declared in technique/sdf/sdf_kernels.h: the portable
 * backend runs each pass at once over tiles of its grid on the CPU's threads (what CI tests against
 * the CPU pipeline), CUDA queues them on its stream. The world is built on the host as the CPU
 * pipeline builds it (technique/sdf/world.h), only when the scene's time changed and something in
 * it moves, and read in its flat form (on CUDA through mirrors, copied only after a rebuild).
 * fipr's pass 5 (blur=true) is kernels too: the transitions' sigma (technique/sdf/kpyr.h) and the
 * blur's two passes (filter/kblur.h). A stereo frame can be rendered as a pair: the world built
 * once, both eyes' passes queued, the films and counters read back into pinned memory, and one
 * host wait for the pair.
 */
#ifndef FV_TECHNIQUE_SDF_SDF_DEVICE_H
#define FV_TECHNIQUE_SDF_SDF_DEVICE_H

#include "fovea/device.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/stats.h"
#include "technique/sdf/sdf_pipeline.h"

typedef struct fv_sdf_device fv_sdf_device;

/* o: the method's options (show=image); device portable or cuda. */
fv_status fv_sdf_device_create(const fv_scene *scene, const fv_sdf_opts *o, fv_device device, fv_sdf_device **out, fv_error *err);
/* Renders one eye of one frame, reporting the CPU pipeline's counters. */
fv_status fv_sdf_device_render(fv_sdf_device *d, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
/* Renders both eyes of a stereo frame (frames[0] the left, frames[1] the right; the technique
 * class's render_pair): the same images and counters as two calls of fv_sdf_device_render, with
 * one host wait on CUDA ("host_syncs" 1 for the pair). */
fv_status fv_sdf_device_render_pair(fv_sdf_device *d, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err);
/* The technique class's submit and collect (technique/class.h): a frame of `eyes` eyes queued with
 * its read-back into the next of two staging slots, no host wait; the oldest one waited for and
 * delivered. render and render_pair are submit then collect. */
fv_status fv_sdf_device_submit(fv_sdf_device *d, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err);
fv_status fv_sdf_device_collect(fv_sdf_device *d, fv_error *err);
void fv_sdf_device_destroy(fv_sdf_device *d);

#endif
