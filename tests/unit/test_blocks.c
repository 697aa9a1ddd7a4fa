/* core/blocks.h: the summation tree over sample blocks, and pt's renders of block ranges added
 * along it (what src/dist does over MPI ranks, here in one process, so every build checks it). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "testkit.h"
#include "core/blocks.h"
#include "film/film_sums.h"

static void test_tree_shape(void **st)
{
    (void)st;
    /* hand-worked: 13 blocks = [0,8) + ([8,12) + [12,13)) */
    assert_int_equal(fv_blocks_mid(0, 13), 8);
    assert_int_equal(fv_blocks_mid(8, 13), 12);
    assert_int_equal(fv_blocks_mid(0, 4), 2);
    assert_int_equal(fv_blocks_mid(0, 5), 4);
    assert_int_equal(fv_blocks_count(64), 1);
    assert_int_equal(fv_blocks_count(65), 2);
    assert_int_equal(fv_blocks_samples(200, 3), 8);
    int nodes[64][2];
    /* blocks 3..9 of 13: [3,4) from [2,4), all of [4,8), [8,10) from [8,12) */
    int k = fv_blocks_cover(13, 3, 10, nodes, 64);
    assert_int_equal(k, 3);
    assert_int_equal(nodes[0][0], 3), assert_int_equal(nodes[0][1], 4);
    assert_int_equal(nodes[1][0], 4), assert_int_equal(nodes[1][1], 8);
    assert_int_equal(nodes[2][0], 8), assert_int_equal(nodes[2][1], 10);
    /* a cover with a hole is refused by the plan */
    int ops[64];
    assert_true(fv_blocks_plan(13, (const int(*)[2])nodes, k, ops, 64) < 0);
}

/* The value of node [lo, hi) streamed through the accumulator. */
static double node_value(const double *v, int lo, int hi)
{
    fv_blocks_acc a = {.n = 0};
    for (int b = lo; b < hi; b++) fv_blocks_acc_push(&a, v[b], 0.0, 0.0);
    double t[3];
    fv_blocks_acc_total(&a, t);
    return t[0];
}

/* The total from `ranks` contiguous shares, each sent as the nodes covering it. */
static double split_total(const double *v, int n, int ranks)
{
    int nodes[256][2], count = 0;
    for (int r = 0; r < ranks; r++) {
        int lo = n * r / ranks, hi = n * (r + 1) / ranks;
        if (lo < hi) count += fv_blocks_cover(n, lo, hi, nodes + count, 256 - count);
    }
    double vals[256][3];
    const double *ptrs[256];
    for (int k = 0; k < count; k++) {
        vals[k][0] = node_value(v, nodes[k][0], nodes[k][1]);
        vals[k][1] = vals[k][2] = 0.0;
        ptrs[k] = vals[k];
    }
    int ops[1024];
    int nops = fv_blocks_plan(n, (const int(*)[2])nodes, count, ops, 1024);
    assert_true(nops > 0);
    double t[3];
    fv_blocks_run(ops, nops, ptrs, 0, t);
    return t[0];
}

/* 2^53, 1, 1, -2^53: the tree gives (2^53 + 1) + (1 - 2^53) = 2^53 + (1 - 2^53) = 1 (2^53 + 1 rounds
 * to 2^53, 1 - 2^53 is exact); left to right gives 0. Whatever the split, the tree's 1. */
static void test_order_fixed(void **st)
{
    (void)st;
    const double big = 9007199254740992.0;
    const double v[4] = {big, 1.0, 1.0, -big};
    assert_true(((v[0] + v[1]) + v[2]) + v[3] == 0.0);
    assert_true(node_value(v, 0, 4) == 1.0);
    for (int ranks = 1; ranks <= 4; ranks++) assert_true(split_total(v, 4, ranks) == 1.0);
    /* 13 blocks of mixed magnitudes: any number of ranks, the very same double */
    double w[13];
    for (int i = 0; i < 13; i++) w[i] = (i % 3 == 0 ? 1e12 : 1e-3) * (1.0 + 0.1 * i) * (i % 2 ? -1.0 : 1.0);
    double whole = node_value(w, 0, 13);
    for (int ranks = 1; ranks <= 13; ranks++)
        if (memcmp(&whole, &(double){split_total(w, 13, ranks)}, sizeof whole) != 0) fail_msg("%d ranks: another sum", ranks);
}

