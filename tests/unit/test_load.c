/* Scene loading, the cases test_loaders.c leaves out: the remaining MTL rules and the glTF PBR
 * rules of docs/scene-format.md (numbers worked by hand below), a glTF node hierarchy with a
 * camera and punctual lights, JSON transforms (quaternion, scale) and animated mesh files, the
 * uncommitted fv_scene_open, the example scenes in scenes/, and more bad input: unknown fields
 * deep in objects, ranges, truncated JSON with its line, bad quads, non-increasing times, bad
 * glTF, directories and unknown file types. Every failure must leave *out NULL and give one line.
 */
#ifndef _DEFAULT_SOURCE
#define _DEFAULT_SOURCE /* mkstemps, fdopen */
#endif
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "scene/light.h"
#include "scene/scene_impl.h"
#include "testkit.h"

#define DATA(f) FOVEA_TEST_DATA "/" f
#define EMBREE_CORNELL "/usr/share/doc/embree3/models/cornell_box.obj"

static const fv_material *mat_named(const fv_scene *s, const char *name)
{
    int id = fv_scene_find_material(s, name);
    if (id < 0) fail_msg("no material '%s'", name);
    return fv_scene_material(s, id);
}

static void assert_vec3(fv_vec3 v, float x, float y, float z, float tol)
{
    if (fabsf(v.x - x) > tol || fabsf(v.y - y) > tol || fabsf(v.z - z) > tol)
        fail_msg("(%g, %g, %g) != (%g, %g, %g)", v.x, v.y, v.z, x, y, z);
}

/* Loads path, failing the test on error; its view goes to *view (NULL: dropped). */
static fv_scene *load_ok(const char *path, const fv_log *log, fv_view **view)
{
    fv_scene *s = NULL;
    fv_error err;
    if (fv_scene_load(path, log, &s, view, &err) != FV_OK) fail_msg("%s: %s", path, err.msg);
    return s;
}

/* illum 5 -> mirror tinted Ks; Ks ~ 1 with Kd ~ 0 -> mirror; d 0.3 < 0.5 with Ni 1.33 ->
 * dielectric; Ks 0.4, Ns 18 -> glossy, alpha = sqrt(2 / 20) = 0.316228, and as Kd + Ks = 1.2 > 1
 * both scale by 1/1.2: albedo 0.666667, F0 0.333333; Ks without Ns -> diffuse. No emission and no
 * light: the commit adds one point light and warns. */
static void test_mtl_rules(void **state)
{
    (void)state;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    fv_scene *s = load_ok(DATA("mtl_rules.obj"), &log, NULL);
    assert_int_equal(fv_scene_triangle_count(s), 10);
    assert_int_equal(fv_scene_object_count(s), 5);
    const fv_material *m = mat_named(s, "polished");
    assert_int_equal(m->type, FV_MAT_MIRROR);
    assert_vec3(m->specular, 0.8f, 0.7f, 0.6f, 1e-6f);
    m = mat_named(s, "chrome");
    assert_int_equal(m->type, FV_MAT_MIRROR);
    assert_vec3(m->specular, 1, 1, 1, 1e-6f);
    m = mat_named(s, "water");
    assert_int_equal(m->type, FV_MAT_DIELECTRIC);
    assert_float_equal(m->ior, 1.33f, 1e-6f);
    m = mat_named(s, "plastic");
    assert_int_equal(m->type, FV_MAT_GLOSSY);
    assert_float_equal(m->roughness, 0.316228f, 1e-5f);
    assert_vec3(m->albedo, 0.666667f, 0.666667f, 0.666667f, 1e-5f);
    assert_vec3(m->specular, 0.333333f, 0.333333f, 0.333333f, 1e-5f);
    m = mat_named(s, "flat");
    assert_int_equal(m->type, FV_MAT_DIFFUSE);
    assert_vec3(m->albedo, 0.6f, 0.5f, 0.4f, 1e-6f);
    assert_int_equal(fv_scene_light_count(s), 2); /* the default sky and key light */
    assert_int_equal(w.count, 1);
    assert_non_null(strstr(w.all, "no lights"));
    fv_scene_destroy(s);
}

