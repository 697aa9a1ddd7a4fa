/* Base-colour textures: sRGB -> linear when added, bilinear sampling with repeat, texture
 * coordinates interpolated at a hit (hand-worked numbers), the quadrants of a test texture where
 * they belong in the albedo buffer and in the EXR's albedo layer (glTF with an embedded PNG, OBJ
 * with map_Kd), warnings (not failures) for missing, corrupt and oversized images, the size limit,
 * and `fovea render` with no options on a closed textured box, a scanned-like blob and an open
 * box: lit, framed, textured. Data: tests/data/textured (make.py). */
#include <stdlib.h>
#include <unistd.h>
#include "testkit.h"
#include "fovea/limits.h"
#include "scene/query.h"
#include "scene/scene_impl.h"
#include "scene/texture.h"

#define DATA FOVEA_TEST_DATA "/textured/"

static void near3(fv_vec3 got, fv_vec3 want, float tol, const char *what)
{
    if (!(fabsf(got.x - want.x) <= tol && fabsf(got.y - want.y) <= tol && fabsf(got.z - want.z) <= tol))
        fail_msg("%s: got (%g, %g, %g), want (%g, %g, %g)", what, got.x, got.y, got.z, want.x, want.y, want.z);
}

/* A scene holding one texture of w x h grey texels with the given sRGB codes. */
static fv_scene *scene_with_texture(const unsigned char *codes, int w, int h, int *id)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    fv_texture_desc d = {"t", w, h, 1, codes};
    assert_int_equal(fv_scene_add_texture(s, &d, id, &err), FV_OK);
    return s;
}

static void test_srgb_and_sampling(void **st)
{
    (void)st;
    /* Codes 0 and 188 side by side: 188/255 = 0.737255 decodes to ((0.737255 + 0.055) / 1.055)^2.4
     * = 0.502886; code 10 sits on the linear segment: 10 / 255 / 12.92 = 0.0030353. */
    const unsigned char codes[3] = {0, 188, 10};
    int id;
    fv_scene *s = scene_with_texture(codes, 3, 1, &id);
    assert_int_equal(id, 1);
    assert_int_equal(fv_scene_texture_count(s), 1);
    const fv_texture *t = &s->tex[0];
    /* Texel centres at u = 1/6, 1/2, 5/6. */
    near3(fv_texture_sample(t, (fv_vec2){1.0f / 6, 0.5f}), fv_v3s(0.0f), 1e-6f, "code 0");
    near3(fv_texture_sample(t, (fv_vec2){0.5f, 0.5f}), fv_v3s(0.502886f), 2e-5f, "code 188");
    near3(fv_texture_sample(t, (fv_vec2){5.0f / 6, 0.2f}), fv_v3s(0.0030353f), 1e-6f, "code 10");
    /* Bilinear: a third of the way from the first centre to the second. */
    near3(fv_texture_sample(t, (fv_vec2){1.0f / 6 + 1.0f / 9, 0.5f}), fv_v3s(0.502886f / 3), 2e-5f, "between");
    /* Repeat: u and u + k read the same; u = 0 lies halfway between the last and the first centre. */
    near3(fv_texture_sample(t, (fv_vec2){2.5f, -3.0f}), fv_texture_sample(t, (fv_vec2){0.5f, 0.0f}), 1e-6f, "repeat");
    near3(fv_texture_sample(t, (fv_vec2){-0.5f, 0.5f}), fv_v3s(0.502886f), 2e-5f, "negative u");
    near3(fv_texture_sample(t, (fv_vec2){0.0f, 0.5f}), fv_v3s(0.5f * 0.0030353f), 1e-6f, "wrap across the edge");
    near3(fv_texture_sample(t, (fv_vec2){NAN, INFINITY}), fv_texture_sample(t, (fv_vec2){0.0f, 0.0f}), 0.0f, "non-finite");
    fv_scene_destroy(s);
}

