/* fovea — the compiled form of a signed distance field (include/fovea/sdf.h), shared by the
 * compiler (compile.c) and the two evaluators (eval1.c scalar, eval8.c eight lanes).
 *
 * The node tree becomes a post-order program for a small stack machine, so evaluation is a flat
 * loop without recursion or pointer chasing: leaves push a distance and a material, operators pop
 * two and push one, TRANSFORM and REPEAT push a new evaluation point before their child and pop
 * it (fixing the child's distance) after. Every constant an instruction needs is precomputed
 * (inverse rotation, 1/period, the height field's Lipschitz divisor).
 *
 * A union of many children (a chain of UNION nodes, which is how a flat JSON "union" list arrives)
 * compiles to a culled chain (issue 29): CULL_BEGIN pushes a far accumulator and an upper bound U
 * of the union's value, each child runs behind a CULL that jumps past it and its UNION when its box
 * proves it cannot be the nearest, and the children sit in groups behind one CULL each (a two-level
 * hierarchy over consecutive children). The rules, and why the result is the unculled fold's bit for
 * bit, are in kernel.h (FV_OP_CULL) and docs/sdf.md.
 */
#ifndef FV_SDF_IMPL_H
#define FV_SDF_IMPL_H

#include "fovea/sdf.h"
#include "sdf/program.h"

struct fv_sdf {
    fv_sdf_op *ops;
    int count;
    fv_vec3 lo, hi;   /* the root's bounds */
    float c;          /* d >= c dist(p, [lo, hi]) outside the box (compile.c) */
    int upper;        /* 1: d never exceeds the distance to the box's farthest point */
    float mag;        /* the magnitude of the coordinates and constants evaluation works with */
    float normal_h;   /* default step of fv_sdf_normal */
};

#endif
