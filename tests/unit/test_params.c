/* Tests of the parameter bag (with the watch the conformance suite reads keys through), a
 * parameter's line of help, the registry's description accessors, the stats record and the
 * counter-based random numbers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>
#include "core/rng.h"
#include "core/params_read.h"
#include "fovea/technique.h"

static void test_params_read_and_validate(void **st)
{
    (void)st;
    fv_params *p;
    fv_error err;
    assert_int_equal(fv_params_create(&p, &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "spp=64", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "ratio=0.25", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "filter=off", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "mode=fast", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "spp=128", &err), FV_OK); /* later value wins */
    int i;
    double d;
    bool b;
    assert_int_equal(fv_params_int(p, "spp", 1, 1, 1000, &i, &err), FV_OK);
    assert_int_equal(i, 128);
    assert_int_equal(fv_params_int(p, "absent", 7, 1, 10, &i, &err), FV_OK);
    assert_int_equal(i, 7);
    assert_int_equal(fv_params_float(p, "ratio", 0.5, 0.0, 1.0, &d, &err), FV_OK);
    assert_float_equal(d, 0.25, 0.0);
    assert_int_equal(fv_params_bool(p, "filter", true, &b, &err), FV_OK);
    assert_false(b);
    const char *const modes[] = {"slow", "fast", NULL};
    assert_int_equal(fv_params_choice(p, "mode", 0, modes, &i, &err), FV_OK);
    assert_int_equal(i, 1);
    assert_int_equal(fv_params_check_used(p, "x", &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "typo=1", &err), FV_OK);
    assert_int_equal(fv_params_check_used(p, "pt", &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "'typo'"));
    assert_non_null(strstr(err.msg, "'pt'"));
    fv_params_destroy(p);
}

static void test_params_errors(void **st)
{
    (void)st;
    fv_params *p;
    fv_error err;
    fv_params_create(&p, &err);
    assert_int_equal(fv_params_parse(p, "novalue", &err), FV_ERR_INVALID);
    assert_int_equal(fv_params_parse(p, "=3", &err), FV_ERR_INVALID);
    assert_int_equal(fv_params_parse(p, "Bad Key=3", &err), FV_ERR_INVALID);
    fv_params_parse(p, "n=12x", &err);
    fv_params_parse(p, "r=nan", &err);
    fv_params_parse(p, "big=5000", &err);
    fv_params_parse(p, "b=maybe", &err);
    int i;
    double d;
    bool b;
    assert_int_equal(fv_params_int(p, "n", 0, 0, 100, &i, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "n=12x"));
    assert_int_equal(fv_params_float(p, "r", 0, 0, 1, &d, &err), FV_ERR_INVALID);
    assert_int_equal(fv_params_int(p, "big", 0, 0, 100, &i, &err), FV_ERR_INVALID);
    assert_non_null(strstr(err.msg, "out of range"));
    assert_int_equal(fv_params_bool(p, "b", false, &b, &err), FV_ERR_INVALID);
    fv_params_destroy(p);
}

typedef struct seen {
    int n;
    char keys[8][16];
    fv_params_read r[8];
} seen;

static void note_key(void *user, const fv_params_read *r)
{
    seen *s = user;
    if (s->n < 8) {
        s->r[s->n] = *r;
        snprintf(s->keys[s->n++], sizeof s->keys[0], "%s", r->key);
    }
}

/* Every reader tells the watcher the key it asks for, in the bag or not, with its default and
 * what it accepts; a clone has no watcher. */
static void test_params_watch(void **st)
{
    (void)st;
    fv_params *p, *q;
    fv_error err;
    assert_int_equal(fv_params_create(&p, &err), FV_OK);
    assert_int_equal(fv_params_parse(p, "spp=4", &err), FV_OK);
    seen s = {0};
    fv_params_watch(p, note_key, &s);
    int i;
    double d;
    bool b;
    static const char *const modes[] = {"a", "b", NULL};
    assert_int_equal(fv_params_int(p, "spp", 1, 1, 16, &i, &err), FV_OK);
    assert_int_equal(fv_params_float(p, "absent", 0.5, 0.0, 1.0, &d, &err), FV_OK);
    assert_int_equal(fv_params_bool(p, "flag", true, &b, &err), FV_OK);
    assert_int_equal(fv_params_choice(p, "mode", 1, modes, &i, &err), FV_OK);
    assert_false(fv_params_has(p, "radius"));
    assert_int_equal(s.n, 5);
    const char *want[5] = {"spp", "absent", "flag", "mode", "radius"};
    for (int k = 0; k < 5; k++) assert_string_equal(s.keys[k], want[k]);
    assert_int_equal(s.r[0].reader, FV_READ_INT);
    assert_true(s.r[0].def == 1 && s.r[0].lo == 1 && s.r[0].hi == 16);
    assert_int_equal(s.r[1].reader, FV_READ_FLOAT);
    assert_true(s.r[1].def == 0.5 && s.r[1].lo == 0.0 && s.r[1].hi == 1.0);
    assert_true(s.r[2].reader == FV_READ_BOOL && s.r[2].def == 1);
    assert_true(s.r[3].reader == FV_READ_CHOICE && s.r[3].def == 1 && s.r[3].choices == modes);
    assert_int_equal(s.r[4].reader, FV_READ_HAS);
    assert_int_equal(fv_params_clone(p, &q, &err), FV_OK);
    assert_int_equal(fv_params_int(q, "spp", 1, 1, 16, &i, &err), FV_OK);
    assert_int_equal(s.n, 5);
    fv_params_watch(p, NULL, NULL);
    assert_int_equal(fv_params_int(p, "spp", 1, 1, 16, &i, &err), FV_OK);
    assert_int_equal(s.n, 5);
    fv_params_destroy(q);
    fv_params_destroy(p);
}

