/* fovea — the shading of the SDF family (Polychronakis et al. 2023, Sec. 4.1: the scenes without
 * soft shadows and ambient occlusion): Lambert plus a Blinn-Phong lobe from each point or spot
 * light, hard shadows by sphere tracing towards the light, normals from the field's gradient.
 *
 * The material model is the scene's: `albedo` is the Lambert term, a GLOSSY material's `specular`
 * and GGX `roughness` alpha become the Blinn-Phong colour and exponent 2 / alpha^2 - 2 (the usual
 * match of the two lobes' widths); MIRROR and DIELECTRIC materials get a sharp lobe (alpha 0.05)
 * of their `specular` tint: no reflection or refraction rays, as in the paper's shaders. The lobe is
 * normalised ((n + 8) / 8 pi), so a diffuse scene shades exactly as `pt max_depth=1` (direct light
 * only) and the two can be compared. Area lights (emissive triangles) are not seen.
 *
 * This is the CPU's batched form: the field evaluations of many hits go eight at a time, and every
 * per-hit step is technique/sdf/ksdf_shade.h's, which the portable and CUDA backends run a hit at a time.
 */
#ifndef FV_TECHNIQUE_SDF_SDF_SHADE_H
#define FV_TECHNIQUE_SDF_SDF_SHADE_H

#include "core/scratch.h"
#include "technique/sdf/ksdf_shade.h"
#include "technique/sdf/march.h"

/* fv_sdf_shade_opts, fv_sdf_shade_counts and the per-hit steps: technique/sdf/ksdf_shade.h. */

/* Which lights reach a shaded point: FV_SDF_VIS_UNKNOWN and the bits, technique/sdf/ksdf_shade.h. */

/* Shades the n marched camera rays: radiance per ray in color (black for a miss; color NULL:
 * visibility only), when normal is not NULL the unit normal (zero for a miss), when vis_out is
 * not NULL which lights reach each hit. vis_in (NULL: none) gives, per ray, visibility already
 * known (ipr's shadow_reuse): those rays trace no shadow ray. The temporaries come from room (the
 * calling thread's, core/scratch.h) and are given back before returning. FV_ERR_NOMEM without
 * scratch. */
fv_status fv_sdf_shade(const fv_sdf_world *w, const fv_march_opts *mo, const fv_sdf_shade_opts *so, const fv_march_ray *rays,
                       const fv_march_hit *hits, int n, const uint32_t *vis_in, uint32_t *vis_out, fv_vec3 *color, fv_vec3 *normal,
                       fv_sdf_shade_counts *counts, fv_scratch *room, fv_error *err);
/* The most fv_sdf_shade takes from its room for n rays (fv_scratch_reserve). */
size_t fv_sdf_shade_room_bound(int n);

#endif
