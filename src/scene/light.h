/* fovea — light sampling shared by every technique: next-event estimation from a shading point,
 * the density of hitting an emitter by chance (for MIS), and emission of photons/VPLs.
 *
 * The sampling itself is kernel code (kernel/klight.h: the pick by power, area lights uniform by
 * area, the environment by hemisphere), shared with the GPU; these wrap it for fv_scene and add
 * what only the CPU needs: photon and VPL emission (the environment's photons start on a disc of
 * the scene's bounding-sphere radius facing their direction, power L pi R^2 / pdf). Point and spot lights may move
 * (fv_scene_animate_light): every query answers at the scene's current time; the pick table stays
 * valid because a delta light's power does not depend on where it stands.
 */
#ifndef FV_SCENE_LIGHT_H
#define FV_SCENE_LIGHT_H

#include <stdbool.h>
#include "core/rng.h"
#include "kernel/klight.h"
#include "scene/query.h"

typedef struct fv_light fv_light;


/* Samples incident light at p with three uniform numbers; false when nothing was sampled
 * (no light, or the point is behind a one-sided emitter). Visibility is NOT tested. */
bool fv_light_sample_li(const fv_scene *s, fv_vec3 p, float u0, float u1, float u2, fv_light_sample *out);

/* The same restricted to the lights that are not delta lights (area lights, the environment),
 * picked by power among themselves; pdf is the density of that restricted choice. For a technique
 * that shades delta lights one by one and samples only the rest. */
bool fv_light_sample_li_area(const fv_scene *s, fv_vec3 p, float u0, float u1, float u2, fv_light_sample *out);

/* The scene's light table as kernels read it (kernel/klight.h): what the shared path kernel samples. */
const fv_klights *fv_scene_klights(const fv_scene *s);
/* The table index of emissive triangle (obj, prim), -1 when it is not a light. */
int fv_light_of_triangle(const fv_scene *s, int obj, int prim);

/* Radiance emitted by triangle (obj, prim) toward direction w (unit, pointing away from the
 * surface), given its geometric normal ng. */
fv_vec3 fv_light_emitted(const fv_scene *s, const fv_material *m, fv_vec3 ng, fv_vec3 w);

/* Solid-angle density with which fv_light_sample_li would pick the point `hit_p` on emissive
 * triangle (obj, prim) seen from p along direction w (unit). */
float fv_light_pdf_li(const fv_scene *s, int obj, int prim, fv_vec3 p, fv_vec3 hit_p, fv_vec3 hit_ng, fv_vec3 w);

/* The environment's radiance arriving along -w, i.e. seen looking towards unit direction w (what a
 * ray escaping the scene along w carries); zero when the scene has none. */
fv_vec3 fv_light_env_radiance(const fv_scene *s, fv_vec3 w);
/* Solid-angle density with which fv_light_sample_li picks direction w (unit) on the environment,
 * including the light pick; 0 when the scene has none. */
float fv_light_env_pdf(const fv_scene *s, fv_vec3 w);

/* Photon emission: origin, unit direction and the power the photon carries (already divided
 * by the pick and sampling densities; divide by the number of photons emitted). u[5]. */
bool fv_light_sample_emission(const fv_scene *s, const float u[5], fv_vec3 *origin, fv_vec3 *dir, fv_vec3 *power,
                              fv_vec3 *normal);
/* Which two of those five numbers choose the emitted direction of the light u[0] picks: 1 (u[1],
 * u[2]) for delta lights and the environment, 3 (u[3], u[4]) for emissive triangles, whose u[1],
 * u[2] choose the point. Photon guiding warps exactly these (technique/photon/guide.h). */
int fv_light_emission_dir_dims(const fv_scene *s, float u0);

/* A point on a light picked by power (the walk's start when it must aim somewhere itself, as
 * photons towards the dynamic objects do): the light index, its pick probability, the point, and
 * for an area light its unit normal (zero for a delta light). Draws one number, two more for an
 * area light. The environment is picked as what it equals inside the bounding sphere: the sphere
 * itself (radius a little over R) emitting inwards, radiance L(-dir) towards dir; its point is
 * uniform on it with the inward normal. False when the scene has no light or the pick has zero probability. */
typedef struct fv_light_point {
    int light;
    float pmf;
    bool delta;
    bool directional; /* a directional light: p is on a disc of the bounding sphere's radius facing
                         it, outside the sphere, and its walks leave along n (its direction) only */
    fv_vec3 p, n;
    fv_vec3 le;       /* an area light: its emitted radiance at p (its emission texture read there) */
} fv_light_point;
bool fv_light_pick_point(const fv_scene *s, fv_rng *rng, fv_light_point *out);
/* Power carried by a walk leaving the picked point along unit dir, divided by `pdf` (the pick
 * probability times the direction's density): intensity / pdf for a delta light, emission |cos|
 * area / pdf for an area light. False when an area light does not emit towards dir. A directional
 * light emits along lp->n alone: dir must be that and pdf the pick probability; power E pi R^2 / pdf. */
bool fv_light_point_power(const fv_scene *s, const fv_light_point *lp, fv_vec3 dir, float pdf, fv_vec3 *power);

/* ---- delta lights one by one, for techniques that shade point lights themselves (the SDF
 * sphere tracers) rather than sample them. fv_light stays opaque: these accessors are all there
 * is. ---- */

/* The point, spot and directional lights that emit (intensity > 0), in the order the scene added them. */
int fv_light_delta_count(const fv_scene *s);
/* Delta light i in [0, fv_light_delta_count); NULL outside. Valid as long as the scene. */
const fv_light *fv_light_delta_at(const fv_scene *s, int i);
/* Its position at the scene's current time (meaningless for a directional light). */
fv_vec3 fv_light_delta_pos(const fv_light *l);
/* True for a directional light, with the way its light travels (unit, at the scene's current
 * time) in *dir (may be NULL): it lights p from -dir, unblocked beyond the scene's bounds. */
bool fv_light_delta_directional(const fv_light *l, fv_vec3 *dir);
/* Radiant intensity of delta light l towards unit direction w (spot fall-off applied, the spot's
 * axis at the scene's current time); a directional light's irradiance E whatever w. */
fv_vec3 fv_light_delta_intensity(const fv_light *l, fv_vec3 w);

/* True when some light moves with time (fv_scene_animate_light): what a technique computed from
 * the lights (a photon map, say) is then stale after fv_scene_set_time, even where no object
 * moved. */
bool fv_scene_lights_move(const fv_scene *s);

/* Total emitted power of all lights (W): the scale of a photon map. */
fv_vec3 fv_light_total_power(const fv_scene *s);

#endif
