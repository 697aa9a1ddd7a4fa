/* fovea — a growable triangle-mesh builder and the procedural shapes the built-in scenes use
 * (quads, tessellated planes, boxes, UV spheres).
 *
 * Every vertex carries a normal: flat shapes store their face normal, spheres their smooth one,
 * so shapes of both kinds can share one builder. Every vertex carries texture coordinates too (a
 * textured material reads them): a quad, each face of a box and a grid span [0,1]^2 from their
 * first corner (p0 -> p1 is +u, p0 -> p3 is +v); a sphere's u runs once around (+x towards +z)
 * and its v from the south pole (0) to the north (1). An allocation failure sets `oom` and turns every
 * later call into a no-op, so a builder can be filled without checking each call; the failure is
 * reported once, by fv_meshbuf_add / fv_meshbuf_check (FV_ERR_NOMEM).
 * Limits: at most INT32_MAX/4 vertices and triangles per builder.
 */
#ifndef FV_SCENE_MESH_GEN_H
#define FV_SCENE_MESH_GEN_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/scene.h"

typedef struct fv_meshbuf {
    fv_vec3 *pos, *nrm; /* nv each */
    fv_vec2 *uv;        /* nv: texture coordinates */
    uint32_t *idx;      /* 3 nt */
    int *mat;           /* nt: per-triangle material id */
    int nv, nt, capv, capt, capuv;
    bool smooth;        /* hand the per-vertex normals to the scene (set by curved shapes) */
    bool oom;
} fv_meshbuf;

void fv_meshbuf_init(fv_meshbuf *mb);
void fv_meshbuf_free(fv_meshbuf *mb);
/* Empties the builder but keeps its memory for the next mesh. */
void fv_meshbuf_clear(fv_meshbuf *mb);

/* Adds a vertex with texture coordinates uv and returns its index (-1 once an allocation has
 * failed); fv_meshbuf_vertex gives it (0, 0). */
int fv_meshbuf_vertex_uv(fv_meshbuf *mb, fv_vec3 p, fv_vec3 n, fv_vec2 uv);
int fv_meshbuf_vertex(fv_meshbuf *mb, fv_vec3 p, fv_vec3 n);
/* Adds triangle a b c (counter-clockwise seen from the side its normal faces). */
void fv_meshbuf_tri(fv_meshbuf *mb, int a, int b, int c, int mat);

/* FV_ERR_NOMEM naming `name` if an allocation failed, else FV_OK. */
fv_status fv_meshbuf_check(const fv_meshbuf *mb, const char *name, fv_error *err);
/* A view of the builder as a mesh description (valid until the builder changes). */
void fv_meshbuf_desc(const fv_meshbuf *mb, const char *name, fv_mesh_desc *out);
/* Adds the built mesh to the scene as one object (fv_scene_add_mesh). */
fv_status fv_meshbuf_add(const fv_meshbuf *mb, fv_scene *scene, const char *name, const fv_log *log,
                         int *object_id, fv_error *err);

/* Flat quad p0 p1 p2 p3 (counter-clockwise seen from the side its normal faces): 2 triangles. */
void fv_mesh_quad(fv_meshbuf *mb, fv_vec3 p0, fv_vec3 p1, fv_vec3 p2, fv_vec3 p3, int mat);
/* Axis-aligned rectangle in the plane {axis = c} (axis 0/1/2 = x/y/z) spanning lo..hi on the two
 * other axes taken cyclically (x: y,z; y: z,x; z: x,y); its normal is +axis when facing > 0,
 * -axis otherwise. 2 triangles. */
void fv_mesh_axis_quad(fv_meshbuf *mb, int axis, float c, float lo_u, float lo_v, float hi_u, float hi_v,
                       int facing, int mat);
/* Plane from `origin` spanned by eu and ev, split into nu x nv quads; normal along eu x ev.
 * 2 nu nv triangles. */
void fv_mesh_grid(fv_meshbuf *mb, fv_vec3 origin, fv_vec3 eu, fv_vec3 ev, int nu, int nv, int mat);
/* Box of half extents `half` around `center`, turned by yaw_deg about +y (counter-clockwise seen
 * from above); outward normals, 12 triangles. */
void fv_mesh_box(fv_meshbuf *mb, fv_vec3 center, fv_vec3 half, float yaw_deg, int mat);
/* The same without its bottom face (10 triangles), for boxes standing on a floor. */
void fv_mesh_box_open(fv_meshbuf *mb, fv_vec3 center, fv_vec3 half, float yaw_deg, int mat);
/* UV sphere with seg_u >= 3 segments around and seg_v >= 2 from pole to pole; smooth normals
 * pointing out (in when `inward`, for a room seen from inside). 2 seg_u (seg_v - 1) triangles. */
void fv_mesh_sphere(fv_meshbuf *mb, fv_vec3 center, float radius, int seg_u, int seg_v, bool inward, int mat);

/* Number of triangles fv_mesh_sphere makes for these segment counts (after clamping). */
int fv_mesh_sphere_triangles(int seg_u, int seg_v);

#endif
