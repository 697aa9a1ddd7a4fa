/* fovea — what a technique may ask a committed scene: rays (closest hit, packets, occlusion,
 * visibility), the material and kind of what was hit, whether an object moves, its bounds now.
 *
 * This is the seam between light transport and geometry: techniques include this header (and
 * scene/light.h for lights), never the scene's representation (scene_impl.h), so any kind of object
 * that answers these queries (triangle meshes and signed distance fields) is rendered by
 * every technique. All queries are thread-safe on a committed scene whose time is not being set.
 */
#ifndef FV_SCENE_QUERY_H
#define FV_SCENE_QUERY_H

#include <stdbool.h>
#include "fovea/scene.h"
#include "fovea/sdf.h"
#include "kernel/khit.h"

/* ---- ray queries (scene.c) ---- */


typedef enum fv_trace_set {
    FV_TRACE_ALL = 0,     /* static and dynamic objects at the current time */
    FV_TRACE_STATIC,      /* static objects only */
    FV_TRACE_DYNAMIC      /* dynamic objects only */
} fv_trace_set;


/* Closest hit along o + t d, t in (eps, tmax). d need not be unit (t is then in units of d). */
bool fv_scene_intersect(const fv_scene *s, fv_trace_set set, fv_vec3 o, fv_vec3 d, float tmax, fv_hit *hit);
/* Closest hits of n <= 8 camera rays from one origin (all geometry, no distance limit), traced as
 * one coherent packet; ok[i] says whether ray i hit. Returns the number of hits. */
int fv_scene_intersect8(const fv_scene *s, fv_vec3 o, const fv_vec3 *d, int n, fv_hit *hits, bool *ok);
/* The same for the lanes marked in active[8] (the others idle; ok is false for them). d must hold
 * eight directions; those of inactive lanes are not read. */
int fv_scene_intersect8_active(const fv_scene *s, fv_vec3 o, const fv_vec3 *d, const bool *active, fv_hit *hits, bool *ok);
/* Any hit in (eps, tmax). */
bool fv_scene_occluded(const fv_scene *s, fv_trace_set set, fv_vec3 o, fv_vec3 d, float tmax);
/* True when nothing blocks the segment from surface point p (geometric normal ng, either side)
 * to point q, q excluded: the shadow ray of next-event estimation and of every light connection.
 * The ray starts off the surface and stops eps short of q, so q may lie on a light's surface. */
bool fv_scene_visible(const fv_scene *s, fv_trace_set set, fv_vec3 p, fv_vec3 ng, fv_vec3 q);

/* fv_scene_visible for up to eight points q[i] (lanes with active[i]) from one surface point p,
 * as one packet of occlusion rays (all geometry): visible[i] false for inactive lanes. Returns how
 * many rays were cast (a q within 2 eps of p is visible without a ray). */
int fv_scene_visible8(const fv_scene *s, fv_vec3 p, fv_vec3 ng, const fv_vec3 *q, const bool *active, bool *visible);

/* How far a new ray starts off a surface, scaled to the scene's size. */
float fv_scene_ray_eps(const fv_scene *s);

/* A point just off the surface on the side of direction d, to start the next ray from. */
static inline fv_vec3 fv_offset_point(const fv_scene *s, fv_vec3 p, fv_vec3 ng, fv_vec3 d)
{
    float e = fv_scene_ray_eps(s);
    return fv_madd(p, ng, fv_dot(ng, d) >= 0.0f ? e : -e);
}

/* World-space vertices of triangle `prim` of object `obj` at the current time. */
void fv_scene_triangle(const fv_scene *s, int obj, int prim, fv_vec3 *a, fv_vec3 *b, fv_vec3 *c);
/* How many triangles object `obj` has (0 for an SDF object): prim runs over [0, count) above. */
int fv_scene_object_triangle_count(const fv_scene *s, int obj);
/* The material id of triangle `prim` of object `obj` (what a hit on it reports as fv_hit.mat). */
int fv_scene_triangle_material(const fv_scene *s, int obj, int prim);

/* ---- objects ---- */

typedef enum fv_object_kind {
    FV_OBJECT_MESH = 0, /* a triangle mesh */
    FV_OBJECT_SDF       /* a signed distance field (fv_scene_add_sdf) */
} fv_object_kind;

fv_object_kind fv_scene_object_kind(const fv_scene *s, int obj);
/* The compiled field of an SDF object, in object space (world space unless the object moves: then
 * evaluate at the point moved back by the object's inverse transform); NULL for a mesh. */
const fv_sdf *fv_scene_object_sdf(const fv_scene *s, int obj);
/* How many objects are signed distance fields. */
int fv_scene_sdf_object_count(const fv_scene *s);
/* True when the object moves (fv_scene_animate_object). */
bool fv_scene_object_dynamic(const fv_scene *s, int obj);
/* The map from world space to the object's own space at the scene's current time (identity for a
 * static object): where an SDF object's field is evaluated. */
void fv_scene_object_world_to_local(const fv_scene *s, int obj, fv_xform *out);
/* World-space box around the object at the scene's current time. */
void fv_scene_object_bounds(const fv_scene *s, int obj, fv_vec3 *lo, fv_vec3 *hi);
/* ---- the material at a surface point (texture.c) ----
 *
 * The one place a surface's albedo and emission are read: a material with an albedo_texture has
 * its albedo looked up at the point (and one with an emission_texture its emission, the same way) (texture coordinates interpolated with the hit's barycentrics, the
 * texture sampled bilinearly and multiplied by the material's constant albedo). An untextured
 * material, or a point without texture coordinates (a mesh without UVs, an SDF object), gets the
 * scene's own material, not a copy: the untextured path costs one test. A textured one is copied
 * into *buf with its albedo resolved; the result points at one or the other, so keep buf alive
 * as long as the result. */

/* The textured case, out of line: material m (id of triangle prim of object obj) at barycentrics
 * (u, v). */
const fv_material *fv_material_textured(const fv_scene *s, const fv_material *m, int obj, int prim, float u, float v, fv_material *buf);

/* Material id mat on triangle prim of object obj at barycentrics (u, v) of its vertices 1 and 2. */
static inline const fv_material *fv_material_at(const fv_scene *s, int mat, int obj, int prim, float u, float v, fv_material *buf)
{
    const fv_material *m = fv_scene_material(s, mat);
    return m->albedo_texture || m->emission_texture ? fv_material_textured(s, m, obj, prim, u, v, buf) : m;
}

/* The material of a hit (its mat id) at the hit. */
static inline const fv_material *fv_hit_material(const fv_scene *s, const fv_hit *h, fv_material *buf)
{
    return fv_material_at(s, h->mat, h->obj, h->prim, h->u, h->v, buf);
}

#endif
