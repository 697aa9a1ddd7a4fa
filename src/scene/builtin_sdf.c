/* fovea — the signed distance field scenes of issue 11, after Sec. 4.1 of Polychronakis,
 * Koulieris and Mania, "An Inverted Pyramid Acceleration Structure Guiding Foveated Sphere
 * Tracing for Implicit Surfaces in VR" (EG 2023): `sdf-primitives` (open: the primitives on a
 * checkerboard ground), `sdf-columns` (enclosed: a room of repeated columns, five moving point lights)
 * and `sdf-temple` (noise terrain with a temple of columns and steps). Each is one or a few
 * fv_scene_add_sdf objects, so every technique renders them (as Embree user geometry) and the
 * sphere tracers of the family can take the fields themselves.
 *
 * Limits: the paper publishes no geometry; sizes, colours and camera paths are ours. Its
 * checkerboard is a shading pattern; here it is geometry (repeated tiles of a second material a
 * hair above the ground) so `pt` shows it too. Its five lights "move around the columns" in
 * sdf-columns with no path given: ours loop once through the aisles in the 4 s of the camera path.
 */
#include <string.h>
#include "scene/builtin_impl.h"

#define P(x, y, z) fv_v3((float)(x), (float)(y), (float)(z))
#define MAX_NODES 128

/* A node array filled bottom-up: each helper appends one node and returns its index. */
typedef struct tree {
    fv_sdf_node n[MAX_NODES];
    int count;
} tree;

static int add(tree *t, fv_sdf_kind k, int mat)
{
    /* The builders below stay far under MAX_NODES; the last slot absorbs a mistake and
     * fv_sdf_create then refuses the tree rather than writing past the array. */
    int i = t->count < MAX_NODES ? t->count++ : MAX_NODES - 1;
    fv_sdf_node *n = &t->n[i];
    memset(n, 0, sizeof *n);
    n->kind = k;
    n->q = (fv_quat){0, 0, 0, 1};
    n->a = n->b = -1;
    n->material = mat;
    return i;
}
static int sphere(tree *t, float r, int mat)
{
    int i = add(t, FV_SDF_SPHERE, mat);
    t->n[i].p[0] = r;
    return i;
}
static int box(tree *t, fv_vec3 half, int mat)
{
    int i = add(t, FV_SDF_BOX, mat);
    t->n[i].v[0] = half;
    return i;
}
static int round_box(tree *t, fv_vec3 half, float r, int mat)
{
    int i = add(t, FV_SDF_ROUND_BOX, mat);
    t->n[i].v[0] = half;
    t->n[i].p[0] = r;
    return i;
}
static int torus(tree *t, float major, float minor, int mat)
{
    int i = add(t, FV_SDF_TORUS, mat);
    t->n[i].p[0] = major;
    t->n[i].p[1] = minor;
    return i;
}
static int capsule(tree *t, fv_vec3 a, fv_vec3 b, float r, int mat)
{
    int i = add(t, FV_SDF_CAPSULE, mat);
    t->n[i].v[0] = a;
    t->n[i].v[1] = b;
    t->n[i].p[0] = r;
    return i;
}
static int cylinder(tree *t, float r, float half_h, int mat)
{
    int i = add(t, FV_SDF_CYLINDER, mat);
    t->n[i].p[0] = r;
    t->n[i].p[1] = half_h;
    return i;
}
static int cone(tree *t, float r_bottom, float r_top, float half_h, int mat)
{
    int i = add(t, FV_SDF_CONE, mat);
    t->n[i].p[0] = r_bottom;
    t->n[i].p[1] = r_top;
    t->n[i].p[2] = half_h;
    return i;
}
static int heightfield(tree *t, float base, float amp, float freq, int octaves, int seed, int mat)
{
    int i = add(t, FV_SDF_HEIGHTFIELD, mat);
    t->n[i].p[0] = base;
    t->n[i].p[1] = amp;
    t->n[i].p[2] = freq;
    t->n[i].p[3] = (float)octaves;
    t->n[i].p[4] = (float)seed;
    return i;
}
static int op(tree *t, fv_sdf_kind k, int a, int b)
{
    int i = add(t, k, 0);
    t->n[i].a = a;
    t->n[i].b = b;
    return i;
}
static int smooth(tree *t, int a, int b, float k)
{
    int i = op(t, FV_SDF_SMOOTH_UNION, a, b);
    t->n[i].p[0] = k;
    return i;
}
static int place(tree *t, int child, fv_vec3 at, fv_quat q, float scale)
{
    int i = add(t, FV_SDF_TRANSFORM, 0);
    t->n[i].a = child;
    t->n[i].v[0] = at;
    t->n[i].q = q;
    t->n[i].p[0] = scale;
    return i;
}
static int at(tree *t, int child, fv_vec3 p) { return place(t, child, p, (fv_quat){0, 0, 0, 1}, 1.0f); }
static int repeat(tree *t, int child, fv_vec3 period, fv_vec3 count)
{
    int i = add(t, FV_SDF_REPEAT, 0);
    t->n[i].a = child;
    t->n[i].v[0] = period;
    t->n[i].v[1] = count;
    return i;
}

