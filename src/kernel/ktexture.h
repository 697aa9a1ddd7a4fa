/* fovea — base-colour textures as kernels read them: linear RGB, bilinear, repeating, and the
 * material at a textured surface point. Kernel code (FV_HD): the CPU scene (scene/texture.c) and
 * the device scene read albedo with these same functions.
 */
#ifndef FV_KERNEL_KTEXTURE_H
#define FV_KERNEL_KTEXTURE_H

#include "fovea/scene.h"

/* A texture's texels: w x h linear RGB triples, rows from the top (host or device memory). */
typedef struct fv_ktexture {
    int w, h;
    const float *rgb; /* 3 w h */
} fv_ktexture;

/* floor(x) mod n, for any finite x. */
FV_HD static inline int fv_ktexture_wrap(float x, int n)
{
    int i = (int)fmodf(floorf(x), (float)n);
    return i < 0 ? i + n : i;
}

/* Linear RGB at (s, t) coordinates uv (u right, v up from the bottom-left corner), bilinear
 * between the four nearest texel centres, repeating outside [0,1]. */
FV_HD static inline fv_vec3 fv_ktexture_sample(const fv_ktexture *t, fv_vec2 uv)
{
    /* Keep the coordinates' fraction first: float texel positions of a large u lose precision,
     * and fmodf of a non-finite value is NaN (read as texel 0). */
    float u = uv.x - floorf(uv.x), v = uv.y - floorf(uv.y);
    if (!isfinite(u) || !isfinite(v)) u = v = 0.0f;
    /* Texel centres sit at half-integers; rows run from the top, v from the bottom. */
    float x = u * (float)t->w - 0.5f, y = (1.0f - v) * (float)t->h - 0.5f;
    float fx = x - floorf(x), fy = y - floorf(y);
    int x0 = fv_ktexture_wrap(x, t->w), y0 = fv_ktexture_wrap(y, t->h);
    int x1 = x0 + 1 == t->w ? 0 : x0 + 1, y1 = y0 + 1 == t->h ? 0 : y0 + 1;
    const float *a = &t->rgb[3 * ((size_t)y0 * t->w + x0)], *b = &t->rgb[3 * ((size_t)y0 * t->w + x1)];
    const float *c = &t->rgb[3 * ((size_t)y1 * t->w + x0)], *d = &t->rgb[3 * ((size_t)y1 * t->w + x1)];
    float w00 = (1.0f - fx) * (1.0f - fy), w10 = fx * (1.0f - fy), w01 = (1.0f - fx) * fy, w11 = fx * fy;
    return fv_v3(w00 * a[0] + w10 * b[0] + w01 * c[0] + w11 * d[0], w00 * a[1] + w10 * b[1] + w01 * c[1] + w11 * d[1],
                 w00 * a[2] + w10 * b[2] + w01 * c[2] + w11 * d[2]);
}

/* Material m with its albedo read from texture ta_tex and its emission from te_tex (either NULL:
 * that one untextured) at barycentrics (u, v) of a triangle whose vertices carry texture
 * coordinates ta, tb, tc: a copy in *buf, returned. */
FV_HD static inline const fv_material *fv_kmaterial_textured(const fv_material *m, const fv_ktexture *albedo_tex,
                                                             const fv_ktexture *emission_tex, fv_vec2 ta, fv_vec2 tb,
                                                             fv_vec2 tc, float u, float v, fv_material *buf)
{
    float w = 1.0f - u - v;
    fv_vec2 st = {w * ta.x + u * tb.x + v * tc.x, w * ta.y + u * tb.y + v * tc.y};
    *buf = *m;
    if (albedo_tex) buf->albedo = fv_mul(m->albedo, fv_ktexture_sample(albedo_tex, st));
    if (emission_tex) buf->emission = fv_mul(m->emission, fv_ktexture_sample(emission_tex, st));
    return buf;
}

/* Texture id (1-based; 0 none) of a table of n as a pointer; NULL when it names none. */
FV_HD static inline const fv_ktexture *fv_ktexture_id(const fv_ktexture *tex, int n, int id)
{
    return tex && id >= 1 && id <= n ? &tex[id - 1] : NULL;
}

#endif