/* pbr.gltf: five unit quads (x, z in [0,1], y = 0), each under a child node translated by
 * (2i, 0, 0) of a parent node scaled by 2 and translated by (0, 0, 10): world x in [4i, 4i + 2],
 * z in [10, 12]. A camera node at (0, 5, 30) with yfov 0.5 rad; a point light (colour
 * (1, .5, .25) x intensity 8) at (1, 4, 11); a spot (intensity 2, cones 0.2 and 0.4 rad) at
 * (3, 6, 11) turned from -z to -y. */
static void test_gltf_pbr(void **state)
{
    (void)state;
    fv_view *v;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    fv_scene *s = load_ok(DATA("pbr.gltf"), &log, &v);
    assert_int_equal(fv_scene_triangle_count(s), 10);
    /* The view takes the file's camera, and says so in one line (issue 25, item 3). */
    assert_non_null(strstr(w.all, "the view is the file's camera 'cam'"));
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    assert_float_equal(lo.x, 0.0f, 1e-5f);
    assert_float_equal(hi.x, 18.0f, 1e-4f);
    assert_float_equal(lo.z, 10.0f, 1e-5f);
    assert_float_equal(hi.z, 12.0f, 1e-5f);

    /* metallic 1, roughness 0.5: a metal, no diffuse part, F0 = base colour, alpha = 0.25. */
    const fv_material *m = mat_named(s, "brushed");
    assert_int_equal(m->type, FV_MAT_GLOSSY);
    assert_vec3(m->specular, 0.9f, 0.6f, 0.2f, 1e-6f);
    assert_vec3(m->albedo, 0, 0, 0, 0);
    assert_float_equal(m->roughness, 0.25f, 1e-6f);
    /* metallic 0, roughness 0.3: plastic, albedo = base colour, F0 = 0.04, alpha = 0.09. */
    m = mat_named(s, "plastic");
    assert_int_equal(m->type, FV_MAT_GLOSSY);
    assert_vec3(m->albedo, 0.2f, 0.4f, 0.6f, 1e-6f);
    assert_vec3(m->specular, 0.04f, 0.04f, 0.04f, 1e-6f);
    assert_float_equal(m->roughness, 0.09f, 1e-6f);
    m = mat_named(s, "glassy");
    assert_int_equal(m->type, FV_MAT_DIELECTRIC);
    assert_float_equal(m->ior, 1.33f, 1e-6f);
    m = mat_named(s, "glow");
    assert_vec3(m->emission, 1.0f, 0.5f, 0.25f, 1e-6f);
    m = mat_named(s, "matte");
    assert_int_equal(m->type, FV_MAT_DIFFUSE);
    assert_vec3(m->albedo, 0.5f, 0.5f, 0.5f, 1e-6f);

    /* Two delta lights and the glowing quad's two triangles. */
    assert_int_equal(fv_scene_light_count(s), 4);
    assert_int_equal(s->ndelta, 2);
    const fv_light_desc *l = &s->delta[0].desc;
    assert_int_equal(l->type, FV_LIGHT_POINT);
    assert_vec3(l->pos, 1, 4, 11, 1e-5f);
    assert_vec3(l->intensity, 8, 4, 2, 1e-5f);
    l = &s->delta[1].desc;
    assert_int_equal(l->type, FV_LIGHT_SPOT);
    assert_vec3(l->pos, 3, 6, 11, 1e-5f);
    assert_vec3(fv_normalize(l->dir), 0, -1, 0, 1e-5f);
    assert_vec3(l->intensity, 2, 2, 2, 1e-6f);
    assert_float_equal(l->inner_deg, 11.4592f, 1e-3f); /* 0.2 rad */
    assert_float_equal(l->outer_deg, 22.9183f, 1e-3f); /* 0.4 rad */

    fv_camera cam;
    fv_view_camera(v, s, 0.0, 300, 200, &cam);
    assert_vec3(cam.pos, 0, 5, 30, 1e-5f);
    assert_float_equal(cam.look.y, 5.0f, 1e-5f);
    assert_true(cam.look.z < 30.0f); /* glTF cameras look down -z */
    assert_float_equal(cam.fov_y, 28.6479f, 0.01f); /* 0.5 rad */
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* xform.json: the quad [0,1]^2 (y = 0) scaled by 2, turned 90 degrees about +y by a quaternion
 * ((x, z) -> (z, -x)), moved by (10, 0, 0): x in [10, 12], z in [-2, 0]. The OBJ's five quads
 * (x in [0, 9], z in [0, 1]) moved by (0, 0, 5), each object animated: at t = 1 they sit 3
 * higher, at t = 3 also turned 180 degrees about y (x in [-9, 0], z in [-6, -5]). The scene's
 * bounds cover every key. */
static void test_json_transforms(void **state)
{
    (void)state;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    fv_view *v;
    fv_scene *s = load_ok(DATA("xform.json"), &log, &v);
    assert_int_equal(fv_scene_triangle_count(s), 12);
    assert_int_equal(fv_scene_object_count(s), 6);
    assert_int_equal(fv_scene_dynamic_object_count(s), 5);
    fv_vec3 lo, hi;
    fv_scene_bounds(s, &lo, &hi);
    assert_vec3(lo, -9, 0, -6, 1e-4f);
    assert_vec3(hi, 12, 3, 6, 1e-4f);
    /* The mesh's own materials, named after the object. */
    assert_int_equal(mat_named(s, "rules/water")->type, FV_MAT_DIELECTRIC);
    /* Straight down onto the first OBJ quad (x in [0, 1], z in [5, 6]) and onto the tile. */
    fv_hit h;
    fv_vec3 down = fv_v3(0, -1, 0), above = fv_v3(0.5f, 10, 5.5f), tile = fv_v3(11, 10, -1);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, above, down, 100, &h));
    assert_float_equal(h.t, 10.0f, 1e-4f);
    assert_int_equal(h.mat, fv_scene_find_material(s, "rules/polished"));
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, tile, down, 100, &h));
    assert_int_equal(h.mat, fv_scene_find_material(s, "white"));
    fv_error err;
    assert_int_equal(fv_scene_set_time(s, 1.0, &err), FV_OK);
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, above, down, 100, &h));
    assert_float_equal(h.t, 7.0f, 1e-4f);
    assert_int_equal(fv_scene_set_time(s, 3.0, &err), FV_OK);
    assert_false(fv_scene_intersect(s, FV_TRACE_ALL, above, down, 100, &h));
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(-0.5f, 10, -5.5f), down, 100, &h));
    assert_float_equal(h.t, 7.0f, 1e-4f);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 64, 64, &cam);
    assert_vec3(cam.pos, 4, 6, 12, 0);
    assert_float_equal(cam.fov_y, 30.0f, 0);
    assert_int_equal(fv_scene_light_count(s), 2); /* the default sky and key light */
    assert_int_equal(w.count, 1);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

