/* Display output (fovea/film.h, fv_film_set_display): a device frame into a display-only film
 * converts its colour where it rendered it (film/display.h's one per-pixel function, as the
 * device kernel device/display_kernels.h) and the PNG written from it is byte-identical to the PNG
 * written from the float colour of the same frame; a CPU frame leaves the display output unfilled
 * (the PNG comes from its floats); a display-only frame refuses other formats and exposures.
 * The bytes read back per pixel on CUDA are asserted in tests/gpu/test_gpu_counts.c. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "testkit.h"

static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) fail_msg("cannot read %s", path);
    fseek(f, 0, SEEK_END);
    *n = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*n ? *n : 1);
    if (!b || fread(b, 1, *n, f) != *n) fail_msg("cannot read %s", path);
    fclose(f);
    return b;
}

/* One frame of `method params` into a plain film and into a display-only one; their PNGs. */
static void compare(const char *method, const char *scene, const char *params, bool fills)
{
    fv_scene *s = NULL;
    fv_view *v = NULL;
    if (fv_test_load(scene, &s, &v) != 0) fail_msg("cannot load %s", scene);
    fv_camera cam;
    fv_view_camera(v, s, 0.0, 24, 16, &cam);
    fv_error err;
    fv_film *plain = NULL, *disp = NULL;
    const float exposure = 1.5f;
    if (fv_film_create(24, 16, 0, &plain, &err) != FV_OK || fv_film_create(24, 16, 0, &disp, &err) != FV_OK ||
        fv_film_set_display(disp, exposure, &err) != FV_OK)
        fail_msg("%s", err.msg);
    fv_frame f;
    fv_frame_init(&f, &cam);
    f.seed = 3;
    fv_stats st;
    for (int k = 0; k < 2; k++) {
        fv_technique *t = fv_test_technique(method, params, s);
        fv_test_render_fresh(t, &f, k ? disp : plain, &st);
        fv_technique_destroy(t);
    }
    if (fv_film_display(plain)) fail_msg("%s: a plain film has display output", method);
    if ((fv_film_display(disp) != NULL) != fills) fail_msg("%s [%s]: display output %s", method, params, fills ? "not filled" : "filled");
    char a[64], b[64];
    snprintf(a, sizeof a, "display_plain_%d.png", (int)getpid());
    snprintf(b, sizeof b, "display_rgba8_%d.png", (int)getpid());
    if (fv_film_write(plain, a, exposure, &err) != FV_OK || fv_film_write(disp, b, exposure, &err) != FV_OK) fail_msg("%s", err.msg);
    size_t na, nb;
    unsigned char *pa = slurp(a, &na), *pb = slurp(b, &nb);
    if (na != nb || memcmp(pa, pb, na) != 0) fail_msg("%s [%s]: the PNG from the display output differs from the one from the floats", method, params);
    free(pa), free(pb);
    remove(a), remove(b);
    if (fills) {
        snprintf(a, sizeof a, "display_refused_%d.exr", (int)getpid());
        fv_test_expect_fail(fv_film_write(disp, a, exposure, &err), &err, FV_ERR_INVALID, "display output only", "EXR of display output");
        snprintf(a, sizeof a, "display_refused_%d.png", (int)getpid());
        fv_test_expect_fail(fv_film_write(disp, a, 2.0f, &err), &err, FV_ERR_INVALID, "display output only", "another exposure");
        if (access(a, F_OK) == 0) fail_msg("a refused write left %s", a);
    }
    printf("%s [%s]: PNG from %s byte-identical\n", method, params, fills ? "the device's RGBA8" : "the floats (not filled)");
    fv_film_destroy(plain);
    fv_film_destroy(disp);
    fv_view_destroy(v);
    fv_scene_destroy(s);
}

static void test_png_identical(void **st)
{
    (void)st;
    compare("pt", "cornell", "spp=2 device=portable", true);
    compare("fipr", "sdf-temple", "spp=1 device=portable", true);
    compare("vpolar", "cornell", "device=portable", true);
    compare("pt", "cornell", "spp=2", false);
}

static void test_refusals(void **st)
{
    (void)st;
    fv_film *f = NULL;
    fv_error err;
    if (fv_film_create(4, 4, 0, &f, &err) != FV_OK) fail_msg("%s", err.msg);
    fv_test_expect_fail(fv_film_set_display(f, -1.0f, &err), &err, FV_ERR_INVALID, "exposure", "negative exposure");
    fv_film_destroy(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_png_identical), cmocka_unit_test(test_refusals)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
