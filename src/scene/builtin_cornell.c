/* fovea — the Cornell box built-ins: `cornell`, the classic box with the geometry and camera
 * position measured by the Cornell Program of Computer Graphics (units: mm, y up, the camera looks
 * down +z so the red wall at x = 556 is on the left), and `cornell-glossy`, the same box with a
 * glossy metal tall block and a glossy plastic short block. The room, light and tall block helpers
 * are shared with `cornell-fpm` (builtin_cornell_fpm.c) and `cornell-fir` (builtin_cornell_fir.c).
 *
 * Limits: the published box has slightly skewed walls (552.8 vs 556 at the floor); we keep those
 * numbers. The measured light spectrum is replaced by an RGB radiance (17, 12, 4), the albedos by
 * the usual RGB fits. The published lens (35 mm focal length, 25 mm film) gives a 39.3 degree
 * field of view; we use 37.5 degrees so the box fills the frame without the thin black border.
 */
#include <stdio.h>
#include "scene/builtin_impl.h"

/* Box: tall block 330 high, short block 165 high; the light sits 0.1 below the ceiling so it
 * does not z-fight with it. */
#define CEIL 548.8f
#define LIGHT_Y 548.7f

static fv_material diffuse(float r, float g, float b)
{
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3(r, g, b);
    return m;
}

fv_status fv_cornell_wall_materials(fv_scene *s, fv_cornell_mats *cm, fv_error *err)
{
    fv_status st;
    cm->light = -1;
    if ((st = fv_builtin_material(s, "white", diffuse(0.725f, 0.71f, 0.68f), &cm->white, err)) != FV_OK ||
        (st = fv_builtin_material(s, "red", diffuse(0.63f, 0.065f, 0.05f), &cm->red, err)) != FV_OK ||
        (st = fv_builtin_material(s, "green", diffuse(0.14f, 0.45f, 0.091f), &cm->green, err)) != FV_OK)
        return st;
    return FV_OK;
}

fv_status fv_cornell_materials(fv_scene *s, fv_cornell_mats *cm, fv_error *err)
{
    fv_material light = diffuse(0.78f, 0.78f, 0.78f);
    light.emission = fv_v3(17.0f, 12.0f, 4.0f);
    fv_status st = fv_cornell_wall_materials(s, cm, err);
    return st != FV_OK ? st : fv_builtin_material(s, "light", light, &cm->light, err);
}

#define P(x, y, z) fv_v3((float)(x), (float)(y), (float)(z))

fv_status fv_cornell_walls(fv_scene *s, const fv_cornell_mats *cm, const fv_log *log, fv_error *err)
{
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    /* Every wall faces into the box. */
    fv_mesh_quad(&mb, P(552.8, 0, 0), P(0, 0, 0), P(0, 0, 559.2), P(549.6, 0, 559.2), cm->white);        /* floor */
    fv_mesh_quad(&mb, P(556, CEIL, 0), P(556, CEIL, 559.2), P(0, CEIL, 559.2), P(0, CEIL, 0), cm->white); /* ceiling */
    fv_mesh_quad(&mb, P(549.6, 0, 559.2), P(0, 0, 559.2), P(0, CEIL, 559.2), P(556, CEIL, 559.2), cm->white); /* back */
    fv_mesh_quad(&mb, P(552.8, 0, 0), P(549.6, 0, 559.2), P(556, CEIL, 559.2), P(556, CEIL, 0), cm->red);     /* left */
    fv_mesh_quad(&mb, P(0, 0, 559.2), P(0, 0, 0), P(0, CEIL, 0), P(0, CEIL, 559.2), cm->green);              /* right */
    fv_status st = fv_meshbuf_add(&mb, s, "room", log, NULL, err);
    fv_meshbuf_free(&mb);
    return st;
}

fv_status fv_cornell_room(fv_scene *s, const fv_cornell_mats *cm, const fv_log *log, fv_error *err)
{
    fv_status st = fv_cornell_walls(s, cm, log, err);
    if (st != FV_OK) return st;
    /* The 130 x 105 light, facing down. */
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_quad(&mb, P(343, LIGHT_Y, 227), P(343, LIGHT_Y, 332), P(213, LIGHT_Y, 332), P(213, LIGHT_Y, 227), cm->light);
    st = fv_meshbuf_add(&mb, s, "light", log, NULL, err);
    fv_meshbuf_free(&mb);
    return st;
}

