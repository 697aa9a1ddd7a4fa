/* Tests of directional lights (FV_LIGHT_DIRECTIONAL: kernel/klight.h, scene/light.c), against
 * analytic answers:
 *  - pt: a diffuse quad of albedo a under a directional light of irradiance E arriving at angle
 *    theta from its normal has radiance a / pi E cos(theta), with next-event estimation alone
 *    (max_depth 1) and with MIS (max_depth 8; a delta light is never hit by chance);
 *  - its photons leave a disc of the bounding sphere's radius facing it: their mean power is
 *    E pi R^2, along its direction, from outside the bounding sphere; pm's photons give the quad
 *    the radiance pt does;
 *  - every method of the registry renders a scene lit by a directional light alone (a quad and an
 *    SDF ball, so that the SDF family runs too) with a non-black image;
 *  - the API refuses a zero direction; JSON scenes read "type": "directional"; glTF's
 *    KHR_lights_punctual directional light (tests/data/sun.gltf) and the COLLADA duck's arrive (no
 *    "ignoring light" warning). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include "core/rng.h"
#include "fovea/sdf.h"
#include "fovea/technique.h"
#include "scene/light.h"
#include "technique/class.h"
#include "transport/path.h"
#include "testkit.h"
#include "pathkit.h"

/* A 2 x 2 diffuse quad at y = 0 facing +y, albedo a, lit by a directional light (dir, E); committed. */
static fv_scene *quad_under_sun(float a, fv_vec3 dir, float E)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(a);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    const fv_vec3 p[4] = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc d = {"quad", p, 4, NULL, idx, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
    fv_light_desc sun = {FV_LIGHT_DIRECTIONAL, {0, 0, 0}, dir, fv_v3s(E), 0, 0};
    assert_int_equal(fv_scene_add_light(s, &sun, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

static void test_analytic_pt(void **st)
{
    (void)st;
    /* normal incidence: L = 0.5 / pi * 3 */
    fv_scene *s = quad_under_sun(0.5f, fv_v3(0, -1, 0), 3.0f);
    double want = 0.5 / FV_PI * 3.0;
    assert_float_equal(fv_test_pt_mean(s, fv_v3(0.1f, 3, 0.2f), fv_v3(0, -1, 0), 1, 100, 1), want, 1e-4 * want);
    assert_float_equal(fv_test_pt_mean(s, fv_v3(0.1f, 3, 0.2f), fv_v3(0, -1, 0), 8, 100, 2), want, 1e-4 * want);
    /* from below, the quad's back: a one-sided diffuse quad is lit from its front only */
    assert_float_equal(fv_test_pt_mean(s, fv_v3(0.1f, -3, 0.2f), fv_v3(0, 1, 0), 8, 100, 3), 0.0, 1e-6);
    fv_scene_destroy(s);
    /* 60 degrees from the normal: half that, unscaled by the light's distance (there is none) */
    s = quad_under_sun(0.5f, fv_v3(sinf(fv_radians(60.0f)), -cosf(fv_radians(60.0f)), 0), 3.0f);
    assert_float_equal(fv_test_pt_mean(s, fv_v3(0.1f, 3, 0.2f), fv_v3(0, -1, 0), 1, 100, 4), 0.5 * want, 1e-3 * want);
    fv_scene_destroy(s);
}

/* Its photons: mean power E pi R^2 (one light: picked always), along dir, from a disc of radius R
 * facing it just outside the bounding sphere. */
static void test_emission(void **st)
{
    (void)st;
    fv_vec3 dir = fv_normalize(fv_v3(0.3f, -1.0f, 0.2f));
    fv_scene *s = quad_under_sun(0.5f, dir, 2.0f);
    const float R = 1.001f * sqrtf(2.0f); /* the quad's bounding sphere, radius sqrt 2 */
    fv_rng rng = fv_rng_stream(7, 1, 0, 0, 0);
    double pw = 0.0;
    const int n = 1000;
    for (int k = 0; k < n; k++) {
        float u[5];
        for (int j = 0; j < 5; j++) u[j] = fv_rng_next(&rng);
        fv_vec3 o, d, power, nrm;
        assert_true(fv_light_sample_emission(s, u, &o, &d, &power, &nrm));
        assert_float_equal(fv_dot(d, dir), 1.0f, 1e-5f);
        assert_float_equal(fv_dot(o, dir), -R, 1e-3f); /* the disc's plane, centre 0 */
        assert_true(fv_length(o) <= sqrtf(2.0f) * R + 1e-3f);
        pw += power.y;
    }
    assert_float_equal(pw / n, 2.0 * FV_PI * R * R, 1e-3 * FV_PI * R * R);
    assert_float_equal(fv_light_total_power(s).y, 2.0f * FV_PI * R * R, 1e-3f);
    fv_light_point lp;
    assert_true(fv_light_pick_point(s, &rng, &lp));
    assert_true(lp.delta && lp.directional);
    fv_vec3 power;
    assert_true(fv_light_point_power(s, &lp, dir, lp.pmf, &power));
    assert_float_equal(power.y, 2.0f * FV_PI * R * R, 1e-3f);
    assert_false(fv_light_point_power(s, &lp, fv_neg(dir), lp.pmf, &power));
    fv_scene_destroy(s);
}

/* pm: the quad under E = 3 at normal incidence, albedo 0.5, has radiance 0.5 / pi * 3; its photons
 * come from the light's disc alone. The centre of the image (well inside the quad, where the
 * gather disc lies on it) averages that within 3%. */
static void test_pm(void **st)
{
    (void)st;
    fv_scene *s = quad_under_sun(0.5f, fv_v3(0, -1, 0), 3.0f);
    const fv_camera cam = {{0, 4, 0.001f}, {0, 0, 0}, {0, 0, -1}, 20.0f, 32, 32};
    fv_film *film = fv_test_render_once("pm", "photons=400000,radius=0.05,filter=false", s, &cam, 1);
    const float *c = fv_film_color(film);
    double sum = 0.0;
    int n = 0;
    for (int y = 8; y < 24; y++)
        for (int x = 8; x < 24; x++, n++) sum += c[3 * (y * 32 + x) + 1];
    double want = 0.5 / FV_PI * 3.0;
    printf("pm: %g, want %g\n", sum / n, want);
    assert_float_equal(sum / n, want, 0.03 * want);
    fv_film_destroy(film);
    fv_scene_destroy(s);
}

/* An SDF node of kind k (material mat) placed at t. */
static void add_sdf(fv_scene *s, const char *name, fv_sdf_kind k, float r, fv_vec3 half, fv_vec3 t, int mat)
{
    fv_sdf_node n[2];
    memset(n, 0, sizeof n);
    n[0].kind = k;
    n[0].p[0] = r;
    n[0].v[0] = half;
    n[0].q = (fv_quat){0, 0, 0, 1};
    n[0].a = n[0].b = -1;
    n[0].material = mat;
    n[1] = n[0];
    n[1].kind = FV_SDF_TRANSFORM;
    n[1].p[0] = 1.0f;
    n[1].v[0] = t;
    n[1].a = 0;
    fv_error err;
    if (fv_scene_add_sdf(s, name, n, 2, 1, NULL, NULL, &err) != FV_OK) fail_msg("%s", err.msg);
}

/* A 6 x 6 SDF slab whose top is y = 0, a mesh quad standing on it and an SDF ball of radius 0.5,
 * all diffuse, lit by a directional light alone (the SDF family draws the SDF objects). */
static fv_scene *floor_and_ball(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.6f);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    const fv_vec3 p[4] = {{-2, 0, -1}, {-1, 0, -1}, {-1, 1, -1}, {-2, 1, -1}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc d = {"card", p, 4, NULL, idx, 2, NULL, mat, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
    add_sdf(s, "ground", FV_SDF_BOX, 0.0f, fv_v3(3.0f, 0.5f, 3.0f), fv_v3(0, -0.5f, 0), mat);
    add_sdf(s, "ball", FV_SDF_SPHERE, 0.5f, fv_v3s(0.0f), fv_v3(0, 0.5f, 0), mat);
    fv_light_desc sun = {FV_LIGHT_DIRECTIONAL, {0, 0, 0}, {0.3f, -1.0f, 0.2f}, fv_v3s(3.0f), 0, 0};
    assert_int_equal(fv_scene_add_light(s, &sun, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

static void test_every_method(void **st)
{
    (void)st;
    fv_scene *s = floor_and_ball();
    const fv_camera cam = {{0, 4, 4}, {0, 0, 0}, {0, 1, 0}, 50.0f, 32, 24};
    /* the floor in the sun: 0.6 / pi * 3 * cos = 0.55; the image is mostly that */
    for (int i = 0; i < fv_technique_count(); i++) {
        const char *name = fv_technique_name(i);
        /* each method's cheap test parameters (as the conformance suite runs it): the light must
         * arrive, not the image converge */
        fv_params *p = fv_test_params_str(fv_technique_class_at(i)->test_params);
        fv_technique *t = NULL;
        fv_error err;
        if (fv_technique_create(name, s, p, NULL, &t, &err) != FV_OK) fail_msg("%s: %s", name, err.msg);
        fv_film *film = NULL;
        assert_int_equal(fv_film_create(cam.width, cam.height, 0, &film, &err), FV_OK);
        fv_frame f;
        fv_frame_init(&f, &cam);
        fv_test_render_frames(t, &f, 1, film, NULL);
        const float *c = fv_film_color(film);
        double sum = 0.0;
        for (int k = 0; k < cam.width * cam.height; k++) sum += c[3 * k + 1];
        double mean = sum / (cam.width * cam.height);
        printf("%-14s mean %.4f\n", name, mean);
        if (!(mean > 0.2 && mean < 1.0)) fail_msg("%s: mean %g under a directional light alone", name, mean);
        fv_film_destroy(film);
        fv_technique_destroy(t);
        fv_params_destroy(p);
    }
    fv_scene_destroy(s);
}

static void test_api_and_files(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_light_desc bad = {FV_LIGHT_DIRECTIONAL, {0, 0, 0}, {0, 0, 0}, {1, 1, 1}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &bad, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "directional light: direction must be non-zero"));
    fv_scene_destroy(s);

    char path[512];
    snprintf(path, sizeof path, "%s/fovea_test_sun_%d.json", P_tmpdir, (int)getpid());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("{\"materials\": {\"grey\": {\"albedo\": [0.5, 0.5, 0.5]}},\n"
          " \"objects\": [{\"quad\": [[-1,0,1],[1,0,1],[1,0,-1],[-1,0,-1]], \"material\": \"grey\"}],\n"
          " \"lights\": [{\"type\": \"directional\", \"dir\": [0, -2, 0], \"intensity\": [3, 3, 3]}]}\n",
          f);
    fclose(f);
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    if (fv_scene_load(path, &log, &s, NULL, &err) != FV_OK) fail_msg("%s", err.msg);
    remove(path);
    assert_int_equal(w.count, 0); /* a light: no default lighting */
    assert_int_equal(fv_light_delta_count(s), 1);
    fv_vec3 dir;
    assert_true(fv_light_delta_directional(fv_light_delta_at(s, 0), &dir));
    assert_float_equal(dir.y, -1.0f, 1e-6f);
    double want = 0.5 / FV_PI * 3.0;
    assert_float_equal(fv_test_pt_mean(s, fv_v3(0.1f, 3, 0.2f), fv_v3(0, -1, 0), 8, 100, 5), want, 1e-4 * want);
    fv_scene_destroy(s);

    /* glTF KHR_lights_punctual: a directional light (colour (1, .5, .25) x 4 lux, taken as W/m^2)
     * on a node turned so that its -z points down, over a grey quad at y = 1 */
    fv_test_warnings w1 = {0};
    fv_log log1 = {fv_test_warn, &w1};
    if (fv_scene_load(FOVEA_TEST_DATA "/sun.gltf", &log1, &s, NULL, &err) != FV_OK) fail_msg("%s", err.msg);
    assert_int_equal(w1.count, 0);
    assert_int_equal(fv_light_delta_count(s), 1);
    assert_true(fv_light_delta_directional(fv_light_delta_at(s, 0), &dir));
    assert_float_equal(dir.y, -1.0f, 1e-5f);
    assert_float_equal(fv_light_delta_intensity(fv_light_delta_at(s, 0), dir).y, 2.0f, 1e-6f);
    want = 0.5 / FV_PI * 2.0;
    assert_float_equal(fv_test_pt_mean(s, fv_v3(0.5f, 3, 0.5f), fv_v3(0, -1, 0), 8, 100, 6), want, 1e-4 * want);
    fv_scene_destroy(s);

    const char *duck = "/usr/share/assimp/models/Collada/duck.dae";
    f = fopen(duck, "rb");
    if (!f) {
        print_message("%s: absent, skipped\n", duck);
        return;
    }
    fclose(f);
    fv_test_warnings w2 = {0};
    fv_log log2 = {fv_test_warn, &w2};
    if (fv_scene_load(duck, &log2, &s, NULL, &err) != FV_OK) fail_msg("%s", err.msg);
    assert_null(strstr(w2.all, "ignoring light"));
    assert_int_equal(fv_light_delta_count(s), 1);
    assert_true(fv_light_delta_directional(fv_light_delta_at(s, 0), NULL));
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_analytic_pt),
        cmocka_unit_test(test_emission),
        cmocka_unit_test(test_pm),
        cmocka_unit_test(test_api_and_files),
        cmocka_unit_test(test_every_method),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
