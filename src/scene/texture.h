/* fovea — base-colour textures: decoding image files in a sandboxed child, keeping them in the
 * scene as linear RGB, and reading them at a surface point (texture.c, texture_decode.c).
 *
 * A texture reaches the scene by one road whichever file names it: the bytes of a PNG or JPEG
 * (a file, an image embedded in a .glb or a data URI) are decoded by stb_image inside a child
 * process (core/sandbox.h; the mesh importer's own child for mesh files, a child of its own for
 * a JSON scene's "albedo_texture"), sent back as 8-bit texels in one record, and added with
 * fv_scene_add_texture, which bounds the size (fovea/limits.h) and converts sRGB to linear.
 * The albedo at a hit is read through query.h's fv_hit_material / fv_material_at.
 */
#ifndef FV_SCENE_TEXTURE_H
#define FV_SCENE_TEXTURE_H

#include <stdbool.h>
#include <stddef.h>
#include "core/sandbox.h"
#include "fovea/scene.h"

/* Texture t's linear RGB at (s, t) coordinates uv (u right, v up from the bottom-left corner),
 * bilinear between the four nearest texel centres, repeating outside [0,1]. */
struct fv_texture;
fv_vec3 fv_texture_sample(const struct fv_texture *tex, fv_vec2 uv);

/* The mean linear colour of texture id over all its texels and the largest texel luminance
 * (an id that names no texture: white, 1), for what a material emits in all (default_light.c). */
void fv_texture_stats(const fv_scene *s, int id, fv_vec3 *mean, float *max_lum);
/* The mean colour of texture id over triangle prim of object obj, as a point drawn uniformly by
 * area sees it (an 8 x 8 grid of fv_klight_triangle_point's numbers): the weight with which the
 * light table picks an emissive triangle whose emission is textured. White without UVs or id. */
fv_vec3 fv_texture_triangle_mean(const fv_scene *s, int id, int obj, int prim);

/* ---- decoding (texture_decode.c) ---- */

/* Decoded 8-bit texels (free px with free(): stb_image allocates with malloc). */
typedef struct fv_texels {
    int w, h, channels;
    unsigned char *px;
} fv_texels;

/* Decodes a PNG or JPEG held in memory. A size beyond FV_TEXTURE_MAX_TEXELS is refused from the
 * header, before any pixel is decoded. On failure returns false with the reason in why. Run it
 * only in a sandbox child: a decoder fault must not take the process down. */
bool fv_texels_decode(const void *bytes, size_t n, fv_texels *out, char *why, size_t why_len);
/* Reads file `path` and decodes it like fv_texels_decode (child side too). */
bool fv_texels_decode_file(const char *path, fv_texels *out, char *why, size_t why_len);
/* Child side: sends texels as one record (size, then the bytes). */
bool fv_texels_put(int fd, const fv_texels *t);
/* Parent side: receives one record, checking the size it claims before allocating; false when
 * the stream ends or the record is not one a child sends. */
bool fv_texels_get(fv_sandbox *sb, fv_texels *out);

/* Reads and decodes image file `path` in a sandbox child and adds it to the scene. Anything
 * wrong with the file (missing, undecodable, too large, a decoder crash) is one warning on log
 * naming the file and `user` (who wanted it: "material 'wood'") and *id = 0, FV_OK; only an
 * allocation failure in this process is an error. */
fv_status fv_texture_load_file(fv_scene *scene, const char *path, const char *user, const fv_log *log, int *id, fv_error *err);

#endif
