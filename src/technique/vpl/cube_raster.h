/* fovea — depth cube maps by rasterising the scene's triangles (Foveated Instant Radiosity
 * Sec. 4.1: the paper renders each VPL's shadow map with the GPU's rasteriser).
 *
 * A texel's depth is defined by its centre ray (cubemap.h): the distance from the map's centre o
 * along the direction d = A + sx U + sy V of the texel centre to the nearest triangle that ray
 * meets. Rasterising computes exactly that, triangle by triangle, without tracing:
 *   - with a, b, c the triangle's corners relative to o and det = a . (b x c), d meets the triangle
 *     in front of o iff d is a non-negative combination of a, b, c, that is iff the three "edge
 *     functions" sign(det) d . (a x b), sign(det) d . (b x c), sign(det) d . (c x a) are all >= 0;
 *     over a face each is linear in (sx, sy), so a row of texels adds a constant per step;
 *   - the distance is then t = det |d| / (nrm . d), nrm = (b - a) x (c - a) (det = nrm . a), also
 *     linear in the denominator;
 *   - which texels to test: the triangle's projection on the face plane (its corners divided by
 *     their depth along the face axis), after clipping at that depth 0; a corner behind the face
 *     turns the clipped edge into a direction to infinity, and the box extends to the face's edge
 *     that way.
 * No clipping or perspective interpolation is involved in the depth itself, so a texel reads what a
 * ray through its centre would find, up to float rounding and the tie rule on shared edges (a
 * texel centre exactly on an edge counts for both triangles; a ray picks one). The cost is per
 * triangle and per covered texel, independent of how many texels miss everything; casting rays
 * costs per texel (cubemap.c chooses, FV_CUBE_BUILD_AUTO).
 *
 * The triangle soup is a snapshot of the committed scene at its current time (moving objects where
 * they are now), taken once per batch of maps and read by every thread. SDF objects have no
 * triangles: a scene with any is built by rays.
 */
#ifndef FV_TECHNIQUE_VPL_CUBE_RASTER_H
#define FV_TECHNIQUE_VPL_CUBE_RASTER_H

#include "fovea/math.h"
#include "fovea/scene.h"
#include "fovea/status.h"

typedef struct fv_tri_soup fv_tri_soup;

/* All triangles of the committed scene s at its current time, in world space, into *io (NULL:
 * created; fv_tri_soup_destroy after): its triangles replaced by s's, its room
 * grown, never shrunk, so that a frame that refreshes a kept soup allocates nothing once warmed up
 * (docs/threads.md, "No allocation in a frame"). Fails with FV_ERR_NOMEM only; *io then keeps its
 * room, and its count is 0. */
fv_status fv_tri_soup_update(fv_tri_soup **io, const fv_scene *s, fv_error *err);
void fv_tri_soup_destroy(fv_tri_soup *t);
int fv_tri_soup_count(const fv_tri_soup *t);

/* Rasterises every triangle into the faces f of one cube map centred at o whose bit (1 << f) is set
 * in face_mask: faces holds 6 faces of n x n, face-major, texel (f, x, y) at [(f n + y) n + x]
 * (cubemap.h's layout). Each texel of a selected face ends as min(its value on entry, the nearest
 * triangle's distance along its centre ray): fill the faces with +inf first. */
void fv_cube_raster(const fv_tri_soup *t, fv_vec3 o, int n, unsigned face_mask, float *faces);

#endif
