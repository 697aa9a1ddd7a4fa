/* fovea — where the viewer looks, and how acuity falls off around it.
 *
 * The display/eye model turns a pixel's distance from the gaze point into an eccentricity angle
 * and splits the image into the three regions all the papers use: fovea (radius r_f), transition
 * (r_f..r_t) and periphery. The acuity models are the ones the papers use to spend effort:
 *   - Foveated Photon Mapping, Eq. 6 (transition blend) and Eq. 7 (r_f = tan(e_f) * b * PPI);
 *   - Foveated Instant Radiosity, Sec. 5: foveal radius as a fraction (25%) of the image width;
 *   - Visual-Polar path tracing, Eq. 1 (acuity V(e)), Eq. 2 (its cumulative distribution) and
 *     Eq. 3 (the fitted inverse);
 *   - Inverted-pyramid sphere tracing, Eq. 1: p(w) = 0.90964 e^(-w/2.9661) + 0.00792 (the sign of
 *     the exponent is negative: the printed positive sign is a typo, acuity falls with w).
 * Gaze over time is fixed, keyframed, or a recorded trace (docs/gaze.md gives the CSV format).
 *
 * Ownership: gaze paths are created and destroyed by the caller (a view takes over the one it is
 * given). The eye model is a plain struct. Every function here only reads its inputs: safe from
 * any number of threads.
 */
#ifndef FOVEA_GAZE_H
#define FOVEA_GAZE_H

#include "fovea/export.h"
#include <stdbool.h>
#include <stdint.h>
#include "fovea/math.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Gaze point in normalised screen coordinates: (0,0) top-left, (1,1) bottom-right. */
typedef struct fv_gaze {
    float x, y;
} fv_gaze;

/* How the foveal and transition radii are given. */
typedef enum fv_fovea_mode {
    FV_FOVEA_ANGLE = 0,  /* angular radii e_f, e_t in degrees -> pixels through the viewing distance */
    FV_FOVEA_WIDTH       /* radii as fractions of the image width (Foveated Instant Radiosity) */
} fv_fovea_mode;

/* Display and eye. The viewing distance in pixels D links pixels and angles: a pixel at distance
 * d pixels from the gaze point has eccentricity atan(d / D), the inverse of Eq. 7 of Foveated
 * Photon Mapping. D comes from the pixel density and the pupil-to-lens distance (D = b * PPI, the
 * HMD case) or, when fov_x_deg > 0, from the horizontal field of view (D = (w/2) / tan(fov/2)). */
typedef struct fv_eye_model {
    int width, height;      /* pixels per eye */
    float ppi;              /* pixel density, pixels per inch (HTC Vive: 615 at 1080 px wide) */
    float eye_dist_mm;      /* pupil-to-lens distance b in mm (HTC Vive: 18) */
    float fov_x_deg;        /* > 0: horizontal field of view, overrides ppi/eye_dist */
    fv_fovea_mode mode;
    float fovea_deg;        /* e_f (default 9.78, Foveated Photon Mapping Sec. 4.1) */
    float transition_deg;   /* e_t, outer edge of the transition (default 2 e_f: the paper gives none) */
    float fovea_frac;       /* FV_FOVEA_WIDTH: r_f / width (default 0.25) */
    float transition_frac;  /* FV_FOVEA_WIDTH: r_t / width (default 0.375) */
} fv_eye_model;

/* The defaults above for a display of the given size: the Vive's panel, its ppi scaled by
 * width / 1080 so that the regions cover the same part of the view at any resolution. */
FV_API void fv_eye_model_default(int width, int height, fv_eye_model *out);
/* Checks every field (positive sizes and densities, 0 < e_f <= e_t < 90, 0 < frac_f <= frac_t). */
FV_API fv_status fv_eye_model_validate(const fv_eye_model *m, fv_error *err);
/* m widened so that, with the gaze at the centre (0.5, 0.5), every pixel lies in the fovea: the
 * model a frame uses while the gaze is unknown under FV_GAZE_MISSING_WIDEN. Same display. */
FV_API void fv_eye_model_whole_screen(const fv_eye_model *m, fv_eye_model *out);

/* Viewing distance D in pixels. */
FV_API double fv_eye_view_dist_px(const fv_eye_model *m);
/* Pixels per degree at the gaze point, D pi / 180: the scale of the "planar degrees" (a screen
 * distance over this) that Visual-Polar Eq. 2 and the linear fall-off are written in. */
FV_API double fv_eye_px_per_deg(const fv_eye_model *m);
/* Foveal and transition radii r_f <= r_t in pixels (Eq. 7 in angle mode). */
FV_API double fv_eye_fovea_radius_px(const fv_eye_model *m);
FV_API double fv_eye_transition_radius_px(const fv_eye_model *m);
/* Eccentricity in degrees of pixel centre (x + 0.5, y + 0.5) for a gaze point. */
FV_API double fv_eye_eccentricity_deg(const fv_eye_model *m, fv_gaze g, double px, double py);
/* Distance of film position (px, py) from the gaze point, in pixels. */
FV_API double fv_eye_gaze_dist_px(const fv_eye_model *m, fv_gaze g, double px, double py);

