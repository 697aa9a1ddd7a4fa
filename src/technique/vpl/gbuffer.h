/* fovea — the first-hit buffer the instant-radiosity family shades from (Foveated Instant Radiosity,
 * Sec. 3.4: deferred shading; Sec. 3.1: the fovea's points are read from it).
 *
 * One ray through each pixel's centre, eight pixels per packet: the CPU equivalent of the paper's
 * rasterised G-buffer. Pixel centres (no jitter) keep the buffer identical from frame to frame when
 * nothing moves, which the temporal stability of the method (Sec. 3.3) relies on. The film's
 * auxiliary buffers (depth, normal, albedo, position, id) are filled from it.
 *
 * Every surface is shaded as diffuse with its material's albedo (the paper's scenes are diffuse;
 * docs/instant-radiosity.md says what this means for glossy and specular materials).
 */
#ifndef FV_TECHNIQUE_VPL_GBUFFER_H
#define FV_TECHNIQUE_VPL_GBUFFER_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/camera.h"
#include "fovea/film.h"
#include "scene/query.h"

typedef struct fv_gpixel {
    fv_vec3 p;      /* world position of the first hit */
    fv_vec3 n;      /* unit shading normal, turned towards the camera */
    fv_vec3 ng;     /* unit geometric normal, turned towards the camera */
    fv_vec3 albedo; /* the material's diffuse albedo */
    fv_vec3 emit;   /* radiance the surface emits towards the camera (a miss: the environment's) */
    float t;        /* distance along the ray; +inf on a miss */
    int obj;        /* object id, -1 on a miss */
} fv_gpixel;

typedef struct fv_gbuffer {
    int width, height;
    fv_gpixel *px; /* width * height, row-major */
} fv_gbuffer;

/* (Re)sizes the buffer for width x height (keeps the allocation when the size does not change).
 * FV_ERR_NOMEM when out of memory (the buffer is then empty). */
fv_status fv_gbuffer_reserve(fv_gbuffer *g, int width, int height, fv_error *err);
void fv_gbuffer_free(fv_gbuffer *g);

/* Traces the pixel centres of cam over the buffer with `threads` threads, fills the film's
 * auxiliary buffers (out may have none), and adds the rays cast to *rays. */
void fv_gbuffer_trace(fv_gbuffer *g, const fv_scene *s, const fv_camera_basis *cam, const fv_film_views *out, int threads,
                      uint64_t *rays);

static inline bool fv_gpixel_hit(const fv_gpixel *g) { return g->obj >= 0; }

#endif