static fv_status diffuse(fv_scene *s, const char *name, fv_vec3 albedo, int *id, fv_error *err)
{
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = albedo;
    return fv_builtin_material(s, name, m, id, err);
}

static fv_status point(fv_scene *s, fv_vec3 pos, fv_vec3 intensity, fv_error *err)
{
    fv_light_desc l = {FV_LIGHT_POINT, pos, P(0, -1, 0), intensity, 0, 0};
    return fv_scene_add_light(s, &l, err);
}

/* A point light going round the loop corner[0] -> ... -> corner[n-1] -> corner[0] once in `period`
 * seconds, in straight lines at a steady pace (a key at each corner). It stands at corner[0]; the
 * keys carry the offsets from there. */
static fv_status looping_point(fv_scene *s, const fv_vec3 *corner, int n, double period, fv_vec3 intensity, fv_error *err)
{
    fv_anim_key keys[9];
    if (n < 1 || n > 8) return fv_error_set(err, FV_ERR_INTERNAL, "looping light: %d corners (1 to 8)", n);
    fv_status st = point(s, corner[0], intensity, err);
    for (int k = 0; k <= n && st == FV_OK; k++)
        keys[k] = (fv_anim_key){period * k / n, fv_sub(corner[k % n], corner[0]), (fv_quat){0, 0, 0, 1}, fv_v3s(1.0f)};
    return st ? st : fv_scene_animate_light(s, fv_scene_light_count(s) - 1, keys, n + 1, err);
}

static fv_quat about_y(float deg) { return fv_quat_axis_angle(P(0, 1, 0), fv_radians(deg)); }

/* A checkerboard ground of 2 x 2 cells of four unit tiles, top at y = 0, over [-half, half]^2:
 * a light slab with dark tiles on two diagonal quarters of each repeated cell. The dark tiles
 * stand 2 mm proud so the surface has one material everywhere (coplanar faces would split). */
static int checker_ground(tree *t, int cells, int light, int dark)
{
    float half = 2.0f * (float)cells + 1.0f;
    int slab = at(t, box(t, P(half, 0.1f, half), light), P(0, -0.1f, 0));
    int tile = box(t, P(0.49f, 0.05f, 0.49f), dark);
    int pair = op(t, FV_SDF_UNION, at(t, tile, P(-0.5f, 0, -0.5f)), at(t, tile, P(0.5f, 0, 0.5f)));
    int tiles = at(t, repeat(t, pair, P(2, 0, 2), P((float)cells, 0, (float)cells)), P(0, -0.048f, 0));
    return op(t, FV_SDF_UNION, slab, tiles);
}

