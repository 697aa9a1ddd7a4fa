/* fovea — emission textures (issue 25, item 2: glTF emissiveTexture, MTL map_Ke): the emitted
 * radiance at a point is the material's emission times its emission texture there, everywhere a
 * method meets light: a camera ray that hits the emitter, next-event estimation's light samples
 * (kernel/klight.h), photons and VPLs leaving it (scene/light.c).
 *
 * Scene: a white diffuse floor (y = 0) under a 1 x 1 emitter at y = 1 facing down, its u along
 * +x. Texture A is two texels, red then green (sRGB 255: linear 1); B the same swapped. With
 * bilinear filtering and repeat, A + B is yellow (1, 1, 0) at every point, so by linearity of
 * light transport the image under A plus the image under B equals the image under an untextured
 * emitter of emission (1, 1, 0), whatever the method's estimator (checked on the image means, to
 * within their noise), while A alone lights the floor's left (-x) half redder than its right.
 * Directly seen at u = 0.25 (texel 0's centre), A's emitter is pure red: exactly E (1, 0, 0).
 * The loaders read the texture from an MTL map_Ke and a glTF emissiveTexture (glTF's default
 * emissiveFactor of 0 emitting nothing) and a JSON scene's "emission_texture".
 */
#include "fovea/film.h"
#include "scene/light.h"
#include "transport/path.h"
#include "testkit.h"

#define W 48
#define H 36
#define E 3.0f
#define GY 0.3f /* the emitter's height */

enum { TEX_A, TEX_B, TEX_NONE };

