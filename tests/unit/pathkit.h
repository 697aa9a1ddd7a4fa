/* Shared by the tests of the path tracing kernel (transport/path.h) on analytic scenes: the mean
 * of many single-path estimates along one ray. Header-only; include after testkit.h. */
#ifndef FV_TEST_PATHKIT_H
#define FV_TEST_PATHKIT_H

#include "core/rng.h"
#include "transport/path.h"

/* Mean of n pt estimates (green channel) from o along d with max_depth vertices, each on its own
 * camera stream (seed, k). */
static inline double fv_test_pt_mean(const fv_scene *s, fv_vec3 o, fv_vec3 d, int max_depth, int n, uint64_t seed)
{
    fv_path_opts opt = {1, max_depth, 3};
    double sum = 0.0;
    for (int k = 0; k < n; k++) {
        fv_rng rng = fv_rng_stream(seed, 1, (uint64_t)k, 0, 0);
        sum += fv_path_trace(s, &opt, o, d, &rng, NULL, NULL).y;
    }
    return sum / n;
}

#endif
