/* fovea — textures in the scene: adding them (sRGB -> linear), sampling them, and the material
 * at a hit with its albedo read from its texture (see texture.h and query.h; the sampling itself
 * is kernel code, kernel/ktexture.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "core/alloc.h"
#include "fovea/film.h"
#include "fovea/limits.h"
#include "scene/scene_impl.h"
#include "kernel/klight.h"
#include "kernel/ktexture.h"
#include "scene/texture.h"

fv_status fv_scene_add_texture(fv_scene *s, const fv_texture_desc *t, int *id, fv_error *err)
{
    if (s->committed) return fv_error_set(err, FV_ERR_INTERNAL, "scene already committed: it cannot be changed");
    const char *name = t->name ? t->name : "texture";
    if (t->width < 1 || t->height < 1 || !t->texels || t->channels < 1 || t->channels > 4)
        return fv_error_set(err, FV_ERR_INVALID, "texture '%s': bad size %dx%d or %d channels", name, t->width, t->height, t->channels);
    long long n = (long long)t->width * t->height;
    if (n > FV_TEXTURE_MAX_TEXELS)
        return fv_error_set(err, FV_ERR_INVALID, "texture '%s': %dx%d is more than the %d texels a texture may have", name, t->width,
                            t->height, FV_TEXTURE_MAX_TEXELS);
    if (s->tex_texels + n > FV_TEXTURE_MAX_TOTAL)
        return fv_error_set(err, FV_ERR_INVALID, "texture '%s': the scene's textures would hold more than %d texels", name,
                            FV_TEXTURE_MAX_TOTAL);
    if (fv_grow((void **)&s->tex, &s->captex, s->ntex + 1, sizeof *s->tex))
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory adding texture '%s'", name);
    fv_texture *x = &s->tex[s->ntex];
    x->rgb = fv_alloc_array((size_t)n, 3 * sizeof(float));
    if (!x->rgb) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for texture '%s' (%dx%d)", name, t->width, t->height);
    /* One table for the 256 codes instead of a power per channel. */
    float lut[256];
    for (int i = 0; i < 256; i++) lut[i] = fv_srgb_decode((float)i / 255.0f);
    const int ch = t->channels;
    for (long long i = 0; i < n; i++) {
        const unsigned char *p = &t->texels[i * ch];
        bool grey = ch < 3;
        x->rgb[3 * i] = lut[p[0]];
        x->rgb[3 * i + 1] = lut[p[grey ? 0 : 1]];
        x->rgb[3 * i + 2] = lut[p[grey ? 0 : 2]];
    }
    snprintf(x->name, sizeof x->name, "%s", name);
    x->w = t->width;
    x->h = t->height;
    s->tex_texels += n;
    *id = ++s->ntex;
    return FV_OK;
}

int fv_scene_texture_count(const fv_scene *s) { return s->ntex; }

fv_vec3 fv_texture_sample(const fv_texture *t, fv_vec2 uv)
{
    fv_ktexture k = {t->w, t->h, t->rgb};
    return fv_ktexture_sample(&k, uv);
}

/* The kernel's view of texture id (0 or out of range: NULL), in *k. */
static const fv_ktexture *kview(const fv_scene *s, int id, fv_ktexture *k)
{
    if (id < 1 || id > s->ntex) return NULL;
    const fv_texture *t = &s->tex[id - 1];
    *k = (fv_ktexture){t->w, t->h, t->rgb};
    return k;
}

const fv_material *fv_material_textured(const fv_scene *s, const fv_material *m, int obj, int prim, float u, float v, fv_material *buf)
{
    const fv_object *o = obj >= 0 && obj < s->nobj ? &s->objs[obj] : NULL;
    if (!o || !o->uv || prim < 0 || prim >= o->nt) return m;
    fv_ktexture ka, ke;
    const fv_ktexture *ta = kview(s, m->albedo_texture, &ka), *te = kview(s, m->emission_texture, &ke);
    if (!ta && !te) return m;
    const uint32_t *ix = &o->idx[3 * prim];
    return fv_kmaterial_textured(m, ta, te, o->uv[ix[0]], o->uv[ix[1]], o->uv[ix[2]], u, v, buf);
}

void fv_texture_stats(const fv_scene *s, int id, fv_vec3 *mean, float *max_lum)
{
    *mean = fv_v3s(1.0f);
    *max_lum = 1.0f;
    if (id < 1 || id > s->ntex) return;
    const fv_texture *t = &s->tex[id - 1];
    double sum[3] = {0.0, 0.0, 0.0};
    float mx = 0.0f;
    size_t n = (size_t)t->w * (size_t)t->h;
    for (size_t i = 0; i < n; i++) {
        const float *p = &t->rgb[3 * i];
        for (int c = 0; c < 3; c++) sum[c] += p[c];
        mx = fv_maxf(mx, fv_luminance(fv_v3(p[0], p[1], p[2])));
    }
    *mean = fv_v3((float)(sum[0] / (double)n), (float)(sum[1] / (double)n), (float)(sum[2] / (double)n));
    *max_lum = mx;
}

fv_vec3 fv_texture_triangle_mean(const fv_scene *s, int id, int obj, int prim)
{
    fv_ktexture k;
    const fv_ktexture *t = kview(s, id, &k);
    const fv_object *o = obj >= 0 && obj < s->nobj ? &s->objs[obj] : NULL;
    if (!t || !o || !o->uv || prim < 0 || prim >= o->nt) return fv_v3s(1.0f);
    const uint32_t *ix = &o->idx[3 * prim];
    fv_vec2 ta = o->uv[ix[0]], tb = o->uv[ix[1]], tc = o->uv[ix[2]];
    /* The same points fv_klight_triangle_point draws, on an 8 x 8 grid of its numbers: uniform
     * by area, so the mean is the triangle's average texel as area-sampling sees it. */
    enum { G = 8 };
    fv_vec3 sum = fv_v3s(0.0f);
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            float w[3];
            fv_klight_triangle_bary(((float)i + 0.5f) / G, ((float)j + 0.5f) / G, w);
            fv_vec2 st = {w[0] * ta.x + w[1] * tb.x + w[2] * tc.x, w[0] * ta.y + w[1] * tb.y + w[2] * tc.y};
            sum = fv_add(sum, fv_ktexture_sample(t, st));
        }
    return fv_scale(sum, 1.0f / (G * G));
}
