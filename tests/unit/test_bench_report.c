/* The bench's report callback (fv_bench_options.report, include/fovea/bench.h): called once, after
 * every report file is written, with exactly the text of <out_dir>/<name>.json; never for a run
 * that fails. The Python package reads a run's figures through it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <cjson/cJSON.h>
#include "fovea/fovea.h"

typedef struct fixture {
    char dir[64];
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    if (!f) return -1;
    snprintf(f->dir, sizeof f->dir, "/tmp/fovea-test-bench-report-XXXXXX");
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

/* What the callbacks were told. */
typedef struct seen {
    int reports, tables;
    char *json;
} seen;

static void on_report(void *user, const char *json)
{
    seen *s = user;
    s->reports++;
    free(s->json);
    s->json = strdup(json);
}

static void on_table(void *user, const char *text)
{
    (void)text;
    ((seen *)user)->tables++;
}

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s) s[n] = '\0';
    fclose(f);
    return s;
}

/* Two methods on a 16x16 Cornell box: the cheapest run that still has rows to report. */
static const char *tiny = "{\"name\": \"tiny\", \"scene\": \"cornell\", \"size\": [16, 16], \"repeats\": 1,"
                          " \"reference\": {\"method\": \"pt\", \"params\": {\"spp\": 4}},"
                          " \"methods\": [{\"label\": \"pt-1\", \"method\": \"pt\", \"params\": {\"spp\": 1}},"
                          "               {\"label\": \"pt-2\", \"method\": \"pt\", \"params\": {\"spp\": 2}}]}";

static fv_bench_options options(const char *dir, seen *s)
{
    fv_bench_options o;
    memset(&o, 0, sizeof o);
    o.out_dir = dir;
    o.threads = 1;
    o.report = on_report;
    o.table = on_table;
    o.status_user = s;
    return o;
}

static void test_report_is_the_file(void **state)
{
    fixture *f = *state;
    seen s = {0};
    fv_bench_options o = options(f->dir, &s);
    fv_error err;
    assert_int_equal(fv_bench_run_text(tiny, "tiny.json", f->dir, &o, &err), FV_OK);
    assert_int_equal(s.reports, 1);
    assert_int_equal(s.tables, 1);
    char path[128];
    snprintf(path, sizeof path, "%s/tiny.json", f->dir);
    char *file = read_all(path);
    assert_non_null(file);
    assert_non_null(s.json);
    assert_string_equal(s.json, file);
    /* and it is the report: its scenario and one row per method, in order */
    cJSON *root = cJSON_Parse(s.json);
    assert_non_null(root);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(root, "scenario");
    assert_true(cJSON_IsString(name));
    assert_string_equal(name->valuestring, "tiny");
    const cJSON *rows = cJSON_GetObjectItemCaseSensitive(root, "results");
    assert_int_equal(cJSON_GetArraySize(rows), 2);
    const cJSON *label = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(rows, 1), "method"); /* the row's label */
    assert_true(cJSON_IsString(label));
    assert_string_equal(label->valuestring, "pt-2");
    cJSON_Delete(root);
    free(file);
    free(s.json);
}

/* A refused scenario (an unknown method) and a failed write (out_dir is a file) report nothing. */
static void test_no_report_on_failure(void **state)
{
    fixture *f = *state;
    seen s = {0};
    fv_bench_options o = options(f->dir, &s);
    fv_error err;
    const char *bad = "{\"name\": \"bad\", \"scene\": \"cornell\", \"size\": [16, 16], \"repeats\": 1,"
                      " \"reference\": {\"method\": \"pt\", \"params\": {\"spp\": 4}},"
                      " \"methods\": [{\"method\": \"no-such-method\"}]}";
    assert_int_equal(fv_bench_run_text(bad, "bad.json", f->dir, &o, &err), FV_ERR_INVALID);
    assert_int_equal(s.reports, 0);
    char file[128];
    snprintf(file, sizeof file, "%s/plain-file", f->dir);
    FILE *fp = fopen(file, "w");
    assert_non_null(fp);
    fclose(fp);
    o.out_dir = file;
    assert_int_not_equal(fv_bench_run_text(tiny, "tiny.json", f->dir, &o, &err), FV_OK);
    assert_int_equal(s.reports, 0);
    assert_int_equal(s.tables, 0);
    free(s.json);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_report_is_the_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_no_report_on_failure, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