/* fv_scene_open leaves the scene open: a light added afterwards means no default light. */
static void test_open_uncommitted(void **state)
{
    (void)state;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    fv_scene *s = NULL;
    fv_error err;
    assert_int_equal(fv_scene_open(DATA("mtl_rules.obj"), &log, &s, NULL, &err), FV_OK);
    fv_light_desc d;
    memset(&d, 0, sizeof d);
    d.type = FV_LIGHT_POINT;
    d.pos = fv_v3(0, 5, 0);
    d.intensity = fv_v3s(10.0f);
    assert_int_equal(fv_scene_add_light(s, &d, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, &log, &err), FV_OK);
    assert_int_equal(fv_scene_light_count(s), 1);
    assert_int_equal(w.count, 0);
    fv_scene_destroy(s);
}

/* Every example scene in scenes/ loads and commits. */
static void test_example_scenes(void **state)
{
    (void)state;
    DIR *d = opendir(FOVEA_SOURCE_DIR "/scenes");
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 5, ".json") != 0) continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/scenes/%s", FOVEA_SOURCE_DIR, e->d_name);
        fv_scene *s = load_ok(path, NULL, NULL);
        assert_true(fv_scene_object_count(s) > 0); /* meshes, or SDF objects only (sdf-shapes.json) */
        fv_scene_destroy(s);
        n++;
    }
    closedir(d);
    assert_true(n >= 3);
}

/* Embree's own Cornell box when the package is installed: 17 faces, 34 triangles once
 * triangulated; its "light" has Ka, not Ke, so it gets the default light. */