fv_camera fv_cornell_camera(void)
{
    fv_camera c = {P(278, 273, -800), P(278, 273, 0), P(0, 1, 0), 37.5f, 512, 512};
    return c;
}

/* The two blocks of the measured data: four sides and a top each (they stand on the floor). */
static fv_status add_short_block(fv_scene *s, int mat, const fv_log *log, fv_error *err)
{
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_quad(&mb, P(130, 165, 65), P(82, 165, 225), P(240, 165, 272), P(290, 165, 114), mat);
    fv_mesh_quad(&mb, P(290, 0, 114), P(290, 165, 114), P(240, 165, 272), P(240, 0, 272), mat);
    fv_mesh_quad(&mb, P(130, 0, 65), P(130, 165, 65), P(290, 165, 114), P(290, 0, 114), mat);
    fv_mesh_quad(&mb, P(82, 0, 225), P(82, 165, 225), P(130, 165, 65), P(130, 0, 65), mat);
    fv_mesh_quad(&mb, P(240, 0, 272), P(240, 165, 272), P(82, 165, 225), P(82, 0, 225), mat);
    fv_status st = fv_meshbuf_add(&mb, s, "short_block", log, NULL, err);
    fv_meshbuf_free(&mb);
    return st;
}

fv_status fv_cornell_tall_block(fv_scene *s, int mat, const fv_log *log, fv_error *err)
{
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_quad(&mb, P(423, 330, 247), P(265, 330, 296), P(314, 330, 456), P(472, 330, 406), mat);
    fv_mesh_quad(&mb, P(423, 0, 247), P(423, 330, 247), P(472, 330, 406), P(472, 0, 406), mat);
    fv_mesh_quad(&mb, P(472, 0, 406), P(472, 330, 406), P(314, 330, 456), P(314, 0, 456), mat);
    fv_mesh_quad(&mb, P(314, 0, 456), P(314, 330, 456), P(265, 330, 296), P(265, 0, 296), mat);
    fv_mesh_quad(&mb, P(265, 0, 296), P(265, 330, 296), P(423, 330, 247), P(423, 0, 247), mat);
    fv_status st = fv_meshbuf_add(&mb, s, "tall_block", log, NULL, err);
    fv_meshbuf_free(&mb);
    return st;
}

static fv_status add_blocks(fv_scene *s, int short_mat, int tall_mat, const fv_log *log, fv_error *err)
{
    fv_status st = add_short_block(s, short_mat, log, err);
    return st != FV_OK ? st : fv_cornell_tall_block(s, tall_mat, log, err);
}

fv_status fv_builtin_cornell(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    fv_cornell_mats cm;
    fv_status st;
    if ((st = fv_cornell_materials(s, &cm, err)) != FV_OK || (st = fv_cornell_room(s, &cm, log, err)) != FV_OK ||
        (st = add_blocks(s, cm.white, cm.white, log, err)) != FV_OK)
        return st;
    fv_camera cam = fv_cornell_camera();
    fv_view_set_camera(view, &cam);
    return FV_OK;
}

fv_status fv_builtin_cornell_glossy(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    fv_cornell_mats cm;
    fv_status st = fv_cornell_materials(s, &cm, err);
    if (st != FV_OK) return st;
    /* A copper-like metal (no diffuse part, coloured F0) and a white plastic (4 % F0). */
    fv_material metal = fv_material_default(FV_MAT_GLOSSY), plastic = fv_material_default(FV_MAT_GLOSSY);
    metal.albedo = fv_v3s(0.0f);
    metal.specular = fv_v3(0.95f, 0.64f, 0.54f);
    metal.roughness = 0.15f;
    plastic.albedo = fv_v3(0.725f, 0.71f, 0.68f);
    plastic.specular = fv_v3s(0.04f);
    plastic.roughness = 0.3f;
    int im, ip;
    if ((st = fv_builtin_material(s, "copper", metal, &im, err)) != FV_OK ||
        (st = fv_builtin_material(s, "plastic", plastic, &ip, err)) != FV_OK ||
        (st = fv_cornell_room(s, &cm, log, err)) != FV_OK || (st = add_blocks(s, ip, im, log, err)) != FV_OK)
        return st;
    fv_camera cam = fv_cornell_camera();
    fv_view_set_camera(view, &cam);
    return FV_OK;
}
