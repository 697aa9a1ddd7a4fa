/* fovea — what the path tracing kernel takes and gives (kernel/path_impl.h is the kernel itself):
 * its options and what the first hit of a camera path saw. Plain data shared by the CPU's
 * transport/path.c and the device kernels of kernel/pt.h.
 *
 * `max_depth` is the number of path vertices that gather light: 1 = direct light only (emission
 * seen directly plus one light connection), the convention of Embree's `--max-path-length`.
 */
#ifndef FV_KERNEL_PATH_H
#define FV_KERNEL_PATH_H

#include <stdbool.h>
#include "fovea/math.h"

typedef struct fv_path_opts {
    int spp;
    int max_depth;
    int rr_depth;
} fv_path_opts;

/* What the first hit of a camera path saw, for the film's auxiliary buffers. */
typedef struct fv_path_first_hit {
    bool hit;
    float t;
    fv_vec3 p, n, albedo;
    int obj;
} fv_path_first_hit;

/* The balance heuristic for two strategies' densities (Veach 1997, ch. 9). */
FV_HD static inline float fv_path_mis(float a, float b) { return a / (a + b); }

#endif