static void test_embree_cornell(void **state)
{
    (void)state;
    if (access(EMBREE_CORNELL, R_OK) != 0) skip();
    fv_scene *s = load_ok(EMBREE_CORNELL, NULL, NULL);
    assert_int_equal(fv_scene_triangle_count(s), 34);
    assert_int_equal(mat_named(s, "red")->type, FV_MAT_DIFFUSE);
    assert_vec3(mat_named(s, "red")->albedo, 1, 0, 0, 0);
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
    /* The uncommitted entry point fails the same way, and without a view too. */
    fv_scene *o = NULL;
    assert_int_equal(fv_scene_open(path, NULL, &o, &v, &err), status);
    assert_null(o);
    assert_null(v);
    assert_int_equal(fv_scene_open(path, NULL, &o, NULL, &err), status);
    assert_null(o);
}

/* Writes text to a temporary .json file and expects loading it to fail with `needle`. */
static void expect_bad_text(const char *text, const char *needle)
{
    char path[] = "/tmp/fovea_test_load_XXXXXX.json";
    int fd = mkstemps(path, 5);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    expect_bad(path, FV_ERR_INVALID, needle);
    unlink(path);
}

/* A light's "animation" takes the objects' keys: a spot carried 2 along x and turned a quarter
 * about z (rotate_deg) in one second; lights[1] is light 1. */
static void test_json_light_animation(void **state)
{
    (void)state;
    static const char text[] =
        "{\"materials\": {\"w\": {}}, \"objects\": [{\"quad\": [[-1,0,-1],[-1,0,1],[1,0,1],[1,0,-1]], \"material\": \"w\"}],\n"
        " \"lights\": [{\"pos\": [0,3,0]},\n"
        "  {\"type\": \"spot\", \"pos\": [0,1,0], \"dir\": [0,-1,0], \"animation\": [{\"time\": 0},\n"
        "   {\"time\": 1, \"translate\": [2,0,0], \"rotate_deg\": [0,0,90]}]}]}";
    char path[] = "/tmp/fovea_test_load_XXXXXX.json";
    int fd = mkstemps(path, 5);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    fv_scene *s = load_ok(path, NULL, NULL);
    unlink(path);
    assert_true(fv_scene_lights_move(s));
    assert_int_equal(fv_light_delta_count(s), 2);
    fv_error err;
    assert_int_equal(fv_scene_set_time(s, 1.0, &err), FV_OK);
    assert_vec3(fv_light_delta_pos(fv_light_delta_at(s, 0)), 0, 3, 0, 0);
    /* (0, 1, 0) turned a quarter about z is (-1, 0, 0), then moved 2 along x; the axis -y turns to +x. */
    const fv_light *spot = fv_light_delta_at(s, 1);
    assert_vec3(fv_light_delta_pos(spot), 1, 0, 0, 1e-5f);
    assert_float_equal(fv_light_delta_intensity(spot, fv_v3(1, 0, 0)).x, 1.0f, 1e-5);
    assert_int_equal(fv_scene_set_time(s, 0.5, &err), FV_OK);
    float h = sqrtf(0.5f);
    assert_vec3(fv_light_delta_pos(spot), 1 - h, h, 0, 1e-5f);
    fv_scene_destroy(s);
}

