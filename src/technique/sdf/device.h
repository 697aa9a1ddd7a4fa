/* fovea — `sdf-gt` and `sdf-relaxed` on the device backends (docs/gpu.md): the pixel kernel of
 * kernel/sdf_pixel.h run by the portable backend (the CPU's threads over film tiles, what CI
 * tests) or by CUDA (device/cuda/sdf.cu). The world is built on the host each frame, as the CPU
 * pipeline builds it (technique/sdf/world.h), and read in its flat form.
 */
#ifndef FV_SDF_DEVICE_H
#define FV_SDF_DEVICE_H

#include "fovea/device.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/stats.h"
#include "technique/sdf/pipeline.h"

typedef struct fv_sdf_device fv_sdf_device;

/* o: the method's options (sdf-gt or sdf-relaxed, show=image); device portable or cuda. */
fv_status fv_sdf_device_create(const fv_scene *scene, const fv_sdf_opts *o, fv_device device, fv_sdf_device **out, fv_error *err);
/* Renders one eye of one frame, reporting the CPU pipeline's counters. */
fv_status fv_sdf_device_render(fv_sdf_device *d, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
void fv_sdf_device_destroy(fv_sdf_device *d);

#endif
