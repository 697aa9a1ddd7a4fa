/* Scene loading: built-in names, OBJ/MTL material mapping (docs/scene-format.md), glTF and PLY
 * through assimp, the fovea JSON format with every block, and each kind of bad input: missing
 * files, malformed JSON (with its line), unknown fields and materials, wrong types, non-finite
 * numbers, NaN vertices, empty meshes, unknown file types. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"

#define DATA(f) FOVEA_TEST_DATA "/" f

static const fv_material *mat_named(const fv_scene *s, const char *name)
{
    int id = fv_scene_find_material(s, name);
    return id >= 0 ? fv_scene_material(s, id) : NULL;
}

static void test_builtin_and_unknown(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_view *v = NULL;
    fv_error err;
    assert_int_equal(fv_scene_load("cornell", NULL, &s, &v, &err), FV_OK);
    assert_true(fv_scene_triangle_count(s) > 0);
    assert_true(fv_view_has_camera(v)); /* the built-in's camera is in the view */
    fv_view_destroy(v);
    fv_scene_destroy(s);
    s = NULL;
    v = NULL;
    assert_int_equal(fv_scene_load("cornel", NULL, &s, &v, &err), FV_ERR_INVALID);
    assert_null(s);
    assert_null(v);
    assert_non_null(strstr(err.msg, "cornel"));
    assert_int_equal(fv_scene_load("/no/such/scene.obj", NULL, &s, NULL, &err), FV_ERR_IO);
    assert_non_null(strstr(err.msg, "/no/such/scene.obj"));
    assert_int_equal(fv_scene_load(DATA("materials.mtl"), NULL, &s, NULL, &err), FV_ERR_INVALID); /* not a scene type */
    assert_null(s);
}

/* MTL mapping: Kd only -> diffuse; Ks + Ns -> glossy with alpha = sqrt(2 / (Ns + 2)) = sqrt(0.02)
 * = 0.141421; illum 3 -> mirror; illum 7 / d < 1 -> dielectric with ior Ni; Ke -> emission. */