static void test_uv_at_hit(void **st)
{
    (void)st;
    /* A 2 x 1 texture, black then white: along u it ramps linearly between the texel centres
     * u = 0.25 (0) and u = 0.75 (1). */
    const unsigned char codes[2] = {0, 255};
    int tex;
    fv_scene *s = scene_with_texture(codes, 2, 1, &tex);
    fv_error err;
    fv_material m = fv_material_default(FV_MAT_DIFFUSE), plain = m;
    m.albedo = fv_v3(0.5f, 1.0f, 1.0f);
    m.albedo_texture = tex;
    int mat, mat_plain;
    assert_int_equal(fv_scene_add_material(s, &m, &mat, &err), FV_OK);
    assert_int_equal(fv_scene_add_material(s, &plain, &mat_plain, &err), FV_OK);
    const fv_vec3 p[6] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {3, 0, 0}, {4, 0, 0}, {3, 1, 0}};
    const fv_vec2 uv[6] = {{0.3f, 0.5f}, {0.7f, 0.5f}, {0.3f, 0.9f}, {0, 0}, {1, 0}, {0, 1}};
    const uint32_t idx[6] = {0, 1, 2, 3, 4, 5};
    const int mats[2] = {mat, mat_plain};
    fv_mesh_desc d = {"tri", p, 6, NULL, idx, 2, mats, mat, uv};
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    /* The point with barycentrics (w, u, v) = (0.25, 0.25, 0.5) is (0.25, 0.5, 0); its texture
     * coordinate s = 0.25 * 0.3 + 0.25 * 0.7 + 0.5 * 0.3 = 0.4, texel position 0.4 * 2 - 0.5 = 0.3:
     * 0.3 of the way from black to white; times the factor (0.5, 1, 1). */
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(0.25f, 0.5f, 1.0f), fv_v3(0, 0, -1), INFINITY, &h));
    assert_true(fabsf(h.u - 0.25f) < 1e-5f && fabsf(h.v - 0.5f) < 1e-5f);
    fv_material buf;
    const fv_material *at = fv_hit_material(s, &h, &buf);
    assert_ptr_equal(at, &buf);
    near3(at->albedo, fv_v3(0.15f, 0.3f, 0.3f), 1e-5f, "albedo at the hit");
    /* The material as stored keeps its constant factor. */
    near3(fv_scene_material(s, mat)->albedo, m.albedo, 0.0f, "stored factor");
    /* Untextured: the scene's own material, not a copy. */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(3.25f, 0.25f, 1.0f), fv_v3(0, 0, -1), INFINITY, &h));
    assert_ptr_equal(fv_hit_material(s, &h, &buf), fv_scene_material(s, mat_plain));
    fv_scene_destroy(s);
}

static void test_refusals(void **st)
{
    (void)st;
    unsigned char px[4] = {0};
    int id = -1;
    fv_scene *s = scene_with_texture(px, 1, 1, &id);
    fv_error err;
    /* The size is checked before the texels are read: a pointer to 4 bytes is enough. */
    fv_texture_desc big = {"big.png", 4097, 4096, 3, px};
    fv_test_expect_fail(fv_scene_add_texture(s, &big, &id, &err), &err, FV_ERR_INVALID, "big.png", "4097x4096");
    fv_test_expect_msg(&err, "texels", "4097x4096");
    fv_texture_desc bad = {"c.png", 1, 1, 5, px};
    fv_test_expect_fail(fv_scene_add_texture(s, &bad, &id, &err), &err, FV_ERR_INVALID, "channels", "5 channels");
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo_texture = 2;
    fv_test_expect_fail(fv_scene_add_material(s, &m, &id, &err), &err, FV_ERR_INVALID, "albedo_texture 2", "no such texture");
    m.albedo_texture = -2;
    fv_test_expect_fail(fv_material_validate(&m, &err), &err, FV_ERR_INVALID, "albedo_texture", "negative id");
    fv_scene_destroy(s);
}

/* ---- the test texture's quadrants in the albedo buffer ---- */

static const fv_vec3 k_red = {1, 0, 0}, k_green = {0, 1, 0}, k_blue = {0, 0, 1}, k_white = {1, 1, 1};

/* Renders the box file facing its +z face (a 64 x 64 pt image, 40 degrees: the face spans 35
 * pixels around the centre) with the albedo buffer, and checks the four quadrants: red top left,
 * green top right, blue bottom left, white bottom right. Then the same through an EXR file. */