/* The floor and the emitter; tex: which texture (TEX_NONE: emission E (1, 1, 0) untextured). */
static fv_scene *make_scene(int tex)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material floor = fv_material_default(FV_MAT_DIFFUSE);
    floor.albedo = fv_v3s(0.8f);
    fv_material glow = fv_material_default(FV_MAT_DIFFUSE);
    glow.albedo = fv_v3s(0.0f);
    if (tex == TEX_NONE) {
        glow.emission = fv_v3(E, E, 0.0f);
    } else {
        static const unsigned char rg[6] = {255, 0, 0, 0, 255, 0}, gr[6] = {0, 255, 0, 255, 0, 0};
        fv_texture_desc t = {"rg", 2, 1, 3, tex == TEX_A ? rg : gr};
        assert_int_equal(fv_scene_add_texture(s, &t, &glow.emission_texture, &err), FV_OK);
        glow.emission = fv_v3s(E);
    }
    int mf, mg;
    assert_int_equal(fv_scene_add_material(s, &floor, &mf, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &glow, &mg, &err), FV_OK);
    const fv_vec3 fp[4] = {{-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}};
    const uint32_t fi[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc fd = {"floor", fp, 4, NULL, fi, 2, NULL, mf, NULL};
    assert_int_equal(fv_scene_add_mesh(s, &fd, NULL, NULL, &err), FV_OK);
    /* facing down (-y): counter-clockwise seen from below */
    const fv_vec3 gp[4] = {{-0.5f, GY, -0.5f}, {0.5f, GY, -0.5f}, {0.5f, GY, 0.5f}, {-0.5f, GY, 0.5f}};
    const fv_vec2 guv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const uint32_t gi[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc gd = {"glow", gp, 4, NULL, gi, 2, NULL, mg, guv};
    assert_int_equal(fv_scene_add_mesh(s, &gd, NULL, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

static void test_seen_directly(void **st)
{
    (void)st;
    fv_scene *s = make_scene(TEX_A);
    fv_path_opts opt = {1, 1, 3};
    /* straight up at x = -0.25 (u = 0.25, texel 0's centre: red) and x = 0.25 (green) */
    for (int side = 0; side < 2; side++) {
        fv_vec3 sum = fv_v3s(0.0f);
        for (int k = 0; k < 16; k++) {
            fv_rng rng = fv_rng_stream(1, 1, (uint64_t)k, 0, 0);
            sum = fv_add(sum, fv_path_trace(s, &opt, fv_v3(side ? 0.25f : -0.25f, 0.1f, 0.1f), fv_v3(0, 1, 0), &rng, NULL, NULL));
        }
        sum = fv_scale(sum, 1.0f / 16);
        assert_float_equal(side ? sum.y : sum.x, E, 1e-4f);
        assert_float_equal(side ? sum.x : sum.y, 0.0f, 1e-6f);
        assert_float_equal(sum.z, 0.0f, 1e-6f);
    }
    fv_scene_destroy(s);
}

/* The light table picks a textured triangle by its mean emission over the triangle and its photons
 * carry the emission where they leave: over many photons their mean power is the emitter's power,
 * pi A E (0.5, 0.5, 0) for A (each texel covers half the quad's texture). */
static void test_photon_power(void **st)
{
    (void)st;
    fv_scene *s = make_scene(TEX_A);
    fv_vec3 sum = fv_v3s(0.0f);
    const int n = 200000;
    for (int i = 0; i < n; i++) {
        fv_rng rng = fv_rng_stream(7, 2, (uint64_t)i, 0, 0);
        float u[5];
        for (int k = 0; k < 5; k++) u[k] = fv_rng_next(&rng);
        fv_vec3 o, d, p, nrm;
        if (fv_light_sample_emission(s, u, &o, &d, &p, &nrm)) sum = fv_add(sum, p);
    }
    sum = fv_scale(sum, 1.0f / n);
    double want = FV_PI * 1.0 * E * 0.5;
    assert_float_equal(sum.x, want, 0.01 * want);
    assert_float_equal(sum.y, want, 0.01 * want);
    assert_float_equal(sum.z, 0.0, 1e-6);
    fv_scene_destroy(s);
}

/* Mean colour of the left and right halves of rows [y0, y1) of a film. */
static void halves(const fv_film *f, int y0, int y1, double left[3], double right[3])
{
    const float *c = fv_film_color_const(f);
    for (int k = 0; k < 3; k++) left[k] = right[k] = 0.0;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++) (x < W / 2 ? left : right)[k] += c[3 * (y * W + x) + k];
    double n = (double)(y1 - y0) * (W / 2);
    for (int k = 0; k < 3; k++) left[k] /= n, right[k] /= n;
}

/* Method with params on the three scenes: A + B equals the untextured yellow emitter on the floor
 * (rows below the emitter), and A's floor is redder on its left. A's two halves in *left, *right. */
static void expect_linear(const char *method, const char *params, double tol, double left[3], double right[3])
{
    fv_camera cam = {{0, 0.25f, 1.6f}, {0, 0.05f, 0}, {0, 1, 0}, 50.0f, W, H};
    double l[3][3], r[3][3];
    for (int t = 0; t < 3; t++) {
        fv_scene *s = make_scene(t);
        fv_film *f = fv_test_render_once(method, params, s, &cam, 11 + (uint64_t)t);
        halves(f, H / 2, H, l[t], r[t]); /* the floor, below the horizon of the view */
        fv_film_destroy(f);
        fv_scene_destroy(s);
    }
    for (int k = 0; k < 2; k++) {
        double sum = l[TEX_A][k] + l[TEX_B][k] + r[TEX_A][k] + r[TEX_B][k], want = l[TEX_NONE][k] + r[TEX_NONE][k];
        if (!(want > 0.01) || fabs(sum - want) > tol * want)
            fail_msg("%s: channel %d: A + B = %g, untextured %g (tolerance %g)", method, k, sum, want, tol);
    }
    /* about 3.2 with the texture read at each light sample, 2.2 for pt and 1.3 for ir when light
     * samples took the triangle's mean emission instead (measured) */
    double ratio_l = l[TEX_A][0] / l[TEX_A][1], ratio_r = r[TEX_A][0] / r[TEX_A][1];
    if (!(ratio_l > 2.8 * ratio_r)) fail_msg("%s: A's floor red/green %g on the left, %g on the right", method, ratio_l, ratio_r);
    for (int k = 0; k < 3; k++) left[k] = l[TEX_A][k], right[k] = r[TEX_A][k];
}

/* pt (a camera ray's emitter hits and next-event estimation) and pm (photons: the emitter's light
 * leaves it as photon power) light A's floor alike, half by half: pm's gather radius is small
 * next to the colour's change across the floor. */
static void test_linear_pt_pm(void **st)
{
    (void)st;
    double lt[3], rt[3], lm[3], rm[3];
    expect_linear("pt", "spp=64", 0.03, lt, rt);
    expect_linear("pm", "photons=200000 radius=0.04 filter=off", 0.04, lm, rm);
    for (int k = 0; k < 2; k++)
        if (fabs(lt[k] - lm[k]) > 0.04 * lt[k] || fabs(rt[k] - rm[k]) > 0.04 * rt[k])
            fail_msg("channel %d: pt's halves %g, %g; pm's %g, %g", k, lt[k], rt[k], lm[k], rm[k]);
}

static void test_linear_ir(void **st)
{
    (void)st;
    double l[3], r[3];
    expect_linear("ir", "vpls=256", 0.04, l, r);
}

static void test_loaders(void **st)
{
    (void)st;
    char path[512];
    fv_scene *s;
    fv_view *v;
    fv_error err;
    /* MTL map_Ke without Ke: the texture alone */
    assert_int_equal(fv_test_load(fv_test_data("emissive_tex/screen.obj", path, sizeof path), &s, &v), 0);
    int id = -1;
    for (int i = 0; i < fv_scene_material_count(s); i++)
        if (strstr(fv_scene_material(s, i)->name, "screen")) id = i;
    assert_true(id >= 0);
    assert_true(fv_scene_material(s, id)->emission_texture > 0);
    assert_float_equal(fv_scene_material(s, id)->emission.x, 1.0f, 0.0f);
    fv_scene_destroy(s);
    fv_view_destroy(v);
    /* glTF emissiveTexture with emissiveFactor 4 */
    assert_int_equal(fv_test_load(fv_test_data("emissive_tex/screen.gltf", path, sizeof path), &s, &v), 0);
    assert_true(fv_scene_material(s, 0)->emission_texture > 0);
    assert_float_equal(fv_scene_material(s, 0)->emission.y, 4.0f, 0.0f);
    fv_scene_destroy(s);
    fv_view_destroy(v);
    /* without emissiveFactor: glTF's default, 0: nothing emitted */
    assert_int_equal(fv_test_load(fv_test_data("emissive_tex/nofactor.gltf", path, sizeof path), &s, &v), 0);
    assert_float_equal(fv_max3(fv_scene_material(s, 0)->emission), 0.0f, 0.0f);
    fv_scene_destroy(s);
    fv_view_destroy(v);
    /* the API refuses a texture id that does not exist */
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.emission_texture = 3;
    fv_test_expect_fail(fv_scene_add_material(s, &m, NULL, &err), &err, FV_ERR_INVALID, "emission_texture 3 does not exist", "bad id");
    m.emission_texture = -1;
    fv_test_expect_fail(fv_scene_add_material(s, &m, NULL, &err), &err, FV_ERR_INVALID, "emission_texture -1", "negative id");
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_seen_directly), cmocka_unit_test(test_photon_power), cmocka_unit_test(test_linear_pt_pm),
        cmocka_unit_test(test_linear_ir),     cmocka_unit_test(test_loaders),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
