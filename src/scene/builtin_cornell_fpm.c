/* fovea — `cornell-fpm`, the scene of Foveated Photon Mapping, Fig. 2: a Cornell-style room with
 * diffuse walls, a transparent (glass) sphere and a specular cube that moves, lit by the ceiling
 * light. It exercises what photon mapping is for: a caustic under the sphere, mirror reflections
 * of the walls and, because the cube is a dynamic object, light photons that must be re-traced
 * towards it every frame (Sec. 3 of the paper). The camera follows a short path (pan and dolly)
 * over the same 0..4 s as the cube, so temporal reuse is tested under camera motion too.
 *
 * Limits: the paper does not publish the figure's geometry; sizes and positions are ours, chosen
 * so the sphere and the cube never overlap and both stay in view along the whole path.
 */
#include "scene/builtin_impl.h"

#define P(x, y, z) fv_v3((float)(x), (float)(y), (float)(z))

/* Glass sphere resting on the floor to the left (from the camera), under the light's edge. */
#define SPHERE_R 90.0f
#define SPHERE_SEG_U 64
#define SPHERE_SEG_V 32
/* Mirror cube of side 150 built around the origin and placed by its animation. */
#define CUBE_HALF 75.0f

fv_status fv_builtin_cornell_fpm(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    fv_cornell_mats cm;
    fv_status st = fv_cornell_materials(s, &cm, err);
    if (st != FV_OK) return st;
    fv_material g = fv_material_default(FV_MAT_DIELECTRIC);
    g.ior = 1.5f;
    g.specular = fv_v3s(1.0f);
    fv_material m = fv_material_default(FV_MAT_MIRROR);
    m.specular = fv_v3s(0.95f);
    int glass, mirror, cube = -1;
    if ((st = fv_builtin_material(s, "glass", g, &glass, err)) != FV_OK ||
        (st = fv_builtin_material(s, "mirror", m, &mirror, err)) != FV_OK ||
        (st = fv_cornell_room(s, &cm, log, err)) != FV_OK)
        return st;

    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_sphere(&mb, P(380, SPHERE_R, 350), SPHERE_R, SPHERE_SEG_U, SPHERE_SEG_V, false, glass);
    st = fv_meshbuf_add(&mb, s, "glass_sphere", log, NULL, err);
    fv_meshbuf_clear(&mb);
    fv_mesh_box(&mb, P(0, 0, 0), fv_v3s(CUBE_HALF), 0.0f, mirror);
    if (st == FV_OK) st = fv_meshbuf_add(&mb, s, "mirror_cube", log, &cube, err);
    fv_meshbuf_free(&mb);
    if (st != FV_OK) return st;

    /* The cube rests on the floor (centre at y = 75) on the right, slides towards the middle and
     * back while swinging between 30 and 50 degrees about +y. Near 45 degrees the two faces the
     * camera sees mirror the red and green walls; turned square to the camera a face would only
     * mirror the black void behind it (the box is open at z = 0). Its half diagonal is 106, so
     * it keeps clear of the walls and, by at least 129, of the sphere. */
    const fv_vec3 up = P(0, 1, 0), one = fv_v3s(1.0f);
    const fv_anim_key keys[3] = {
        {0.0, P(150, CUBE_HALF, 170), fv_quat_axis_angle(up, fv_radians(30.0f)), one},
        {2.0, P(270, CUBE_HALF, 150), fv_quat_axis_angle(up, fv_radians(50.0f)), one},
        {4.0, P(150, CUBE_HALF, 170), fv_quat_axis_angle(up, fv_radians(30.0f)), one},
    };
    if ((st = fv_scene_animate_object(s, cube, keys, 3, err)) != FV_OK) return st;

    /* Start at the measured Cornell camera, pan right and move in a little, then drift back. */
    fv_camera cam = fv_cornell_camera();
    const fv_camera_key path[3] = {
        {0.0, cam.pos, cam.look, up, cam.fov_y},
        {2.0, P(320, 290, -740), P(290, 260, 0), up, cam.fov_y},
        {4.0, P(240, 265, -780), P(270, 273, 0), up, cam.fov_y},
    };
    fv_view_set_camera(view, &cam);
    return fv_view_set_camera_path(view, path, 3, err);
}
