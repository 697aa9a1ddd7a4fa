/* fovea — the flat scene (scene/flat_export.h, kernel/kscene.h) on a device backend (device/backend.h),
 * for the kernels that trace it. Every array links by index, so the copy is made array by array
 * and only the arrays' own pointers change. What time changes (objects' transforms, instances, the
 * top-level BVH, the light table) is kept in mirrors (fv_mirror): a later frame copies an array only
 * when its bytes changed, through pinned memory, so a still scene is copied once and a moving one
 * never makes the host wait. On a backend whose device memory is the host's (portable) the view is
 * the host snapshot itself: nothing is copied.
 */
#ifndef FV_SCENE_FLAT_EXPORT_DEVICE_H
#define FV_SCENE_FLAT_EXPORT_DEVICE_H

#include "device/backend.h"
#include "fovea/status.h"
#include "kernel/kscene.h"

typedef struct fv_scene_device fv_scene_device;

/* Copies host (the export's view, host memory) onto b. */
fv_status fv_scene_device_create(fv_backend *b, const fv_kscene *host, fv_scene_device **out, fv_error *err);
/* Brings the device copy to host's state (the same export, at a later time): queues the copies of
 * the arrays time changed; FV_ERR_INTERNAL when the scene's shape changed. */
fv_status fv_scene_device_update(fv_scene_device *d, const fv_kscene *host, fv_error *err);
/* The scene as the kernels read it (device pointers), passed to them by value. */
const fv_kscene *fv_scene_device_view(const fv_scene_device *d);
void fv_scene_device_destroy(fv_scene_device *d);

#endif
