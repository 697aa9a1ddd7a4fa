/* fovea — what the sphere tracers of the SDF family see of a scene at one frame: the union of its
 * signed distance field objects as one field, the box around them, and the point, spot and directional lights.
 *
 * Polychronakis, Koulieris and Mania (EG 2023, Sec. 2.1 and 3) march one implicit scene; a fovea
 * scene may hold several SDF objects, some moving. The world evaluates them as one field, the
 * union (minimum) over objects, each taken in its own space. The static objects are merged into one
 * compiled union (fv_sdf_union_create), so many objects cost what one "union" of the same shapes
 * costs and give its values bit for bit: the kernel culls the objects far from the point (issue 29).
 * A moving object's points are moved back by its inverse transform and its distance scaled by
 * that transform's smallest stretch so it stays a lower bound; the moving objects come after the
 * static union, each skipped when its box proves it cannot be nearer than what was found (which
 * changes no value): the 8-wide and the scalar evaluation give the same numbers bit for bit.
 *
 * The world is also built in the flat form of technique/sdf/ksdf_world.h, which the scalar evaluation, the
 * portable backend and the CUDA backend read (one evaluation of the world, docs/gpu.md).
 *
 * Meshes are not sphere-traced (the family's techniques warn once); pt renders mixed scenes.
 */
#ifndef FV_SDF_WORLD_H
#define FV_SDF_WORLD_H

#include <stdbool.h>
#include "technique/sdf/ksdf_world.h"
#include "scene/light.h"
#include "scene/query.h"

typedef struct fv_sdf_world {
    const fv_scene *scene;
    const fv_sdf *statics;     /* the static objects' union (NULL: none); owned when merged */
    fv_sdf *merged;            /* statics when several were merged, else NULL */
    const fv_sdf **sdfs;       /* the moving objects' fields, in the order of k.objs */
    /* The flat form (technique/sdf/ksdf_world.h): what the scalar evaluation, the portable backend and a
     * GPU's copy read. Its arrays (the static union's program then each moving object's, the
     * moving objects, the lights) are owned here; mats is the scene's. */
    fv_ksdf_world k;
    fv_sdf_op *ops;
    fv_ksdf_object *objs;
    fv_ksdf_light *lights;
    float eps_abs;             /* = k.eps_abs */
    /* what fv_sdf_world_refresh keeps: the SDF objects and delta lights it was built for, the
     * room of ops, and the static fields' list (n entries) */
    int nsdf, nlights, ops_cap;
    const fv_sdf **static_list;
} fv_sdf_world;

/* The scene's SDF objects and delta lights at its current time. FV_ERR_INVALID when the scene has
 * no SDF object; FV_ERR_NOMEM. fv_sdf_world_free releases it (safe on a zeroed world). */
fv_status fv_sdf_world_build(fv_sdf_world *w, const fv_scene *s, fv_error *err);
/* The same for a world kept from frame to frame (zeroed before its first call): a world already
 * built for s is brought to s's current time in place (the moving objects, the lights), its
 * arrays and its static union kept, so that a warmed-up frame allocates nothing (docs/threads.md,
 * "No allocation in a frame"); otherwise it is built afresh. The same world as
 * fv_sdf_world_build's. */
fv_status fv_sdf_world_refresh(fv_sdf_world *w, const fv_scene *s, fv_error *err);
void fv_sdf_world_free(fv_sdf_world *w);

/* The field at eight points (x, y, z need no alignment), with the nearest leaf's material. */
void fv_sdf_world_eval8(const fv_sdf_world *w, const float *x, const float *y, const float *z, float *d, int *mat);
/* The same at one point (fv_ksdf_world_eval1), bit-identical to a lane of fv_sdf_world_eval8. */
float fv_sdf_world_eval1(const fv_sdf_world *w, float x, float y, float z, int *mat);

/* Clips the ray o + t d (d unit) to the world's box: false when it misses the box. */
bool fv_sdf_world_clip(const fv_sdf_world *w, fv_vec3 o, fv_vec3 d, float *t0, float *t1);

#endif
