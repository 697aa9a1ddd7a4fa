/* fovea — a ray's closest hit as every technique and every kernel sees it, whichever traversal
 * found it: Embree on the CPU (scene/query.h) or the portable BVH (kernel/ktraverse.h) on the CPU
 * backend and on CUDA. Plain data, no functions.
 */
#ifndef FV_KERNEL_KHIT_H
#define FV_KERNEL_KHIT_H

#include "fovea/math.h"

typedef struct fv_hit {
    float t;
    fv_vec3 p;      /* world position */
    fv_vec3 ng;     /* unit geometric normal, world, as wound (not flipped toward the ray) */
    fv_vec3 ns;     /* unit shading normal, world, same hemisphere as ng */
    int obj, prim, mat;
    float u, v;     /* barycentrics of vertices 1 and 2 */
} fv_hit;

#endif
