/* fovea — the voxel grid of Foveated Instant Radiosity (issue 12): a dense grid over the scene's
 * bounds, its mip pyramid, rays cast through level 0 and cones traced through the pyramid.
 *
 * Alg. 1 voxelizes the static part of the scene once (line 1) and the dynamic part every frame
 * (line 4), so a frame pays only for what moves. Static and dynamic contributions are kept in two
 * accumulators per cell; removing the dynamic ones leaves the static accumulator untouched, so the
 * static state comes back bit for bit. Triangles mark every cell their conservative triangle/box
 * overlap (separating axis test) reaches; an SDF object marks the cells whose centre lies within
 * half a cell diagonal of its surface (the field is 1-Lipschitz, so such a cell may meet the
 * surface and a cell farther away cannot). Both are surface voxelizations: a solid's inside is
 * empty.
 *
 * A level-0 cell keeps its occupancy, the average of its writers' unit normals (triangle geometric
 * normals as wound, or the field's gradient) renormalised, the average of their materials' albedos,
 * and one object id: the last writer in voxelization order (objects in increasing id), a dynamic
 * writer over a static one, since the VPLs of Sec. 3.3 follow the object that moves. Radiance is a
 * slot per level-0 cell, filled by the caller (direct-light injection, to come).
 *
 * The pyramid (Sec. 3.4: radiosity by cone tracing on the mipmapped voxelization, Eq. 3) halves the
 * resolution per level down to one cell; a level-l cell holds its occupancy fraction (occupied
 * children / 8, a child outside the grid empty) and premultiplied albedo, normal and radiance (the
 * children's values times their occupancy, / 8). Alg. 3 casts rays, not cones (Sec. 3.2,
 * "Discussion"): fv_voxels_cast walks level 0.
 *
 * Memory: flat arrays sized once at create, about 90 bytes per level-0 cell (about 190 MB at 128^3
 * for a cubic scene: the resolution is bounded by memory long before 1024). Re-voxelizing never
 * allocates. Threads: the getters, cast and cone only read and may run concurrently; the updates
 * and setters must not overlap any other call. The scene must outlive the handle.
 */
#ifndef FV_VPL_VOXELS_H
#define FV_VPL_VOXELS_H

#include <stdbool.h>
#include "scene/query.h"

typedef struct fv_voxels fv_voxels;

/* One level-0 cell as the getters report it (no padding: compare with memcmp). An empty cell is
 * all zeros with object -1. normal is (0, 0, 0) where its writers' normals cancel. */
typedef struct fv_voxel {
    fv_vec3 normal;
    fv_vec3 albedo;
    int object;
    int occupied;
} fv_voxel;

/* One cell of any level: occupancy in [0, 1] and the premultiplied averages (level 0: the cell's
 * own values when occupied, zeros otherwise; normal is then unit). */
typedef struct fv_voxel_mip {
    float occupancy;
    fv_vec3 albedo;
    fv_vec3 normal;
    fv_vec3 radiance;
} fv_voxel_mip;

typedef struct fv_voxel_hit {
    int cell;        /* level-0 index (fv_voxels_index) */
    int ijk[3];
    float t;         /* where the ray enters the cell (the ray's start when it starts inside it) */
    fv_voxel v;
} fv_voxel_hit;

/* Builds the grid over the committed scene's bounds (every time of its dynamic objects):
 * `resolution` cells along the longest axis, cubic cells, as many as cover the other axes (at least
 * one). Voxelizes the static objects, then the dynamic ones at the scene's current time, and builds
 * the pyramid. resolution outside [8, 1024] -> FV_ERR_INVALID naming `resolution`; no memory ->
 * FV_ERR_NOMEM. */
fv_status fv_voxels_create(const fv_scene *scene, int resolution, fv_voxels **out, fv_error *err);
void fv_voxels_destroy(fv_voxels *v);

/* Alg. 1 line 4: clears the cells the dynamic objects wrote last time, voxelizes them at the
 * scene's current time and rebuilds the pyramid over the cells that changed. Radiance slots keep
 * their values (re-inject after). A step of a merged region: every thread of the team calls it (or
 * one thread outside any region); the voxelization is the opening thread's (reported as serial
 * time), the pyramid the team's, with the same bits at any thread count. */
void fv_voxels_update_dynamic(fv_voxels *v);
/* How many level-0 cells the dynamic objects occupy now. */
int fv_voxels_dynamic_cells(const fv_voxels *v);

/* ---- the grid ---- */

/* Cells per axis of `level` (0 = the full resolution). */
void fv_voxels_dims(const fv_voxels *v, int level, int dims[3]);
int fv_voxels_levels(const fv_voxels *v);
/* Edge of a level-0 cell, and the grid's minimum corner (the scene bounds' lo). */
float fv_voxels_cell_size(const fv_voxels *v);
fv_vec3 fv_voxels_origin(const fv_voxels *v);
/* Level-0 index of (i, j, k) (x fastest), -1 outside the grid. */
int fv_voxels_index(const fv_voxels *v, int i, int j, int k);
/* The world-space centre of level-0 cell `cell`. */
fv_vec3 fv_voxels_centre(const fv_voxels *v, int cell);
/* The level-0 cell `cell` (0 <= cell < the product of the level-0 dims). */
void fv_voxels_cell(const fv_voxels *v, int cell, fv_voxel *out);
/* Cell (i, j, k) of `level`; all zeros outside the grid. */
void fv_voxels_mip_cell(const fv_voxels *v, int level, int i, int j, int k, fv_voxel_mip *out);

/* ---- radiance ---- */

/* Sets one cell's slot: threads may set different cells at once (nothing else is written). */
void fv_voxels_set_radiance(fv_voxels *v, int cell, fv_vec3 radiance);
fv_vec3 fv_voxels_radiance(const fv_voxels *v, int cell);
/* Rebuilds every level's radiance from level 0 (after the slots were set); a step of the team as
 * fv_voxels_update_dynamic is. */
void fv_voxels_build_radiance(fv_voxels *v);

/* ---- queries ---- */

/* The first occupied level-0 cell along origin + t dir, t in [0, tmax] (dir need not be unit: t is
 * in units of dir), by a 3D DDA; origin may lie inside or outside the grid. A ray that starts in an
 * occupied cell reports it at t = 0: start rays from a surface one cell off it. False: no hit. */
bool fv_voxels_cast(const fv_voxels *v, fv_vec3 origin, fv_vec3 dir, float tmax, fv_voxel_hit *hit);

/* Voxel cone tracing (Crassin et al. 2011, the paper's [2]) along unit dir from origin, up to
 * tmax: at distance t the cone is d = max(cell, 2 t aperture_tan) wide; the pyramid is sampled
 * there at level l = log2(d / cell) (trilinear in the two nearest levels, blended), the sample's
 * occupancy turned into the coverage of a surface sheet (times 2^l, at most 1: the voxelization is
 * of surfaces), corrected for a step of d/2, and composited front to back. Returns the occlusion
 * reached (0..1) and the radiance in *radiance. Stops when the occlusion passes 0.995 or the cone
 * leaves the grid. */
float fv_voxels_cone(const fv_voxels *v, fv_vec3 origin, fv_vec3 dir, float aperture_tan, float tmax, fv_vec3 *radiance);

#endif
