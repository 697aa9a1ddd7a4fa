/* fovea — the scene: triangle meshes and signed distance fields (static or rigidly animated),
 * materials and lights (point and spot lights may move too). How the
 * scene is looked at (camera, camera path, display, gaze) is an fv_view (fovea/view.h); the
 * loaders return both.
 *
 * Ownership: fv_scene_create returns a scene the caller destroys with fv_scene_destroy. Every
 * fv_scene_add_* call copies what it is given. After fv_scene_commit the geometry is frozen; only
 * the time (fv_scene_set_time, which moves dynamic objects and animated lights) changes. Area lights are emissive
 * triangles: any triangle whose material has non-zero emission.
 * Lifetime and threads: techniques and drivers keep a pointer to the scene, which must outlive
 * them. Building (add_*, commit) and fv_scene_set_time must not overlap any other call on the
 * scene; the queries of a committed scene are safe from any number of threads.
 */
#ifndef FOVEA_SCENE_H
#define FOVEA_SCENE_H

#include <stdbool.h>
#include "fovea/export.h"
#include <stdint.h>
#include "fovea/math.h"
#include "fovea/status.h"
#include "fovea/sdf.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_scene fv_scene;
typedef struct fv_view fv_view; /* fovea/view.h */

typedef enum fv_material_type {
    FV_MAT_DIFFUSE = 0, /* Lambert: albedo */
    FV_MAT_MIRROR,      /* perfect specular reflection tinted by `specular` */
    FV_MAT_GLOSSY,      /* Lambert `albedo` + GGX microfacet lobe (`specular` = F0, `roughness` = alpha) */
    FV_MAT_DIELECTRIC   /* smooth glass: Fresnel reflection + refraction with index `ior`, tint `specular` */
} fv_material_type;

#define FV_NAME_MAX 64

typedef struct fv_material {
    char name[FV_NAME_MAX];
    fv_material_type type;
    fv_vec3 albedo;    /* diffuse reflectance, each channel in [0,1] */
    fv_vec3 specular;  /* specular reflectance / transmission tint, each channel in [0,1] */
    float roughness;   /* GGX alpha in [0.001, 1] (GLOSSY only) */
    float ior;         /* index of refraction > 1 inside the object (DIELECTRIC only) */
    fv_vec3 emission;  /* emitted radiance (W/m^2/sr), on the side the triangle's normal faces */
    bool two_sided_emission;
    int albedo_texture; /* 0: none; else an id from fv_scene_add_texture: the albedo at a point is
                           this texture's (linear) colour there times `albedo`, on meshes with UVs
                           (fv_mesh_desc.uvs); elsewhere (no UVs, SDF objects) `albedo` alone */
    int emission_texture; /* 0: none; else a texture id: the emitted radiance at a point is this
                             texture's colour there times `emission` (glTF emissiveTexture, MTL
                             map_Ke), on meshes with UVs; elsewhere `emission` alone */
} fv_material;

/* A default material of the given type (grey diffuse, white mirror, ...), to be adjusted. */
FV_API fv_material fv_material_default(fv_material_type type);
/* Checks ranges and finiteness; the message names the material and field. */
FV_API fv_status fv_material_validate(const fv_material *m, fv_error *err);
/* "diffuse" | "mirror" | "glossy" | "dielectric" <-> type; false when unknown. */
FV_API bool fv_material_type_from_name(const char *name, fv_material_type *out);
FV_API const char *fv_material_type_name(fv_material_type type);

typedef enum fv_light_type { FV_LIGHT_POINT = 0, FV_LIGHT_SPOT, FV_LIGHT_DIRECTIONAL } fv_light_type;

/* Delta lights. Area lights are emissive triangles (see fv_material.emission). A directional light
 * (the sun) is at infinity: parallel light along `dir`, `pos` unused. */
typedef struct fv_light_desc {
    fv_light_type type;
    fv_vec3 pos;
    fv_vec3 dir;         /* SPOT: axis the light points along; DIRECTIONAL: the way its light travels */
    fv_vec3 intensity;   /* radiant intensity, W/sr; DIRECTIONAL: irradiance on a surface facing it, W/m^2 */
    float inner_deg;     /* SPOT: full intensity inside this half-angle */
    float outer_deg;     /* SPOT: zero outside this half-angle, smooth in between */
} fv_light_desc;

/* The environment light: radiance arriving from infinitely far away, a function of direction only
 * (what escapes the scene sees). A sky gradient about `up`: for a unit direction w towards the
 * sky with t = dot(w, up), the radiance is horizon + (zenith - horizon) t above the horizon (t >= 0)
 * and horizon + (ground - horizon) (-t) below; the three equal make a uniform environment. Every
 * technique that samples lights sees it (docs/scene-format.md, "environment", says which do). */
