/* fovea — where the viewer looks.
 *
 * This header holds the gaze point every technique receives with a frame. The display/eye model,
 * eccentricity, regions and acuity models build on it (see docs/architecture.md, src/gaze/).
 */
#ifndef FOVEA_GAZE_H
#define FOVEA_GAZE_H

#include "fovea/math.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Gaze point in normalised screen coordinates: (0,0) top-left, (1,1) bottom-right. */
typedef struct fv_gaze {
    float x, y;
} fv_gaze;

#ifdef __cplusplus
}
#endif
#endif
