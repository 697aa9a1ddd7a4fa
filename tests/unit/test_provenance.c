/* Provenance: image metadata written into PNG (tEXt and iTXt chunks) and EXR (string attributes)
 * and read back exactly, without changing a pixel; typed parameters from the registry's help; the
 * build and host records. */
#include <omp.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "core/provenance_json.h"
#include "fovea/fovea.h"
#include "drive/params_json.h"

typedef struct fixture {
    char dir[64];
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    if (!f) return -1;
    snprintf(f->dir, sizeof f->dir, "/tmp/fovea-test-prov-XXXXXX");
    if (!mkdtemp(f->dir)) return -1;
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", f->dir);
    int rc = system(cmd);
    free(f);
    return rc == 0 ? 0 : -1;
}

/* A 5x3 image with values a PNG can hold (in [0,1]) and a non-grey pattern. */
static void pattern(float *rgb, int n)
{
    for (int i = 0; i < n; i++) {
        rgb[3 * i] = (float)(i % 5) / 4.0f;
        rgb[3 * i + 1] = (float)(i % 3) / 2.0f;
        rgb[3 * i + 2] = 0.25f;
    }
}

static fv_params *sample_meta(void)
{
    fv_params *m = NULL;
    assert_int_equal(fv_params_create(&m, NULL), FV_OK);
    assert_int_equal(fv_params_set(m, "method", "fpm", NULL), FV_OK);
    assert_int_equal(fv_params_set(m, "params", "{\"photons\":20000,\"filter\":false}", NULL), FV_OK);
    assert_int_equal(fv_params_set(m, "gaze", "0.3,0.6", NULL), FV_OK);
    /* Not Latin-1: goes into an iTXt chunk as UTF-8. */
    assert_int_equal(fv_params_set(m, "scene", "sc\xc3\xa8ne-\xe2\x86\x92.json", NULL), FV_OK);
    return m;
}

static const char *get(const fv_params *p, const char *key)
{
    for (int i = 0; i < fv_params_count(p); i++)
        if (strcmp(fv_params_key(p, i), key) == 0) return fv_params_value(p, i);
    return NULL;
}

/* Every entry comes back as written, and the pixels equal those of a write without metadata. */
static void round_trip(const char *dir, const char *ext)
{
    enum { W = 5, H = 3 };
    float rgb[W * H * 3];
    pattern(rgb, W * H);
    fv_params *m = sample_meta();
    char with[128], without[128];
    snprintf(with, sizeof with, "%s/with.%s", dir, ext);
    snprintf(without, sizeof without, "%s/without.%s", dir, ext);
    fv_error err;
    assert_int_equal(fv_image_write_meta(with, rgb, W, H, 1.0f, m, &err), FV_OK);
    assert_int_equal(fv_image_write(without, rgb, W, H, 1.0f, &err), FV_OK);
    fv_params *back = NULL;
    assert_int_equal(fv_image_read_meta(with, &back, &err), FV_OK);
    assert_int_equal(fv_params_count(back), fv_params_count(m));
    for (int i = 0; i < fv_params_count(m); i++) {
        const char *v = get(back, fv_params_key(m, i));
        assert_non_null(v);
        assert_string_equal(v, fv_params_value(m, i));
    }
    fv_params_destroy(back);
    /* A file written without metadata has none. */
    assert_int_equal(fv_image_read_meta(without, &back, &err), FV_OK);
    assert_int_equal(fv_params_count(back), 0);
    fv_params_destroy(back);
    fv_image a, b;
    assert_int_equal(fv_image_read(with, &a, &err), FV_OK);
    assert_int_equal(fv_image_read(without, &b, &err), FV_OK);
    assert_int_equal(a.width, W);
    assert_int_equal(a.height, H);
    assert_memory_equal(a.rgb, b.rgb, sizeof rgb);
    fv_image_free(&a);
    fv_image_free(&b);
    fv_params_destroy(m);
}

static void png_metadata_round_trip(void **state) { round_trip(((fixture *)*state)->dir, "png"); }
static void exr_metadata_round_trip(void **state) { round_trip(((fixture *)*state)->dir, "exr"); }

/* PFM has no place for metadata: written without error, read back as none. A missing file is an
 * I/O error naming it. */
