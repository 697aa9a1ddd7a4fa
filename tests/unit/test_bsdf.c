/* Unit tests of the BSDFs (src/scene/bsdf.c) with hand-worked numbers and integrals. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include "core/rng.h"
#include "kernel/kbsdf.h"

static void test_fresnel_hand_values(void **st)
{
    (void)st;
    /* Normal incidence air->glass: ((1 - 1.5) / (1 + 1.5))^2 = 0.04. */
    assert_float_equal(fv_fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-6);
    /* Glass->air at 60 degrees: sin_t^2 = 0.75 * 1.5^2 = 1.6875 > 1, total internal reflection. */
    assert_float_equal(fv_fresnel_dielectric(0.5f, 1.0f / 1.5f), 1.0f, 0.0);
    /* Air->glass at 45 degrees: cos_t = sqrt(1 - 0.5/2.25) = 0.881917; rs = (0.707107 - 1.5*0.881917) /
     * (0.707107 + 1.5*0.881917) = -0.303337; rp = (1.5*0.707107 - 0.881917)/(1.5*0.707107 + 0.881917)
     * = 0.092013; F = (0.092013 + 0.008466)/2 = 0.050240. */
    assert_float_equal(fv_fresnel_dielectric(0.70710678f, 1.5f), 0.050240f, 2e-5);
}

/* D(h) cos(h) integrates to 1 over the hemisphere (the normalisation of a microfacet distribution). */
static void test_ggx_normalised(void **st)
{
    (void)st;
    const float alphas[] = {0.1f, 0.3f, 0.7f};
    for (int a = 0; a < 3; a++) {
        double sum = 0.0;
        const int n = 20000;
        for (int i = 0; i < n; i++) { /* midpoint rule in cos(theta) over [0,1], times 2 pi */
            float c = ((float)i + 0.5f) / (float)n;
            sum += fv_ggx_d(c, alphas[a]) * c * (1.0 / n) * 2.0 * M_PI;
        }
        assert_float_equal(sum, 1.0, 0.01);
    }
    /* G1 at normal incidence is 1. */
    assert_float_equal(fv_ggx_g1(1.0f, 0.5f), 1.0f, 1e-6);
}

/* A Lambert surface returns exactly its albedo as the sample weight and its pdf is cos/pi. */
static void test_lambert(void **st)
{
    (void)st;
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3(0.5f, 0.25f, 1.0f);
    fv_bsdf_sample s;
    fv_vec3 wo = fv_normalize(fv_v3(0.3f, -0.2f, 0.9f));
    assert_true(fv_bsdf_sample_dir(&m, wo, FV_TRANSPORT_RADIANCE, 0.3f, 0.7f, 0.1f, &s));
    assert_float_equal(s.weight.x, 0.5f, 1e-6);
    assert_float_equal(s.weight.y, 0.25f, 1e-6);
    assert_float_equal(s.pdf, s.wi.z / (float)M_PI, 1e-6);
    float pdf;
    fv_vec3 f = fv_bsdf_eval(&m, wo, s.wi, &pdf);
    assert_float_equal(f.x, 0.5f / (float)M_PI, 1e-6);
    assert_float_equal(pdf, s.pdf, 1e-6);
    /* Below the surface: nothing. */
    f = fv_bsdf_eval(&m, wo, fv_v3(0, 0, -1), &pdf);
    assert_float_equal(f.x, 0.0f, 0.0);
}

/* For the glossy BSDF, the albedo estimated by importance sampling (mean of weights) agrees with
 * the one estimated by uniform hemisphere sampling of eval(): this checks eval, sample and pdf
 * against each other. */
