/* fovea — the inverted pyramid's image operations (pyramid.h). */
#include <math.h>
#include "fovea/gaze.h"
#include "technique/sdf/pyramid.h"

void fv_pyramid_levels(int sw, int sh, int levels, fv_pyramid_level *level)
{
    for (int k = 0; k < levels; k++) {
        int f = 1 << (levels - 1 - k);
        level[k].f = f;
        level[k].w = (sw + f - 1) / f;
        level[k].h = (sh + f - 1) / f;
    }
}

void fv_pyramid_centre(const fv_pyramid_level *l, int sw, int sh, int i, int j, float *sx, float *sy)
{
    int x0 = i * l->f, y0 = j * l->f;
    int x1 = x0 + l->f < sw ? x0 + l->f : sw, y1 = y0 + l->f < sh ? y0 + l->f : sh;
    *sx = 0.5f * (float)(x0 + x1);
    *sy = 0.5f * (float)(y0 + y1);
}

float fv_pyramid_start(const float *depth, const fv_pyramid_level *parent, int pi, int pj, bool min_filter)
{
    if (!min_filter) return depth[(size_t)pj * parent->w + pi];
    float m = INFINITY;
    for (int dy = -1; dy <= 1; dy++) {
        int y = pj + dy;
        if (y < 0 || y >= parent->h) continue;
        for (int dx = -1; dx <= 1; dx++) {
            int x = pi + dx;
            if (x < 0 || x >= parent->w) continue;
            float d = depth[(size_t)y * parent->w + x];
            if (d < m) m = d;
        }
    }
    return m;
}

void fv_pyramid_sobel(const float *depth, int w, int h, float threshold, uint8_t *edge)
{
    float far = 0.0f;
    for (size_t i = 0; i < (size_t)w * h; i++)
        if (isfinite(depth[i]) && depth[i] > far) far = depth[i];
    float sky = far > 0.0f ? 2.0f * far : 1.0f;
#define D(x, y) (isfinite(depth[(size_t)(y) * w + (x)]) ? depth[(size_t)(y) * w + (x)] : sky)
    for (int y = 0; y < h; y++) {
        int ym = y > 0 ? y - 1 : 0, yp = y + 1 < h ? y + 1 : h - 1;
        for (int x = 0; x < w; x++) {
            int xm = x > 0 ? x - 1 : 0, xp = x + 1 < w ? x + 1 : w - 1;
            float gx = (D(xp, ym) + 2.0f * D(xp, y) + D(xp, yp)) - (D(xm, ym) + 2.0f * D(xm, y) + D(xm, yp));
            float gy = (D(xm, yp) + 2.0f * D(x, yp) + D(xp, yp)) - (D(xm, ym) + 2.0f * D(x, ym) + D(xp, ym));
            float g = sqrtf(gx * gx + gy * gy);
            edge[(size_t)y * w + x] = g > threshold * D(x, y) ? 1 : 0;
        }
    }
#undef D
}

double fv_pyramid_probability(double ecc_deg, double fovea_deg, double outer_deg, bool edge)
{
    if (ecc_deg <= fovea_deg) return 1.0;
    if (outer_deg > 0.0 && ecc_deg > outer_deg) return 0.0;
    return edge ? 1.0 : fv_acuity_hyperbolic(ecc_deg, fovea_deg, outer_deg);
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