typedef struct fv_env_desc {
    fv_vec3 zenith, horizon, ground; /* radiance, W/m^2/sr, each channel >= 0 */
    fv_vec3 up;                      /* the zenith's direction (normalised when set) */
} fv_env_desc;

/* A uniform environment of the given radiance, up +y. */
FV_API fv_env_desc fv_env_uniform(fv_vec3 radiance);

typedef struct fv_mesh_desc {
    const char *name;
    const fv_vec3 *positions;
    int vertex_count;
    const fv_vec3 *normals;      /* optional per-vertex shading normals (NULL: flat shading) */
    const uint32_t *indices;     /* 3 per triangle */
    int triangle_count;
    const int *materials;        /* optional per-triangle material ids (NULL: all `material`) */
    int material;
    const fv_vec2 *uvs;          /* optional per-vertex texture coordinates (NULL: none): u to the
                                    right, v up, (0,0) the image's bottom-left corner, repeating
                                    outside [0,1] (OBJ's convention; the glTF importer flips v) */
} fv_mesh_desc;

/* An image a material's albedo_texture reads: 8-bit sRGB-encoded texels, rows from the top,
 * `channels` bytes per texel (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA; alpha is ignored). */
typedef struct fv_texture_desc {
    const char *name;            /* for messages (a file name) */
    int width, height;
    int channels;
    const unsigned char *texels; /* width * height * channels bytes */
} fv_texture_desc;

/* One key of a rigid animation: scale first, then rotation, then translation. */
typedef struct fv_anim_key {
    double time;
    fv_vec3 translate;
    fv_quat rotate;
    fv_vec3 scale;
} fv_anim_key;

FV_API fv_status fv_scene_create(fv_scene **out, fv_error *err);
FV_API void fv_scene_destroy(fv_scene *scene);

/* Returns the new material's id in *id; its albedo_texture (when not 0) must already exist. */
FV_API fv_status fv_scene_add_material(fv_scene *scene, const fv_material *m, int *id, fv_error *err);
/* Looks a material up by name; -1 when absent. */
FV_API int fv_scene_find_material(const fv_scene *scene, const char *name);

/* Adds a texture: its texels are decoded from sRGB to linear when added (IEC 61966-2-1) and kept
 * as floats. Sampling is bilinear with wrap mode repeat (no mipmaps). Refused (FV_ERR_INVALID,
 * naming it): a size below 1 or above FV_TEXTURE_MAX_TEXELS texels (fovea/limits.h), or a scene
 * whose textures would then hold more than FV_TEXTURE_MAX_TOTAL texels; channels outside 1..4.
 * Returns its id (>= 1; 0 means "no texture" in fv_material) in *id. */
FV_API fv_status fv_scene_add_texture(fv_scene *scene, const fv_texture_desc *tex, int *id, fv_error *err);
/* How many textures the scene holds (ids 1..count). */
FV_API int fv_scene_texture_count(const fv_scene *scene);


/* Adds a triangle mesh as one object (static until fv_scene_animate_object makes it dynamic).
 * Triangles with a non-finite vertex, an index out of range or zero area are dropped, with one
 * warning per mesh through log; a mesh left empty is refused. *object_id may be NULL. */
FV_API fv_status fv_scene_add_mesh(fv_scene *scene, const fv_mesh_desc *mesh, const fv_log *log,
                            int *object_id, fv_error *err);

/* Adds a signed distance field (fovea/sdf.h) as one object, in world space: nodes[root] is its
 * root and each leaf's `material` is a material id of this scene. It is rendered by every
 * technique (an Embree user geometry sphere-traced on demand, docs/scene-format.md) and may be
 * made dynamic with fv_scene_animate_object like a mesh. Refused (FV_ERR_INVALID, naming the node):
 * what fv_sdf_create refuses, a material id that does not exist, an emissive material (lights are
 * emissive triangles or delta lights). log is unused today (warnings to come). *object_id may be
 * NULL. */
FV_API fv_status fv_scene_add_sdf(fv_scene *scene, const char *name, const fv_sdf_node *nodes, int count, int root,
                                  const fv_log *log, int *object_id, fv_error *err);

/* Makes an object dynamic, moved rigidly along keys (times strictly increasing; translation lerp,
 * rotation slerp, scale lerp). A dynamic object may not be emissive. */
FV_API fv_status fv_scene_animate_object(fv_scene *scene, int object_id, const fv_anim_key *keys, int count,
                                  fv_error *err);

/* Adds a point, spot or directional light. The scene numbers its lights 0, 1, 2, ... in the order of these
 * calls: that number is fv_scene_animate_light's light_index. */
