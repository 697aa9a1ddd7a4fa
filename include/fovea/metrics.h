/* fovea — image error metrics, over the whole image and per gaze region (docs/metrics.md).
 *
 * MSE and PSNR; E, the average RGB error of Foveated Instant Radiosity (Sec. 5); SSIM (Wang et
 * al. 2004, on luminance); LDR-FLIP (Andersson et al. 2020), written from the paper's definition;
 * and the temporal errors MSE' (Foveated Photon Mapping Eq. 9) and E' (Foveated Instant
 * Radiosity Eq. 4) over a frame sequence. Every metric is a per-pixel map averaged over the
 * pixels of a region; by default on display values (exposure, clamp to [0,1], sRGB encoding).
 *
 * Ownership: images and label maps are the caller's, only read; the temporal accumulator
 * (fv_temporal) is created and destroyed by the caller and used by one thread at a time. The
 * one-shot comparisons are safe from several threads at once.
 */
#ifndef FOVEA_METRICS_H
#define FOVEA_METRICS_H

#include "fovea/export.h"
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "fovea/gaze.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_metric_opts {
    float exposure;  /* linear values are multiplied by this first (default 1) */
    bool linear;     /* compare linear values instead of display values (FLIP always uses display) */
    float ppd;       /* pixels per degree for FLIP (default 67: 0.7 m from a 0.7 m wide 3840 px screen) */
} fv_metric_opts;

FV_API void fv_metric_opts_default(fv_metric_opts *o);

typedef struct fv_metric_values {
    double mse, psnr, e, ssim, flip;  /* psnr is +inf when mse is 0 */
    long long pixels;                 /* pixels in the region; the other fields are NaN when none */
    long long nonfinite;              /* of those, pixels with a NaN or infinite channel in ref or test:
                                         every metric counts such a channel as black, so callers
                                         must report this count (fovea compare does) */
} fv_metric_values;

typedef struct fv_metric_report {
    fv_metric_values region[FV_REGION_COUNT]; /* indexed by fv_region */
} fv_metric_report;

/* Compares test against ref (w x h linear RGB). labels (w*h fv_region values) may be NULL: then
 * only FV_REGION_ALL is filled. flip_map (w*h floats) receives the per-pixel FLIP when not NULL. */
FV_API fv_status fv_metrics_compare(const float *ref, const float *test, int w, int h, const uint8_t *labels,
                             const fv_metric_opts *opts, fv_metric_report *out, float *flip_map, fv_error *err);

/* Per-pixel maps (w*h floats) of values already in display space (3 floats per pixel, [0,1]). */
FV_API fv_status fv_metrics_ssim_map(const float *a, const float *b, int w, int h, float *map, fv_error *err);
FV_API fv_status fv_metrics_flip_map(const float *ref, const float *test, int w, int h, float ppd, float *map, fv_error *err);

/* Linear RGB -> the values metrics compare (display or linear, per opts), into out (3 per pixel). */
FV_API void fv_metrics_prepare(const float *rgb, size_t pixels, const fv_metric_opts *opts, float *out);

/* ---- temporal error over a sequence ---- */

typedef struct fv_temporal fv_temporal;
FV_API fv_status fv_temporal_create(int w, int h, const fv_metric_opts *opts, fv_temporal **out, fv_error *err);
/* Adds the next frame; each pair (previous, this) is judged with this frame's labels (may be NULL). */
FV_API fv_status fv_temporal_push(fv_temporal *t, const float *rgb, const uint8_t *labels, fv_error *err);
/* MSE' and E' of a region: the mean over the consecutive pairs in which the region has pixels;
 * 0 with fewer than two frames, NaN when the region was empty in every pair. */
FV_API void fv_temporal_result(const fv_temporal *t, fv_region region, double *mse, double *e);
FV_API int fv_temporal_frames(const fv_temporal *t);
FV_API void fv_temporal_destroy(fv_temporal *t);

/* ---- heat maps ---- */

/* How a heat map is drawn. Zero-initialised: scaled to the map's largest value, no rings, no
 * colour bar. */
typedef struct fv_heatmap_opts {
    float vmax;              /* the value drawn as the ramp's top colour (larger ones too); <= 0 or not
                                finite: fv_heatmap_scale of the map. Give several heat maps the same
                                vmax to compare them by eye */
    const fv_eye_model *eye; /* non-NULL: the fovea and transition rings of this model (of the map's
                                size) around gaze, and a cross at the gaze point */
    fv_gaze gaze;
    const char *label;       /* non-NULL: a colour bar strip below the map with this name (the metric)
                                and the scale: 0, vmax / 2, vmax */
} fv_heatmap_opts;

/* The scale a heat map of this map gets without a vmax: its largest finite value, 1 when none
 * is positive. */
FV_API float fv_heatmap_scale(const float *map, int w, int h);
/* Writes map (w*h values, 0..vmax) as a PNG through a perceptual colour ramp (near black for 0,
 * through purple, red and orange, to pale yellow for vmax), with the rings and the colour bar
 * o asks for (o NULL: none, the map's own scale). The colour bar adds rows below the map (and
 * columns to the right of a map too narrow for it); the map keeps its pixels at the top left.
 * The file's metadata (fovea/film.h) says what it is: `heatmap` (the label, or "error"),
 * `heatmap_max` (vmax), and `overlay` when rings are drawn, so it is never taken for an image. */
FV_API fv_status fv_heatmap_write(const char *path, const float *map, int w, int h, const fv_heatmap_opts *o, fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
