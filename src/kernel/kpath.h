/* fovea — what the path tracing kernel takes and gives (kernel/kpath_impl.h is the kernel itself):
 * its options and what the first hit of a camera path saw. Plain data shared by the CPU's
 * transport/path.c and the device kernels of kernel/kpt.h.
 *
 * `max_depth` is the number of path vertices that gather light: 1 = direct light only (emission
 * seen directly plus one light connection), the convention of Embree's `--max-path-length`.
 */
#ifndef FV_KERNEL_KPATH_H
#define FV_KERNEL_KPATH_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/camera.h"
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
    fv_vec3 reflectance; /* what a denoiser demodulates by: fv_bsdf_demod_reflectance */
    int obj;
} fv_path_first_hit;

/* One eye of one frame of camera paths, as a device kernel is launched with it: the camera, the
 * frame's seed, eye and index (the random stream of sample k of pixel p is the camera stream at
 * (p * 2 + eye, k, frame), technique/kit.h's convention) and the path options. */
typedef struct fv_kpt_frame {
    fv_camera_basis cam;
    uint64_t seed;
    int eye, frame;
    fv_path_opts opt;
} fv_kpt_frame;

/* A radiance estimate that is not finite is replaced by black and counted in *dropped, so one bad
 * path never poisons a pixel, a filter or a reference (technique/kit.h's guard is this one). */
FV_HD static inline fv_vec3 fv_path_guard(fv_vec3 L, uint64_t *dropped)
{
    if (fv_is_finite3(L)) return L;
    (*dropped)++;
    return fv_v3s(0.0f);
}

/* The balance heuristic for two strategies' densities (Veach 1997, ch. 9). */
FV_HD static inline float fv_path_mis(float a, float b) { return a / (a + b); }

#endif