FV_API fv_status fv_scene_add_light(fv_scene *scene, const fv_light_desc *light, fv_error *err);

/* Moves light light_index (the (light_index + 1)-th fv_scene_add_light) along keys, with the rules
 * and interpolation of fv_scene_animate_object: at time t the key transform, interpolated at t,
 * is applied to the light's `pos` (so a key's translate is an offset when pos is the path's
 * origin, and its scale scales pos about the world origin), and a spot's `dir` is turned by the
 * key's rotation. Before the first key the first holds, after the last the last. Call before
 * fv_scene_commit; a second call replaces the keys. Refused (FV_ERR_INVALID): an index that is
 * not a light added so far, keys that break the rules. */
FV_API fv_status fv_scene_animate_light(fv_scene *scene, int light_index, const fv_anim_key *keys, int count,
                                        fv_error *err);

/* Sets the scene's environment light (one per scene: a second call replaces it). Refused
 * (FV_ERR_INVALID): a non-finite or negative radiance, a zero or non-finite up. All-zero radiance
 * removes it. */
FV_API fv_status fv_scene_set_env(fv_scene *scene, const fv_env_desc *env, fv_error *err);
/* Copies the environment into *out; false (and *out untouched) when the scene has none. */
FV_API bool fv_scene_env(const fv_scene *scene, fv_env_desc *out);

/* When the scene has no light at all (no point or spot light, no emissive triangle, no
 * environment), adds the default lighting a mesh file without lights gets: a sky-gradient
 * environment and a point key light above and in front of the view's default camera (view may be
 * NULL: the scene's default framing), both scaled to the scene's bounding sphere; log receives
 * one line saying what was added. Also added when the only lights are small emissive triangles
 * (under 2% of the default lighting's power on the model, or none brighter than a white surface
 * under it: docs/scene-format.md, "Default view and light"). Call before fv_scene_commit; a no-op
 * when the scene has another light. *added (may be NULL) says whether anything was added. */
FV_API fv_status fv_scene_add_default_lighting(fv_scene *scene, const fv_view *view, const fv_log *log, bool *added, fv_error *err);

/* Validates the scene and builds the acceleration structures. A scene without any object (mesh
 * or SDF) is refused; a scene without any light gets a default point light (a warning says so). */
FV_API fv_status fv_scene_commit(fv_scene *scene, const fv_log *log, fv_error *err);

/* Moves dynamic objects and animated lights to time t (seconds) and refits only what moved. */
FV_API fv_status fv_scene_set_time(fv_scene *scene, double t, fv_error *err);
FV_API double fv_scene_time(const fv_scene *scene);

/* Queries. */
FV_API void fv_scene_bounds(const fv_scene *scene, fv_vec3 *lo, fv_vec3 *hi);
FV_API int fv_scene_triangle_count(const fv_scene *scene);
FV_API int fv_scene_object_count(const fv_scene *scene);
FV_API int fv_scene_dynamic_object_count(const fv_scene *scene);
FV_API int fv_scene_light_count(const fv_scene *scene);       /* delta lights + emissive triangles + environment */
FV_API int fv_scene_material_count(const fv_scene *scene);
/* The material as added (a textured material's albedo is its constant factor). */
FV_API const fv_material *fv_scene_material(const fv_scene *scene, int id);

/* ---- loading ---- */

/* Loads SCENE, a built-in name (see fv_builtin_*) or a file path: .json (fovea scene format,
 * docs/scene-format.md) or any mesh file assimp reads (.obj, .gltf, .glb, .ply, ...). The scene
 * is committed. The view data (camera, camera path, display, gaze) goes to a new *view, or is
 * checked and dropped when view is NULL; the caller destroys both. On failure neither is returned.
 * Errors name the file (and line or field) at fault. */
FV_API fv_status fv_scene_load(const char *name_or_path, const fv_log *log, fv_scene **out, fv_view **view, fv_error *err);

/* Like fv_scene_load but leaves the scene uncommitted, so the caller can still add lights,
 * materials or meshes (the CLI's --point-light) before fv_scene_commit. */
FV_API fv_status fv_scene_open(const char *name_or_path, const fv_log *log, fv_scene **out, fv_view **view, fv_error *err);

/* Built-in scenes: they need no file. */
FV_API int fv_builtin_count(void);
FV_API const char *fv_builtin_name(int i);
FV_API const char *fv_builtin_summary(int i);
/* Builds (uncommitted) built-in scene `name` into an empty scene, and its camera (and camera
 * path) into view (NULL: dropped); FV_ERR_INVALID if unknown. */
FV_API fv_status fv_builtin_build(const char *name, fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
