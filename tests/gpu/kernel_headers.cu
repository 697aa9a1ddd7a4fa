/* Built only in a CUDA build (tests/CMakeLists.txt): every kernel header compiles for the device.
 * pt's kernel (device/cuda/pt.cu) already instantiates the BSDFs, lights, textures, the flat
 * scene's traversal with SDF leaves and the path estimator; this unit calls what no CUDA kernel
 * uses yet (the eye model and the acuity models of kernel/eye.h, the light table's other queries),
 * so a change that makes them host-only fails the build, not a later GPU kernel. */
#include "kernel/eye.h"
#include "kernel/pt.h"

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
