/* fovea — umbrella header of libfovea. */
#ifndef FOVEA_H
#define FOVEA_H

#include "fovea/export.h"
#include "fovea/status.h"
#include "fovea/math.h"
#include "fovea/camera.h"
#include "fovea/gaze.h"
#include "fovea/scene.h"
#include "fovea/view.h"
#include "fovea/drive.h"
#include "fovea/film.h"
#include "fovea/params.h"
#include "fovea/stats.h"
#include "fovea/progress.h"
#include "fovea/frame.h"
#include "fovea/technique.h"
#include "fovea/device.h"
#include "fovea/metrics.h"
#include "fovea/bench.h"
#include "fovea/sdf.h"
#include "fovea/limits.h"
#include "fovea/provenance.h"

#ifdef __cplusplus
extern "C" {
#endif
/* sizeof the public struct called type_name ("fv_drive_opts", ...), 0 for a name it does not know:
 * a binding that mirrors the structs (the Python package) checks its layouts against the library
 * it loaded before passing any of them. */
FV_API size_t fv_abi_sizeof(const char *type_name);
#ifdef __cplusplus
}
#endif

#endif
