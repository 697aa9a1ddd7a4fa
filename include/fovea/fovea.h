/* fovea — umbrella header of libfovea. */
#ifndef FOVEA_H
#define FOVEA_H

#define FOVEA_VERSION_MAJOR 0
#define FOVEA_VERSION_MINOR 1
#define FOVEA_VERSION_PATCH 0
#define FOVEA_VERSION_STRING "0.1.0"

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
#include "fovea/frame.h"
#include "fovea/technique.h"
#include "fovea/device.h"
#include "fovea/metrics.h"
#include "fovea/bench.h"
#include "fovea/sdf.h"
#include "fovea/limits.h"
#include "fovea/provenance.h"

#endif