/* pt at 200 spp (four blocks, the last of 8 samples) in one render, and as the nodes [0,1), [1,2),
 * [2,4) (three ranks' shares) rendered apart and added along the tree: the same floats. And 64 spp
 * is the plain float mean. */
static void test_pt_blocks(void **st)
{
    (void)st;
    fv_scene *scene = NULL;
    fv_view *view = NULL;
    assert_int_equal(fv_test_load("cornell", &scene, &view), 0);
    fv_camera cam;
    fv_view_camera(view, scene, 0.0, 24, 16, &cam);
    fv_film *whole = fv_test_render_once("pt", "spp=200", scene, &cam, 5);
    const char *parts[3] = {"spp=200 block_first=0 block_count=1", "spp=200 block_first=1 block_count=1",
                            "spp=200 block_first=2 block_count=2"};
    double *sums[3];
    const size_t npix = 24 * 16;
    fv_film *ref = NULL;
    for (int i = 0; i < 3; i++) {
        fv_params *p = fv_test_params_str(parts[i]);
        fv_technique *t = NULL;
        fv_film *f = NULL;
        fv_error err;
        if (fv_technique_create("pt", scene, p, NULL, &t, &err) != FV_OK) fail_msg("%s", err.msg);
        if (fv_film_create(24, 16, 0, &f, &err) != FV_OK || fv_film_want_sums(f, &err) != FV_OK) fail_msg("%s", err.msg);
        fv_frame fr;
        fv_frame_init(&fr, &cam);
        fr.seed = 5;
        fv_test_render_frames(t, &fr, 1, f, NULL);
        sums[i] = malloc(npix * 3 * sizeof(double));
        memcpy(sums[i], fv_film_sums(f), npix * 3 * sizeof(double));
        fv_technique_destroy(t);
        fv_params_destroy(p);
        if (i == 0) ref = f;
        else fv_film_destroy(f);
    }
    int nodes[3][2] = {{0, 1}, {1, 2}, {2, 4}}, ops[8];
    int nops = fv_blocks_plan(4, (const int(*)[2])nodes, 3, ops, 8);
    assert_int_equal(nops, 5); /* ((n0 n1 +) n2 +) */
    const float *c = fv_film_color_const(whole);
    for (size_t i = 0; i < npix; i++) {
        double t[3];
        float px[3];
        fv_blocks_run(ops, nops, (const double *const *)sums, i, t);
        fv_blocks_pixel(t, 200, px);
        if (memcmp(px, c + 3 * i, sizeof px) != 0) fail_msg("pixel %zu: %g vs %g", i, px[0], c[3 * i]);
    }
    /* a range alone is its own mean: block 0 alone is not the whole */
    assert_memory_not_equal(fv_film_color_const(ref), c, npix * 3 * sizeof(float));
    /* one block: the float loop's mean, sum x (1/spp) in float, as pt always computed it */
    fv_film *f64 = fv_test_render_once("pt", "spp=64", scene, &cam, 5);
    fv_film *f64b = fv_test_render_once("pt", "spp=64 block_first=0 block_count=1", scene, &cam, 5);
    assert_memory_equal(fv_film_color_const(f64), fv_film_color_const(f64b), npix * 3 * sizeof(float));
    fv_film_destroy(f64);
    fv_film_destroy(f64b);
    for (int i = 0; i < 3; i++) free(sums[i]);
    fv_film_destroy(ref);
    fv_film_destroy(whole);
    fv_scene_destroy(scene);
    fv_view_destroy(view);
}

/* Ranges that are not blocks of the estimate are refused with the parameter's name. */
static void test_pt_block_params(void **st)
{
    (void)st;
    fv_scene *scene = NULL;
    fv_view *view = NULL;
    assert_int_equal(fv_test_load("cornell", &scene, &view), 0);
    const char *bad[] = {"spp=200 block_first=4", "spp=200 block_first=2 block_count=3", "spp=64 block_first=1"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        fv_params *p = fv_test_params_str(bad[i]);
        fv_technique *t = NULL;
        fv_error err;
        fv_status s = fv_technique_create("pt", scene, p, NULL, &t, &err);
        fv_test_expect_fail(s, &err, FV_ERR_INVALID, "block_", bad[i]);
        fv_technique_destroy(t);
        fv_params_destroy(p);
    }
    fv_scene_destroy(scene);
    fv_view_destroy(view);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tree_shape),
        cmocka_unit_test(test_order_fixed),
        cmocka_unit_test(test_pt_blocks),
        cmocka_unit_test(test_pt_block_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
