/* fovea — scene file loaders, dispatched by load.c (see docs/scene-format.md). */
#ifndef FV_SCENE_LOAD_IMPL_H
#define FV_SCENE_LOAD_IMPL_H

#include <stdbool.h>
#include "fovea/scene.h"
#include "fovea/view.h"
#include "core/json_util.h"

/* Options a JSON scene applies to a mesh file it references. */
typedef struct fv_import_opts {
    int material_override;   /* >= 0: every triangle gets this material instead of the file's */
    const fv_xform *xform;   /* NULL: identity; applied after the file's node transforms */
    bool import_camera;      /* take the file's camera into the view when it has one */
    bool import_lights;      /* take the file's point and spot lights */
    const char *prefix;      /* material and object name prefix ("" for none) */
} fv_import_opts;

/* Imports every triangle mesh of a file assimp reads, and its camera into view when
 * opts->import_camera (view may be NULL otherwise). When first_object is not NULL it gets the id
 * of the first object added and *object_count how many (a JSON object may animate them). */
fv_status fv_load_assimp(const char *path, fv_scene *scene, fv_view *view, const fv_import_opts *opts, const fv_log *log,
                         int *first_object, int *object_count, fv_error *err);
/* True when assimp can import files with this path's extension. */
bool fv_load_assimp_supports(const char *path);
/* After a failed import of OBJ file obj_path: the first statement of a material library it names
 * whose numbers do not parse, as "material library 'x.mtl', line N: ..." in why; false when none
 * is found (or the path is not an OBJ). mtl_check.c. */
bool fv_mtl_find_fault(const char *obj_path, char *why, size_t n);

/* A fovea JSON scene file: geometry, materials and lights into scene, the view blocks into view
 * (not NULL). */
fv_status fv_load_json(const char *path, fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);

#endif
