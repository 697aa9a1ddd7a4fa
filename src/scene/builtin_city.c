/* fovea — `city`, the large built-in scene for performance work: a 24 x 24 grid of blocks on a
 * tessellated ground, each block either a tower (a stack of two or three shrinking boxes, turned
 * a little) or a finely tessellated sphere, in diffuse, glossy (three roughnesses), mirror and
 * glass materials. Lit by a warm, distant sun-like spot light, three street-level point lights
 * and emissive panels on some roofs (38 panels, 76 emissive triangles). 180,906 triangles in
 * four objects: ground 28,800, towers 12,190, 92 spheres 139,840, panels 76.
 *
 * Deterministic: every choice comes from an integer hash of the block's grid coordinates (no
 * rand()), so the scene is the same on every machine and run. Limits: no instancing; the towers
 * have no windows or other detail.
 */
#include <stdio.h>
#include "scene/builtin_impl.h"

#define GRID 24
#define CELL 10.0f
#define GROUND_SEG 120
#define SPHERE_SEG_U 40
#define SPHERE_SEG_V 20

/* A small integer hash (multiply-xorshift, "lowbias32"-style constants) mapped to [0, 1). */
static float hash01(unsigned x, unsigned y, unsigned salt)
{
    unsigned h = x * 0x8da6b343u ^ y * 0xd8163841u ^ salt * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return (float)(h >> 8) / 16777216.0f;
}

enum { N_DIFFUSE = 6, N_GLOSSY = 3 };

typedef struct city_mats {
    int diffuse[N_DIFFUSE], glossy[N_GLOSSY], mirror, glass, ground, lamp;
} city_mats;

static fv_status add_materials(fv_scene *s, city_mats *cm, fv_error *err)
{
    static const float k_colors[N_DIFFUSE][3] = {{0.75f, 0.74f, 0.70f}, {0.62f, 0.30f, 0.22f}, {0.30f, 0.42f, 0.60f},
                                                 {0.45f, 0.55f, 0.32f}, {0.80f, 0.68f, 0.40f}, {0.35f, 0.33f, 0.36f}};
    static const float k_rough[N_GLOSSY] = {0.05f, 0.2f, 0.5f};
    char name[32];
    fv_status st = FV_OK;
    for (int i = 0; i < N_DIFFUSE && st == FV_OK; i++) {
        fv_material m = fv_material_default(FV_MAT_DIFFUSE);
        m.albedo = fv_v3(k_colors[i][0], k_colors[i][1], k_colors[i][2]);
        snprintf(name, sizeof name, "diffuse%d", i);
        st = fv_builtin_material(s, name, m, &cm->diffuse[i], err);
    }
    for (int i = 0; i < N_GLOSSY && st == FV_OK; i++) {
        fv_material m = fv_material_default(FV_MAT_GLOSSY);
        m.albedo = fv_v3(0.2f, 0.25f + 0.2f * (float)i, 0.5f);
        m.specular = fv_v3s(0.5f);
        m.roughness = k_rough[i];
        snprintf(name, sizeof name, "glossy%d", i);
        st = fv_builtin_material(s, name, m, &cm->glossy[i], err);
    }
    if (st != FV_OK) return st;
    fv_material mirror = fv_material_default(FV_MAT_MIRROR), glass = fv_material_default(FV_MAT_DIELECTRIC);
    mirror.specular = fv_v3s(0.9f);
    glass.ior = 1.5f;
    fv_material ground = fv_material_default(FV_MAT_DIFFUSE), lamp = fv_material_default(FV_MAT_DIFFUSE);
    ground.albedo = fv_v3s(0.5f);
    lamp.emission = fv_v3(8.0f, 7.0f, 5.0f);
    if ((st = fv_builtin_material(s, "mirror", mirror, &cm->mirror, err)) != FV_OK ||
        (st = fv_builtin_material(s, "glass", glass, &cm->glass, err)) != FV_OK ||
        (st = fv_builtin_material(s, "ground", ground, &cm->ground, err)) != FV_OK ||
        (st = fv_builtin_material(s, "lamp", lamp, &cm->lamp, err)) != FV_OK)
        return st;
    return FV_OK;
}

/* 55 % diffuse, 30 % glossy, 10 % mirror, 5 % glass. */
static int pick_material(const city_mats *cm, float pick)
{
    if (pick < 0.55f) return cm->diffuse[(int)(pick / 0.55f * N_DIFFUSE) % N_DIFFUSE];
    if (pick < 0.85f) return cm->glossy[(int)((pick - 0.55f) / 0.30f * N_GLOSSY) % N_GLOSSY];
    return pick < 0.95f ? cm->mirror : cm->glass;
}

