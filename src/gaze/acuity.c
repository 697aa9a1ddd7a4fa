/* fovea — the acuity models the papers use to decide where effort goes. Each function is the
 * paper's equation as printed (with the documented sign fix of the sphere-tracing fall-off);
 * tests/unit/test_gaze.c checks them against values worked by hand.
 */
#include <math.h>
#include "fovea/gaze.h"

/* Visual-Polar, Eq. 1: 60 cycles/degree up to 5.79 degrees, then 449.4 / (0.3 e + 1)^2. The two
 * branches meet at 5.79 (449.4 / 2.737^2 = 60.0). */
double fv_acuity_v(double e)
{
    if (e <= 5.79) return 60.0;
    double k = 0.3 * e + 1.0;
    return 449.4 / (k * k);
}

/* Visual-Polar, Eq. 2. */
double fv_acuity_cdf(double d)
{
    double k = 0.3 * d + 1.0;
    return (1.0 / k + log(k)) * 166.4 * FV_PI_D - 612.3;
}

/* Visual-Polar, Eq. 3 (Horner form of 25.09 p^4 + 0.1680 p^3 + 27.61 p^2 + 23.87 p + 3.232). */
double fv_acuity_cdf_inv_fit(double p)
{
    return (((25.09 * p + 0.1680) * p + 27.61) * p + 23.87) * p + 3.232;
}

/* Inverted-pyramid sphere tracing, Eq. 1 with its three zones (Sec. 3, third pass). */
double fv_acuity_hyperbolic(double w, double fovea_deg, double outer_deg)
{
    if (w <= fovea_deg) return 1.0;
    if (outer_deg > 0.0 && w > outer_deg) return 0.0;
    double p = 0.90964 * exp(-w / 2.9661) + 0.00792;
    return p > 1.0 ? 1.0 : p;
}

double fv_acuity_linear(double e, double e0, double e1, double min_value)
{
    if (e <= e0) return 1.0;
    if (e >= e1 || e1 <= e0) return min_value;
    return 1.0 + (min_value - 1.0) * (e - e0) / (e1 - e0);
}
