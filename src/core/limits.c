/* fovea — coordinate and intensity limits (see include/fovea/limits.h for why these values). */
#include <math.h>
#include "fovea/limits.h"

/* The bound as the smallest float at or above it: readers check the double they parsed and the
 * library checks the float it was converted to, and both must agree (float(1e20) > 1e20). */
static double float_ceil(double x)
{
    float f = (float)x;
    if ((double)f < x) f = nextafterf(f, INFINITY);
    return f;
}

static fv_status check(const char *what, const double *v, int n, double lo, double hi, const char *kind, fv_error *err)
{
    lo = -float_ceil(-lo);
    hi = float_ceil(hi);
    for (int i = 0; i < n; i++) {
        if (!isfinite(v[i])) return fv_error_set(err, FV_ERR_INVALID, "%s: %s %g is not finite", what, kind, v[i]);
        if (v[i] < lo || v[i] > hi) {
            if (lo < 0.0)
                return fv_error_set(err, FV_ERR_INVALID, "%s: %s %g is beyond +-%g, the range the ray kernels take", what, kind, v[i], FV_COORD_MAX);
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s %g is outside [0, %g]", what, kind, v[i], FV_INTENSITY_MAX);
        }
    }
    return FV_OK;
}

fv_status fv_limit_coords(const char *what, const double *v, int n, fv_error *err)
{
    return check(what, v, n, -FV_COORD_MAX, FV_COORD_MAX, "coordinate", err);
}

fv_status fv_limit_intensity(const char *what, const double *v, int n, fv_error *err)
{
    return check(what, v, n, 0.0, FV_INTENSITY_MAX, "intensity", err);
}

fv_status fv_limit_vec3(const char *what, fv_vec3 v, fv_error *err)
{
    const double d[3] = {v.x, v.y, v.z};
    return fv_limit_coords(what, d, 3, err);
}

fv_status fv_limit_intensity3(const char *what, fv_vec3 v, fv_error *err)
{
    const double d[3] = {v.x, v.y, v.z};
    return fv_limit_intensity(what, d, 3, err);
}
