/* fovea — the range of coordinates and intensities fovea accepts, in one place.
 *
 * Embree refuses (and in its assertion builds aborts the process on) any ray whose origin or
 * direction has a component beyond FLT_LARGE = 1.844e18: measured here, `fovea render
 * --camera-pos 1.8e18,273,-800` renders and 1e19 aborts inside the packet intersector. Every ray
 * fovea traces starts at a camera (a position, moved by at most half the stereo separation), at a
 * point on the scene's geometry or at a light, so bounding all of them bounds every ray origin.
 * Our own float arithmetic is the tighter bound: a triangle's area test squares the length of the
 * cross product of two edges, up to (2 sqrt(3) C)^4 = 144 C^4 for coordinates within C, which
 * must stay below FLT_MAX = 3.4e38, so C <= 1.2e9 (found by the fuzzer: a triangle with edges of
 * 1e15 was dropped as degenerate). FV_COORD_MAX = 1e9 keeps that, nine orders of magnitude below
 * Embree's limit; in metres it is a million kilometres, in millimetres a thousand.
 *
 * FV_INTENSITY_MAX bounds a point or spot light's intensity and a material's emission. A light's
 * power (4 pi I) and a path's contribution (I over a squared distance, times a few inverse pdfs,
 * summed over samples) must stay finite in float; 1e20 leaves 18 orders of magnitude of headroom
 * below FLT_MAX and is far beyond any physical light in any unit of length.
 *
 * The command line, the JSON scene and scenario readers, the CSV traces, the mesh importer and
 * the library's own checks (cameras, lights, scene bounds, driver options) all call these, so a
 * value is refused alike wherever it comes from.
 */
#ifndef FOVEA_LIMITS_H
#define FOVEA_LIMITS_H

#include "fovea/export.h"
#include "fovea/math.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define FV_COORD_MAX 1.0e9       /* largest |coordinate| of a position, extent or offset */
#define FV_INTENSITY_MAX 1.0e20  /* largest light intensity (W/sr) or emission */
/* The environment's radiance: its power is pi R^2 times 2 pi times the radiance for a bounding
 * sphere of radius R (up to about 1.7e9), so 1e9 keeps it within float with room to spare. */
#define FV_RADIANCE_MAX 1.0e9
/* Textures are kept as linear float RGB, 12 bytes a texel: one of 4096 x 4096 takes 192 MiB, and
 * all of a scene's together at most four times that. Their decoders refuse a larger image before
 * reading its pixels (a PNG header may claim 2^31 x 2^31). */
#define FV_TEXTURE_MAX_TEXELS (4096 * 4096)
#define FV_TEXTURE_MAX_TOTAL (4 * FV_TEXTURE_MAX_TEXELS)

/* Checks n coordinates (finite, |v| <= FV_COORD_MAX). On failure the message reads
 * "<what>: <why>", e.g. "--camera-pos 1e19,273,-800: coordinate 1e+19 is beyond +-1e+09, the
 * range the ray kernels take". Readers check the double they parsed, before converting it to
 * float, so 1e39 is reported as itself rather than as inf. */
FV_API fv_status fv_limit_coords(const char *what, const double *v, int n, fv_error *err);
FV_API fv_status fv_limit_vec3(const char *what, fv_vec3 v, fv_error *err);
/* Checks n intensities (finite, 0 <= v <= FV_INTENSITY_MAX). */
FV_API fv_status fv_limit_intensity(const char *what, const double *v, int n, fv_error *err);
FV_API fv_status fv_limit_intensity3(const char *what, fv_vec3 v, fv_error *err);

/* How far along dir, up to dist, a point leaving c stays within +-FV_COORD_MAX on every axis (for
 * what is placed outside a scene: its framing camera, its default key light). c itself within the
 * range gives a result >= 0. */
static inline float fv_limit_reach(fv_vec3 c, fv_vec3 dir, float dist)
{
    const float cc[3] = {c.x, c.y, c.z}, dd[3] = {dir.x, dir.y, dir.z}, m = (float)FV_COORD_MAX;
    for (int k = 0; k < 3; k++) {
        if (dd[k] * dist + cc[k] > m) dist = (m - cc[k]) / dd[k];
        if (dd[k] * dist + cc[k] < -m) dist = (-m - cc[k]) / dd[k];
    }
    return dist;
}

#ifdef __cplusplus
}
#endif
#endif
