/* fovea — the acuity models the papers use to decide where effort goes: the public entry points
 * of the kernel's equations (kernel/keye.h), which a GPU kernel calls directly; tests/unit/test_gaze.c
 * checks them against values worked by hand.
 */
#include "fovea/gaze.h"
#include "kernel/keye.h"

double fv_acuity_v(double e) { return fv_kacuity_v(e); }

double fv_acuity_cdf(double d) { return fv_kacuity_cdf(d); }

double fv_acuity_cdf_inv_fit(double p) { return fv_kacuity_cdf_inv_fit(p); }

double fv_acuity_hyperbolic(double w, double fovea_deg, double outer_deg) { return fv_kacuity_hyperbolic(w, fovea_deg, outer_deg); }

double fv_acuity_linear(double e, double e0, double e1, double min_value) { return fv_kacuity_linear(e, e0, e1, min_value); }
