/* fovea — internal interface of the built-in scenes: one builder per scene (builtin_*.c), all
 * registered in the table of builtin.c, plus helpers the Cornell-box family shares. Each builder
 * fills an empty, uncommitted scene and its view (never NULL) through the public scene and view
 * APIs only.
 */
#ifndef FV_SCENE_BUILTIN_IMPL_H
#define FV_SCENE_BUILTIN_IMPL_H

#include "fovea/scene.h"
#include "fovea/view.h"
#include "scene/mesh_gen.h"

fv_status fv_builtin_cornell(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_cornell_glossy(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_cornell_fpm(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_cornell_fir(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_city(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_sdf_primitives(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_sdf_columns(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_sdf_temple(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_sdf_furnace(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
fv_status fv_builtin_furnace(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);

/* Adds material m under `name`; its id goes to *id. */
fv_status fv_builtin_material(fv_scene *scene, const char *name, fv_material m, int *id, fv_error *err);

/* ---- the Cornell box family (builtin_cornell.c) ---- */

/* Triangles of the room (10) and of the ceiling light (2). */
#define FV_CORNELL_ROOM_TRIS 10
#define FV_CORNELL_LIGHT_TRIS 2

typedef struct fv_cornell_mats {
    int white, red, green, light;
} fv_cornell_mats;

/* The four materials of the measured box: white, red, green walls and the warm-white light. */
fv_status fv_cornell_materials(fv_scene *scene, fv_cornell_mats *out, fv_error *err);
/* Only the three wall materials (out->light = -1), for boxes lit by delta lights: no emissive
 * material is left in the scene for a technique to mistake for a light. */
fv_status fv_cornell_wall_materials(fv_scene *scene, fv_cornell_mats *out, fv_error *err);
/* Adds the room (floor, ceiling, back, red and green walls) and the light as two static objects. */
fv_status fv_cornell_room(fv_scene *scene, const fv_cornell_mats *m, const fv_log *log, fv_error *err);
/* Adds only the room, as the static object "room" (10 triangles), without the light. */
fv_status fv_cornell_walls(fv_scene *scene, const fv_cornell_mats *m, const fv_log *log, fv_error *err);
/* Adds the measured tall block (10 triangles, 330 high, standing on the floor) as "tall_block". */
fv_status fv_cornell_tall_block(fv_scene *scene, int mat, const fv_log *log, fv_error *err);
/* The camera of the measured data set (sized 512 x 512; callers resize). */
fv_camera fv_cornell_camera(void);

#endif