static void check_box_quadrants(const char *file)
{
    fv_scene *s;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    if (fv_scene_load(file, &log, &s, NULL, &err) != FV_OK) fail_msg("%s: %s", file, err.msg);
    if (strstr(w.all, "texture")) fail_msg("%s: %s", file, w.all);
    assert_int_equal(fv_scene_texture_count(s), 1);
    fv_camera cam = {{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40.0f, 64, 64};
    fv_film *film;
    assert_int_equal(fv_film_create(64, 64, FV_AUX_ALL, &film, &err), FV_OK);
    fv_params *p = fv_test_params_str("spp=1");
    fv_technique *t;
    assert_int_equal(fv_technique_create("pt", s, p, NULL, &t, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, &cam);
    fv_test_render_frames(t, &fr, 1, film, NULL);
    const float *alb = fv_film_albedo(film);
    const int at[4][2] = {{23, 23}, {41, 23}, {23, 41}, {41, 41}}; /* (x, y), y down: 9 pixels off the centre */
    const fv_vec3 want[4] = {k_red, k_green, k_blue, k_white};
    for (int q = 0; q < 4; q++) {
        size_t i = (size_t)at[q][1] * 64 + at[q][0];
        char what[300];
        snprintf(what, sizeof what, "%s: albedo of quadrant %d", file, q);
        near3(fv_v3(alb[3 * i], alb[3 * i + 1], alb[3 * i + 2]), want[q], 1e-3f, what);
    }
    /* Outside the box: nothing hit, no albedo. */
    near3(fv_v3(alb[0], alb[1], alb[2]), fv_v3s(0.0f), 0.0f, "background");

    char path[] = "/tmp/fovea-texture-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(fv_film_write(film, path, 1.0f, &err), FV_OK);
    fv_image img;
    if (fv_image_read_layer(path, "albedo", &img, &err) != FV_OK) fail_msg("%s", err.msg);
    assert_int_equal(img.width, 64);
    assert_int_equal(img.height, 64);
    for (size_t i = 0; i < (size_t)3 * 64 * 64; i++)
        if (fabsf(img.rgb[i] - alb[i]) > 1e-3f) fail_msg("%s: EXR albedo value %zu: %g, film %g", file, i, img.rgb[i], alb[i]);
    fv_image_free(&img);
    unlink(path);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    fv_film_destroy(film);
    fv_scene_destroy(s);
}

static void test_gltf_embedded(void **st)
{
    (void)st;
    check_box_quadrants(DATA "box.glb");
}

static void test_obj_map_kd(void **st)
{
    (void)st;
    check_box_quadrants(DATA "box.obj");
}

/* ---- unreadable textures: one warning, the constant colour, the scene loads ---- */

static void expect_warning(const char *file, const char *needle)
{
    fv_scene *s;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    if (fv_scene_open(file, &log, &s, NULL, &err) != FV_OK) fail_msg("%s: %s", file, err.msg);
    if (w.count != 1 || !strstr(w.last, needle) || !strstr(w.last, "material 'tex'") || !strstr(w.last, "constant colour"))
        fail_msg("%s: %d warnings, last '%s' (wanted one naming '%s' and material 'tex')", file, w.count, w.last, needle);
    assert_int_equal(fv_scene_texture_count(s), 0);
    const fv_material *m = fv_scene_material(s, fv_scene_find_material(s, "tex"));
    assert_non_null(m);
    assert_int_equal(m->albedo_texture, 0);
    near3(m->albedo, fv_v3s(1.0f), 0.0f, "Kd kept");
    fv_scene_destroy(s);
}

static void test_missing(void **st)
{
    (void)st;
    expect_warning(DATA "missing.obj", "no-such-texture.png");
}

static void test_corrupt(void **st)
{
    (void)st;
    expect_warning(DATA "corrupt.obj", "corrupt.png");
}

static void test_huge(void **st)
{
    (void)st;
    expect_warning(DATA "huge.obj", "8192x8192");
}

/* A JSON scene's "albedo_texture", relative to the scene file, and a missing one. */
/* A header declaring more texels than a texture may have is refused by its size, for PNG and JPEG
 * alike (issue 25, item 10: stb_image alone says "unknown image type"). The bytes after the
 * header are not an image: the size must be read before any decoding. */
static void test_huge_header(void **st)
{
    (void)st;
    const unsigned char png[33] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 1, 0x86, 0xa0, /* 100000 */
                                   0, 1, 0x86, 0xa0, 8, 2, 0, 0, 0, 0, 0, 0, 0};
    const unsigned char jpeg[] = {0xff, 0xd8, 0xff, 0xe0, 0, 4, 'J', 'F', 0xff, 0xc0, 0, 11, 8, 0xff, 0xff, 0xff, 0xff, 1, 1, 0x11, 0, 0, 0};
    fv_texels t;
    char why[256];
    assert_false(fv_texels_decode(png, sizeof png, &t, why, sizeof why));
    assert_non_null(strstr(why, "100000x100000 is more than the 16777216 texels"));
    assert_false(fv_texels_decode(jpeg, sizeof jpeg, &t, why, sizeof why));
    assert_non_null(strstr(why, "65535x65535 is more than the 16777216 texels"));
}

static void test_json(void **st)
{
    (void)st;
    char dir[] = "/tmp/fovea-texjson-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256], cmd[600];
    snprintf(cmd, sizeof cmd, "cp %s %s/", DATA "quad4.png", dir);
    assert_int_equal(system(cmd), 0);
    snprintf(path, sizeof path, "%s/scene.json", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "{\"materials\": {\"a\": {\"albedo\": [0.5, 0.5, 0.5], \"albedo_texture\": \"quad4.png\"},\n"
               "               \"b\": {\"albedo_texture\": \"gone.png\"}},\n"
               " \"objects\": [{\"mesh\": \"%s\", \"material\": \"a\"}, {\"box\": {\"center\": [3, 0, 0], \"half\": [0.5, 0.5, 0.5]}, \"material\": \"b\"},\n"
               "             {\"quad\": [[5, -1, 0], [7, -1, 0], [7, 1, 0], [5, 1, 0]], \"material\": \"a\"}]}\n",
            DATA "box.obj");
    fclose(f);
    fv_scene *s;
    fv_error err;
    fv_test_warnings w = {0};
    fv_log log = {fv_test_warn, &w};
    if (fv_scene_open(path, &log, &s, NULL, &err) != FV_OK) fail_msg("%s: %s", path, err.msg);
    if (w.count != 1 || !strstr(w.last, "gone.png") || !strstr(w.last, "materials.b")) fail_msg("warnings: %s", w.all);
    assert_int_equal(fv_scene_texture_count(s), 1);
    const fv_material *a = fv_scene_material(s, fv_scene_find_material(s, "a"));
    assert_int_equal(a->albedo_texture, 1);
    assert_int_equal(fv_scene_material(s, fv_scene_find_material(s, "b"))->albedo_texture, 0);
    /* The mesh file's UVs come with it under the JSON material: the +z face's top-left quadrant is
     * red times the factor 0.5. */
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    fv_hit h;
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(-0.25f, 0.25f, 3.0f), fv_v3(0, 0, -1), INFINITY, &h));
    fv_material buf;
    near3(fv_hit_material(s, &h, &buf)->albedo, fv_v3(0.5f, 0, 0), 1e-4f, "JSON material on the OBJ's UVs");
    /* An inline quad spans the texture from its first corner (bottom left here): (5.5, 0.5) is
     * u = 0.25, v = 0.75, the red quadrant; (6.5, -0.5) the white one. */
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(5.5f, 0.5f, 3.0f), fv_v3(0, 0, -1), INFINITY, &h));
    near3(fv_hit_material(s, &h, &buf)->albedo, fv_v3(0.5f, 0, 0), 1e-4f, "quad, top left");
    assert_true(fv_scene_intersect(s, FV_TRACE_ALL, fv_v3(6.5f, -0.5f, 3.0f), fv_v3(0, 0, -1), INFINITY, &h));
    near3(fv_hit_material(s, &h, &buf)->albedo, fv_v3s(0.5f), 1e-4f, "quad, bottom right");
    fv_scene_destroy(s);
    snprintf(cmd, sizeof cmd, "rm -r %s", dir);
    assert_int_equal(system(cmd), 0);
}

