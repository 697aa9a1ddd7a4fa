/* fovea — benchmark harness internals shared by the runner (run.c) and the reports (report.c). */
#ifndef FV_BENCH_IMPL_H
#define FV_BENCH_IMPL_H

#include <stdbool.h>
#include "bench/scenario.h"
#include "fovea/drive.h"
#include "fovea/metrics.h"

/* The heat maps of a report: each method's FLIP error of the last frame. FLIP lies in [0,1], so
 * its fixed top is one scale shared by every method of a comparison (and by every report): the
 * same colour is the same error in every heat map, and the colour bar says so. */
#define FV_BENCH_HEAT_LABEL "FLIP"
#define FV_BENCH_HEAT_MAX 1.0f

/* What one method measured over all frames and repeats. */
typedef struct fv_bench_result {
    const fv_bench_method *m;
    double *ms;                 /* per repeat: mean ms per frame */
    double ms_median, ms_min, ms_max;
    /* Frame pacing over every timed frame of every repeat (docs/bench.md): nearest-rank p50 and
     * p99 (core/order_stats.h) and the worst frame, in ms. */
    double frame_p50, frame_p99, frame_max;
    double speedup;             /* median over rounds of baseline / this (run.c) */
    fv_stats stages;            /* per stage: median over repeats of the mean per frame */
    fv_stats stages_min, stages_max; /* the same stages (same order): least and most over repeats */
    fv_stats counters;          /* mean per frame, last repeat */
    fv_metric_report error;     /* mean over frames, per region */
    fv_metric_report error_vs[FV_BENCH_MAX_EXTRA]; /* the same against each extra reference */
    int rank;                   /* the process that timed it (fv_bench_split); 0 in one process */
    bool has_temporal;
    double temporal_mse[FV_REGION_COUNT], temporal_e[FV_REGION_COUNT];
    double image_mean[3];       /* the last frame's mean linear RGB (devices compared: gpu-pt) */
    char img[4096], heat[4096], crop[4096]; /* paths relative to the output folder */
} fv_bench_result;

/* The reference's own error, estimated from a probe render (ref_noise.c). */
typedef struct fv_bench_ref_noise {
    bool estimated;
    char why_not[160];           /* when not estimated */
    const char *spp_key;         /* the reference method's samples-per-pixel parameter */
    int spp, probe_spp;
    double mse[FV_REGION_COUNT]; /* the reference's estimated MSE per region, at the last frame */
    bool warn;                   /* more than a tenth of the smallest error measured against it */
    int warn_region;             /* where the reference's share of an error is largest */
    double warn_mse;             /* that error */
    char warn_label[64];         /* the row that measured it */
    int spp_needed;              /* samples that bring the reference's share below a tenth */
} fv_bench_ref_noise;

typedef struct fv_bench_run_info {
    const fv_scenario *sc;
    const fv_bench_options *opt;
    int threads;
    const char *out_dir;
    fv_driver *driver;          /* the frames of every measured method */
    fv_driver *ref_driver;      /* the same frames on the reference stream */
    double ref_ms;              /* reference render time per frame (0 when cached) */
    int ref_cached;             /* how many reference frames came from the cache */
    double extra_ms[FV_BENCH_MAX_EXTRA];
    int extra_cached[FV_BENCH_MAX_EXTRA];
    char ref_img[4096];
    fv_gaze last_gaze;          /* gaze at the last frame (the images show it) */
    fv_bench_ref_noise ref_noise;
} fv_bench_run_info;

/* ref_noise.c. Whether the scenario's reference can be probed, and with how many samples (else
 * why_not says why); the estimate from the probe's errors against the reference; whether the
 * rows' errors are too small for it (warn, spp_needed); the one-line warning (empty when none). */
bool fv_bench_ref_noise_plan(const fv_scenario *sc, fv_bench_ref_noise *rn);
void fv_bench_ref_noise_estimate(fv_bench_ref_noise *rn, const fv_metric_report *probe_vs_ref);
void fv_bench_ref_noise_check(fv_bench_ref_noise *rn, const fv_bench_result *res, int n);
void fv_bench_ref_noise_message(const fv_bench_ref_noise *rn, const fv_scenario *sc, char *buf, size_t n);

/* report.c */
fv_status fv_bench_write_reports(const fv_bench_run_info *info, const fv_bench_result *res, int n, fv_error *err);

#endif
