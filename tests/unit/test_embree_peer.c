/* Peer test: our reference path tracer against Embree's own `pathtracer` (package embree-tools)
 * on the cornell_box.obj it ships, lit by the point light and seen by the camera of the
 * cornell_box.ecs beside it. Both images go through Embree's output mapping (linear, clamped to
 * [0,1], 8 bits by truncation of 255.01 x) and their mean pixel values must agree within 3%.
 * The same max path length (8) is used on both sides, so the truncated integrals are the same.
 * 64x64 at 1024 spp: the mean of 12,288 values of 1024 samples each is the image's integral to far
 * better than the 3% (Embree's own mean moves 0.25% from 128x128), at a quarter of the time of
 * both renders (Embree's pathtracer is not instrumented: it cost the sanitized suite as much as the
 * plain one). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include "fovea/fovea.h"

#define MODELS "/usr/share/doc/embree3/models"
#define SIZE 64
#define SPP 1024

/* Reads a binary P6 PPM with maxval 255 into 8-bit values; returns the mean over all channels. */
static double ppm_mean(const char *path, int *w, int *h)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    int maxval;
    assert_int_equal(fscanf(f, "P6 %d %d %d", w, h, &maxval), 3);
    fgetc(f);
    assert_int_equal(maxval, 255);
    size_t n = (size_t)*w * (size_t)*h * 3;
    unsigned char *buf = malloc(n);
    assert_int_equal(fread(buf, 1, n, f), n);
    fclose(f);
    double sum = 0;
    for (size_t i = 0; i < n; i++) sum += buf[i];
    free(buf);
    return sum / (double)n;
}

static void test_embree_pathtracer_peer(void **st)
{
    (void)st;
    if (access("/usr/bin/pathtracer", X_OK) != 0 || access(MODELS "/cornell_box.obj", R_OK) != 0)
        fail_msg("Embree's pathtracer or its cornell_box.obj is missing: run scripts/install-deps --with-tests");
    char dir[] = "/tmp/fovea-peer-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char ppm[256], cmd[1024];
    snprintf(ppm, sizeof ppm, "%s/embree.ppm", dir);
    snprintf(cmd, sizeof cmd,
             "pathtracer -i " MODELS "/cornell_box.obj -pointlight 213 300 227 100000 100000 100000 "
             "--vp 278 273 -800 --vi 278 273 0 --vu 0 1 0 --fov 37 --size %d %d --spp %d --max-path-length 8 "
             "-o %s > %s/embree.log 2>&1",
             SIZE, SIZE, SPP, ppm, dir);
    assert_int_equal(system(cmd), 0);
    int w, h;
    double embree_mean = ppm_mean(ppm, &w, &h);
    assert_int_equal(w, SIZE);
    assert_int_equal(h, SIZE);

    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_open(MODELS "/cornell_box.obj", NULL, &s, NULL, &err), FV_OK);
    fv_light_desc l = {FV_LIGHT_POINT, {213, 300, 227}, {0, -1, 0}, {100000, 100000, 100000}, 0, 0};
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
    fv_camera cam = {{278, 273, -800}, {278, 273, 0}, {0, 1, 0}, 37.0f, SIZE, SIZE};
    fv_params *p;
    fv_params_create(&p, &err);
    fv_params_set(p, "spp", "1024", &err);
    fv_params_set(p, "max_depth", "8", &err);
    fv_technique *t;
    assert_int_equal(fv_technique_create("pt", s, p, NULL, &t, &err), FV_OK);
    fv_film *film;
    assert_int_equal(fv_film_create(SIZE, SIZE, 0, &film, &err), FV_OK);
    fv_frame fr;
    fv_frame_init(&fr, NULL);
    fr.seed = 1;
    fr.camera = &cam;
    fv_stats stats;
    fv_stats_clear(&stats);
    assert_int_equal(fv_technique_render(t, &fr, film, &stats, &err), FV_OK);
    const float *c = fv_film_color(film);
    double sum = 0;
    for (int i = 0; i < SIZE * SIZE * 3; i++) {
        float v = c[i] < 0 ? 0 : (c[i] > 1 ? 1 : c[i]);
        sum += (unsigned)(255.01f * v);
    }
    double ours = sum / (SIZE * SIZE * 3);
    printf("mean 8-bit value: embree %.3f, fovea %.3f (ratio %.4f)\n", embree_mean, ours, ours / embree_mean);
    assert_float_equal(ours, embree_mean, 0.03 * embree_mean);
    fv_film_destroy(film);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    fv_scene_destroy(s);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_embree_pathtracer_peer)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