/* ---- `fovea render MODEL` with no options: lit, framed, textured ---- */

typedef struct default_look {
    double coverage;   /* share of the frame the object covers (pixels with an albedo) */
    double mean_lum;   /* mean luminance of the object's pixels */
    double quadrant[4]; /* share of the object's pixels showing red, green, blue, white */
} default_look;

static default_look render_default(const char *model)
{
    char dir[] = "/tmp/fovea-texcli-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char out[128], cmd[1024];
    snprintf(out, sizeof out, "%s/x.exr", dir);
    /* Only the size (small, for speed) and the output; nothing about light, camera or material. */
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --size 96x72 --out '%s' 2>%s/err", FOVEA_CLI, model, out, dir);
    if (system(cmd) != 0) fail_msg("%s failed", cmd);
    fv_image col, alb;
    fv_error err;
    if (fv_image_read(out, &col, &err) != FV_OK || fv_image_read_layer(out, "albedo", &alb, &err) != FV_OK) fail_msg("%s", err.msg);
    default_look r = {0};
    const fv_vec3 q[4] = {k_red, k_green, k_blue, k_white};
    int n = 0;
    for (int i = 0; i < col.width * col.height; i++) {
        fv_vec3 a = fv_v3(alb.rgb[3 * i], alb.rgb[3 * i + 1], alb.rgb[3 * i + 2]);
        if (fv_max3(a) <= 0.0f) continue;
        n++;
        r.mean_lum += 0.2126 * col.rgb[3 * i] + 0.7152 * col.rgb[3 * i + 1] + 0.0722 * col.rgb[3 * i + 2];
        for (int k = 0; k < 4; k++)
            if (fv_max3(fv_vmax(fv_sub(a, q[k]), fv_sub(q[k], a))) < 0.05f) r.quadrant[k] += 1.0;
    }
    r.coverage = (double)n / (col.width * col.height);
    if (n > 0) {
        r.mean_lum /= n;
        for (int k = 0; k < 4; k++) r.quadrant[k] /= n;
    }
    fv_image_free(&col);
    fv_image_free(&alb);
    snprintf(cmd, sizeof cmd, "rm -r %s", dir);
    assert_int_equal(system(cmd), 0);
    print_message("%s: coverage %.3f, mean luminance %.3f, quadrants %.3f %.3f %.3f %.3f\n", model, r.coverage, r.mean_lum, r.quadrant[0],
                  r.quadrant[1], r.quadrant[2], r.quadrant[3]);
    return r;
}

