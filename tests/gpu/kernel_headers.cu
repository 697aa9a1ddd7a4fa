/* Built only in a CUDA build (tests/CMakeLists.txt): every kernel header compiles for the device.
 * pt's kernel (device/cuda/pt.cu) already instantiates the BSDFs, lights, textures, the flat
 * scene's traversal with SDF leaves and the path estimator; this unit calls what no CUDA kernel
 * uses yet (the eye model and the acuity models of kernel/keye.h, the light table's other queries),
 * so a change that makes them host-only fails the build, not a later GPU kernel. The sphere-tracing
 * family's headers (technique/sdf/k*.h) are instantiated on their
 * own below, outside any backend. */
#include "kernel/keye.h"
#include "kernel/kpt.h"
#include "technique/sdf/ksdf_pixel.h"

__global__ void fv_check_eye(fv_eye_model m, fv_gaze g, double *out)
{
    double px = threadIdx.x + 0.5, py = blockIdx.x + 0.5;
    out[0] = fv_keye_eccentricity_deg(&m, g, px, py) + fv_keye_blend(&m, g, px, py) +
             (double)fv_keye_classify(fv_keye_gaze_dist_px(&m, g, px, py), fv_keye_fovea_radius_px(&m), fv_keye_transition_radius_px(&m));
    out[1] = fv_kacuity_v(px) + fv_kacuity_cdf(px) + fv_kacuity_cdf_inv_fit(0.5) + fv_kacuity_hyperbolic(px, 5.0, 30.0) +
             fv_kacuity_linear(px, 5.0, 30.0, 0.1);
}

__global__ void fv_check_lights(fv_kscene s, float *out)
{
    fv_light_sample ls;
    bool ok = fv_klights_sample_li(&s.lights, fv_v3(0, 0, 0), 0.5f, 0.5f, 0.5f, &ls);
    out[0] = ok ? ls.pdf : fv_klights_env_pdf(&s.lights, fv_v3(0, 1, 0)) + fv_klights_env_radiance(&s.lights, fv_v3(0, 1, 0)).x;
    fv_vec3 e = s.ntex > 0 ? fv_ktexture_sample(&s.tex[0], fv_vec2{0.5f, 0.5f}) : fv_v3s(0.0f);
    out[1] = e.x + (fv_kscene_occluded(&s, fv_v3(0, 0, 0), fv_v3(0, 0, 1), 1.0f) ? 1.0f : 0.0f);
}

/* The sphere-tracing family's kernels: the world's field, the march (over-relaxed, any hit), the
 * shading of one hit and sdf-gt's pixel. */
__global__ void fv_check_sdf(fv_ksdf_world w, fv_ksdf_frame f, fv_film_views out, float *res)
{
    fv_march_ray r;
    fv_ksdf_camera_ray(&w, &f, 0.5f, 0.5f, &r);
    fv_march_hit h;
    fv_kmarch_one(&w, f.march.max_steps, FV_SDF_SHADOW_RELAX, &r, true, &h);
    fv_sdf_shade_counts sc = {0, 0, 0};
    fv_vec3 n;
    fv_vec3 c = fv_ksdf_shade_one(&w, &f.march, &f.shade, &r, &h, &sc, &n);
    fv_ksdf_counts pc;
    memset(&pc, 0, sizeof pc);
    fv_ksdf_pixel(&w, &f, 0, 0, &out, &pc);
    res[0] = c.x + n.y + fv_ksdf_world_eval1(&w, 0.0f, 1.0f, 2.0f, 0) + (float)pc.steps + fv_ksdf_lobe_of(&w.mats[0]).norm;
}

/* Visual-Polar's kernels (technique/vpolar/kvp_space.h, technique/vpolar/kvp_map.h): a sample's screen position, a
 * pixel's coordinates through the radial table, a φ-mip cell and lookup. */
#include "technique/vpolar/kvp_map.h"
#include "technique/vpolar/kvp_space.h"

__global__ void fv_check_vp(fv_kvp_space s, fv_kvp_view v, const float *table, int n, fv_kphi_mips m, float *out)
{
    float px, py, X, V, level, sigma;
    fv_kvp_to_screen(&s, &v, threadIdx.x + 0.5f, 0.25f, &px, &py);
    fv_kvp_table_coords(table, n, 2.0f, px - v.gx, py - v.gy, &X, &V, &level, &sigma);
    if (m.levels > 1) fv_kphi_halve_cell(&m, 1, threadIdx.x, blockIdx.x);
    fv_kphi_sample(&m, X, V, level, out);
    out[3] = sigma + (float)fv_kvp_nearest_cell(m.rows[0], m.w, 4, X, V);
}

/* Visual-Polar's trace (technique/vpolar/kvp_trace.h): one grid sample's path on the flat scene. */
#include "technique/vpolar/kvp_trace.h"

__global__ void fv_check_vp_trace(fv_kscene s, fv_kvp_trace_frame f, fv_kvp_gbuf g, fv_kvp_trace_counts *c)
{
    fv_kvp_trace_sample(&s, &f, &g, (long)blockIdx.x * blockDim.x + threadIdx.x, c);
}

/* Visual-Polar's foveated blur (filter/kblur.h): a pixel of each pass. */
#include "filter/kblur.h"

__global__ void fv_check_vp_blur(fv_kblur_table t, const float *sigma, float *rgb, float *tmp)
{
    fv_kblur_h_pixel(&t, sigma, rgb, tmp, threadIdx.x, blockIdx.x);
    fv_kblur_v_pixel(&t, sigma, tmp, rgb, threadIdx.x, blockIdx.x);
}

/* Visual-Polar's history reprojection (technique/vpolar/kvp_reproject.h): one grid sample. */
#include "technique/vpolar/kvp_reproject.h"

__global__ void fv_check_vp_reproject(fv_kvp_reproject_frame f, float *prev_coord)
{
    const long i = (long)blockIdx.x * blockDim.x + threadIdx.x;
    fv_kvp_reproject_sample(&f, i, &prev_coord[2 * i]);
}
