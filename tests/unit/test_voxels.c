/* Tests of the voxel grid of Foveated Instant Radiosity (src/technique/vpl/voxels.c), worked by
 * hand on small grids:
 *  - a box mesh [0, 4]^3 at resolution 8 (cells of 0.5): exactly the 8^3 - 6^3 = 296 cells with an
 *    index 0 or 7 are occupied, face cells carry the outward axis and the material's albedo, the
 *    level-1 occupancies are 7/8, 4/8 and 0 and the top level holds 296/512;
 *  - an SDF sphere: the occupied cells are those whose centre lies within half a diagonal of the
 *    sphere, normals radial;
 *  - rays through level 0 from outside, from inside, missing, stopped by tmax, along a diagonal;
 *  - a moving box re-voxelized at two times: it moves, every other cell stays bit-identical, and
 *    the first time again restores every level bit for bit;
 *  - cones: zero occlusion through empty cells, a fully occupied slab returns its radiance with
 *    occlusion near 1, and any cone's radiance is the radiance times its occlusion there;
 *  - refusals of the resolution.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "technique/vpl/voxels.h"
#include "testkit.h"

/* ---- scenes built by hand ---- */

static fv_scene *new_scene(void)
{
    fv_scene *s;
    fv_error err;
    assert_int_equal(fv_scene_create(&s, &err), FV_OK);
    return s;
}

static int add_mat(fv_scene *s, const char *name, fv_vec3 albedo)
{
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    snprintf(m.name, sizeof m.name, "%s", name);
    m.albedo = albedo;
    int id;
    fv_error err;
    assert_int_equal(fv_scene_add_material(s, &m, &id, &err), FV_OK);
    return id;
}