/* Fills the blocks: towers go to `towers`, spheres to `spheres`, roof panels to `lamps`. */
static void add_blocks(const city_mats *cm, fv_meshbuf *towers, fv_meshbuf *spheres, fv_meshbuf *lamps)
{
    for (unsigned gy = 0; gy < GRID; gy++)
        for (unsigned gx = 0; gx < GRID; gx++) {
            float cx = ((float)gx + 0.5f) * CELL, cz = ((float)gy + 0.5f) * CELL;
            int mat = pick_material(cm, hash01(gx, gy, 2));
            if (hash01(gx, gy, 1) < 0.16f) {
                float r = 2.0f + 2.0f * hash01(gx, gy, 5);
                fv_mesh_sphere(spheres, fv_v3(cx, r, cz), r, SPHERE_SEG_U, SPHERE_SEG_V, false, mat);
                continue;
            }
            /* Heights 4..30, skewed low by the product of two uniforms: a few tall towers. */
            float h = 4.0f + 26.0f * hash01(gx, gy, 3) * hash01(gx, gy, 4);
            float w = 3.0f + 1.5f * hash01(gx, gy, 6), y = 0.0f, yaw = 30.0f * hash01(gx, gy, 7);
            int levels = hash01(gx, gy, 8) > 0.5f ? 3 : 2;
            for (int l = 0; l < levels; l++) {
                float lh = h / (float)levels;
                /* Each level stands on the one below, so its bottom is never seen. */
                fv_mesh_box_open(towers, fv_v3(cx, y + 0.5f * lh, cz), fv_v3(w, 0.5f * lh, w), yaw,
                                 l == levels - 1 ? mat : cm->diffuse[0]);
                y += lh;
                w *= 0.75f;
            }
            if (hash01(gx, gy, 9) < 0.08f) /* an emissive panel just above the roof, facing up */
                fv_mesh_axis_quad(lamps, 1, y + 0.05f, cz - 1.0f, cx - 1.0f, cz + 1.0f, cx + 1.0f, 1, cm->lamp);
        }
}

fv_status fv_builtin_city(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    city_mats cm;
    fv_status st = add_materials(s, &cm, err);
    if (st != FV_OK) return st;

    float extent = GRID * CELL;
    fv_meshbuf ground, towers, spheres, lamps;
    fv_meshbuf_init(&ground);
    fv_meshbuf_init(&towers);
    fv_meshbuf_init(&spheres);
    fv_meshbuf_init(&lamps);
    /* The ground overhangs the grid by 10 on every side; eu x ev = +y. */
    fv_mesh_grid(&ground, fv_v3(-10.0f, 0.0f, extent + 10.0f), fv_v3(extent + 20.0f, 0, 0),
                 fv_v3(0, 0, -(extent + 20.0f)), GROUND_SEG, GROUND_SEG, cm.ground);
    add_blocks(&cm, &towers, &spheres, &lamps);
    st = fv_meshbuf_add(&ground, s, "ground", log, NULL, err);
    if (st == FV_OK) st = fv_meshbuf_add(&towers, s, "towers", log, NULL, err);
    if (st == FV_OK) st = fv_meshbuf_add(&spheres, s, "spheres", log, NULL, err);
    if (st == FV_OK && lamps.nt > 0) st = fv_meshbuf_add(&lamps, s, "lamps", log, NULL, err);
    fv_meshbuf_free(&ground);
    fv_meshbuf_free(&towers);
    fv_meshbuf_free(&spheres);
    fv_meshbuf_free(&lamps);
    if (st != FV_OK) return st;

    /* A low warm "sun" far away over the near corner (about 420 from the centre, so its cone of
     * 35 degrees covers the whole grid) and three cool street-level lights. */
    const fv_light_desc sun = {FV_LIGHT_SPOT, {-150.0f, 220.0f, -120.0f}, {1.0f, -0.9f, 1.0f},
                               {4.0e5f, 3.6e5f, 2.9e5f}, 25.0f, 35.0f};
    if ((st = fv_scene_add_light(s, &sun, err)) != FV_OK) return st;
    for (int i = 0; i < 3; i++) {
        /* Over street crossings, 6 above the ground: the nearest block centres are 7.07 away and
         * no tower reaches further than its half diagonal, 4.5 sqrt 2 = 6.4, from its centre. */
        const fv_light_desc p = {FV_LIGHT_POINT, {40.0f + 80.0f * (float)i, 6.0f, 60.0f + 60.0f * (float)i}, {0, 0, 0},
                                 {60.0f, 64.0f, 80.0f}, 0.0f, 0.0f};
        if ((st = fv_scene_add_light(s, &p, err)) != FV_OK) return st;
    }
    const fv_camera cam = {{-25.0f, 55.0f, -25.0f}, {110.0f, 0.0f, 110.0f}, {0, 1, 0}, 55.0f, 640, 480};
    fv_view_set_camera(view, &cam);
    return FV_OK;
}
