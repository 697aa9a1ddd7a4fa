/* fovea — the eight-lane SDF evaluator (sdf_eval.h): kernel.h with GCC vector extensions, for the
 * packet sphere tracer of issue 11 (eight rays of a tile step together).
 *
 * The kernel is built here for the baseline x86-64 (two SSE halves per vector) and, in
 * eval8_avx2.c, for AVX2 (one 256-bit register); the AVX2 build is chosen at run time when the CPU
 * has it. Neither enables FMA, so both give the scalar kernel's results bit for bit. */
#include <string.h>
#define FV_K_WIDE 1
#include "sdf/kernel.h"
#include "sdf/sdf_eval.h"

void fv_sdf_distance8(const fv_sdf *sdf, const float x[8], const float y[8], const float z[8], float d[8], int mat[8])
{
#if defined(__x86_64__) && defined(__GNUC__)
    if (__builtin_cpu_supports("avx2")) {
        fv_sdf_distance8_avx2(sdf, x, y, z, d, mat);
        return;
    }
#endif
    fv_sdf_distance8_base(sdf, x, y, z, d, mat);
}

void fv_sdf_distance8_base(const fv_sdf *sdf, const float x[8], const float y[8], const float z[8], float d[8], int mat[8])
{
    k_eval_arrays(sdf, x, y, z, d, mat);
}
