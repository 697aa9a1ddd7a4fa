/* fovea — library-internal edits of an uncommitted scene, for callers that open a scene and
 * change it before committing (the bench's "diffuse" and "animate" scenario fields,
 * docs/bench.md). Not part of the public API: the bench is inside the library. */
#ifndef FV_SCENE_EDIT_H
#define FV_SCENE_EDIT_H

#include "fovea/scene.h"

/* The first object named `name` (fv_mesh_desc.name, a JSON object's "name", a built-in's mesh
 * name), or -1. */
int fv_scene_find_object(const fv_scene *scene, const char *name);

/* Turns every mirror, glossy and dielectric material into FV_MAT_DIFFUSE with albedo
 * min(albedo + specular, 0.95) per channel, so a mirror or glass becomes a light-grey diffuse
 * surface rather than a black one; emission is kept, diffuse materials are left as they are.
 * FV_ERR_INTERNAL on a committed scene. */
fv_status fv_scene_make_diffuse(fv_scene *uncommitted, fv_error *err);

#endif
