/* fovea — the SVGF sweeps (svgf_sweeps.h) built for AVX2: eight pixels per vector instead of the
 * baseline's four. svgf.c calls them when the CPU has AVX2 (fv_svgf_set_isa). FMA stays off, so
 * every operation rounds as in the baseline build and the results are the same bits. */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"

#if defined(__x86_64__) && defined(__GNUC__)
#pragma GCC push_options
#pragma GCC target("avx2")
#include "filter/svgf_impl.h"
#define SVGF_ISA(name) fv_svgf_##name##_avx2
#define SVGF_VW 8 /* floats per AVX2 vector */
#include "filter/svgf_sweeps.h"
#pragma GCC pop_options
#else
/* Not x86-64: svgf.c never calls these (fv_svgf_set_isa refuses AVX2); they only keep the
 * symbols defined. */
#include "filter/svgf_impl.h"
void fv_svgf_variance_avx2(fv_svgf *f) { fv_svgf_variance_base(f); }
void fv_svgf_prefilter_avx2(fv_svgf *f, const float *var) { fv_svgf_prefilter_base(f, var); }
void fv_svgf_atrous_avx2(fv_svgf *f, int step, int src, bool write_hist) { fv_svgf_atrous_base(f, step, src, write_hist); }
#endif
