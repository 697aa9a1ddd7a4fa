/* fovea — the default lighting of a scene without any light (fv_scene_add_default_lighting in
 * fovea/scene.h): what users of model viewers expect when they open a mesh file that carries none.
 *
 * A point light somewhere inside the bounds would sit inside any closed model (a box, a scanned
 * animal) and light nothing anyone sees, so the light comes from outside: a sky-gradient
 * environment about the model's up axis lights every side softly, and a key light above and to
 * the left of the default camera, outside the bounding sphere, gives shape and shadows. Both scale
 * with the scene: the environment is at infinity, the key light's intensity is set so that it
 * gives a fixed irradiance at the centre of the bounds.
 *
 * A scene whose only lights are small emissive triangles (labels, screens, indicator LEDs: below,
 * the rule) renders nearly black without it, so it gets the same lighting, said in its own line.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "fovea/limits.h"
#include "scene/query.h"
#include "scene/scene_impl.h"
#include "scene/texture.h"
#include "scene/view_impl.h"

/* The sky: a blue-grey zenith, a light grey horizon and a dark ground (radiance); the key light's
 * irradiance at the bounds' centre (W/m^2), about what the sky gives an upward-facing surface. */
static const fv_vec3 k_zenith = {0.40f, 0.50f, 0.65f}, k_horizon = {0.55f, 0.55f, 0.55f}, k_ground = {0.20f, 0.19f, 0.18f};
static const float k_key_irradiance = 2.0f;

/* What the default lighting gives the model: about k_key_irradiance from the key plus pi times the
 * sky's upper mean luminance (~1.6) on an upward-facing surface, 3.6 W/m^2; a white diffuse surface
 * under it has a radiance of that over pi, 1.16. */
static float default_irradiance(void)
{
    return k_key_irradiance + FV_PI * 0.5f * fv_luminance(fv_add(k_zenith, k_horizon));
}

/* The emissive triangles: how many, their area, their emitted power (W, luminance), the brightest
 * one's luminance, and the area of all the triangles. */
typedef struct emit_stats {
    int n;
    double area, power, total_area;
    float max_lum;
} emit_stats;

/* What material id emits at most (its largest luminance) and on average (colour): its emission,
 * times its emission texture's largest and mean texel when it has one. */
static void material_emission(const fv_scene *s, int id, fv_vec3 *mean, float *max_lum)
{
    const fv_material *m = &s->mats[id];
    fv_vec3 tmean;
    float tmax;
    fv_texture_stats(s, m->emission_texture, &tmean, &tmax); /* no texture: white, 1 */
    *mean = fv_mul(m->emission, tmean);
    *max_lum = fv_luminance(m->emission) * tmax;
}

