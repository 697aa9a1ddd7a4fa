/* fovea — the scene's internal representation, shared by the library's modules (loaders,
 * lights, techniques). Not part of the public API.
 *
 * Geometry: every object is a triangle mesh or a signed distance field (an Embree user geometry
 * that sphere-traces it, scene_sdf.c) in object space. Static objects live in one Embree
 * scene (`rtc_static`). Each dynamic object gets its own Embree scene instanced into the top-level
 * scene (`rtc_all`) with a per-frame transform; when the scene has dynamic objects, the static
 * scene is instanced into `rtc_all` too (identity), so moving an object rebuilds only the tiny
 * top-level BVH, never the static one. `rtc_dynamic` holds only the dynamic instances: the
 * photon mapper traces light towards dynamic objects with it (Foveated Photon Mapping, Sec. 3).
 */
#ifndef FV_SCENE_IMPL_H
#define FV_SCENE_IMPL_H

#include <stdbool.h>
#include <embree3/rtcore.h>
#include "fovea/scene.h"
#include "fovea/sdf.h"
#include "kernel/klight.h"
#include "scene/anim.h"
#include "scene/query.h"

typedef struct fv_object {
    char name[FV_NAME_MAX];
    fv_sdf *sdf;         /* a signed distance field (Embree user geometry, scene_sdf.c); NULL: a mesh,
                            and for an SDF the triangle arrays below are NULL and nt = 0 */
    float sdf_eps;       /* sphere tracing's hit distance, scaled to the field's bounds */
    fv_vec3 *pos;        /* object-space vertices */
    fv_vec3 *nrm;        /* optional per-vertex normals */
    fv_vec2 *uv;         /* optional per-vertex texture coordinates (texture.c reads them at hits) */
    uint32_t *idx;       /* 3 per triangle */
    int *mat;            /* per-triangle material ids */
    int nv, nt;
    bool dynamic;
    fv_anim anim;        /* dynamic objects: their keys */
    fv_xform xf, inv;    /* object -> world at the current time, and its inverse */
    RTCScene rtc_child;  /* dynamic objects: the object's own scene */
    fv_vec3 lo, hi;      /* object-space bounds */
} fv_object;

/* A delta light as added, and its keys when it moves (fv_scene_animate_light). */
typedef struct fv_delta {
    fv_light_desc desc;  /* as given, direction normalised: where it stands when not animated */
    fv_anim anim;
} fv_delta;

/* One sampleable light (struct fv_light) is kernel data: kernel/klight.h. */

/* A texture as fv_scene_add_texture keeps it: linear RGB, rows from the top (texture.c). */
typedef struct fv_texture {
    char name[FV_NAME_MAX];
    int w, h;
    float *rgb;          /* 3 w h */
} fv_texture;

struct fv_scene {
    fv_material *mats;
    int nmat, capmat;
    fv_texture *tex;           /* texture id i is tex[i - 1] */
    int ntex, captex;
    long long tex_texels;      /* their total, bounded by FV_TEXTURE_MAX_TOTAL */
    fv_object *objs;
    int nobj, capobj;
    fv_delta *delta;           /* delta lights in the order they were added */
    int ndelta, capdelta;
    bool has_env;              /* the environment light (fv_scene_set_env) */
    fv_env_desc env;

    /* Built at commit. */
    bool committed;
    fv_light *lights;          /* the delta lights that emit first (in the order added), then triangles, then
                                  the environment */
    float *light_cdf;          /* klights.n + 1 entries, light_cdf[n] = 1 */
    fv_klights klights;        /* the table as kernels read it: lights, light_cdf, counts, the environment */
    fv_ktexture *ktex;         /* ntex views of tex as kernels read them (klights.tex) */
    bool lights_move;          /* some delta light has keys */
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

/* fv_scene_add_mesh without its warning: *dropped receives how many triangles were dropped, for a
 * loader that adds many meshes and says it once (load_assimp.c). */
fv_status fv_scene_add_mesh_counted(fv_scene *s, const fv_mesh_desc *m, int *dropped, int *object_id, fv_error *err);

/* World bounds of the objects, dynamic ones over all their keys; valid before commit too. */
void fv_scene_world_bounds(const fv_scene *s, fv_vec3 *lo, fv_vec3 *hi);

/* The Embree user geometry of SDF object o (scene_sdf.c), ready to attach. */
RTCGeometry fv_scene_sdf_geometry(fv_scene *s, fv_object *o);
/* The material of SDF object o at object-space point p (on its surface). */
int fv_scene_sdf_material(const fv_object *o, fv_vec3 p);

#endif
