/* fovea — the scalar SDF evaluator and the public distance and normal (include/fovea/sdf.h).
 * The kernel is kernel.h with one lane; eval8.c builds the same kernel with eight. */
#define FV_K_WIDE 0
#include "sdf/kernel.h"
#include "sdf/sdf_eval.h"

float fv_sdf_distance1(const fv_sdf *sdf, float x, float y, float z, int *mat)
{
    kf d;
    ki m;
    k_eval(sdf, x, y, z, &d, &m);
    if (mat) *mat = m;
    return d;
}

float fv_sdf_distance(const fv_sdf *sdf, fv_vec3 p, int *material)
{
    return fv_sdf_distance1(sdf, p.x, p.y, p.z, material);
}

/* Central differences: the six probes go through the eight-lane evaluator in one call. */
fv_vec3 fv_sdf_normal(const fv_sdf *sdf, fv_vec3 p, float h)
{
    if (!(h > 0.0f)) h = sdf->normal_h;
    float x[8] = {p.x + h, p.x - h, p.x, p.x, p.x, p.x, p.x, p.x};
    float y[8] = {p.y, p.y, p.y + h, p.y - h, p.y, p.y, p.y, p.y};
    float z[8] = {p.z, p.z, p.z, p.z, p.z + h, p.z - h, p.z, p.z};
    float d[8];
    fv_sdf_distance8(sdf, x, y, z, d, NULL);
    fv_vec3 g = fv_v3(d[0] - d[1], d[2] - d[3], d[4] - d[5]);
    float l = fv_length(g);
    return l > 0.0f && isfinite(l) ? fv_scale(g, 1.0f / l) : fv_v3(0.0f, 0.0f, 0.0f);
}