static fv_status emitters(const fv_scene *s, emit_stats *e, fv_error *err)
{
    memset(e, 0, sizeof *e);
    fv_vec3 *mean = fv_alloc_array((size_t)s->nmat + 1, sizeof *mean);
    float *max_lum = fv_alloc_array((size_t)s->nmat + 1, sizeof *max_lum);
    if (!mean || !max_lum) {
        free(mean);
        free(max_lum);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    for (int m = 0; m < s->nmat; m++) material_emission(s, m, &mean[m], &max_lum[m]);
    for (int i = 0; i < s->nobj; i++)
        for (int t = 0; t < s->objs[i].nt; t++) {
            fv_vec3 a, b, c;
            fv_scene_triangle(s, i, t, &a, &b, &c);
            double area = 0.5 * (double)fv_length(fv_cross(fv_sub(b, a), fv_sub(c, a)));
            if (!isfinite(area)) continue;
            e->total_area += area;
            int id = s->objs[i].mat[t];
            const fv_material *m = &s->mats[id];
            if (!(fv_max3(m->emission) > 0.0f)) continue;
            e->n++;
            e->area += area;
            e->max_lum = fv_maxf(e->max_lum, max_lum[id]);
            e->power += FV_PI * (double)fv_luminance(mean[id]) * area * (m->two_sided_emission ? 2.0 : 1.0);
        }
    free(mean);
    free(max_lum);
    return FV_OK;
}

fv_status fv_scene_add_default_lighting(fv_scene *s, const fv_view *view, const fv_log *log, bool *added, fv_error *err)
{
    if (added) *added = false;
    if (s->committed) return fv_error_set(err, FV_ERR_INTERNAL, "scene already committed: it cannot be changed");
    if (s->nobj == 0 || s->ndelta > 0 || s->has_env) return FV_OK;
    fv_vec3 lo, hi;
    fv_scene_world_bounds(s, &lo, &hi);
    float R = 0.5f * fv_length(fv_sub(hi, lo));
    if (!(R > 0.0f) || !isfinite(R)) return FV_OK; /* fv_scene_commit says what is wrong */
    /* Emissive triangles alone light the model unless they are small: emitting under 2% of the
     * power the default lighting brings onto the model's cross-section (pi R^2 times its
     * irradiance), or none of them brighter than a white surface under the default lighting (a
     * glow such as glTF's emissiveFactor <= 1 on labels and screens: even filling a surface's
     * whole view it would light it less than the default does). */
    emit_stats em;
    fv_status st = emitters(s, &em, err);
    if (st != FV_OK) return st;
    const double def_power = (double)default_irradiance() * FV_PI * (double)R * (double)R;
    const bool dim = em.max_lum <= default_irradiance() / FV_PI;
    if (em.n > 0 && !(em.power < 0.02 * def_power) && !dim) return FV_OK;
    fv_vec3 c = fv_scale(fv_add(lo, hi), 0.5f), up = fv_view_up_axis(view);
    fv_camera cam;
    fv_view_frame_bounds(view, lo, hi, 512, 512, &cam);
    fv_vec3 to_cam = fv_sub(cam.pos, c);
    float D = fv_length(to_cam);
    to_cam = D > 0.0f ? fv_scale(to_cam, 1.0f / D) : fv_v3(0, 0, 1);
    fv_vec3 right = fv_cross(fv_neg(to_cam), up);
    right = fv_length(right) > 1e-4f ? fv_normalize(right) : fv_v3(1, 0, 0);
    /* above the camera and to its left, at least 2.5 radii out */
    float dist = fv_maxf(D, 2.5f * R);
    fv_vec3 key_dir = fv_normalize(fv_add(to_cam, fv_add(fv_scale(up, 0.9f), fv_scale(right, -0.35f))));
    /* A scene at the edge of the coordinate range (fovea/limits.h) keeps its key light inside it:
     * the light stops at the edge on its way out from the centre. A centre beyond the range adds
     * nothing: fv_scene_commit names the object at fault. */
    dist = fv_limit_reach(c, key_dir, dist);
    if (!(dist > 0.0f) || fv_limit_vec3("default key light", fv_madd(c, key_dir, dist), NULL) != FV_OK) return FV_OK;
    const float I = fv_minf(k_key_irradiance * dist * dist, (float)FV_INTENSITY_MAX);
    fv_light_desc key = {FV_LIGHT_POINT, fv_madd(c, key_dir, dist), fv_neg(key_dir), fv_v3s(I), 0, 0};
    fv_env_desc env = {k_zenith, k_horizon, k_ground, up};
    if ((st = fv_scene_set_env(s, &env, err)) != FV_OK || (st = fv_scene_add_light(s, &key, err)) != FV_OK) return st;
    if (em.n > 0)
        fv_log_warn(log,
                    "scene's only lights are %d small emissive triangles (%.2g%% of the surface, %s): added the default sky "
                    "environment and key point light too (--no-default-light turns this off)",
                    em.n, em.total_area > 0.0 ? 100.0 * em.area / em.total_area : 0.0,
                    dim ? "none brighter than a white surface under the default light" : "under 2% of the default light's power");
    else
        fv_log_warn(log,
                "scene has no lights: added a sky environment (up %g,%g,%g) and a key point light at (%g, %g, %g) of intensity %g "
                "(--env R,G,B sets the environment, --no-default-light turns this off)",
                up.x, up.y, up.z, key.pos.x, key.pos.y, key.pos.z, key.intensity.x);
    if (added) *added = true;
    return FV_OK;
}