fv_status fv_builtin_sdf_primitives(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    int light, dark, red, orange, yellow, green, cyan, blue, violet, gold = -1;
    fv_status st;
    if ((st = diffuse(s, "checker_light", P(0.75, 0.75, 0.72), &light, err)) || (st = diffuse(s, "checker_dark", P(0.12, 0.12, 0.13), &dark, err)) ||
        (st = diffuse(s, "red", P(0.75, 0.12, 0.1), &red, err)) || (st = diffuse(s, "orange", P(0.8, 0.4, 0.08), &orange, err)) ||
        (st = diffuse(s, "yellow", P(0.8, 0.7, 0.15), &yellow, err)) || (st = diffuse(s, "green", P(0.15, 0.6, 0.2), &green, err)) ||
        (st = diffuse(s, "cyan", P(0.1, 0.55, 0.65), &cyan, err)) || (st = diffuse(s, "blue", P(0.15, 0.25, 0.75), &blue, err)) ||
        (st = diffuse(s, "violet", P(0.5, 0.2, 0.65), &violet, err)))
        return st;
    fv_material g = fv_material_default(FV_MAT_GLOSSY);
    g.albedo = P(0.2, 0.12, 0.02);
    g.specular = P(0.9, 0.7, 0.3);
    g.roughness = 0.25f;
    if ((st = fv_builtin_material(s, "gold", g, &gold, err))) return st;

    tree t = {.count = 0};
    int ground = checker_ground(&t, 4, light, dark);
    /* Seven primitives on an arc, each resting on the ground. */
    int shapes[7];
    shapes[0] = at(&t, sphere(&t, 0.7f, red), P(-4.2, 0.7, 0.6));
    shapes[1] = place(&t, box(&t, P(0.55, 0.55, 0.55), orange), P(-2.8, 0.55, -0.6), about_y(25), 1.0f);
    shapes[2] = place(&t, round_box(&t, P(0.6, 0.45, 0.5), 0.15f, yellow), P(-1.3, 0.45, -1.3), about_y(-20), 1.0f);
    shapes[3] = place(&t, torus(&t, 0.55f, 0.2f, gold), P(0.2, 0.75, -1.6), fv_quat_axis_angle(P(1, 0, 0), fv_radians(65)), 1.0f);
    shapes[4] = at(&t, capsule(&t, P(-0.3, 0.3, 0), P(0.3, 1.1, 0.1), 0.3f, green), P(1.7, 0, -1.2));
    shapes[5] = at(&t, cylinder(&t, 0.45f, 0.6f, cyan), P(3.0, 0.6, -0.5));
    shapes[6] = at(&t, cone(&t, 0.6f, 0.0f, 0.75f, blue), P(4.2, 0.75, 0.6));
    int all = ground;
    for (int i = 0; i < 7; i++) all = op(&t, FV_SDF_UNION, all, shapes[i]);
    /* A smooth union in front, so the operators show too. */
    int blob = smooth(&t, at(&t, sphere(&t, 0.45f, violet), P(-0.4, 0.45, 0)), at(&t, sphere(&t, 0.35f, violet), P(0.2, 0.35, 0.1)), 0.3f);
    all = op(&t, FV_SDF_UNION, all, at(&t, blob, P(0, 0, 1.3)));
    if ((st = fv_scene_add_sdf(s, "primitives", t.n, t.count, all, log, NULL, err))) return st;
    if ((st = point(s, P(-4, 8, 6), fv_v3s(70), err)) || (st = point(s, P(5, 5, 4), P(18, 18, 22), err))) return st;

    const fv_vec3 up = P(0, 1, 0), look = P(0, 0.5, -0.3);
    fv_camera cam = {P(0, 5.0, 11.0), look, up, 48.0f, 512, 512};
    const fv_camera_key path[3] = {
        {0.0, cam.pos, look, up, 48.0f},
        {2.0, P(-5.5, 4.5, 10.0), look, up, 48.0f},
        {4.0, P(4.5, 3.8, 9.5), look, up, 48.0f},
    };
    fv_view_set_camera(view, &cam);
    return fv_view_set_camera_path(view, path, 3, err);
}

