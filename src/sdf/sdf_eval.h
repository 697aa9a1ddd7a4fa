/* fovea — internal entry points of the SDF evaluators (for the sphere tracer of issue 11).
 *
 * fv_sdf_distance8 evaluates eight points at once with GCC vector extensions (eval8.c, with an
 * AVX2 build in eval8_avx2.c chosen at run time);
 * fv_sdf_distance1 is the scalar evaluator (eval1.c). Both are compiled from the same kernel
 * (kernel.h) with the same operation order, and neither is built with FMA contraction (C11 mode:
 * -ffp-contract=off), so lane i of distance8 is bit-identical to distance1 of point i.
 */
#ifndef FV_SDF_EVAL_H
#define FV_SDF_EVAL_H

#include "fovea/sdf.h"

/* mat may be NULL. x, y, z, d and mat need no alignment. */
void fv_sdf_distance8(const fv_sdf *sdf, const float x[8], const float y[8], const float z[8], float d[8], int mat[8]);
/* The two builds fv_sdf_distance8 picks from (baseline x86-64 / any target, and AVX2), callable
 * directly so tests check both against the scalar kernel. The AVX2 one needs an AVX2 CPU. */
void fv_sdf_distance8_base(const fv_sdf *sdf, const float x[8], const float y[8], const float z[8], float d[8], int mat[8]);
void fv_sdf_distance8_avx2(const fv_sdf *sdf, const float x[8], const float y[8], const float z[8], float d[8], int mat[8]);
float fv_sdf_distance1(const fv_sdf *sdf, float x, float y, float z, int *mat);

/* One field that is the union of n compiled fields, parts[0] first (compile.c): the program a
 * "union" of their trees compiles to (a culled chain when eight or more parts can be culled), so
 * it gives their fold's values and materials bit for bit; the SDF family's world merges its static
 * objects with it. The parts stay owned by the caller; the result is released with
 * fv_sdf_destroy. FV_ERR_INVALID, NOMEM. */
fv_status fv_sdf_union_create(const fv_sdf *const *parts, int n, fv_sdf **out, fv_error *err);
/* c of the field's bounds: outside fv_sdf_bounds' box, d >= c times the distance to it (c in [0, 1]). */
float fv_sdf_bound_c(const fv_sdf *sdf);

#endif
