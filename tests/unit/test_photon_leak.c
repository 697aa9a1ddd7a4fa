/* Light leaks (issue 14, item 7): photons must not shine through a wall thinner than the gather
 * disc. A closed box of thin walls (an inner box of half-size 1 inside an outer one of half-size
 * 1.01: walls 0.01 thick, the gather radius of Eq. 8 at 32x32 is 1.26) is lit from one side only;
 * the other side must stay black for every method of the photon family (the registry's classes
 * with gathers_photons: pm, pm-t, fpm, ppm, and whatever joins them), as it is for pt, which
 * never sees a light through a closed surface. What keeps the photons on the lit face out of the
 * dark one is the gather's normal test (photon_map.h, fv_photon_query_facing): the two faces of a
 * wall face opposite ways.
 *   outside  a point light above the box, then a uniform environment: a camera inside sees black;
 *   inside   a point light inside: a camera outside sees black (the box's outer faces on a black
 *            background), while the camera inside sees the lit walls (the photons exist).
 * "Black" is a mean below 1e-4 of what the same method shows on the lit side: exactly 0 today,
 * with room for a filter's rounding. pt must be exactly 0. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>
#include "scene/mesh_gen.h"
#include "technique/class.h"
#include "testkit.h"

#define W 32
#define H 32

typedef enum lighting { LIGHT_ABOVE, LIGHT_ENV, LIGHT_INSIDE } lighting;

/* The thin-walled box, diffuse (albedo 0.7), with one lighting; committed. */
static fv_scene *box_scene(lighting l)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.7f);
    int mat;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_box(&mb, fv_v3(0, 0, 0), fv_v3s(1.0f), 0.0f, mat);
    fv_mesh_box(&mb, fv_v3(0, 0, 0), fv_v3s(1.01f), 0.0f, mat);
    assert_int_equal(fv_meshbuf_add(&mb, s, "shell", NULL, NULL, &err), FV_OK);
    fv_meshbuf_free(&mb);
    if (l == LIGHT_ENV) {
        fv_env_desc env = fv_env_uniform(fv_v3s(1.0f));
        assert_int_equal(fv_scene_set_env(s, &env, &err), FV_OK);
    } else {
        fv_light_desc pl = {FV_LIGHT_POINT, l == LIGHT_ABOVE ? fv_v3(0.3f, 3.0f, 0.4f) : fv_v3(0.2f, 0.3f, -0.1f), {0, -1, 0},
                            fv_v3s(l == LIGHT_ABOVE ? 20.0f : 2.0f), 0, 0};
        assert_int_equal(fv_scene_add_light(s, &pl, &err), FV_OK);
    }
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    return s;
}

/* Inside, looking at the back wall with the floor, ceiling and side walls in view; outside, a
 * three-quarter view of the box. */
static const fv_camera k_inside = {{0, 0, 0.6f}, {0, -0.1f, -1}, {0, 1, 0}, 90.0f, W, H};
static const fv_camera k_outside = {{2.5f, 2.0f, 4.0f}, {0, 0, 0}, {0, 1, 0}, 45.0f, W, H};

/* Mean radiance (over pixels and channels) of one frame of `method` with its test parameters. */
static double mean_of(const char *method, const char *params, const fv_scene *s, const fv_camera *cam)
{
    fv_film *film = fv_test_render_once(method, params, s, cam, 1);
    const float *c = fv_film_color_const(film);
    double sum = 0.0;
    for (size_t i = 0; i < (size_t)3 * W * H; i++) {
        if (!isfinite(c[i])) fail_msg("%s: pixel %zu is %g", method, i / 3, c[i]);
        sum += c[i];
    }
    fv_film_destroy(film);
    return sum / (3.0 * W * H);
}

static void test_leaks(void **st)
{
    (void)st;
    fv_scene *above = box_scene(LIGHT_ABOVE), *env = box_scene(LIGHT_ENV), *inside = box_scene(LIGHT_INSIDE);
    /* pt: the truth is black on the far side of every wall, and the lit side is lit. */
    assert_true(mean_of("pt", "spp=4", above, &k_inside) == 0.0);
    assert_true(mean_of("pt", "spp=4", env, &k_inside) == 0.0);
    assert_true(mean_of("pt", "spp=4", inside, &k_outside) == 0.0);
    assert_true(mean_of("pt", "spp=4", inside, &k_inside) > 0.01);
    int photon_methods = 0;
    for (int i = 0; i < fv_technique_count(); i++) {
        const fv_technique_class *c = fv_technique_class_at(i);
        if (!c->gathers_photons) continue;
        photon_methods++;
        const double lit_in = mean_of(c->name, c->test_params, inside, &k_inside);
        const double lit_out = mean_of(c->name, c->test_params, above, &k_outside);
        const double dark[3] = {mean_of(c->name, c->test_params, above, &k_inside), mean_of(c->name, c->test_params, env, &k_inside),
                                mean_of(c->name, c->test_params, inside, &k_outside)};
        print_message("%-10s lit inside %.4g, lit outside %.4g; dark: inside (light above) %.3g, inside (sky) %.3g, outside (light inside) %.3g\n",
                      c->name, lit_in, lit_out, dark[0], dark[1], dark[2]);
        assert_true(lit_in > 0.01 && lit_out > 0.01);
        const double floor = 1e-4 * fmin(lit_in, lit_out);
        for (int k = 0; k < 3; k++)
            if (!(dark[k] <= floor)) fail_msg("%s: light leaks through a wall 0.01 thick: mean %g on the dark side (case %d)", c->name, dark[k], k);
    }
    /* pm, pm-t, fpm, ppm at least: the family flag must not leave the loop empty. */
    assert_true(photon_methods >= 4);
    fv_scene_destroy(above);
    fv_scene_destroy(env);
    fv_scene_destroy(inside);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_leaks)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
