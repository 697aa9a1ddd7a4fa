/* fovea — the radiosity of fir's VPLs (Foveated Instant Radiosity, Sec. 3.4, Eq. 3).
 *
 * First the direct light is injected into the voxels: every occupied level-0 cell gets the radiance
 * its surface reflects, albedo / pi times the direct irradiance (direct.h) at a point one half cell
 * diagonal in front of the cell's centre along its normal (the centre itself may lie behind the
 * surface, where every shadow ray would be blocked); the pyramid then averages it upwards.
 *
 * A VPL's radiosity is then B = albedo (E_direct + E_cone) with E_direct its own direct irradiance
 * (exact, as the pixels') and E_cone the light that reached it after one more bounce: Eq. 3's sum of
 * cone-traced radiance times directional weights, with six 60-degree cones (one along the normal, five
 * at 60 degrees around it), weighted by the cosine-weighted solid angle each covers (1/4 and 3/20; the
 * usual set since Crassin et al., the paper's [2]), E_cone = pi sum w_i L_i. So a pixel receives two
 * bounces of indirect light (light -> VPL -> pixel and light -> voxel -> VPL -> pixel), as the paper
 * says of its method (Sec. 1).
 *
 * Intensity (Sec. 3.4, "uniform density"): the VPLs stand for the surfaces they were spread over.
 * We make that local: a VPL in density cell c (manage.h's grid) stands for area(c) / n(c), the surface
 * area in the cell shared by the n(c) VPLs there; area(c) counts the occupied level-0 voxels in c
 * times the scene's mean surface area per occupied voxel (the meshes' total area over the occupied
 * voxels; one cell face when the scene has signed distance fields, whose area is not known). Its power
 * for the gather kernel is P = B / pi * area(c) / n(c).
 */
#ifndef FV_TECHNIQUE_VPL_RADIOSITY_H
#define FV_TECHNIQUE_VPL_RADIOSITY_H

#include <stdint.h>
#include "technique/vpl/voxels.h"

/* Index ranges within FV_STREAM_VPL: light walk w of ir is index w; fir's draws start at 1 << 40
 * (fir.c), the injection's at 5 << 40, so no two purposes share a stream. */
#define FV_VPL_RNG_INJECT ((uint64_t)5 << 40)

/* Injects direct light into every occupied cell (scratch: 3 floats per level-0 cell) and rebuilds
 * the pyramid's radiance. Area lights use `area_samples` samples from stream (seed, FV_STREAM_VPL,
 * FV_VPL_RNG_INJECT + cell, 0, frame). Runs inside a region the caller opened, called by every
 * thread of its team: adds the shadow rays cast to *rays (shared); the slots are set and the
 * pyramid rebuilt by the team too; ends with the team's barrier. */
void fv_vpl_inject_team(fv_voxels *v, const fv_scene *s, uint64_t seed, uint64_t frame, int area_samples, float *scratch,
                        uint64_t *rays);

/* E_cone at surface point p with unit normal n (the cones start one cell off the surface). */
fv_vec3 fv_vpl_cone_irradiance(const fv_voxels *v, fv_vec3 p, fv_vec3 n);

/* The mean surface area per occupied level-0 voxel (see above). */
float fv_vpl_area_per_voxel(const fv_voxels *v, const fv_scene *s);

#endif
