/* Film buffers and image files: size limits, sRGB transfer values worked by hand, exact PFM/EXR
 * round trips, PNG quantisation, byte order, malformed files, and that a failed write leaves
 * nothing behind. */
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
#include <OpenEXR/openexr.h>
#include "fovea/film.h"

static char g_dir[256];

static int setup(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "/tmp/fovea-test-film-XXXXXX");
    return mkdtemp(g_dir) ? 0 : -1;
}

static int teardown(void **st)
{
    (void)st;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *path_in_dir(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
    return buf;
}

static int count_files(void)
{
    DIR *d = opendir(g_dir);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (e->d_name[0] != '.') n++;
    closedir(d);
    return n;
}

static void test_sizes(void **st)
{
    (void)st;
    fv_error err;
    assert_int_equal(fv_film_check_size(1, 1, &err), FV_OK);
    assert_int_equal(fv_film_check_size(0, 10, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "0x10"));
    assert_int_equal(fv_film_check_size(-5, 10, &err), FV_ERR_INVALID);
    assert_int_equal(fv_film_check_size(16385, 1, &err), FV_ERR_INVALID);
    assert_int_equal(fv_film_check_size(100000, 100000, &err), FV_ERR_INVALID);
    assert_int_equal(fv_film_check_size(16384, 16384, &err), FV_ERR_INVALID); /* > 8192^2 pixels */
    assert_int_equal(fv_film_check_size(16384, 4096, &err), FV_OK);
    fv_film *f = NULL;
    assert_int_equal(fv_film_create(0, 5, 0, &f, &err), FV_ERR_INVALID);
    assert_null(f);
}

static void test_buffers(void **st)
{
    (void)st;
    fv_error err;
    fv_film *f;
    assert_int_equal(fv_film_create(4, 3, FV_AUX_DEPTH | FV_AUX_ID, &f, &err), FV_OK);
    assert_int_equal(fv_film_width(f), 4);
    assert_int_equal(fv_film_height(f), 3);
    assert_non_null(fv_film_depth(f));
    assert_non_null(fv_film_id(f));
    assert_null(fv_film_normal(f));
    assert_null(fv_film_albedo(f));
    assert_null(fv_film_position(f));
    assert_true(isinf(fv_film_depth(f)[11]));
    assert_int_equal(fv_film_id(f)[5], 0);
    assert_float_equal(fv_film_color(f)[35], 0.0f, 0.0f);
    fv_film_color(f)[7] = 3.0f;
    fv_film_depth(f)[2] = 1.0f;
    fv_film_clear(f);
    assert_float_equal(fv_film_color(f)[7], 0.0f, 0.0f);
    assert_true(isinf(fv_film_depth(f)[2]));
    fv_film_destroy(f);
    assert_int_equal(fv_film_create(4, 3, 0x100, &f, &err), FV_ERR_INVALID);
}

/* sRGB: encode(0.5) = 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357; decode(0.5) = (0.555/1.055)^2.4 =
 * 0.214041; the linear segment below 0.0031308 has slope 12.92. */
static void test_srgb(void **st)
{
    (void)st;
    assert_float_equal(fv_srgb_encode(0.5f), 0.735357f, 1e-5f);
    assert_float_equal(fv_srgb_decode(0.5f), 0.214041f, 1e-5f);
    assert_float_equal(fv_srgb_encode(0.002f), 0.02584f, 1e-6f);
    assert_float_equal(fv_srgb_encode(2.0f), 1.0f, 0.0f);
    assert_float_equal(fv_srgb_encode(NAN), 0.0f, 0.0f);
    assert_float_equal(fv_srgb_encode(-1.0f), 0.0f, 0.0f);
    for (int i = 0; i <= 100; i++) {
        float x = i / 100.0f;
        assert_float_equal(fv_srgb_decode(fv_srgb_encode(x)), x, 1e-5f);
    }
}

static void test_formats(void **st)
{
    (void)st;
    assert_int_equal(fv_image_format_from_path("a/b.PNG"), FV_IMG_PNG);
    assert_int_equal(fv_image_format_from_path("x.pfm"), FV_IMG_PFM);
    assert_int_equal(fv_image_format_from_path("x.Exr"), FV_IMG_EXR);
    assert_int_equal(fv_image_format_from_path("x.jpg"), FV_IMG_UNKNOWN);
    assert_int_equal(fv_image_format_from_path("dir.png/x"), FV_IMG_UNKNOWN);
    assert_int_equal(fv_image_format_from_path("noext"), FV_IMG_UNKNOWN);
}

/* A 3x2 image with values that survive float round trips exactly. */
static void fill(float *rgb, int n)
{
    for (int i = 0; i < n; i++) rgb[i] = (float)i * 0.37f - 1.5f + (i == 4 ? 1e6f : 0.0f);
}

static void test_pfm_roundtrip(void **st)
{
    (void)st;
    char p[300];
    float rgb[18];
    fill(rgb, 18);
    fv_error err;
    assert_int_equal(fv_image_write(path_in_dir(p, sizeof p, "a.pfm"), rgb, 3, 2, 1.0f, &err), FV_OK);
    fv_image img;
    assert_int_equal(fv_image_read(p, &img, &err), FV_OK);
    assert_int_equal(img.width, 3);
    assert_int_equal(img.height, 2);
    assert_memory_equal(img.rgb, rgb, sizeof rgb);
    fv_image_free(&img);
    /* PFM stores rows bottom-up: the first pixel in the file is the bottom-left one. */
    FILE *f = fopen(p, "rb");
    char hdr[32];
    assert_non_null(fgets(hdr, sizeof hdr, f));
    assert_string_equal(hdr, "PF\n");
    assert_non_null(fgets(hdr, sizeof hdr, f));
    assert_string_equal(hdr, "3 2\n");
    assert_non_null(fgets(hdr, sizeof hdr, f));
    float first;
    assert_int_equal(fread(&first, 4, 1, f), 1);
    fclose(f);
    assert_float_equal(first, rgb[9], 0.0f);
}

/* A big-endian grey PFM written byte by byte: 2x1, values 1.0 (3f800000) and -2.5 (c0200000). */
static void test_pfm_big_endian_grey(void **st)
{
    (void)st;
    char p[300];
    FILE *f = fopen(path_in_dir(p, sizeof p, "be.pfm"), "wb");
    const unsigned char data[] = {'P', 'f', '\n', '2', ' ', '1', '\n', '1', '.', '0', '\n', 0x3f, 0x80, 0, 0, 0xc0, 0x20, 0, 0};
    fwrite(data, 1, sizeof data, f);
    fclose(f);
    fv_image img;
    fv_error err;
    assert_int_equal(fv_image_read(p, &img, &err), FV_OK);
    assert_int_equal(img.width, 2);
    for (int c = 0; c < 3; c++) {
        assert_float_equal(img.rgb[c], 1.0f, 0.0f);
        assert_float_equal(img.rgb[3 + c], -2.5f, 0.0f);
    }
    fv_image_free(&img);
}

static void write_bytes(const char *path, const char *bytes, size_t n)
{
    FILE *f = fopen(path, "wb");
    fwrite(bytes, 1, n, f);
    fclose(f);
}

static void test_bad_files(void **st)
{
    (void)st;
    char p[300];
    fv_image img;
    fv_error err;
    assert_int_equal(fv_image_read(path_in_dir(p, sizeof p, "missing.pfm"), &img, &err), FV_ERR_IO);
    assert_non_null(strstr(err.msg, "missing.pfm"));
    const char trunc[] = "PF\n4 4\n-1.0\n\0\0\0\0";
    write_bytes(path_in_dir(p, sizeof p, "trunc.pfm"), trunc, sizeof trunc - 1);
    assert_int_equal(fv_image_read(p, &img, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "truncated"));
    const char huge[] = "PF\n100000 100000\n-1.0\n";
    write_bytes(path_in_dir(p, sizeof p, "huge.pfm"), huge, sizeof huge - 1);
    assert_int_equal(fv_image_read(p, &img, &err), FV_ERR_INVALID);
    const char junk[] = "hello world, not an image";
    write_bytes(path_in_dir(p, sizeof p, "junk.pfm"), junk, sizeof junk - 1);
    assert_int_equal(fv_image_read(p, &img, &err), FV_ERR_INVALID);
    write_bytes(path_in_dir(p, sizeof p, "junk.png"), junk, sizeof junk - 1);
    assert_int_equal(fv_image_read(p, &img, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "junk.png"));
    write_bytes(path_in_dir(p, sizeof p, "junk.exr"), junk, sizeof junk - 1);
    assert_int_equal(fv_image_read(p, &img, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "junk.exr"));
    assert_null(img.rgb);
    assert_int_equal(fv_image_read(path_in_dir(p, sizeof p, "x.bmp"), &img, &err), FV_ERR_IO);
}

/* PNG: 0.05 linear -> sRGB 0.24782 -> 63/255 -> decodes to 0.049704. Exposure scales before the
 * curve; values above 1 and NaN clamp. */
static void test_png(void **st)
{
    (void)st;
    char p[300];
    float rgb[12] = {0.05f, 0.025f, 0.0f, 1.0f, 7.0f, NAN, 0.5f, -3.0f, 0.0031308f, 0.214041f, 0.2f, 1e-9f};
    fv_error err;
    assert_int_equal(fv_image_write(path_in_dir(p, sizeof p, "a.png"), rgb, 2, 2, 1.0f, &err), FV_OK);
    fv_image img;
    assert_int_equal(fv_image_read(p, &img, &err), FV_OK);
    assert_float_equal(img.rgb[0], 0.049704f, 2e-5f);
    assert_float_equal(img.rgb[2], 0.0f, 0.0f);
    assert_float_equal(img.rgb[3], 1.0f, 0.0f);
    assert_float_equal(img.rgb[4], 1.0f, 0.0f);
    assert_float_equal(img.rgb[5], 0.0f, 0.0f);
    assert_float_equal(img.rgb[7], 0.0f, 0.0f);
    fv_image_free(&img);
    assert_int_equal(fv_image_write(p, rgb, 2, 2, 2.0f, &err), FV_OK);
    assert_int_equal(fv_image_read(p, &img, &err), FV_OK);
    assert_float_equal(img.rgb[1], 0.049704f, 2e-5f); /* 0.025 * 2 */
    fv_image_free(&img);
    assert_int_equal(fv_image_write(p, rgb, 2, 2, NAN, &err), FV_ERR_INVALID);
}

static void test_exr_roundtrip_and_aux(void **st)
{
    (void)st;
    char p[300];
    fv_error err;
    fv_film *f;
    const int w = 5, h = 37; /* taller than one ZIP chunk (16 lines) */
    assert_int_equal(fv_film_create(w, h, FV_AUX_ALL, &f, &err), FV_OK);
    float *c = fv_film_color(f);
    for (int i = 0; i < 3 * w * h; i++) c[i] = (float)i * 0.125f - 3.0f;
    for (int i = 0; i < w * h; i++) {
        fv_film_depth(f)[i] = (float)i;
        fv_film_id(f)[i] = (uint32_t)(7 * i);
        fv_film_normal(f)[3 * i + 2] = 1.0f;
    }
    assert_int_equal(fv_film_write(f, path_in_dir(p, sizeof p, "a.exr"), 1.0f, &err), FV_OK);
    fv_image img;
    assert_int_equal(fv_image_read(p, &img, &err), FV_OK);
    assert_int_equal(img.width, w);
    assert_int_equal(img.height, h);
    assert_memory_equal(img.rgb, c, sizeof(float) * 3 * w * h);
    fv_image_free(&img);

    /* The auxiliary buffers are channels of the same file. */
    exr_context_t ctx;
    assert_int_equal(exr_start_read(&ctx, p, NULL), EXR_ERR_SUCCESS);
    const exr_attr_chlist_t *cl;
    assert_int_equal(exr_get_channels(ctx, 0, &cl), EXR_ERR_SUCCESS);
    const char *want[] = {"B", "G", "N.X", "N.Y", "N.Z", "P.X", "P.Y", "P.Z", "R", "Z", "albedo.B", "albedo.G", "albedo.R", "id"};
    assert_int_equal(cl->num_channels, 14);
    for (int i = 0; i < 14; i++) assert_string_equal(cl->entries[i].name.str, want[i]);
    assert_int_equal(cl->entries[13].pixel_type, EXR_PIXEL_UINT);
    exr_finish(&ctx);
    fv_film_destroy(f);
}

static void test_failed_write_leaves_nothing(void **st)
{
    (void)st;
    char p[300];
    float rgb[3] = {1, 2, 3};
    fv_error err;
    int before = count_files();
    assert_int_equal(fv_image_write(path_in_dir(p, sizeof p, "nodir/x.png"), rgb, 1, 1, 1.0f, &err), FV_ERR_IO);
    assert_non_null(strstr(err.msg, "nodir/x.png"));
    /* The target is an existing directory: the rename fails and the temporary file is removed. */
    path_in_dir(p, sizeof p, "isdir.pfm");
    mkdir(p, 0755);
    before = count_files();
    assert_int_equal(fv_image_write(p, rgb, 1, 1, 1.0f, &err), FV_ERR_IO);
    assert_int_equal(fv_image_write(path_in_dir(p, sizeof p, "isdir.pfm"), rgb, 1, 1, 1.0f, &err), FV_ERR_IO);
    assert_int_equal(count_files(), before);
    assert_int_equal(fv_image_write(path_in_dir(p, sizeof p, "y.tga"), rgb, 1, 1, 1.0f, &err), FV_ERR_INVALID);
    assert_int_equal(fv_image_write(path_in_dir(p, sizeof p, "y.png"), rgb, 0, 1, 1.0f, &err), FV_ERR_INVALID);
    assert_int_equal(count_files(), before);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sizes),
        cmocka_unit_test(test_buffers),
        cmocka_unit_test(test_srgb),
        cmocka_unit_test(test_formats),
        cmocka_unit_test(test_pfm_roundtrip),
        cmocka_unit_test(test_pfm_big_endian_grey),
        cmocka_unit_test(test_bad_files),
        cmocka_unit_test(test_png),
        cmocka_unit_test(test_exr_roundtrip_and_aux),
        cmocka_unit_test(test_failed_write_leaves_nothing),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