static void test_obj_materials(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    assert_int_equal(fv_scene_load(DATA("materials.obj"), &log, &s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_triangle_count(s), 10);
    const fv_material *m = mat_named(s, "red");
    assert_non_null(m);
    assert_int_equal(m->type, FV_MAT_DIFFUSE);
    assert_float_equal(m->albedo.x, 0.8f, 1e-6f);
    m = mat_named(s, "shiny");
    assert_int_equal(m->type, FV_MAT_GLOSSY);
    assert_float_equal(m->roughness, 0.141421f, 1e-5f);
    assert_float_equal(m->specular.x, 0.5f, 1e-6f);
    assert_int_equal(mat_named(s, "mirror")->type, FV_MAT_MIRROR);
    m = mat_named(s, "glass");
    assert_int_equal(m->type, FV_MAT_DIELECTRIC);
    assert_float_equal(m->ior, 1.45f, 1e-6f);
    m = mat_named(s, "lamp");
    assert_float_equal(m->emission.x, 5.0f, 1e-6f);
    assert_float_equal(m->emission.z, 3.0f, 1e-6f);
    assert_int_equal(fv_scene_light_count(s), 2); /* the lamp quad's two triangles */
    assert_int_equal(w.count, 0);                 /* it has a light: no default light */
    fv_scene_destroy(s);
}

static void test_gltf_and_ply(void **st)
{
    (void)st;
    fv_scene *s;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    assert_int_equal(fv_scene_load(DATA("quad.gltf"), &log, &s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_triangle_count(s), 2);
    const fv_material *m = mat_named(s, "chrome");
    assert_non_null(m);
    assert_int_equal(m->type, FV_MAT_MIRROR); /* metallic 1, roughness 0 */
    assert_float_equal(m->specular.x, 0.9f, 1e-6f);
    /* The node's translation is baked in: the quad sits at y = 1. */
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    assert_float_equal(lo.y, 1.0f, 1e-5f);
    /* No lights in the file: the default sky and key light, announced. */
    assert_int_equal(fv_scene_light_count(s), 2);
    assert_int_equal(w.count, 1);
    assert_non_null(strstr(w.last, "no lights"));
    fv_scene_destroy(s);
    assert_int_equal(fv_scene_load(DATA("quad.ply"), NULL, &s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_triangle_count(s), 2);
    fv_scene_destroy(s);
}

static void test_nan_and_empty(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    assert_int_equal(fv_scene_load(DATA("nan.obj"), &log, &s, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_triangle_count(s), 1); /* the NaN and the degenerate one are dropped */
    assert_true(w.count >= 1);
    fv_scene_destroy(s);
    s = NULL;
    assert_int_equal(fv_scene_load(DATA("empty.obj"), NULL, &s, NULL, &err), FV_ERR_INVALID);
    assert_null(s);
    assert_non_null(strstr(err.msg, "empty.obj"));
}

/* Triangles dropped in several meshes of one file are said once, with the totals (issue 25,
 * item 3: a CAD model printed 40 lines, the same mesh up to four times). */
static void test_drops_said_once(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    assert_int_equal(fv_scene_load(DATA("drops.obj"), &log, &s, NULL, &err), FV_OK);
    int drops = 0;
    for (const char *p = w.all; (p = strstr(p, "dropped")); p++) drops++;
    assert_int_equal(drops, 1);
    assert_non_null(strstr(w.all, "dropped 4 of 6 triangles in 3 meshes"));
    assert_non_null(strstr(w.all, "the most in 'second' (2)"));
    assert_int_equal(fv_scene_triangle_count(s), 2); /* 'third' had no valid triangle: no object */
    fv_scene_destroy(s);
}

/* An index past the vertices: assimp drops the face itself, and its warning is passed on (issue 25,
 * item 10: the loss was silent). bad_index.gltf is quad.gltf with index 999 in its first triangle. */
static void test_importer_drop_said(void **st)
{
    (void)st;
    fv_scene *s = NULL;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    assert_int_equal(fv_scene_load(DATA("bad_index.gltf"), &log, &s, NULL, &err), FV_OK);
    assert_non_null(strstr(w.all, "the importer (assimp): Some faces had out-of-range indices"));
    assert_int_equal(fv_scene_triangle_count(s), 1);
    fv_scene_destroy(s);
}

static void test_json_scene(void **st)
{
    (void)st;
    fv_scene *s;
    fv_view *v;
    fv_error err;
    fv_status rc = fv_scene_load(DATA("scene.json"), NULL, &s, &v, &err);
    if (rc != FV_OK) fail_msg("%s", err.msg);
    /* floor 2 + light 2 + box 12 + sphere 2*16*7 = 224 + ply quad 2 = 242 triangles. */
    assert_int_equal(fv_scene_triangle_count(s), 242);
    assert_int_equal(fv_scene_object_count(s), 5);
    assert_int_equal(fv_scene_dynamic_object_count(s), 1);
    assert_int_equal(fv_scene_light_count(s), 2 + 2); /* point, spot, two emissive triangles */
    assert_true(fv_view_has_camera_path(v));
    fv_camera cam;
    fv_view_camera(v, s, 1.0, 64, 48, &cam);
    assert_float_equal(cam.pos.x, 1.0f, 1e-5f); /* halfway along the path */
    assert_int_equal(cam.width, 64);
    fv_eye_model eye;
    assert_true(fv_view_display(v, &eye));
    assert_int_equal(eye.width, 1080);
    assert_float_equal(eye.fovea_deg, 5.0f, 0.0f);
    const fv_gaze_path *g = fv_view_gaze_path(v);
    assert_non_null(g);
    fv_gaze l;
    fv_gaze_path_eval(g, 1.0, &l, NULL);
    assert_float_equal(l.x, 0.4f, 1e-6f);
    assert_int_equal(fv_scene_material(s, fv_scene_find_material(s, "gold"))->type, FV_MAT_GLOSSY);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void expect_bad(const char *path, fv_status status, const char *needle)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    fv_error err;
    fv_status rc = fv_scene_load(path, NULL, &s, &v, &err);
    fv_test_expect_fail(rc, &err, status, needle, path);
    assert_null(s);
    assert_null(v);
}

static void test_json_errors(void **st)
{
    (void)st;
    expect_bad(DATA("bad_syntax.json"), FV_ERR_INVALID, "bad_syntax.json:4:");
    expect_bad(DATA("bad_field.json"), FV_ERR_INVALID, "unknown field 'albdo'");
    expect_bad(DATA("bad_material.json"), FV_ERR_INVALID, "unknown material 'whte'");
    expect_bad(DATA("bad_inf.json"), FV_ERR_INVALID, "materials.white.emission");
    expect_bad(DATA("bad_type.json"), FV_ERR_INVALID, "materials.white.albedo");
    expect_bad(DATA("bad_mesh.json"), FV_ERR_IO, "does_not_exist.obj");
    expect_bad(DATA("bad_gaze.json"), FV_ERR_INVALID, "gaze");
}

/* Camera traces: CSV keys (with a header and a comment), interpolated; a JSON scene may name one;
 * a short line is an error with its line number. */
static void test_camera_trace(void **st)
{
    (void)st;
    fv_camera base = {{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 30.0f, 64, 48};
    fv_camera_key *k = NULL;
    int n = 0;
    fv_error err;
    assert_int_equal(fv_camera_path_load_csv(DATA("camera.csv"), &base, &k, &n, &err), FV_OK);
    assert_int_equal(n, 2);
    fv_camera_path p = {k, n};
    fv_camera c;
    fv_camera_path_eval(&p, 1.0, &base, &c);
    assert_float_equal(c.pos.x, 1.0f, 1e-6f);
    assert_float_equal(c.fov_y, 47.5f, 1e-5f);
    assert_int_equal(c.width, 64);
    fv_camera_keys_free(k);
    k = NULL;
    assert_int_equal(fv_camera_path_load_csv(DATA("camera_bad.csv"), &base, &k, &n, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "camera_bad.csv:2:"));
    assert_null(k);
    assert_int_equal(fv_camera_path_load_csv(DATA("nope.csv"), &base, &k, &n, &err), FV_ERR_IO);
    fv_scene *s;
    fv_view *v;
    assert_int_equal(fv_scene_load(DATA("scene_trace.json"), NULL, &s, &v, &err), FV_OK);
    assert_true(fv_view_has_camera_path(v));
    fv_view_camera(v, s, 2.0, 32, 32, &c);
    assert_float_equal(c.pos.x, 2.0f, 1e-6f);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_builtin_and_unknown), cmocka_unit_test(test_obj_materials), cmocka_unit_test(test_gltf_and_ply),
        cmocka_unit_test(test_nan_and_empty),       cmocka_unit_test(test_drops_said_once), cmocka_unit_test(test_importer_drop_said),
        cmocka_unit_test(test_json_scene),    cmocka_unit_test(test_json_errors),
        cmocka_unit_test(test_camera_trace),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