/* An axis-aligned box lo..hi, two triangles per face wound so their normals point out. */
static int add_box(fv_scene *s, fv_vec3 lo, fv_vec3 hi, int mat)
{
    fv_vec3 pos[24];
    uint32_t idx[36];
    const float l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    int nv = 0, ni = 0;
    for (int a = 0; a < 3; a++)
        for (int side = 0; side < 2; side++) {
            int u = (a + 1) % 3, w = (a + 2) % 3;
            /* (0,0) (1,0) (1,1) (0,1) in (u, w) turns about +a (u x w = a): reversed for the low side. */
            const int order[2][4][2] = {{{0, 0}, {0, 1}, {1, 1}, {1, 0}}, {{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
            for (int q = 0; q < 4; q++) {
                float c[3];
                c[a] = side ? h[a] : l[a];
                c[u] = order[side][q][0] ? h[u] : l[u];
                c[w] = order[side][q][1] ? h[w] : l[w];
                pos[nv + q] = fv_v3(c[0], c[1], c[2]);
            }
            const int tri[6] = {0, 1, 2, 0, 2, 3};
            for (int q = 0; q < 6; q++) idx[ni++] = (uint32_t)(nv + tri[q]);
            nv += 4;
        }
    fv_mesh_desc d = {"box", pos, nv, NULL, idx, 12, NULL, mat, NULL};
    int id;
    fv_error err;
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, &id, &err), FV_OK);
    return id;
}

/* The square x = c, y and z in [0, 4]. */
static void add_x_plane(fv_scene *s, float c, int mat)
{
    fv_vec3 pos[4] = {fv_v3(c, 0, 0), fv_v3(c, 4, 0), fv_v3(c, 4, 4), fv_v3(c, 0, 4)};
    uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    fv_mesh_desc d = {"plane", pos, 4, NULL, idx, 2, NULL, mat, NULL};
    fv_error err;
    assert_int_equal(fv_scene_add_mesh(s, &d, NULL, NULL, &err), FV_OK);
}

static void commit(fv_scene *s)
{
    fv_light_desc l = {FV_LIGHT_POINT, fv_v3(2, 2, 2), fv_v3(0, -1, 0), fv_v3s(1), 0, 0};
    fv_error err;
    assert_int_equal(fv_scene_add_light(s, &l, &err), FV_OK);
    assert_int_equal(fv_scene_commit(s, NULL, &err), FV_OK);
}

static fv_voxels *new_voxels(const fv_scene *s, int res)
{
    fv_voxels *v = NULL;
    fv_error err;
    if (fv_voxels_create(s, res, &v, &err) != FV_OK) fail_msg("%s", err.msg);
    return v;
}

static void assert_vec(fv_vec3 got, fv_vec3 want, float tol)
{
    assert_float_equal(got.x, want.x, tol);
    assert_float_equal(got.y, want.y, tol);
    assert_float_equal(got.z, want.z, tol);
}

static const fv_vec3 box_albedo = {0.2f, 0.4f, 0.6f};

static fv_scene *box_scene(int *id)
{
    fv_scene *s = new_scene();
    *id = add_box(s, fv_v3s(0), fv_v3s(4), add_mat(s, "grey", box_albedo));
    commit(s);
    return s;
}

/* ---- the box ---- */

static void test_box(void **st)
{
    (void)st;
    int id;
    fv_scene *s = box_scene(&id);
    fv_voxels *v = new_voxels(s, 8);
    int d[3];
    fv_voxels_dims(v, 0, d);
    assert_int_equal(d[0], 8), assert_int_equal(d[1], 8), assert_int_equal(d[2], 8);
    assert_float_equal(fv_voxels_cell_size(v), 0.5f, 0);
    assert_int_equal(fv_voxels_levels(v), 4); /* 8, 4, 2, 1 */
    int occupied = 0;
    for (int k = 0; k < 8; k++)
        for (int j = 0; j < 8; j++)
            for (int i = 0; i < 8; i++) {
                fv_voxel x;
                fv_voxels_cell(v, fv_voxels_index(v, i, j, k), &x);
                const int c[3] = {i, j, k};
                int on_face = 0, axis = -1;
                for (int a = 0; a < 3; a++)
                    if (c[a] == 0 || c[a] == 7) on_face++, axis = a;
                if (!on_face) {
                    if (x.occupied) fail_msg("interior cell (%d %d %d) occupied", i, j, k);
                    continue;
                }
                if (!x.occupied) fail_msg("face cell (%d %d %d) empty", i, j, k);
                occupied++;
                assert_int_equal(x.object, id);
                assert_vec(x.albedo, box_albedo, 1e-6f);
                if (on_face == 1) { /* one face: its outward axis */
                    float want[3] = {0, 0, 0};
                    want[axis] = c[axis] == 0 ? -1.0f : 1.0f;
                    assert_vec(x.normal, fv_v3(want[0], want[1], want[2]), 1e-6f);
                }
            }
    assert_int_equal(occupied, 296);

    /* Level 1: a corner parent has 7 shell children of 8, a face parent 4, the centre none. */
    fv_voxel_mip m;
    fv_voxels_mip_cell(v, 1, 0, 0, 0, &m);
    assert_float_equal(m.occupancy, 7.0f / 8.0f, 0);
    fv_voxels_mip_cell(v, 1, 0, 1, 1, &m);
    assert_float_equal(m.occupancy, 0.5f, 0);
    assert_vec(m.albedo, fv_scale(box_albedo, 0.5f), 1e-6f);        /* premultiplied */
    assert_vec(m.normal, fv_v3(-0.5f, 0, 0), 1e-6f);
    fv_voxels_mip_cell(v, 1, 1, 1, 1, &m);
    assert_float_equal(m.occupancy, 0.0f, 0);
    fv_voxels_mip_cell(v, 3, 0, 0, 0, &m);
    assert_float_equal(m.occupancy, 296.0f / 512.0f, 1e-6);
    fv_voxels_mip_cell(v, 1, 4, 0, 0, &m); /* outside level 1 */
    assert_float_equal(m.occupancy, 0.0f, 0);
    fv_voxels_destroy(v);
    fv_scene_destroy(s);
}

/* ---- the SDF sphere ---- */

static void test_sdf_sphere(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    fv_vec3 red = fv_v3(0.7f, 0.2f, 0.1f);
    int mat = add_mat(s, "red", red);
    fv_sdf_node n;
    memset(&n, 0, sizeof n);
    n.kind = FV_SDF_SPHERE;
    n.q = (fv_quat){0, 0, 0, 1};
    n.a = n.b = -1;
    n.p[0] = 1.5f;
    n.material = mat;
    int id;
    fv_error err;
    assert_int_equal(fv_scene_add_sdf(s, "ball", &n, 1, 0, NULL, &id, &err), FV_OK);
    commit(s);
    fv_voxels *v = new_voxels(s, 16);
    int d[3];
    fv_voxels_dims(v, 0, d);
    float h = fv_voxels_cell_size(v), half_diag = 0.5f * h * sqrtf(3.0f);
    fv_vec3 org = fv_voxels_origin(v);
    int occupied = 0;
    for (int k = 0; k < d[2]; k++)
        for (int j = 0; j < d[1]; j++)
            for (int i = 0; i < d[0]; i++) {
                fv_voxel x;
                fv_voxels_cell(v, fv_voxels_index(v, i, j, k), &x);
                fv_vec3 c = fv_add(org, fv_v3((i + 0.5f) * h, (j + 0.5f) * h, (k + 0.5f) * h));
                float off = fabsf(fv_length(c) - 1.5f);
                if (!x.occupied) {
                    if (off < half_diag - 1e-4f) fail_msg("cell (%d %d %d) %g from the surface is empty", i, j, k, off);
                    continue;
                }
                occupied++;
                if (off > half_diag + 1e-4f) fail_msg("cell (%d %d %d) %g from the surface is occupied", i, j, k, off);
                float cosr = fv_dot(x.normal, fv_normalize(c));
                if (!(cosr > 0.9f)) fail_msg("cell (%d %d %d): normal . radial = %g", i, j, k, cosr);
                assert_vec(x.albedo, red, 1e-6f);
                assert_int_equal(x.object, id);
            }
    assert_true(occupied > 100);
    fv_voxel_hit hit;
    /* From the centre: the shell, not the inside. */
    assert_true(fv_voxels_cast(v, fv_v3s(0), fv_v3(1, 0, 0), INFINITY, &hit));
    assert_true(hit.t > 1.5f - half_diag - h && hit.t < 1.5f);
    fv_voxels_destroy(v);
    fv_scene_destroy(s);
}

/* ---- rays ---- */

static void expect_hit(const fv_voxels *v, fv_vec3 o, fv_vec3 d, float tmax, int i, int j, int k, float t, fv_vec3 normal)
{
    fv_voxel_hit hit;
    if (!fv_voxels_cast(v, o, d, tmax, &hit)) fail_msg("ray from (%g %g %g) missed", o.x, o.y, o.z);
    if (hit.ijk[0] != i || hit.ijk[1] != j || hit.ijk[2] != k)
        fail_msg("ray from (%g %g %g): cell (%d %d %d), expected (%d %d %d)", o.x, o.y, o.z, hit.ijk[0], hit.ijk[1], hit.ijk[2], i, j, k);
    assert_int_equal(hit.cell, fv_voxels_index(v, i, j, k));
    assert_float_equal(hit.t, t, 1e-5);
    assert_vec(hit.v.normal, normal, 1e-6f);
    assert_vec(hit.v.albedo, box_albedo, 1e-6f);
    assert_true(hit.v.occupied);
}

static void test_cast(void **st)
{
    (void)st;
    int id;
    fv_scene *s = box_scene(&id);
    fv_voxels *v = new_voxels(s, 8);
    /* From outside along +x: the -x face's cell (0, 2, 2), entered at x = 0. */
    expect_hit(v, fv_v3(-1, 1.25f, 1.25f), fv_v3(1, 0, 0), INFINITY, 0, 2, 2, 1.0f, fv_v3(-1, 0, 0));
    /* From above along -z, with a unit and a double-length direction (t in units of dir). */
    expect_hit(v, fv_v3(1.25f, 1.25f, 10), fv_v3(0, 0, -1), INFINITY, 2, 2, 7, 6.0f, fv_v3(0, 0, 1));
    expect_hit(v, fv_v3(1.25f, 1.25f, 10), fv_v3(0, 0, -2), INFINITY, 2, 2, 7, 3.0f, fv_v3(0, 0, 1));
    /* From inside the box: the far face, entered at x = 3.5 and y = 0.5. */
    expect_hit(v, fv_v3(2.1f, 2.2f, 2.3f), fv_v3(1, 0, 0), INFINITY, 7, 4, 4, 1.4f, fv_v3(1, 0, 0));
    expect_hit(v, fv_v3(2.1f, 2.2f, 2.3f), fv_v3(0, -1, 0), INFINITY, 4, 0, 4, 1.7f, fv_v3(0, -1, 0));
    /* Along the diagonal into the corner cell, entered at the grid's corner. */
    fv_voxel_hit hit;
    assert_true(fv_voxels_cast(v, fv_v3s(-1), fv_v3s(1), INFINITY, &hit));
    assert_int_equal(hit.cell, fv_voxels_index(v, 0, 0, 0));
    assert_float_equal(hit.t, 1.0f, 1e-5);
    /* Misses: beside the grid, away from it, short of the face. */
    assert_false(fv_voxels_cast(v, fv_v3(-1, 5, 1), fv_v3(1, 0, 0), INFINITY, &hit));
    assert_false(fv_voxels_cast(v, fv_v3(-1, 1, 1), fv_v3(-1, 0, 0), INFINITY, &hit));
    assert_false(fv_voxels_cast(v, fv_v3(-1, 1.25f, 1.25f), fv_v3(1, 0, 0), 0.9f, &hit));
    assert_false(fv_voxels_cast(v, fv_v3(2.1f, 2.2f, 2.3f), fv_v3(1, 0, 0), 1.3f, &hit));
    fv_voxels_destroy(v);
    fv_scene_destroy(s);
}

/* ---- a dynamic object ---- */

typedef struct snapshot {
    fv_voxel *cells;
    fv_voxel_mip *mips; /* every level, in order */
    int ncells, nmips;
} snapshot;

static snapshot take(const fv_voxels *v)
{
    snapshot sn = {0};
    int d[3];
    fv_voxels_dims(v, 0, d);
    sn.ncells = d[0] * d[1] * d[2];
    sn.cells = calloc((size_t)sn.ncells, sizeof *sn.cells);
    for (int c = 0; c < sn.ncells; c++) fv_voxels_cell(v, c, &sn.cells[c]);
    for (int l = 0; l < fv_voxels_levels(v); l++) {
        fv_voxels_dims(v, l, d);
        sn.nmips += d[0] * d[1] * d[2];
    }
    sn.mips = calloc((size_t)sn.nmips, sizeof *sn.mips);
    int q = 0;
    for (int l = 0; l < fv_voxels_levels(v); l++) {
        fv_voxels_dims(v, l, d);
        for (int k = 0; k < d[2]; k++)
            for (int j = 0; j < d[1]; j++)
                for (int i = 0; i < d[0]; i++) fv_voxels_mip_cell(v, l, i, j, k, &sn.mips[q++]);
    }
    return sn;
}

static void release(snapshot *sn)
{
    free(sn->cells);
    free(sn->mips);
}

/* A static box [0, 2]^3 and a small box [0.2, 0.8]^2 x [6.2, 6.8] sliding 7.2 along x from t = 0
 * to t = 1: the bounds are x [0, 8], y [0, 2], z [0, 6.8], so resolution 16 gives cells of 0.5
 * and 16 x 4 x 14 cells. The small box fills cells x 0..1, y 0..1, z 12..13 at t = 0 and x 14..15
 * at t = 1: 8 cells, away from the static box. */
static void test_dynamic(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    int stat = add_box(s, fv_v3s(0), fv_v3s(2), add_mat(s, "grey", box_albedo));
    fv_vec3 blue = fv_v3(0.1f, 0.2f, 0.9f);
    int dyn = add_box(s, fv_v3(0.2f, 0.2f, 6.2f), fv_v3(0.8f, 0.8f, 6.8f), add_mat(s, "blue", blue));
    fv_anim_key keys[2] = {{0.0, fv_v3s(0), {0, 0, 0, 1}, fv_v3s(1)}, {1.0, fv_v3(7.2f, 0, 0), {0, 0, 0, 1}, fv_v3s(1)}};
    fv_error err;
    assert_int_equal(fv_scene_animate_object(s, dyn, keys, 2, &err), FV_OK);
    commit(s);
    assert_int_equal(fv_scene_set_time(s, 0.0, &err), FV_OK);
    fv_voxels *v = new_voxels(s, 16);
    int d[3];
    fv_voxels_dims(v, 0, d);
    assert_int_equal(d[0], 16), assert_int_equal(d[1], 4), assert_int_equal(d[2], 14);

    snapshot s0 = take(v);
    assert_int_equal(fv_voxels_dynamic_cells(v), 8);
    assert_int_equal(fv_scene_set_time(s, 1.0, &err), FV_OK);
    fv_voxels_update_dynamic(v);
    assert_int_equal(fv_voxels_dynamic_cells(v), 8);
    snapshot s1 = take(v);

    int moved0 = 0, moved1 = 0, still = 0;
    for (int c = 0; c < s0.ncells; c++) {
        int i = c % d[0], j = c / d[0] % d[1], k = c / (d[0] * d[1]);
        bool in0 = i <= 1 && j <= 1 && k >= 12, in1 = i >= 14 && j <= 1 && k >= 12;
        const fv_voxel *a = &s0.cells[c], *b = &s1.cells[c];
        if (in0) {
            assert_true(a->occupied && a->object == dyn && !b->occupied);
            assert_vec(a->albedo, blue, 1e-6f);
            moved0++;
        } else if (in1) {
            assert_true(b->occupied && b->object == dyn && !a->occupied);
            moved1++;
        } else {
            if (memcmp(a, b, sizeof *a) != 0) fail_msg("cell (%d %d %d) changed", i, j, k);
            if (a->occupied) assert_int_equal(a->object, stat), still++;
        }
    }
    assert_int_equal(moved0, 8);
    assert_int_equal(moved1, 8);
    /* The static box: its faces at x, z = 2 touch cells 3 and 4, at y = 2 the grid's top layer 3,
     * so it spans 5 x 4 x 5 cells of which the 2 x 2 x 2 inside are empty. */
    assert_int_equal(still, 5 * 4 * 5 - 8);

    /* Back to t = 0 through t = 0.5: every cell and every level bit for bit. */
    assert_int_equal(fv_scene_set_time(s, 0.5, &err), FV_OK);
    fv_voxels_update_dynamic(v);
    assert_int_equal(fv_scene_set_time(s, 0.0, &err), FV_OK);
    fv_voxels_update_dynamic(v);
    snapshot s2 = take(v);
    assert_memory_equal(s0.cells, s2.cells, (size_t)s0.ncells * sizeof *s0.cells);
    assert_memory_equal(s0.mips, s2.mips, (size_t)s0.nmips * sizeof *s0.mips);
    release(&s0);
    release(&s1);
    release(&s2);
    fv_voxels_destroy(v);
    fv_scene_destroy(s);
}

/* ---- cones ---- */

/* Planes x = 0, 2, 2.5, 3, 3.5, 4 across [0, 4]^2 at resolution 8: a plane on a cell face marks
 * both cells it touches, so layers x 0 and 3..7 are full and layers 1 and 2 empty. */
static void test_cones(void **st)
{
    (void)st;
    fv_scene *s = new_scene();
    int mat = add_mat(s, "grey", box_albedo);
    const float xs[6] = {0, 2, 2.5f, 3, 3.5f, 4};
    for (int q = 0; q < 6; q++) add_x_plane(s, xs[q], mat);
    commit(s);
    fv_voxels *v = new_voxels(s, 8);
    for (int c = 0; c < 512; c++) {
        fv_voxel x;
        fv_voxels_cell(v, c, &x);
        int i = c % 8;
        assert_int_equal(x.occupied, i == 1 || i == 2 ? 0 : 1);
    }
    fv_vec3 L = fv_v3(1.0f, 0.5f, 0.25f);
    for (int c = 0; c < 512; c++) fv_voxels_set_radiance(v, c, L);
    fv_voxels_build_radiance(v);
    assert_vec(fv_voxels_radiance(v, 5), L, 0);
    fv_voxel_mip m;
    fv_voxels_mip_cell(v, 1, 0, 2, 3, &m); /* children in layers 0 (full) and 1 (empty) */
    assert_float_equal(m.occupancy, 0.5f, 0);
    assert_vec(m.radiance, fv_scale(L, 0.5f), 1e-6f);
    fv_voxels_mip_cell(v, 1, 2, 2, 3, &m);
    assert_float_equal(m.occupancy, 1.0f, 0);
    assert_vec(m.radiance, L, 1e-6f);

    /* Through the empty layers (x = 1 lies between the centres of layers 1 and 2). */
    fv_vec3 rad;
    float occ = fv_voxels_cone(v, fv_v3(1.0f, 0.6f, 2.0f), fv_v3(0, 1, 0), 0.01f, 2.5f, &rad);
    assert_float_equal(occ, 0.0f, 0);
    assert_vec(rad, fv_v3s(0), 0);
    /* Into the slab: its radiance, nearly opaque. */
    occ = fv_voxels_cone(v, fv_v3(1.0f, 2.0f, 2.0f), fv_v3(1, 0, 0), 0.05f, INFINITY, &rad);
    assert_true(occ > 0.99f);
    assert_vec(rad, L, 0.01f);
    /* Wide cones sample coarse levels mixing full and empty cells: still radiance = L x occlusion. */
    const fv_vec3 dirs[3] = {{1, 0, 0}, {-1, 0.2f, 0}, {0.3f, 1, 0.5f}};
    for (int q = 0; q < 3; q++) {
        occ = fv_voxels_cone(v, fv_v3(1.0f, 2.0f, 2.0f), fv_normalize(dirs[q]), 0.6f, INFINITY, &rad);
        assert_true(occ > 0.0f && occ <= 1.0f);
        assert_vec(rad, fv_scale(L, occ), 1e-4f);
    }
    fv_voxels_destroy(v);
    fv_scene_destroy(s);
}

/* ---- refusals ---- */

static void test_refusals(void **st)
{
    (void)st;
    int id;
    fv_scene *s = box_scene(&id);
    const int bad[3] = {0, 7, 2000};
    for (int q = 0; q < 3; q++) {
        fv_voxels *v = (fv_voxels *)&id; /* must come back NULL */
        fv_error err;
        char what[32];
        snprintf(what, sizeof what, "resolution %d", bad[q]);
        fv_test_expect_fail(fv_voxels_create(s, bad[q], &v, &err), &err, FV_ERR_INVALID, "resolution", what);
        assert_null(v);
    }
    fv_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box),     cmocka_unit_test(test_sdf_sphere), cmocka_unit_test(test_cast),
        cmocka_unit_test(test_dynamic), cmocka_unit_test(test_cones),      cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
