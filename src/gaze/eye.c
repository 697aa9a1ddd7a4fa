/* fovea — display/eye model: its defaults and checks, and the public entry points of its geometry
 * (eccentricity of a pixel, the fovea / transition / periphery split, the transition's blend),
 * whose equations are kernel code (kernel/keye.h, which cites the papers).
 */
#include <math.h>
#include "fovea/gaze.h"
#include "kernel/keye.h"

void fv_eye_model_default(int width, int height, fv_eye_model *m)
{
    m->width = width;
    m->height = height;
    /* The HTC Vive's panel (Foveated Photon Mapping, Sec. 4.1): 1080 px per eye at 615 ppi. A
     * render of another width shows the same view on the same panel, so the density scales with
     * the width and the regions cover the same part of the view at any resolution. */
    m->ppi = 615.0f * (float)width / 1080.0f;
    m->eye_dist_mm = 18.0f; /* HTC Vive pupil-to-lens distance, same section */
    m->fov_x_deg = 0.0f;
    m->mode = FV_FOVEA_ANGLE;
    m->fovea_deg = 9.78f;
    m->transition_deg = 2.0f * 9.78f;
    m->fovea_frac = 0.25f;  /* Foveated Instant Radiosity, Sec. 5 */
    m->transition_frac = 0.375f;
}

fv_status fv_eye_model_validate(const fv_eye_model *m, fv_error *err)
{
    if (m->width < 1 || m->height < 1)
        return fv_error_set(err, FV_ERR_INVALID, "eye model: display size %dx%d must be positive", m->width, m->height);
    if (!(m->fov_x_deg >= 0.0f && m->fov_x_deg < 180.0f))
        return fv_error_set(err, FV_ERR_INVALID, "eye model: field of view %g must be in (0,180) degrees (0: use ppi)", m->fov_x_deg);
    if (m->fov_x_deg == 0.0f && !(m->ppi > 0.0f && isfinite(m->ppi) && m->eye_dist_mm > 0.0f && isfinite(m->eye_dist_mm)))
        return fv_error_set(err, FV_ERR_INVALID, "eye model: ppi (%g) and eye distance (%g mm) must be positive", m->ppi, m->eye_dist_mm);
    if (m->mode == FV_FOVEA_ANGLE) {
        if (!(m->fovea_deg > 0.0f && m->fovea_deg <= m->transition_deg && m->transition_deg < 90.0f))
            return fv_error_set(err, FV_ERR_INVALID, "eye model: need 0 < fovea (%g) <= transition (%g) < 90 degrees", m->fovea_deg,
                                m->transition_deg);
    } else if (m->mode == FV_FOVEA_WIDTH) {
        if (!(m->fovea_frac > 0.0f && m->fovea_frac <= m->transition_frac && m->transition_frac <= 4.0f))
            return fv_error_set(err, FV_ERR_INVALID, "eye model: need 0 < fovea fraction (%g) <= transition fraction (%g) <= 4",
                                m->fovea_frac, m->transition_frac);
    } else {
        return fv_error_set(err, FV_ERR_INVALID, "eye model: unknown fovea mode %d", (int)m->mode);
    }
    return FV_OK;
}

void fv_eye_model_whole_screen(const fv_eye_model *m, fv_eye_model *out)
{
    /* Radii as fractions of the width: from the centre the farthest pixel centre is half the
     * diagonal away; one pixel more covers rounding. The transition equals the fovea (nothing is
     * blended). Capped at the validator's bound of 4 widths (an image 7.9 times taller than wide). */
    *out = *m;
    out->mode = FV_FOVEA_WIDTH;
    double frac = (0.5 * hypot((double)m->width, (double)m->height) + 1.0) / (m->width > 0 ? m->width : 1);
    out->fovea_frac = out->transition_frac = (float)fmin(frac, 4.0);
}

double fv_eye_view_dist_px(const fv_eye_model *m) { return fv_keye_view_dist_px(m); }

double fv_eye_px_per_deg(const fv_eye_model *m) { return fv_keye_view_dist_px(m) * FV_PI_D / 180.0; }

double fv_eye_fovea_radius_px(const fv_eye_model *m) { return fv_keye_fovea_radius_px(m); }

double fv_eye_transition_radius_px(const fv_eye_model *m) { return fv_keye_transition_radius_px(m); }

double fv_eye_gaze_dist_px(const fv_eye_model *m, fv_gaze g, double px, double py) { return fv_keye_gaze_dist_px(m, g, px, py); }

double fv_eye_eccentricity_deg(const fv_eye_model *m, fv_gaze g, double px, double py) { return fv_keye_eccentricity_deg(m, g, px, py); }

const char *fv_region_name(fv_region r)
{
    switch (r) {
    case FV_REGION_FOVEA: return "fovea";
    case FV_REGION_TRANSITION: return "transition";
    case FV_REGION_PERIPHERY: return "periphery";
    case FV_REGION_ALL: return "all";
    default: return "?";
    }
}

fv_region fv_eye_region(const fv_eye_model *m, fv_gaze g, int x, int y)
{
    return fv_keye_classify(fv_keye_gaze_dist_px(m, g, x + 0.5, y + 0.5), fv_keye_fovea_radius_px(m), fv_keye_transition_radius_px(m));
}

void fv_eye_region_labels(const fv_eye_model *m, fv_gaze g, uint8_t *labels)
{
    double rf = fv_keye_fovea_radius_px(m), rt = fv_keye_transition_radius_px(m);
    for (int y = 0; y < m->height; y++)
        for (int x = 0; x < m->width; x++)
            labels[(size_t)y * m->width + x] = (uint8_t)fv_keye_classify(fv_keye_gaze_dist_px(m, g, x + 0.5, y + 0.5), rf, rt);
}

double fv_eye_blend(const fv_eye_model *m, fv_gaze g, double px, double py) { return fv_keye_blend(m, g, px, py); }