/* The line `fovea methods NAME` prints for each kind of entry, written out by hand. */
static void test_param_format(void **st)
{
    (void)st;
    static const char *const orders[] = {"grid", "random", NULL}, *const spps[] = {"1", "4", "16", NULL};
    const struct {
        fv_param_info p;
        const char *line;
    } cases[] = {
        {{.key = "photons", .type = FV_PARAM_INT, .def = "300000", .min = 1, .max = 500000000, .help = "photons per frame"},
         "photons=int (300000) in [1, 500000000]: photons per frame"},
        {{.key = "alpha", .type = FV_PARAM_FLOAT, .def = "0.66666666666666663", .min = 0, .max = 1, .min_open = true, .max_open = true,
          .help = "shrinking"},
         "alpha=float (0.666667) in (0, 1): shrinking"},
        {{.key = "radius", .type = FV_PARAM_FLOAT, .def_note = "Eq. 8", .min = 0, .max = 1e9, .min_open = true, .help = "r"},
         "radius=float (Eq. 8) in (0, 1000000000]: r"},
        {{.key = "periphery_deg", .type = FV_PARAM_FLOAT, .def = "20", .def_note = "at most blur_ramp_deg", .min = 0, .max = 180, .help = "e"},
         "periphery_deg=float (20, at most blur_ramp_deg) in [0, 180]: e"},
        {{.key = "order", .type = FV_PARAM_CHOICE, .def = "grid", .choices = orders, .help = "launch order"}, "order=grid|random (grid): launch order"},
        {{.key = "spp", .type = FV_PARAM_INT, .def = "1", .min = 1, .max = 16, .choices = spps, .help = "grid"}, "spp=1|4|16 (1): grid"},
        {{.key = "blur", .type = FV_PARAM_BOOL, .def = "true", .help = "blur"}, "blur=bool (true): blur"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char buf[160];
        int n = fv_param_info_format(&cases[k].p, buf, sizeof buf);
        assert_string_equal(buf, cases[k].line);
        assert_int_equal(n, (int)strlen(cases[k].line));
        /* a short buffer: truncated, terminated, the full length returned */
        char small[8];
        assert_int_equal(fv_param_info_format(&cases[k].p, small, sizeof small), n);
        assert_int_equal(strlen(small), sizeof small - 1);
        assert_int_equal(strncmp(small, cases[k].line, sizeof small - 1), 0);
        assert_int_equal(fv_param_info_format(&cases[k].p, NULL, 0), n);
    }
    assert_string_equal(fv_param_type_name(FV_PARAM_STRING), "string");
}

/* Out of range, the description accessors answer nothing rather than read past the registry. */
static void test_registry_bounds(void **st)
{
    (void)st;
    const int n = fv_technique_count();
    const int bad[2] = {-1, n};
    for (int k = 0; k < 2; k++) {
        int i = bad[k];
        assert_null(fv_technique_family(i));
        assert_null(fv_technique_baseline(i));
        assert_int_equal(fv_technique_warmup_frames(i), 0);
        assert_int_equal(fv_technique_param_count(i), 0);
        assert_null(fv_technique_param_at(i, 0));
        assert_null(fv_technique_param_find(i, "spp"));
        assert_null(fv_technique_main_param(i));
        assert_int_equal(fv_technique_main_step_count(i), 0);
        assert_null(fv_technique_main_step(i, 0));
        assert_int_equal(fv_technique_main_default_step(i), -1);
        assert_false(fv_technique_progressive(i));
        assert_null(fv_technique_bench_scene(i));
        assert_null(fv_technique_block_unit(i));
        const char *param = "x";
        assert_null(fv_technique_unsplit(i, &param));
        assert_null(param);
    }
    const int pt = fv_technique_index("pt");
    assert_null(fv_technique_param_at(pt, fv_technique_param_count(pt)));
    assert_null(fv_technique_param_find(pt, "no_such_key"));
    assert_null(fv_technique_main_step(pt, fv_technique_main_step_count(pt)));
    assert_true(fv_technique_index(fv_technique_default_interactive()) >= 0);
    fv_error err;
    assert_null(fv_methods_json("no-such-method", &err));
    assert_non_null(strstr(err.msg, "unknown method 'no-such-method' (known: pt,"));
}

static void test_stats(void **st)
{
    (void)st;
    fv_stats s;
    fv_stats_clear(&s);
    fv_stats_add_ms(&s, "trace", 1.5);
    fv_stats_add_ms(&s, "trace", 2.0);
    fv_stats_add_count(&s, "rays", 10);
    assert_float_equal(fv_stats_get_ms(&s, "trace"), 3.5, 0.0);
    assert_float_equal(fv_stats_get_count(&s, "rays"), 10, 0.0);
    assert_float_equal(fv_stats_get_count(&s, "absent"), 0, 0.0);
}

/* The generator is a pure function of (seed, pixel, sample, frame, dimension) and its output
 * is uniform: mean 1/2, variance 1/12, and neighbouring streams uncorrelated. */
static void test_rng(void **st)
{
    (void)st;
    fv_rng a = fv_rng_make(1, 2, 3, 4), b = fv_rng_make(1, 2, 3, 4), c = fv_rng_make(1, 2, 3, 5);
    float fa = fv_rng_next(&a);
    assert_float_equal(fa, fv_rng_next(&b), 0.0);
    assert_true(fa != fv_rng_next(&c));
    double sum = 0, sum2 = 0, cross = 0;
    const int n = 1000000;
    for (int i = 0; i < n; i++) {
        fv_rng r = fv_rng_make(9, (uint64_t)i, 0, 0), q = fv_rng_make(9, (uint64_t)i + 1, 0, 0);
        double x = fv_rng_next(&r), y = fv_rng_next(&q);
        assert_true(x >= 0.0 && x < 1.0);
        sum += x;
        sum2 += x * x;
        cross += (x - 0.5) * (y - 0.5);
    }
    double mean = sum / n, var = sum2 / n - mean * mean;
    assert_float_equal(mean, 0.5, 0.002);
    assert_float_equal(var, 1.0 / 12.0, 0.001);
    assert_float_equal(cross / n, 0.0, 0.001);
}

/* The facts the MPI split and `fovea bench scaling` once decided by method name, now read from
 * each class: the values the name tests gave, for every registered method. */
static void test_registry_family_facts(void **st)
{
    (void)st;
    static const struct {
        const char *method, *scene, *block_unit, *unsplit_param;
    } k[] = {
        {"pt", "cornell", "samples", NULL},           {"pm", "cornell-fpm", NULL, "passes"},
        {"pm-t", "cornell-fpm", NULL, NULL},          {"fpm", "cornell-fpm", NULL, NULL},
        {"fpm-guided", "cornell-fpm", NULL, NULL},    {"ppm", "cornell-fpm", "passes", NULL},
        {"vpolar", "cornell", NULL, NULL},            {"cartesian", "cornell", NULL, NULL},
        {"cartesian-full", "cornell", NULL, NULL},    {"linear-falloff", "cornell", NULL, NULL},
        {"log-polar", "cornell", NULL, NULL},         {"sdf-gt", "sdf-temple", NULL, NULL},
        {"sdf-relaxed", "sdf-temple", NULL, NULL},    {"ipr", "sdf-temple", NULL, NULL},
        {"fipr", "sdf-temple", NULL, NULL},           {"ir", "cornell-fir", NULL, NULL},
        {"ir-low", "cornell-fir", NULL, NULL},        {"fir", "cornell-fir", NULL, NULL},
    };
    const int n = (int)(sizeof k / sizeof k[0]);
    assert_int_equal(fv_technique_count(), n); /* a new method is added to this table too */
    for (int j = 0; j < n; j++) {
        const int i = fv_technique_index(k[j].method);
        assert_true(i >= 0);
        assert_string_equal(fv_technique_bench_scene(i), k[j].scene);
        const char *unit = fv_technique_block_unit(i), *param = NULL, *why = fv_technique_unsplit(i, &param);
        if (k[j].block_unit) assert_string_equal(unit, k[j].block_unit);
        else assert_null(unit);
        if (k[j].unsplit_param) {
            assert_string_equal(param, k[j].unsplit_param);
            assert_non_null(why);
        } else {
            assert_null(param);
            assert_null(why);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params_read_and_validate),
        cmocka_unit_test(test_params_errors),
        cmocka_unit_test(test_params_watch),
        cmocka_unit_test(test_param_format),
        cmocka_unit_test(test_registry_bounds),
        cmocka_unit_test(test_registry_family_facts),
        cmocka_unit_test(test_stats),
        cmocka_unit_test(test_rng),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