typedef enum fv_region {
    FV_REGION_FOVEA = 0,
    FV_REGION_TRANSITION,
    FV_REGION_PERIPHERY,
    FV_REGION_ALL,         /* for reports: the whole image */
    FV_REGION_COUNT
} fv_region;
FV_API const char *fv_region_name(fv_region r); /* "fovea", "transition", "periphery", "all" */

/* Region of the pixel (x, y) (its centre) for a gaze. */
FV_API fv_region fv_eye_region(const fv_eye_model *m, fv_gaze g, int x, int y);
/* Fills labels[y * width + x] with the fv_region of every pixel. */
FV_API void fv_eye_region_labels(const fv_eye_model *m, fv_gaze g, uint8_t *labels);
/* Transition blend weight b(x) of Foveated Photon Mapping Eq. 6, clamped to [0,1]: 0 in the
 * fovea, 1 in the periphery, linear in the pixel distance in between. */
FV_API double fv_eye_blend(const fv_eye_model *m, fv_gaze g, double px, double py);

/* ---- acuity models ---- */

/* Visual acuity in cycles per degree at eccentricity e (Visual-Polar, Eq. 1). */
FV_API double fv_acuity_v(double e_deg);
/* The cumulative distribution of Visual-Polar Eq. 2 at distance d (degrees) from the gaze. */
FV_API double fv_acuity_cdf(double d_deg);
/* Eq. 3: the fitted polynomial inverse of the cumulative distribution, for p in [0,1]. */
FV_API double fv_acuity_cdf_inv_fit(double p);
/* Sphere-tracing probability (Inverted pyramid, Eq. 1, exponent negative) with its three zones:
 * 1 inside fovea_deg, 0 beyond outer_deg (<= 0: no outer zone), the fitted fall-off between. */
FV_API double fv_acuity_hyperbolic(double w_deg, double fovea_deg, double outer_deg);
/* Linear fall-off: 1 up to e0, min_value from e1 on, linear between (Visual-Polar's baseline). */
FV_API double fv_acuity_linear(double e_deg, double e0, double e1, double min_value);

/* ---- gaze over time ---- */

typedef struct fv_gaze_key {
    double time;
    fv_gaze left, right;   /* right == left for a monocular trace */
} fv_gaze_key;

typedef struct fv_gaze_path fv_gaze_path;

/* A fixed gaze (both eyes). Coordinates must be in [0,1]. */
FV_API fv_status fv_gaze_path_create_fixed(fv_gaze g, fv_gaze_path **out, fv_error *err);
/* Keys with strictly increasing times, linear interpolation, end keys held. */
FV_API fv_status fv_gaze_path_create_keys(const fv_gaze_key *keys, int count, fv_gaze_path **out, fv_error *err);
/* A recorded trace: CSV lines "time,x,y" or "time,xl,yl,xr,yr" (docs/gaze.md); '#' comments
 * and a header line are allowed. An empty coordinate or "nan" marks a missing sample (a blink,
 * track loss); at least one sample of each eye must be known. Errors name the file and line. */
FV_API fv_status fv_gaze_path_load_csv(const char *path, fv_gaze_path **out, fv_error *err);
FV_API void fv_gaze_path_destroy(fv_gaze_path *p);
/* Gaze of each eye at time t. Keys may mark an eye's gaze missing (x and y NaN, as the CSV's
 * empty fields): from a missing key until the next known one the gaze holds the last known one
 * (the first known before any), and false is returned (true: both eyes known at t). */
FV_API bool fv_gaze_path_eval(const fv_gaze_path *p, double t, fv_gaze *left, fv_gaze *right);
FV_API int fv_gaze_path_key_count(const fv_gaze_path *p);

/* What the sequence driver does while a path says the gaze is unknown (docs/gaze.md):
 *   HOLD   keep the last known gaze (the default: a blink is shorter than a fixation);
 *   WIDEN  render as if the whole screen were the fovea (fv_eye_model_whole_screen), so nothing is
 *          rendered at peripheral quality where the viewer may be looking. */
typedef enum fv_gaze_missing {
    FV_GAZE_MISSING_PATH = 0, /* driver option only: the policy of the gaze path in use */
    FV_GAZE_MISSING_HOLD,
    FV_GAZE_MISSING_WIDEN
} fv_gaze_missing;
/* A path's own policy (HOLD when created; a scene's "gaze" block may say "missing": "widen"). */
FV_API void fv_gaze_path_set_missing(fv_gaze_path *p, fv_gaze_missing policy);
FV_API fv_gaze_missing fv_gaze_path_missing(const fv_gaze_path *p);
/* "hold" or "widen" -> the policy; false for any other name. */
FV_API bool fv_gaze_missing_from_name(const char *name, fv_gaze_missing *out);