fv_status fv_builtin_sdf_columns(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    int wall, floor_mat, stone;
    fv_status st;
    if ((st = diffuse(s, "wall", P(0.7, 0.66, 0.6), &wall, err)) || (st = diffuse(s, "floor", P(0.45, 0.35, 0.28), &floor_mat, err)) ||
        (st = diffuse(s, "stone", P(0.75, 0.75, 0.78), &stone, err)))
        return st;
    tree t = {.count = 0};
    /* The room: a shell 15 x 6 x 15 inside (floor at y = 0), as a box minus a box, with a floor
     * slab of its own material on top of the shell's bottom. */
    int shell = op(&t, FV_SDF_SUBTRACT, at(&t, box(&t, P(8, 3.5, 8), wall), P(0, 3, 0)), at(&t, box(&t, P(7.5, 3, 7.5), wall), P(0, 3, 0)));
    int floor_slab = at(&t, box(&t, P(7.5, 0.05, 7.5), floor_mat), P(0, 0.0, 0));
    /* A column: base, shaft, capital; repeated 3 x 3 with a 4 m period. */
    int base = at(&t, box(&t, P(0.6, 0.2, 0.6), stone), P(0, 0.25, 0));
    int shaft = at(&t, cylinder(&t, 0.38f, 2.6f, stone), P(0, 3.0, 0));
    int capital = at(&t, round_box(&t, P(0.6, 0.2, 0.6), 0.05f, stone), P(0, 5.8, 0));
    int column = op(&t, FV_SDF_UNION, op(&t, FV_SDF_UNION, base, shaft), capital);
    int columns = at(&t, repeat(&t, at(&t, column, P(0, -3, 0)), P(4, 0, 4), P(1, 0, 1)), P(0, 3, 0));
    int root = op(&t, FV_SDF_UNION, op(&t, FV_SDF_UNION, shell, floor_slab), columns);
    if ((st = fv_scene_add_sdf(s, "columns", t.n, t.count, root, log, NULL, err))) return st;
    /* Five lights under the ceiling, each looping once in 4 s along the aisles (x or z = +-2, and
     * +-6 between the outer columns and the walls): a white one around the central column, a warm
     * one around each corner column. Every corner of a loop is an aisle crossing, at least 2 m
     * from the nearest column's axis (1.6 m from its shaft) and 1.5 m from the walls, and so is
     * every point in between. The corner loops pass the crossings they share with the central
     * one at other times than it does. */
    const fv_vec3 centre[4] = {P(2, 5, 2), P(-2, 5, 2), P(-2, 5, -2), P(2, 5, -2)};
    const fv_vec3 corners[4][4] = {
        {P(-2, 4.5, -6), P(-2, 4.5, -2), P(-6, 4.5, -2), P(-6, 4.5, -6)},
        {P(6, 4.5, -6), P(6, 4.5, -2), P(2, 4.5, -2), P(2, 4.5, -6)},
        {P(-6, 4.5, 6), P(-6, 4.5, 2), P(-2, 4.5, 2), P(-2, 4.5, 6)},
        {P(6, 4.5, 6), P(2, 4.5, 6), P(2, 4.5, 2), P(6, 4.5, 2)},
    };
    if ((st = looping_point(s, centre, 4, 4.0, fv_v3s(7), err))) return st;
    for (int i = 0; i < 4 && st == FV_OK; i++) st = looping_point(s, corners[i], 4, 4.0, P(4, 3.5, 2.8), err);
    if (st) return st;

    const fv_vec3 up = P(0, 1, 0);
    fv_camera cam = {P(-6, 2.2, 6.5), P(0, 2.4, -2), up, 60.0f, 512, 512};
    const fv_camera_key path[3] = {
        {0.0, cam.pos, cam.look, up, 60.0f},
        {2.0, P(-2, 2.0, 6.0), P(2, 2.6, -4), up, 60.0f},
        {4.0, P(2, 1.8, 6.5), P(-1, 2.8, -5), up, 60.0f},
    };
    fv_view_set_camera(view, &cam);
    return fv_view_set_camera_path(view, path, 3, err);
}

