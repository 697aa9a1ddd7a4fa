/* fovea — the eight-lane SDF kernel built for AVX2 (see eval8.c, which calls it when the CPU has
 * AVX2). FMA stays off, so results equal the scalar kernel's bit for bit. */
#include <string.h>
#include "sdf/sdf_eval.h"

#if defined(__x86_64__) && defined(__GNUC__)
#pragma GCC push_options
#pragma GCC target("avx2")
#define FV_K_WIDE 1
#include "sdf/kernel.h"

void fv_sdf_distance8_avx2(const fv_sdf *sdf, const float x[8], const float y[8], const float z[8], float d[8], int mat[8])
{
    k_eval_arrays(sdf, x, y, z, d, mat);
}
#pragma GCC pop_options
#else
/* Not x86-64: eval8.c never calls this; it only keeps the symbol defined. */
void fv_sdf_distance8_avx2(const fv_sdf *sdf, const float x[8], const float y[8], const float z[8], float d[8], int mat[8])
{
    fv_sdf_distance8_base(sdf, x, y, z, d, mat);
}
#endif
