/* fovea — the film: linear float RGB plus auxiliary buffers shared by all techniques, and image
 * files (PNG tone-mapped sRGB, PFM linear, EXR linear with auxiliary channels).
 *
 * A film is created with the auxiliary buffers asked for; the colour buffer always exists.
 * Buffers are row-major from the top-left pixel. Writes go to a temporary file in the target's
 * directory and are renamed into place, so a failed or interrupted write leaves nothing behind.
 *
 * Ownership: the caller creates and destroys films; the buffer pointers a film hands out live as
 * long as it. Threads: a film is plain memory; techniques write disjoint pixels from their
 * threads, callers must not use a film that is being rendered into.
 */
#ifndef FOVEA_FILM_H
#define FOVEA_FILM_H

#include "fovea/export.h"
#include <stdbool.h>
#include <stdint.h>
#include "fovea/math.h"
#include "fovea/status.h"
#include "fovea/params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest accepted width or height, and pixel count: sizes are refused before allocating. */
#define FV_FILM_MAX_DIM 16384
#define FV_FILM_MAX_PIXELS (8192LL * 8192LL)

typedef enum fv_film_aux {
    FV_AUX_DEPTH = 1 << 0,    /* 1 float: distance along the primary ray, +inf for no hit */
    FV_AUX_NORMAL = 1 << 1,   /* 3 floats: world shading normal at the first hit */
    FV_AUX_ALBEDO = 1 << 2,   /* 3 floats: first-hit reflectance */
    FV_AUX_ID = 1 << 3,       /* 1 uint32: object id + 1 at the first hit, 0 for none */
    FV_AUX_POSITION = 1 << 4, /* 3 floats: world position at the first hit */
    FV_AUX_ALL = 0x1f
} fv_film_aux;

typedef struct fv_film fv_film;

/* Checks the size (1..FV_FILM_MAX_DIM each, at most FV_FILM_MAX_PIXELS) before allocating. */
FV_API fv_status fv_film_check_size(int width, int height, fv_error *err);
FV_API fv_status fv_film_create(int width, int height, unsigned aux, fv_film **out, fv_error *err);
FV_API void fv_film_destroy(fv_film *film);
/* Zeroes colour, sets depth to +inf, ids to 0. */
FV_API void fv_film_clear(fv_film *film);

FV_API int fv_film_width(const fv_film *film);
FV_API int fv_film_height(const fv_film *film);
FV_API unsigned fv_film_aux_flags(const fv_film *film);
FV_API float *fv_film_color(fv_film *film);          /* 3 floats per pixel */
FV_API const float *fv_film_color_const(const fv_film *film);
FV_API float *fv_film_depth(fv_film *film);          /* NULL when not requested */
FV_API float *fv_film_normal(fv_film *film);
FV_API float *fv_film_albedo(fv_film *film);
FV_API float *fv_film_position(fv_film *film);
FV_API uint32_t *fv_film_id(fv_film *film);
/* Read-only views: depth/normal/albedo/position by flag (NULL when absent), and the ids. */
FV_API const float *fv_film_aux_const(const fv_film *film, fv_film_aux which);
FV_API const uint32_t *fv_film_id_const(const fv_film *film);

/* All buffers at once (absent ones NULL), for a technique's inner loop. */
typedef struct fv_film_views {
    float *color, *depth, *normal, *albedo, *position;
    uint32_t *id;
} fv_film_views;
FV_API fv_film_views fv_film_views_of(fv_film *film);

/* Writes pixel pix's auxiliary buffers (those the film has) from the first surface its camera ray
 * met; with hit false, the "nothing" values: depth +inf, zero vectors, id 0. */
FV_HD static inline void fv_film_store_first_hit(const fv_film_views *v, size_t pix, bool hit, float t, fv_vec3 p, fv_vec3 n, fv_vec3 albedo,
                                           int obj)
{
    const fv_vec3 zero = {0.0f, 0.0f, 0.0f};
    if (!hit) p = n = albedo = zero;
    if (v->depth) v->depth[pix] = hit ? t : INFINITY;
    if (v->normal) v->normal[3 * pix] = n.x, v->normal[3 * pix + 1] = n.y, v->normal[3 * pix + 2] = n.z;
    if (v->albedo) v->albedo[3 * pix] = albedo.x, v->albedo[3 * pix + 1] = albedo.y, v->albedo[3 * pix + 2] = albedo.z;
    if (v->position) v->position[3 * pix] = p.x, v->position[3 * pix + 1] = p.y, v->position[3 * pix + 2] = p.z;
    if (v->id) v->id[pix] = hit ? (uint32_t)obj + 1u : 0u;
}