fv_status fv_builtin_sdf_temple(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    int rock, marble, roof;
    fv_status st;
    if ((st = diffuse(s, "rock", P(0.45, 0.38, 0.3), &rock, err)) || (st = diffuse(s, "marble", P(0.82, 0.8, 0.75), &marble, err)) ||
        (st = diffuse(s, "roof", P(0.6, 0.3, 0.2), &roof, err)))
        return st;
    tree t = {.count = 0};
    /* Cliff terrain: an fbm height field clipped by a 40 x 40 box reaching 3 m below its base. */
    int hf = heightfield(&t, 0.0f, 2.5f, 0.12f, 5, 7, rock);
    int terrain = op(&t, FV_SDF_INTERSECT, hf, at(&t, box(&t, P(20, 4.5, 20), rock), P(0, 0.5, 0)));
    /* The temple on a stepped platform whose lowest step reaches well into the ground. */
    int step1 = at(&t, box(&t, P(4.2, 2.0, 3.2), marble), P(0, 1.0, 0));
    int step2 = at(&t, box(&t, P(3.8, 0.2, 2.8), marble), P(0, 3.2, 0));
    int step3 = at(&t, box(&t, P(3.4, 0.2, 2.4), marble), P(0, 3.6, 0));
    int platform = op(&t, FV_SDF_UNION, op(&t, FV_SDF_UNION, step1, step2), step3);
    /* Columns on the long sides (7 each) and the short sides (2 more each, between the corners). */
    int col = cylinder(&t, 0.22f, 1.6f, marble);
    int row = repeat(&t, col, P(1.05, 0, 0), P(3, 0, 0));
    int rows = op(&t, FV_SDF_UNION, at(&t, row, P(0, 5.4, 2.0)), at(&t, row, P(0, 5.4, -2.0)));
    int side = repeat(&t, col, P(0, 0, 1.3), P(0, 0, 1));
    int sides = op(&t, FV_SDF_UNION, at(&t, side, P(3.15, 5.4, 0)), at(&t, side, P(-3.15, 5.4, 0)));
    int lintel = at(&t, box(&t, P(3.5, 0.2, 2.5), marble), P(0, 7.2, 0));
    int roof_cut = op(&t, FV_SDF_INTERSECT, at(&t, place(&t, box(&t, P(3.6, 1.0, 1.0), roof), P(0, 0, 0),
                                                         fv_quat_axis_angle(P(1, 0, 0), fv_radians(45)), 2.1f), P(0, 7.4, 0)),
                     at(&t, box(&t, P(3.7, 1.0, 2.7), roof), P(0, 8.4, 0)));
    int temple = op(&t, FV_SDF_UNION, op(&t, FV_SDF_UNION, op(&t, FV_SDF_UNION, platform, rows), op(&t, FV_SDF_UNION, sides, lintel)), roof_cut);
    int root = op(&t, FV_SDF_UNION, terrain, temple);
    if ((st = fv_scene_add_sdf(s, "temple", t.n, t.count, root, log, NULL, err))) return st;
    if ((st = point(s, P(-25, 30, 25), fv_v3s(1400), err)) || (st = point(s, P(15, 10, 18), P(60, 65, 90), err))) return st;

    const fv_vec3 up = P(0, 1, 0), look = P(0, 4.5, 0);
    fv_camera cam = {P(-6, 9, 16), look, up, 50.0f, 512, 512};
    const fv_camera_key path[3] = {
        {0.0, cam.pos, look, up, 50.0f},
        {2.0, P(4, 8, 15), look, up, 50.0f},
        {4.0, P(13, 10, 9), look, up, 50.0f},
    };
    fv_view_set_camera(view, &cam);
    return fv_view_set_camera_path(view, path, 3, err);
}

/* `sdf-furnace`: the sphere tracers' analogue of the white furnace. The camera and a point light
 * of intensity 2 pi sit at the centre of a hollow sphere of radius 1 (a box minus the ball) whose
 * inside is diffuse with albedo 0.5: every camera ray meets the wall head-on at distance 1, where
 * direct light alone gives albedo / pi x I / r^2 x cos 0 = 0.5 / pi x 2 pi = 1 exactly, in every
 * pixel and channel. (Path tracing adds the interreflections: 1 / (1 - 0.5) = 2.) */
fv_status fv_builtin_sdf_furnace(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    int wall;
    fv_status st;
    if ((st = diffuse(s, "wall", fv_v3s(0.5f), &wall, err))) return st;
    tree t = {.count = 0};
    int root = op(&t, FV_SDF_SUBTRACT, box(&t, P(1.5, 1.5, 1.5), wall), sphere(&t, 1.0f, wall));
    if ((st = fv_scene_add_sdf(s, "furnace", t.n, t.count, root, log, NULL, err))) return st;
    if ((st = point(s, P(0, 0, 0), fv_v3s(2.0f * FV_PI), err))) return st;
    const fv_camera cam = {P(0, 0, 0), P(0, 0, 1), P(0, 1, 0), 60.0f, 256, 256};
    fv_view_set_camera(view, &cam);
    return FV_OK;
}
