/* fovea — injection of direct light into the voxels and the VPLs' cone-traced bounce (see
 * radiosity.h). */
#include <math.h>
#include "core/parallel.h"
#include "core/rng.h"
#include "fovea/stats.h"
#include "technique/vpl/direct.h"
#include "technique/vpl/radiosity.h"

typedef struct inject_job {
    fv_voxels *v;
    const fv_scene *s;
    uint64_t seed, frame;
    int area_samples;
    float *out;
    int dims[3];
    uint64_t *rays; /* shared by the team: each chunk adds its rays once */
} inject_job;

static void inject_range(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    inject_job *j = ctx;
    uint64_t rays = 0;
    const float h = fv_voxels_cell_size(j->v);
    for (int64_t c = b; c < e; c++) {
        float *o = &j->out[3 * c];
        o[0] = o[1] = o[2] = 0.0f;
        fv_voxel vx;
        fv_voxels_cell(j->v, (int)c, &vx);
        if (!vx.occupied || !(fv_dot(vx.normal, vx.normal) > 0.0f)) continue;
        const fv_vec3 centre = fv_voxels_centre(j->v, (int)c);
        /* Either side of the cell's surface may be the lit one (a wall seen from inside a room, a sphere
         * lit from within, a thin panel): the voxel's radiance is isotropic, so it takes the side that
         * receives more light. */
        fv_rng rng = fv_rng_stream(j->seed, FV_STREAM_VPL, FV_VPL_RNG_INJECT + (uint64_t)c, 0, j->frame);
        const float off = 0.5f * sqrtf(3.0f) * h;
        const fv_vec3 nb = fv_neg(vx.normal);
        fv_vec3 E1 = fv_vpl_direct_irradiance(j->s, fv_madd(centre, vx.normal, off), vx.normal, vx.normal, j->area_samples, &rng,
                                              &rays);
        fv_vec3 E2 = fv_vpl_direct_irradiance(j->s, fv_madd(centre, nb, off), nb, nb, j->area_samples, &rng, &rays);
        fv_vec3 E = fv_max3(E1) >= fv_max3(E2) ? E1 : E2;
        fv_vec3 L = fv_scale(fv_mul(vx.albedo, E), 1.0f / (float)M_PI);
        o[0] = L.x, o[1] = L.y, o[2] = L.z;
    }
#pragma omp atomic
    *j->rays += rays;
}

static void set_range(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    const inject_job *j = ctx;
    for (int64_t c = b; c < e; c++) fv_voxels_set_radiance(j->v, (int)c, fv_v3(j->out[3 * c], j->out[3 * c + 1], j->out[3 * c + 2]));
}

void fv_vpl_inject_team(fv_voxels *v, const fv_scene *s, uint64_t seed, uint64_t frame, int area_samples, float *scratch,
                        uint64_t *rays)
{
    inject_job j = {0};
    j.v = v;
    j.s = s;
    j.seed = seed;
    j.frame = frame;
    j.area_samples = area_samples;
    j.out = scratch;
    j.rays = rays;
    fv_voxels_dims(v, 0, j.dims);
    const int64_t n = (int64_t)j.dims[0] * j.dims[1] * j.dims[2];
    fv_team_for(n, 1024, inject_range, &j);
    /* then into the slots (a cell each, so shared out too) and up the pyramid */
    fv_team_for(n, 4096, set_range, &j);
    fv_voxels_build_radiance(v);
}

fv_vec3 fv_vpl_cone_irradiance(const fv_voxels *v, fv_vec3 p, fv_vec3 n)
{
    /* six 60-degree cones: half-angle 30 degrees, one along n and five at 60 degrees from it */
    static const float k_tan_half = 0.57735027f;
    fv_vec3 t, b;
    fv_basis(n, &t, &b);
    const float h = fv_voxels_cell_size(v);
    const fv_vec3 o = fv_madd(p, n, h);
    fv_vec3 sum = fv_v3s(0.0f), L;
    fv_voxels_cone(v, o, n, k_tan_half, INFINITY, &L);
    sum = fv_madd(sum, L, 0.25f);
    const float st = sinf((float)M_PI / 3.0f), ct = cosf((float)M_PI / 3.0f);
    for (int k = 0; k < 5; k++) {
        const float phi = 2.0f * (float)M_PI * (float)k / 5.0f;
        const fv_vec3 d = fv_from_local(fv_v3(st * cosf(phi), st * sinf(phi), ct), t, b, n);
        fv_voxels_cone(v, o, d, k_tan_half, INFINITY, &L);
        sum = fv_madd(sum, L, 0.15f);
    }
    return fv_scale(sum, (float)M_PI);
}

float fv_vpl_area_per_voxel(const fv_voxels *v, const fv_scene *s)
{
    const float h = fv_voxels_cell_size(v);
    int dims[3];
    fv_voxels_dims(v, 0, dims);
    const int64_t n = (int64_t)dims[0] * dims[1] * dims[2];
    int64_t occupied = 0;
    for (int64_t c = 0; c < n; c++) {
        fv_voxel vx;
        fv_voxels_cell(v, (int)c, &vx);
        occupied += vx.occupied != 0;
    }
    if (occupied == 0 || fv_scene_sdf_object_count(s) > 0) return h * h;
    double area = 0.0;
    for (int o = 0, no = fv_scene_object_count(s); o < no; o++)
        for (int p = 0, np = fv_scene_object_triangle_count(s, o); p < np; p++) {
            fv_vec3 a, b, c;
            fv_scene_triangle(s, o, p, &a, &b, &c);
            area += 0.5 * (double)fv_length(fv_cross(fv_sub(b, a), fv_sub(c, a)));
        }
    return (float)(area / (double)occupied);
}