/* ---- importing eye-tracker recordings (docs/gaze.md, "Importing") ---- */

typedef enum fv_gaze_format {
    FV_GAZE_FORMAT_AUTO = 0,     /* from the extension (a trailing .gz aside): .asc EyeLink, .csv Pupil Labs, .tsv
                                    Tobii Pro Lab (from its header); a .csv or .tsv with a column mapping: TABLE */
    FV_GAZE_FORMAT_EYELINK_ASC,  /* EyeLink sample file (edf2asc) */
    FV_GAZE_FORMAT_PUPIL_CSV,    /* Pupil Labs gaze_positions.csv (Pupil Player export) */
    FV_GAZE_FORMAT_TABLE,        /* any delimited table (CSV, TSV, semicolons) under fv_gaze_table_opts' mapping */
    FV_GAZE_FORMAT_TOBII         /* Tobii Pro Lab data export (.tsv): the table reader with Tobii's columns */
} fv_gaze_format;

/* Which eye's gaze a recording of both eyes becomes (docs/gaze.md, "Which eye"). */
typedef enum fv_gaze_eyes {
    FV_GAZE_EYES_DEFAULT = 0, /* the format's own: EyeLink EACH, Pupil BOTH */
    FV_GAZE_EYES_LEFT,        /* the left eye's samples (a Pupil row of both eyes counts too) */
    FV_GAZE_EYES_RIGHT,
    FV_GAZE_EYES_BOTH,        /* one gaze: the mean of the two eyes' known samples, or the one known */
    FV_GAZE_EYES_EACH         /* each eye its own gaze: a five-column trace (stereo renders) */
} fv_gaze_eyes;

/* The column mapping of FV_GAZE_FORMAT_TABLE (docs/gaze.md, "Other tables"). A column is named by
 * its header text (exact, any case) or by its 1-based number (a file without a header line: every
 * column given by number, and the first line's time field not a number). Either x and y (one
 * gaze) or the per-eye pairs (either eye or both). Strings are borrowed for the call. */
typedef struct fv_gaze_table_opts {
    const char *time, *x, *y;
    const char *left_x, *left_y, *right_x, *right_y;
    const char *valid;  /* optional: a row whose value here is not 1, true, valid or yes (any case) is missing */
    double time_unit;   /* seconds per unit of the time column [0: seconds; Tobii: the header's unit, else µs] */
    bool pixels;        /* coordinates in pixels of width x height (fv_gaze_import_opts), not normalised */
    bool bottom_left;   /* the origin is at the bottom left (y up), not the top left */
} fv_gaze_table_opts;

typedef struct fv_gaze_import_opts {
    fv_gaze_format format;
    double min_confidence; /* Pupil: samples below this confidence are missing [0.6] */
    int width, height;     /* the screen in pixels: EyeLink, replacing DISPLAY_COORDS (0: from the file); a table in
                              pixels; Tobii, where the export has no recording resolution */
    fv_gaze_eyes eyes;     /* [FV_GAZE_EYES_DEFAULT] */
    uint64_t max_inflated; /* a gzip-compressed recording may inflate to at most this many bytes [1 GiB] */
    fv_gaze_table_opts table; /* TABLE: the column mapping (all NULL: none); Tobii: time_unit alone */
} fv_gaze_import_opts;

typedef struct fv_gaze_import_info {
    fv_gaze_format format;
    long samples, missing, dropped; /* written; of those missing; dropped (time not increasing) */
    double width, height;           /* EyeLink, a table in pixels, Tobii: the screen the coordinates were divided by
                                       (Tobii: the last row's recording resolution) */
    bool binocular;                 /* a five-column trace was written (each eye its own gaze) */
    fv_gaze_eyes eyes;              /* the choice applied (after a successful import never DEFAULT) */
    bool compressed;                /* the recording was gzip-compressed */
    double rate;                    /* EyeLink: the sample rate in Hz the recording gave (0: none) */
    long gaps;                      /* EyeLink: gaps between recording blocks, written as missing samples */
    long paired;                    /* Pupil: samples made of one row per eye (both, each) */
    long skipped;                   /* Tobii: rows without eye-tracker data (events, other sensors), left out */
} fv_gaze_import_info;

FV_API void fv_gaze_import_opts_init(fv_gaze_import_opts *o);
/* Converts a recording (or its gzip-compressed form) into a gaze trace CSV at out_path (written
 * whole or not at all), missing samples as empty fields. info (may be NULL) says what was read.
 * Errors name the file, and the line for malformed input. */
FV_API fv_status fv_gaze_import(const char *in_path, const char *out_path, const fv_gaze_import_opts *opts, fv_gaze_import_info *info,
                                fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
