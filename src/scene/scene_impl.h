/* fovea — the scene's internal representation, shared by the library's modules (loaders,
 * lights, techniques). Not part of the public API.
 *
 * Geometry: every object is a triangle mesh in object space. Static objects live in one Embree
 * scene (`rtc_static`). Each dynamic object gets its own Embree scene instanced into the top-level
 * scene (`rtc_all`) with a per-frame transform; when the scene has dynamic objects, the static
 * scene is instanced into `rtc_all` too (identity), so moving an object rebuilds only the tiny
 * top-level BVH, never the static one. `rtc_dynamic` holds only the dynamic instances: the
 * photon mapper traces light towards dynamic objects with it (Foveated Photon Mapping, Sec. 3).
 */
#ifndef FV_SCENE_IMPL_H
#define FV_SCENE_IMPL_H

#include <embree3/rtcore.h>
#include "fovea/scene.h"

typedef struct fv_object {
    char name[FV_NAME_MAX];
    fv_vec3 *pos;        /* object-space vertices */
    fv_vec3 *nrm;        /* optional per-vertex normals */
    uint32_t *idx;       /* 3 per triangle */
    int *mat;            /* per-triangle material ids */
    int nv, nt;
    bool dynamic;
    fv_anim_key *keys;
    int nkeys;
    fv_xform xf, inv;    /* object -> world at the current time, and its inverse */
    RTCScene rtc_child;  /* dynamic objects: the object's own scene */
    fv_vec3 lo, hi;      /* object-space bounds */
} fv_object;

/* One sampleable light: a delta light or an emissive triangle. */
typedef struct fv_light {
    int kind;            /* 0: delta light (desc), 1: emissive triangle */
    fv_light_desc desc;
    int obj, prim;       /* emissive triangle */
    float area;
    fv_vec3 n;           /* unit geometric normal of the triangle */
    fv_vec3 emission;
    bool two_sided;
    float power;         /* selection weight ~ emitted power */
} fv_light;

struct fv_scene {
    fv_material *mats;
    int nmat, capmat;
    fv_object *objs;
    int nobj, capobj;
    fv_light_desc *delta;
    int ndelta, capdelta;

    /* Built at commit. */
    bool committed;
    fv_light *lights;
    int nlights;
    float *light_cdf;          /* nlights + 1 entries, light_cdf[nlights] = 1 */
    int **tri_light;           /* per object: per triangle light index or -1 (NULL: none) */
    RTCDevice dev;
    RTCScene rtc_static, rtc_all, rtc_dynamic;
    unsigned static_inst_id;   /* geometry id of the static instance inside rtc_all */
    int ndynamic;
    fv_vec3 lo, hi;            /* world bounds over all times sampled at commit */
    float eps;                 /* ray offset scaled to the scene's size */
    double time;
    char embree_msg[256];      /* last message from Embree's error callback */
};

/* ---- ray queries (scene.c) ---- */

typedef enum fv_trace_set {
    FV_TRACE_ALL = 0,     /* static and dynamic objects at the current time */
    FV_TRACE_STATIC,      /* static objects only */
    FV_TRACE_DYNAMIC      /* dynamic objects only */
} fv_trace_set;

typedef struct fv_hit {
    float t;
    fv_vec3 p;      /* world position */
    fv_vec3 ng;     /* unit geometric normal, world, as wound (not flipped toward the ray) */
    fv_vec3 ns;     /* unit shading normal, world, same hemisphere as ng */
    int obj, prim, mat;
    float u, v;     /* barycentrics of vertices 1 and 2 */
} fv_hit;

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

/* A point just off the surface on the side of direction d, to start the next ray from. */
static inline fv_vec3 fv_offset_point(const fv_scene *s, fv_vec3 p, fv_vec3 ng, fv_vec3 d)
{
    float e = s->eps;
    return fv_madd(p, ng, fv_dot(ng, d) >= 0.0f ? e : -e);
}

/* World-space vertices of triangle `prim` of object `obj` at the current time. */
void fv_scene_triangle(const fv_scene *s, int obj, int prim, fv_vec3 *a, fv_vec3 *b, fv_vec3 *c);

#endif