static void test_glossy_sample_matches_eval(void **st)
{
    (void)st;
    fv_material m = fv_material_default(FV_MAT_GLOSSY);
    m.albedo = fv_v3s(0.3f);
    m.specular = fv_v3s(0.5f);
    const float rough[] = {0.15f, 0.5f};
    for (int r = 0; r < 2; r++) {
        m.roughness = rough[r];
        fv_vec3 wo = fv_normalize(fv_v3(0.5f, 0.1f, 0.8f));
        const int n = 400000;
        double is = 0.0, uni = 0.0, pdf_int = 0.0;
        for (int i = 0; i < n; i++) {
            fv_rng rng = fv_rng_make(7, (uint64_t)i, 0, 0);
            float u0 = fv_rng_next(&rng), u1 = fv_rng_next(&rng), u2 = fv_rng_next(&rng);
            fv_bsdf_sample s;
            if (fv_bsdf_sample_dir(&m, wo, FV_TRANSPORT_RADIANCE, u0, u1, u2, &s)) is += s.weight.x;
            /* uniform hemisphere: pdf 1/(2 pi) */
            float z = u0, rr = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * (float)M_PI * u1;
            fv_vec3 wi = fv_v3(rr * cosf(phi), rr * sinf(phi), z);
            float pdf;
            fv_vec3 f = fv_bsdf_eval(&m, wo, wi, &pdf);
            uni += f.x * wi.z * 2.0 * M_PI;
            pdf_int += pdf * 2.0 * M_PI;
        }
        is /= n;
        uni /= n;
        pdf_int /= n;
        assert_float_equal(is, uni, 0.02 * uni);
        assert_true(is < 1.0);            /* no energy gain */
        assert_true(pdf_int <= 1.01);     /* pdf integrates to at most 1 (some mass lost below the horizon) */
        assert_true(pdf_int > 0.85);
    }
}

static void test_mirror(void **st)
{
    (void)st;
    fv_material m = fv_material_default(FV_MAT_MIRROR);
    m.specular = fv_v3(0.9f, 0.8f, 0.7f);
    fv_vec3 wo = fv_normalize(fv_v3(0.6f, 0.0f, 0.8f));
    fv_bsdf_sample s;
    assert_true(fv_bsdf_sample_dir(&m, wo, FV_TRANSPORT_RADIANCE, 0.5f, 0.5f, 0.5f, &s));
    assert_true(s.delta);
    assert_float_equal(s.wi.x, -0.6f, 1e-6);
    assert_float_equal(s.wi.z, 0.8f, 1e-6);
    assert_float_equal(s.weight.y, 0.8f, 1e-6);
    float pdf;
    assert_float_equal(fv_bsdf_eval(&m, wo, s.wi, &pdf).x, 0.0f, 0.0);
}

/* Refraction obeys Snell's law, the choice between the two lobes follows Fresnel, and camera
 * paths (radiance) are scaled by 1/eta^2 on entering while light paths (importance) are not. */
static void test_dielectric(void **st)
{
    (void)st;
    fv_material m = fv_material_default(FV_MAT_DIELECTRIC);
    m.ior = 1.5f;
    float sin_i = 0.6f;
    fv_vec3 wo = fv_v3(sin_i, 0.0f, 0.8f);
    float F = fv_fresnel_dielectric(0.8f, 1.5f);
    fv_bsdf_sample s;
    assert_true(fv_bsdf_sample_dir(&m, wo, FV_TRANSPORT_RADIANCE, F * 0.5f, 0, 0, &s));
    assert_true(s.wi.z > 0.0f); /* reflected */
    assert_float_equal(s.pdf, F, 1e-6);
    assert_true(fv_bsdf_sample_dir(&m, wo, FV_TRANSPORT_RADIANCE, F + 0.5f * (1.0f - F), 0, 0, &s));
    assert_true(s.wi.z < 0.0f); /* refracted into the object */
    float sin_t = sqrtf(s.wi.x * s.wi.x + s.wi.y * s.wi.y);
    assert_float_equal(sin_t, sin_i / 1.5f, 1e-5);  /* Snell: 1.0 * 0.6 = 1.5 * sin_t */
    assert_float_equal(s.wi.x, -sin_i / 1.5f, 1e-5); /* continues on the other side */
    assert_float_equal(s.weight.x, 1.0f / 2.25f, 1e-5);
    assert_true(fv_bsdf_sample_dir(&m, wo, FV_TRANSPORT_IMPORTANCE, 0.99f, 0, 0, &s));
    assert_float_equal(s.weight.x, 1.0f, 1e-6);
    /* Leaving the glass: the ray goes back out with sin = 1.5 * sin_inside. */
    fv_vec3 wo_in = fv_v3(0.3f, 0.0f, -sqrtf(1.0f - 0.09f));
    assert_true(fv_bsdf_sample_dir(&m, wo_in, FV_TRANSPORT_RADIANCE, 0.999f, 0, 0, &s));
    assert_true(s.wi.z > 0.0f);
    assert_float_equal(s.wi.x, -0.45f, 1e-5);
    assert_float_equal(s.weight.x, 2.25f, 1e-4);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fresnel_hand_values), cmocka_unit_test(test_ggx_normalised),
        cmocka_unit_test(test_lambert),             cmocka_unit_test(test_glossy_sample_matches_eval),
        cmocka_unit_test(test_mirror),              cmocka_unit_test(test_dielectric),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