static void test_errors(void **state)
{
    (void)state;
    expect_bad(DATA("bad_objfield.json"), FV_ERR_INVALID, "bad_objfield.json: objects[2]: unknown field 'materail'");
    expect_bad(DATA("bad_range.json"), FV_ERR_INVALID, "materials.red.albedo: expected 3 numbers in [0, 1]");
    expect_bad(DATA("bad_eof.json"), FV_ERR_INVALID, "bad_eof.json:4: malformed JSON");
    expect_bad(DATA("bad.gltf"), FV_ERR_INVALID, "bad.gltf': GLTF: Missing section \"accessors\"");
    expect_bad(FOVEA_TEST_DATA, FV_ERR_IO, "directory");
    expect_bad(DATA("no_such.json"), FV_ERR_IO, "No such file or directory");

    static const char quad[] = "\"quad\": [[0,0,0],[1,0,0],[1,0,1],[0,0,1]], \"material\": \"w\"";
    char buf[1024];
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}},\n\"objects\": [{%s}, {\"quad\": [[0,0,0],[1,0,0],[1,0],[0,0,1]], \"material\": \"w\"}]}", quad);
    expect_bad_text(buf, "objects[1].quad[2]: expected 3 finite numbers");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s, \"transform\": {\"rotate_quat\": [0,0,0,0]}}]}", quad);
    expect_bad_text(buf, "objects[0].transform.rotate_quat: not a rotation");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s, \"transform\": {\"rotate_quat\": [0,0,0,1], \"rotate_deg\": [0,0,0]}}]}",
             quad);
    expect_bad_text(buf, "objects[0].transform: give rotate_deg or rotate_quat");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s, \"animation\": [{\"time\": 1}, {\"time\": 1}]}]}", quad);
    expect_bad_text(buf, "objects[0]");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s}], \"lights\": [{\"pos\": [0,1,0], \"animation\": [{\"time\": 0}, {\"time\": 1, \"rotate_quat\": [0,0,0,0]}]}]}", quad);
    expect_bad_text(buf, "lights[0].animation[1].rotate_quat: not a rotation");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s}], \"lights\": [{\"pos\": [0,1,0], \"animation\": [{\"time\": 1}, {\"time\": 0}]}]}", quad);
    expect_bad_text(buf, "lights[0].animation: animation of light 0: key times must increase (key 1)");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s}], \"lights\": [{\"pos\": [0,1,0], \"animation\": [{\"time\": 0, \"spin\": 1}]}]}", quad);
    expect_bad_text(buf, "lights[0].animation[0]: unknown field 'spin'");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s}], \"lights\": [{\"pos\": [0,1,0], \"animation\": {\"time\": 0}}]}", quad);
    expect_bad_text(buf, "lights[0].animation: expected an array of keys");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s, \"transform\": {\"scale\": 1e999}}]}", quad);
    expect_bad_text(buf, "objects[0].transform.scale: expected a finite number");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {\"type\": \"metal\"}}, \"objects\": [{%s}]}", quad);
    expect_bad_text(buf, "materials.w.type: unknown material type 'metal'");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s}], \"lights\": [{\"type\": \"area\", \"pos\": [0,1,0]}]}", quad);
    expect_bad_text(buf, "lights[0].type: unknown light type 'area'");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s}], \"camera\": {\"pos\": [0,1,0], \"look\": [0,1,0]}}", quad);
    expect_bad_text(buf, "camera");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{\"sphere\": {\"radius\": 1}}]}");
    expect_bad_text(buf, "objects[0]: an inline shape needs a 'material'");
    snprintf(buf, sizeof buf, "{\"materials\": {\"w\": {}}, \"objects\": [{%s, \"box\": {\"half\": [1,1,1]}}]}", quad);
    expect_bad_text(buf, "objects[0]: give exactly one of mesh, quad, box, sphere");
    expect_bad_text("{\"objects\": []}", "objects: expected a non-empty array");
    expect_bad_text("[1, 2]", "top level: expected an object");
    expect_bad_text("{\"materials\": {\"w\": {}},\n\n\"objects\": [{\"quad\": [[0,0,0],[1,0,0],[1,0,1],[0,0,1]] \"material\": \"w\"}]}",
                    ":3: malformed JSON near '\"material\"");

    /* A file of a type nobody reads: FV_ERR_INVALID naming the file and the types we take. */
    char path[] = "/tmp/fovea_test_load_XXXXXX.xyzzy";
    int fd = mkstemps(path, 6);
    assert_true(fd >= 0);
    close(fd);
    expect_bad(path, FV_ERR_INVALID, ".json");
    /* Unreadable (root reads everything, so only as another user). */
    if (geteuid() != 0) {
        char obj[] = "/tmp/fovea_test_load_XXXXXX.obj";
        fd = mkstemps(obj, 4);
        assert_true(fd >= 0);
        close(fd);
        chmod(obj, 0);
        expect_bad(obj, FV_ERR_IO, "cannot open scene");
        unlink(obj);
    }
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mtl_rules),        cmocka_unit_test(test_gltf_pbr),       cmocka_unit_test(test_json_transforms),
        cmocka_unit_test(test_open_uncommitted), cmocka_unit_test(test_example_scenes), cmocka_unit_test(test_embree_cornell),
        cmocka_unit_test(test_json_light_animation), cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
