/* fovea — foveated weights (Alg. 2) and importance (Alg. 3) (see weights.h). */
#include <math.h>
#include "core/parallel.h"
#include "technique/vpl/weights.h"

void fv_vpl_dirs_make(int count, fv_vpl_dirs *out)
{
    if (count < 1) count = 1;
    if (count > FV_VPL_MAX_DIRECTIONS) count = FV_VPL_MAX_DIRECTIONS;
    out->count = count;
    /* A Fibonacci spiral, uniform in z = cos(theta) over the hemisphere, so each direction stands for
     * an equal solid angle and the cosine alone weights it. */
    const float golden = (float)M_PI * (3.0f - sqrtf(5.0f));
    double sum = 0.0;
    for (int i = 0; i < count; i++) {
        const float z = 1.0f - ((float)i + 0.5f) / (float)count;
        const float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        const float phi = golden * (float)i;
        out->d[i] = fv_v3(r * cosf(phi), r * sinf(phi), z);
        out->w[i] = z;
        sum += z;
    }
    for (int i = 0; i < count; i++) out->w[i] = (float)(out->w[i] / sum);
}

typedef struct weight_job {
    const fv_voxels *v;
    const fv_camera_basis *cam;
    const fv_gbuffer *gb;
    float gx, gy, R;
    float *weight;
    int dims[3];
    int *count; /* shared by the team: each chunk adds its cells once */
} weight_job;

static void weight_range(void *ctx, int64_t b, int64_t e, int thread)
{
    (void)thread;
    weight_job *j = ctx;
    int cells = 0;
    const float h = fv_voxels_cell_size(j->v);
    const float tol = h * sqrtf(3.0f);
    for (int64_t c = b; c < e; c++) {
        j->weight[c] = 0.0f;
        fv_voxel vx;
        fv_voxels_cell(j->v, (int)c, &vx);
        if (!vx.occupied) continue;
        const fv_vec3 centre = fv_voxels_centre(j->v, (int)c);
        float px, py;
        if (!fv_camera_project(j->cam, centre, &px, &py)) continue;
        if (!(px >= 0.0f && py >= 0.0f && px < (float)j->gb->width && py < (float)j->gb->height)) continue;
        const fv_gpixel *g = &j->gb->px[(size_t)py * (size_t)j->gb->width + (size_t)px];
        const float dist = fv_length(fv_sub(centre, j->cam->pos));
        /* hidden when the pixel sees a surface clearly in front of the voxel (a miss sees nothing) */
        if (fv_gpixel_hit(g) && g->t < dist - tol) continue;
        const float d = hypotf(px - j->gx, py - j->gy);
        j->weight[c] = fv_vpl_acuity(d, j->R);
        cells++;
    }
#pragma omp atomic
    *j->count += cells;
}

void fv_vpl_foveated_weights_team(const fv_voxels *v, const fv_camera_basis *cam, const fv_gbuffer *gb, float gx, float gy,
                                  float R, float *weight, int *count)
{
    weight_job j = {0};
    j.v = v;
    j.cam = cam;
    j.gb = gb;
    j.gx = gx;
    j.gy = gy;
    j.R = R;
    j.weight = weight;
    j.count = count;
    fv_voxels_dims(v, 0, j.dims);
    const int64_t n = (int64_t)j.dims[0] * j.dims[1] * j.dims[2];
    fv_team_for(n, 4096, weight_range, &j);
}

float fv_vpl_importance(const fv_voxels *v, const float *weight, const fv_vpl_dirs *dirs, fv_vec3 p, fv_vec3 n)
{
    fv_vec3 t, b;
    fv_basis(n, &t, &b);
    const float h = fv_voxels_cell_size(v);
    const fv_vec3 o = fv_madd(p, n, h);
    double imp = 0.0;
    for (int i = 0; i < dirs->count; i++) {
        const fv_vec3 d = fv_from_local(dirs->d[i], t, b, n);
        fv_voxel_hit hit;
        if (fv_voxels_cast(v, o, d, INFINITY, &hit)) imp += (double)dirs->w[i] * weight[hit.cell];
    }
    return (float)imp;
}
