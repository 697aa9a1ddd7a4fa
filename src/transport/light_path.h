/* fovea — light paths shared by every family that traces light from the lights: photons (pm, pm-t,
 * fpm; Foveated Photon Mapping, Sec. 3) and virtual point lights (instant radiosity).
 *
 * A walk leaves a light in proportion to its power, bounces with the shared BSDFs (importance
 * transport), and Russian roulette on the change of power keeps the flux it carries near
 * constant. At every hit on a diffuse or glossy surface the walk calls `visit` with that vertex
 * (mirrors and glass only redirect, so caustics form); what a vertex becomes (a stored photon, a
 * VPL) is the caller's business.
 */
#ifndef FV_TRANSPORT_LIGHT_PATH_H
#define FV_TRANSPORT_LIGHT_PATH_H

#include <stdbool.h>
#include <stdint.h>
#include "core/rng.h"
#include "scene/query.h"

/* A vertex of a light path: where, the unit direction the light arrived along, the flux it
 * carries (signed: negative walks cancel light), the surface's unit geometric normal and its
 * material id (a VPL reflects with it). */
typedef void (*fv_light_vertex_fn)(void *ctx, fv_vec3 pos, fv_vec3 dir, fv_vec3 flux, fv_vec3 ng, int mat);

/* Starts a walk: a point on a light picked by power and a direction from its emission, with the
 * flux of one of `count` walks; the origin is already off an area light's surface. Draws five
 * numbers. False when nothing was emitted. */
bool fv_light_path_emit(const fv_scene *s, fv_rng *rng, int64_t count, fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux);
/* The same from five given numbers in [0,1) (fv_light_sample_emission's u), for samplers that
 * choose them themselves (photon guiding). */
bool fv_light_path_emit_u(const fv_scene *s, const float u[5], int64_t count, fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux);

/* At hit h of a walk arriving along *d: visits the vertex if the surface is diffuse or glossy,
 * then scatters the walk (new *o, *d, *flux). False when the walk ends there (absorbed, Russian
 * roulette, no valid direction). */
bool fv_light_path_scatter(const fv_scene *s, const fv_hit *h, fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux, fv_rng *rng,
                           fv_light_vertex_fn visit, void *ctx);

/* Follows a walk from o along d through the objects of `set`, `depth` bounces already behind it,
 * up to max_depth bounces; *rays is increased by the rays cast. */
void fv_light_path_trace(const fv_scene *s, fv_trace_set set, fv_vec3 o, fv_vec3 d, fv_vec3 flux, int depth, int max_depth,
                         fv_rng *rng, fv_light_vertex_fn visit, void *ctx, uint64_t *rays);

#endif
