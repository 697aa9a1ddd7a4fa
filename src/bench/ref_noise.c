/* fovea — how noisy a bench's reference is, and whether it is too noisy for what it measures.
 *
 * A Monte Carlo reference of N samples per pixel is itself off by its variance: its MSE against
 * the true image is sigma^2 / N per pixel. A method's MSE measured against it is the method's own
 * error plus that (independent estimates add their variances), so an error that is not well above
 * the reference's is mostly the reference's noise. The reference's error is estimated from a probe:
 * the same method with n = N / 4 samples on an independent random stream, whose MSE against the
 * reference is sigma^2 / n + sigma^2 / N = (k + 1) sigma^2 / N with k = N / n. The estimate is
 * therefore MSE(probe, reference) / (k + 1), per region, at a cost of a quarter of one reference
 * frame. Errors are measured on display values, whose sRGB curve compresses a noisier image's
 * errors more: a probe of fewer samples makes the estimate low (pt on cornell at 32x32, 32 samples:
 * -21% with a 4-sample probe, -13% with 8; 128 samples: -3% with 16, +9% with 32). Methods whose frames carry history between frames (a temporal reference) are not probed:
 * one frame alone is not a sample of their sequence.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench/bench_impl.h"
#include "fovea/technique.h"

/* The probe's share of the reference's samples: the cost of the estimate against its bias (above). */
#define PROBE_FRACTION 4

/* The warning fires when the reference's error is more than this share of the smallest error it
 * measures (issue 27): the smallest method error is then at least 10% reference noise. */
#define NOISE_SHARE 0.1

bool fv_bench_ref_noise_plan(const fv_scenario *sc, fv_bench_ref_noise *rn)
{
    memset(rn, 0, sizeof *rn);
    const fv_bench_method *m = &sc->reference;
    const int mi = fv_technique_index(m->method);
    const char *key = fv_technique_spp_param(mi);
    if (!key) {
        snprintf(rn->why_not, sizeof rn->why_not, "%s has no samples-per-pixel parameter", m->method);
        return false;
    }
    if (fv_technique_warmup_frames(mi) > 0 || fv_technique_still_warmup(mi) > 0) {
        snprintf(rn->why_not, sizeof rn->why_not, "%s keeps state between frames", m->method);
        return false;
    }
    /* the reference's samples per pixel, as the scenario sets them (a reference left at its default is
     * not probed: the default is rarely what a reference is rendered with) */
    int spp = 0;
    for (int i = 0; i < fv_params_count(m->params); i++)
        if (!strcmp(fv_params_key(m->params, i), key)) spp = atoi(fv_params_value(m->params, i));
    if (spp <= 0) {
        snprintf(rn->why_not, sizeof rn->why_not, "the reference does not set %s", key);
        return false;
    }
    if (spp < 2) {
        snprintf(rn->why_not, sizeof rn->why_not, "a reference of 1 sample per pixel");
        return false;
    }
    rn->spp = spp;
    rn->probe_spp = spp / PROBE_FRACTION > 0 ? spp / PROBE_FRACTION : 1;
    rn->spp_key = key;
    return true;
}

void fv_bench_ref_noise_estimate(fv_bench_ref_noise *rn, const fv_metric_report *probe_vs_ref)
{
    const double k = (double)rn->spp / rn->probe_spp;
    for (int r = 0; r < FV_REGION_COUNT; r++) rn->mse[r] = probe_vs_ref->region[r].mse / (k + 1.0);
    rn->estimated = true;
}

void fv_bench_ref_noise_check(fv_bench_ref_noise *rn, const fv_bench_result *res, int n)
{
    rn->warn = false;
    if (!rn->estimated) return;
    double worst = 0.0; /* the largest share of a measured error that is the reference's */
    for (int i = 0; i < n; i++)
        for (int r = 0; r < FV_REGION_COUNT; r++) {
            const fv_metric_values *v = &res[i].error.region[r];
            if (v->pixels == 0 || !(v->mse > 0.0) || !isfinite(v->mse)) continue;
            double share = rn->mse[r] / v->mse;
            if (share > worst) {
                worst = share;
                rn->warn_region = r;
                rn->warn_mse = v->mse;
                snprintf(rn->warn_label, sizeof rn->warn_label, "%s", res[i].m->label);
            }
        }
    if (!(worst > NOISE_SHARE)) return;
    rn->warn = true;
    /* The measured error is the method's own plus the reference's, and the reference's falls as
     * 1 / spp: spp' keeps it within a tenth of what is then measured when
     * ref spp / spp' <= NOISE_SHARE (own + ref spp / spp'), i.e. spp' >= spp ref (1 - s) / (s own),
     * s = NOISE_SHARE; the method's own error is at least a hundredth of the measured one here
     * (below that it cannot be told from the reference's noise at all). Rounded up to a power of 2. */
    const double ref = rn->mse[rn->warn_region], own = fmax(rn->warn_mse - ref, 0.01 * rn->warn_mse);
    const double need = rn->spp * ref * (1.0 - NOISE_SHARE) / (NOISE_SHARE * own);
    int spp = rn->spp;
    while (spp < need && spp < (1 << 24)) spp *= 2;
    rn->spp_needed = spp;
}

void fv_bench_ref_noise_message(const fv_bench_ref_noise *rn, const fv_scenario *sc, char *buf, size_t n)
{
    if (!rn->warn) {
        buf[0] = '\0';
        return;
    }
    snprintf(buf, n,
             "the reference (%s, %s=%d) is too noisy for the errors it measures: its own MSE in the %s is about %.3g, "
             "more than a tenth of %s's %.3g there; render it with %s=%d (--reference %s:%s=%d, or the scenario's "
             "\"reference\")",
             sc->reference.method, rn->spp_key, rn->spp, fv_region_name(rn->warn_region), rn->mse[rn->warn_region], rn->warn_label,
             rn->warn_mse, rn->spp_key, rn->spp_needed, sc->reference.method, rn->spp_key, rn->spp_needed);
}
