/* fovea — the inverted pyramid's image operations (pyramid.h): the kernel steps of
 * technique/sdf/kpyr.h over whole buffers, and the host buffers. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "technique/sdf/pyramid.h"

void fv_pyramid_levels(int sw, int sh, int levels, fv_pyramid_level *level) { fv_kpyr_levels(sw, sh, levels, level); }

void fv_pyramid_centre(const fv_pyramid_level *l, int sw, int sh, int i, int j, float *sx, float *sy)
{
    fv_kpyr_centre(l, sw, sh, i, j, sx, sy);
}

float fv_pyramid_start(const float *depth, const fv_pyramid_level *parent, int pi, int pj, bool min_filter)
{
    return fv_kpyr_start(depth, parent, pi, pj, min_filter);
}

void fv_pyramid_sobel(const float *depth, int w, int h, float threshold, uint8_t *edge)
{
    float far = 0.0f;
    for (size_t i = 0; i < (size_t)w * h; i++)
        if (isfinite(depth[i]) && depth[i] > far) far = depth[i];
    const float sky = fv_kpyr_sky(far);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) edge[(size_t)y * w + x] = fv_kpyr_sobel_cell(depth, w, h, sky, threshold, x, y);
}

double fv_pyramid_probability(double ecc_deg, double fovea_deg, double outer_deg, bool edge)
{
    return fv_kpyr_probability(ecc_deg, fovea_deg, outer_deg, edge);
}

/* A ramp blue -> cyan -> green -> yellow -> red over u in [0, 1]. */
static fv_vec3 ramp(float u)
{
    u = u < 0.0f ? 0.0f : u > 1.0f ? 1.0f : u;
    float s = 4.0f * u;
    if (s < 1.0f) return fv_v3(0.0f, s, 1.0f);
    if (s < 2.0f) return fv_v3(0.0f, 1.0f, 2.0f - s);
    if (s < 3.0f) return fv_v3(s - 2.0f, 1.0f, 0.0f);
    return fv_v3(1.0f, 4.0f - s, 0.0f);
}

fv_vec3 fv_pyramid_heat(float steps) { return ramp(steps > 1.0f ? log2f(steps) / 8.0f : 0.0f); }

fv_vec3 fv_pyramid_level_colour(int level, int levels) { return ramp(levels > 1 ? 1.0f - (float)level / (float)(levels - 1) : 0.0f); }

void fv_pyramid_free(fv_kpyr *k)
{
    for (int i = 0; i < FV_PYRAMID_MAX_LEVELS; i++) {
        free(k->depth[i]);
        free(k->steps[i]);
    }
    free(k->need);
    free(k->edge);
    free(k->mask);
    free(k->vis);
    memset(k, 0, sizeof *k);
}

fv_status fv_pyramid_alloc(fv_kpyr *k, int w, int h, int S, int L, bool fipr, bool vis, fv_error *err)
{
    if (k->w == w && k->h == h && k->S == S && k->L == L) return FV_OK;
    fv_pyramid_free(k);
    k->S = S;
    k->L = L;
    k->sw = w * S;
    k->sh = h * S;
    fv_kpyr_levels(k->sw, k->sh, L, k->lv);
    bool ok = true;
    for (int i = 0; i + 1 < L; i++) {
        size_t n = (size_t)k->lv[i].w * k->lv[i].h;
        ok &= (k->depth[i] = fv_alloc_array(n, sizeof(float))) != NULL;
        ok &= (k->steps[i] = fv_calloc_array(n, sizeof(uint16_t))) != NULL;
    }
    if (vis && L > 1) ok &= (k->vis = fv_alloc_array((size_t)k->lv[L - 2].w * k->lv[L - 2].h, sizeof(uint32_t))) != NULL;
    if (fipr) {
        const fv_pyramid_level *mid = &k->lv[L - 2];
        ok &= (k->need = fv_alloc_array((size_t)mid->w * mid->h, 1)) != NULL;
        ok &= (k->edge = fv_alloc_array((size_t)k->lv[0].w * k->lv[0].h, 1)) != NULL;
        ok &= (k->mask = fv_alloc_array((size_t)w * h, 1)) != NULL;
    }
    if (!ok) {
        fv_pyramid_free(k);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d sphere-tracing pyramid at %d spp", w, h, S * S);
    }
    k->w = w;
    k->h = h;
    return FV_OK;
}

void fv_pyramid_history_free(fv_pyramid_history *hs)
{
    free(hs->color);
    free(hs->stamp);
    memset(hs, 0, sizeof *hs);
}

fv_status fv_pyramid_history_attach(fv_pyramid_history *hs, fv_kpyr *k, int index, fv_error *err)
{
    const fv_pyramid_level *mid = &k->lv[k->L - 2];
    size_t n = (size_t)mid->w * mid->h;
    if (hs->sw != k->sw || hs->sh != k->sh || !hs->color) {
        fv_pyramid_history_free(hs);
        hs->color = fv_calloc_array(n * 3, sizeof(float));
        hs->stamp = fv_alloc_array(n, sizeof(int));
        if (!hs->color || !hs->stamp) {
            fv_pyramid_history_free(hs);
            return fv_error_set(err, FV_ERR_NOMEM, "out of memory for fipr's history");
        }
        hs->sw = k->sw;
        hs->sh = k->sh;
        index = 0;
    }
    /* a sequence's first frame starts without history */
    if (index == 0)
        for (size_t i = 0; i < n; i++) hs->stamp[i] = INT_MIN;
    k->hist_color = hs->color;
    k->hist_stamp = hs->stamp;
    return FV_OK;
}