/* ---- image files ---- */

typedef enum fv_image_format { FV_IMG_UNKNOWN = 0, FV_IMG_PNG, FV_IMG_PFM, FV_IMG_EXR } fv_image_format;

/* Format from the path's extension (case-insensitive); FV_IMG_UNKNOWN when not recognised. */
FV_API fv_image_format fv_image_format_from_path(const char *path);

/* Writes linear RGB (3 floats per pixel). PNG: multiplied by `exposure`, clamped to [0,1],
 * sRGB-encoded, 8 bits. PFM: exact floats. EXR: half-free 32-bit float R,G,B. */
FV_API fv_status fv_image_write(const char *path, const float *rgb, int width, int height, float exposure,
                         fv_error *err);
/* Image metadata: how an image was made, as a bag of key=value text (fovea/params.h; keys
 * [a-z0-9_-]). Written as PNG text chunks and EXR string attributes named "fovea:KEY"; PFM files
 * have no metadata (it is dropped). The keys `fovea render` writes are listed in docs/metrics.md.
 * meta may be NULL (none); the pixels are the same either way. */
FV_API fv_status fv_image_write_meta(const char *path, const float *rgb, int width, int height, float exposure,
                                     const fv_params *meta, fv_error *err);
FV_API fv_status fv_film_write_meta(const fv_film *film, const char *path, float exposure, const fv_params *meta,
                                    fv_error *err);
/* Reads the "fovea:" metadata of a PNG or EXR (an empty bag for a PFM or a file without any) into
 * a new bag *out (release with fv_params_destroy). Other software's entries are left out. */
FV_API fv_status fv_image_read_meta(const char *path, fv_params **out, fv_error *err);

/* Writes the film: PNG/PFM get the colour; EXR gets colour plus every auxiliary buffer as named
 * channels (depth Z, normal N.x/N.y/N.z, albedo albedo.R/G/B, position P.x/P.y/P.z, id). */
FV_API fv_status fv_film_write(const fv_film *film, const char *path, float exposure, fv_error *err);

/* A loaded image: linear RGB floats (PNG is decoded from sRGB). Free with fv_image_free. */
typedef struct fv_image {
    int width, height;
    float *rgb;
} fv_image;

/* Reads PNG, PFM or EXR (RGB channels). Errors name the file and what is wrong with it. */
FV_API fv_status fv_image_read(const char *path, fv_image *out, fv_error *err);
/* Reads an EXR's layer: its LAYER.R, LAYER.G, LAYER.B channels ("albedo" for the albedo fv_film_write
 * stores); "" is fv_image_read. */
FV_API fv_status fv_image_read_layer(const char *path, const char *layer, fv_image *out, fv_error *err);
FV_API void fv_image_free(fv_image *img);

/* ---- display output (docs/gpu.md, "Display output on the device") ----
 *
 * fv_film_set_display makes film display-only, for a consumer that wants nothing but what a
 * display shows (a PNG sequence, `fovea render` asks for it then): a frame rendered on a device (pt,
 * the sphere tracers and the Visual-Polar family on portable or cuda) converts its colour there with
 * `exposure` (clamped, sRGB-encoded, 8 bits: what a PNG holds) and reads back 4 bytes a pixel
 * (RGBA8, alpha 255) instead of the 12 of its float colour, which that frame then leaves unwritten.
 * Any other method
 * writes the float colour as before. fv_film_display returns the RGBA8 pixels when the last frame
 * filled them, else NULL. fv_film_write_meta writes a PNG from them (the bytes it would write from
 * the float colour at that exposure) and refuses, for such a frame, another format or exposure.
 * FV_ERR_INVALID for an exposure that is not finite and >= 0. */
FV_API fv_status fv_film_set_display(fv_film *film, float exposure, fv_error *err);
FV_API const uint8_t *fv_film_display(const fv_film *film);

/* The sRGB transfer function and its inverse, on one channel. */
FV_API float fv_srgb_encode(float linear);
FV_API float fv_srgb_decode(float encoded);

#ifdef __cplusplus
}
#endif
#endif