/* Lit: the object's mean luminance well above black (a model lit from inside, or from behind,
 * renders near 0). Framed: it covers between 10% and 90% of the frame. */
static void expect_lit_and_framed(const default_look *r, const char *what)
{
    if (!(r->mean_lum > 0.05)) fail_msg("%s: mean luminance %g: not lit", what, r->mean_lum);
    if (!(r->coverage > 0.10 && r->coverage < 0.90)) fail_msg("%s: covers %g of the frame", what, r->coverage);
}

static void test_default_render(void **st)
{
    (void)st;
    const char *textured[] = {DATA "box.glb", DATA "openbox.obj"};
    for (int m = 0; m < 2; m++) {
        default_look r = render_default(textured[m]);
        expect_lit_and_framed(&r, textured[m]);
        /* Textured: every colour of the test texture is seen on a good share of the object. */
        for (int k = 0; k < 4; k++)
            if (!(r.quadrant[k] > 0.03)) fail_msg("%s: colour %d on %g of the object", textured[m], k, r.quadrant[k]);
    }
    default_look b = render_default(DATA "blob.ply");
    expect_lit_and_framed(&b, "blob.ply");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_srgb_and_sampling), cmocka_unit_test(test_uv_at_hit), cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_gltf_embedded),     cmocka_unit_test(test_obj_map_kd), cmocka_unit_test(test_missing),
        cmocka_unit_test(test_corrupt),           cmocka_unit_test(test_huge),      cmocka_unit_test(test_huge_header),
        cmocka_unit_test(test_json),
        cmocka_unit_test(test_default_render),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
