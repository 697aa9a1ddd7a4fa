/* fovea — the sphere tracer of the SDF family: many rays marched through the world's field,
 * eight at a time.
 *
 * Sphere tracing (Polychronakis et al. 2023, Sec. 2.1, Fig. 2): a ray advances by the distance the
 * field returns, which never passes a surface, until that distance falls under the hit distance.
 * Over-relaxation (Keinert et al., "Enhanced Sphere Tracing", 2014; `sdf-relaxed`, and `relax` of
 * ipr/fipr) advances by relax x distance instead; when the unbounding spheres of two consecutive
 * points no longer overlap, the step may have jumped a surface, so the ray goes back to the safe
 * step from the previous point and continues unrelaxed.
 *
 * Why batches: on a CPU the field is evaluated for eight points at once (src/sdf, AVX2 when the
 * machine has it), so the tracer keeps eight lanes busy. A lane whose ray finishes takes the next
 * ray of the batch at once (no lane waits for the slowest ray of its packet), and every ray's
 * result depends only on the ray: the 8-wide and the scalar tracer (`wide` false, the "plain
 * scalar loop" the issue compares against) give bit-identical results in any order.
 *
 * The step rule is technique/sdf/kmarch.h's, shared with the portable and CUDA backends.
 *
 * Termination, after the shader convention of the paper's scenes: a hit when the distance is under
 * max(eps, eps_k t) (eps_k: a fraction of a target sample's footprint per unit distance, the same
 * on every pyramid level); a miss when t passes t1; a ray still marching
 * after max_steps evaluations counts as a hit where it stands (grazing rays along silhouettes), or
 * for a shadow ray as not blocked. A camera ray whose point lies inside a solid (distance below
 * minus the hit distance: a pyramid start behind a surface) steps back by the distance until it
 * reaches the surface it entered by; a shadow ray there is blocked. (The paper's shader takes such a
 * point for a hit; stepping back is ours, docs/sdf-tracing.md: it only changes pixels the 3x3
 * minimum failed to protect.)
 */
#ifndef FV_SDF_MARCH_H
#define FV_SDF_MARCH_H

#include <stdbool.h>
#include <stdint.h>
#include "technique/sdf/kmarch.h"
#include "technique/sdf/world.h"

/* fv_march_opts, fv_march_ray, fv_march_hit and the step rule: technique/sdf/kmarch.h. */

/* Marches n rays. any_hit: stop at the first surface (shadow rays: hit = blocked, an exhausted
 * ray counts as not blocked). */
void fv_march(const fv_sdf_world *w, const fv_march_opts *o, const fv_march_ray *rays, fv_march_hit *out, int n, bool any_hit);

/* The field at n points (gradients, fipr's helpers), eight at a time or one by one as o->wide. */
void fv_march_eval_points(const fv_sdf_world *w, bool wide, const fv_vec3 *p, float *d, int n);

#endif
