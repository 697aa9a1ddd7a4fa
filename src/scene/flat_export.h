/* fovea — a committed scene exported as a kernel scene (kernel/kscene.h): flat arrays and a
 * two-level BVH that kernel/ktraverse.h walks on the CPU and, once a backend copies it, on a GPU.
 *
 * The exporter owns every array the view points at (except the materials, which stay the
 * scene's), so the scene must outlive the export. Creating builds the bottom-level BVHs once (all
 * static meshes in one, each dynamic mesh in its object space) with Embree's generic builder;
 * updating after fv_scene_set_time only copies the dynamic objects' transforms and rebuilds the
 * small top level. Not thread-safe against itself: update while nothing traverses the view.
 */
#ifndef FV_SCENE_FLAT_EXPORT_H
#define FV_SCENE_FLAT_EXPORT_H

#include <stddef.h>
#include "fovea/scene.h"
#include "fovea/status.h"
#include "kernel/kscene.h"

typedef struct fv_scene_export fv_scene_export;

/* What the export holds, for the docs and benchmarks. */
typedef struct fv_scene_export_stats {
    int nodes;          /* bottom-level BVH nodes (fv_knode, 64 bytes each) */
    int leaves;         /* bottom-level leaves */
    int max_depth;      /* deepest bottom-level leaf (root = 1) */
    int triangles;
    int tnodes;         /* top-level nodes */
    int instances;
    double build_ms;    /* creating the export: arrays and every BVH */
    double update_ms;   /* the last fv_scene_export_update that did anything */
    size_t bytes;       /* every array the view points at, materials excluded */
} fv_scene_export_stats;

/* The committed scene s at its current time. FV_ERR_INVALID (scene not committed, too many
 * triangles for the leaf encoding), FV_ERR_NOMEM, FV_ERR_INTERNAL (Embree's builder failed);
 * nothing is left allocated on failure. */
fv_status fv_scene_export_create(const fv_scene *s, fv_scene_export **out, fv_error *err);
/* Brings the snapshot to s's current time (after fv_scene_set_time): dynamic objects' transforms
 * and the top-level BVH. Nothing to do when no object moves or the time has not changed. */
fv_status fv_scene_export_update(fv_scene_export *x, const fv_scene *s, fv_error *err);
/* The kernel scene in host memory; valid until the next update or destroy. */
const fv_kscene *fv_scene_export_view(const fv_scene_export *x);
void fv_scene_export_stats_get(const fv_scene_export *x, fv_scene_export_stats *out);
void fv_scene_export_destroy(fv_scene_export *x);

#endif