static void pfm_and_missing(void **state)
{
    const char *dir = ((fixture *)*state)->dir;
    float rgb[3] = {0.5f, 0.5f, 0.5f};
    char path[128];
    snprintf(path, sizeof path, "%s/x.pfm", dir);
    fv_params *m = sample_meta(), *back = NULL;
    fv_error err;
    assert_int_equal(fv_image_write_meta(path, rgb, 1, 1, 1.0f, m, &err), FV_OK);
    assert_int_equal(fv_image_read_meta(path, &back, &err), FV_OK);
    assert_int_equal(fv_params_count(back), 0);
    fv_params_destroy(back);
    snprintf(path, sizeof path, "%s/none.png", dir);
    assert_int_equal(fv_image_read_meta(path, &back, &err), FV_ERR_IO);
    assert_null(back);
    assert_non_null(strstr(err.msg, "none.png"));
    fv_params_destroy(m);
}

/* The registry declares spp=int, filter=bool, gather=fovea|focus (text); an undeclared key is a
 * number when it reads as one. */
static void typed_parameters(void **state)
{
    (void)state;
    fv_params *p = NULL;
    assert_int_equal(fv_params_create(&p, NULL), FV_OK);
    assert_int_equal(fv_params_set(p, "spp", "16", NULL), FV_OK);
    assert_int_equal(fv_params_set(p, "device", "cpu", NULL), FV_OK);
    assert_int_equal(fv_params_set(p, "extra", "2.5", NULL), FV_OK);
    cJSON *j = fv_params_typed_json("pt", p);
    assert_non_null(j);
    const cJSON *spp = cJSON_GetObjectItemCaseSensitive(j, "spp");
    assert_true(cJSON_IsNumber(spp));
    assert_true(spp->valuedouble == 16.0);
    assert_true(cJSON_IsString(cJSON_GetObjectItemCaseSensitive(j, "device")));
    assert_true(cJSON_GetObjectItemCaseSensitive(j, "extra")->valuedouble == 2.5);
    cJSON_Delete(j);
    fv_params_destroy(p);

    assert_int_equal(fv_params_create(&p, NULL), FV_OK);
    assert_int_equal(fv_params_set(p, "filter", "off", NULL), FV_OK);
    assert_int_equal(fv_params_set(p, "photons", "20000", NULL), FV_OK);
    j = fv_params_typed_json("pm", p);
    assert_true(cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(j, "filter")));
    assert_true(cJSON_GetObjectItemCaseSensitive(j, "photons")->valuedouble == 20000.0);
    cJSON_Delete(j);
    fv_params_destroy(p);
    /* The flag image metadata records: fpm and fir spend less effort away from the gaze; pt and pm
     * do not; no method is out of range. */
    assert_true(fv_technique_foveated(fv_technique_index("fpm")));
    assert_true(fv_technique_foveated(fv_technique_index("fir")));
    assert_false(fv_technique_foveated(fv_technique_index("pt")));
    assert_false(fv_technique_foveated(fv_technique_index("pm")));
    assert_false(fv_technique_foveated(-1));
    assert_false(fv_technique_foveated(fv_technique_count()));
}

static void build_and_host(void **state)
{
    (void)state;
    fv_build_info b;
    fv_build_info_get(&b);
    assert_string_equal(b.version, FOVEA_VERSION_STRING);
    /* Either a full hash (a git checkout) or "unknown" (a tarball). */
    size_t n = strlen(b.commit);
    assert_true(strcmp(b.commit, "unknown") == 0 || (n == 40 && strspn(b.commit, "0123456789abcdef") == 40));
    assert_true(b.dirty >= -1 && b.dirty <= 1);
    assert_true(strcmp(b.commit, "unknown") != 0 || b.dirty == -1);
    fv_host_info h;
    fv_host_info_get(&h);
    assert_true(h.cores >= 1);
    assert_true(h.cpu[0] != 0);
    /* 0 means all: the count OpenMP would use (ctest sets OMP_NUM_THREADS=2), never 0. */
    assert_int_equal(fv_threads_used(0), omp_get_max_threads());
    assert_int_equal(fv_threads_used(3), 3);
    char date[32];
    fv_utc_now(date, sizeof date);
    assert_int_equal(strlen(date), 20);
    assert_int_equal(date[10], 'T');
    assert_int_equal(date[19], 'Z');
    cJSON *j = fv_provenance_json(0);
    assert_true(cJSON_GetObjectItemCaseSensitive(j, "threads")->valuedouble == (double)omp_get_max_threads());
    assert_string_equal(cJSON_GetObjectItemCaseSensitive(j, "commit")->valuestring, b.commit);
    cJSON_Delete(j);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(png_metadata_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(exr_metadata_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(pfm_and_missing, setup, teardown),
        cmocka_unit_test(typed_parameters),
        cmocka_unit_test(build_and_host),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
