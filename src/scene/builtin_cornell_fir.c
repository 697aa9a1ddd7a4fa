/* fovea — `cornell-fir`, a Cornell box for Foveated Instant Radiosity (issue 12). The paper's
 * scenes are diffuse, with a dynamic object and moving lights, and its Cornell box has a yellow
 * cube whose colour bleeds onto the white walls. So: the measured room with every material
 * diffuse; no area light but one point light under the ceiling that circles its centre; the
 * measured tall block (static) and, in place of the short block, a yellow diffuse cube of about
 * its size that slides across the floor and back over 0..4 s. Instant radiosity has to re-place
 * its VPLs as the light moves and re-shade the indirect light the moving cube changes.
 *
 * Limits: the paper publishes no coordinates; sizes, paths and the intensity are ours. The
 * circle is a polygon of 16 keys (lerped translation), within 1 % of a true circle's radius.
 */
#include <math.h>
#include "scene/builtin_impl.h"

#define P(x, y, z) fv_v3((float)(x), (float)(y), (float)(z))

/* The light circles (LIGHT_CX, LIGHT_Y, LIGHT_CZ), the ceiling's centre 48.8 below it, with
 * radius LIGHT_R once every LOOP seconds. */
#define LIGHT_CX 278.0f
#define LIGHT_Y 500.0f
#define LIGHT_CZ 279.6f
#define LIGHT_R 120.0f
#define LOOP 4.0
#define LIGHT_KEYS 17
/* The area light of `cornell` has radiance (17, 12, 4) over 130 x 105 mm, i.e. an intensity of
 * L A = (232k, 164k, 55k) W/sr straight down, falling with the cosine. A point light emits as
 * much sideways and upwards, onto the white ceiling and walls that then light the room again, and
 * it hangs 49 mm lower; (17, 12, 4) x 4000 = (68k, 48k, 16k) W/sr gives the median pixel of a
 * 64-spp `pt` image the value of cornell's (0.049, checked by eye too). */
#define LIGHT_SCALE 4000.0f
/* Yellow cube of side 160 (the short block is 165 high, 160 wide), built around the origin and
 * placed by its animation. */
#define CUBE_HALF 80.0f

fv_status fv_builtin_cornell_fir(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    fv_cornell_mats cm;
    fv_status st = fv_cornell_wall_materials(s, &cm, err);
    if (st != FV_OK) return st;
    fv_material y = fv_material_default(FV_MAT_DIFFUSE);
    y.albedo = fv_v3(0.75f, 0.62f, 0.12f);
    int yellow, cube = -1;
    if ((st = fv_builtin_material(s, "yellow", y, &yellow, err)) != FV_OK || (st = fv_cornell_walls(s, &cm, log, err)) != FV_OK ||
        (st = fv_cornell_tall_block(s, cm.white, log, err)) != FV_OK)
        return st;

    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_box(&mb, P(0, 0, 0), fv_v3s(CUBE_HALF), 0.0f, yellow);
    st = fv_meshbuf_add(&mb, s, "yellow_cube", log, &cube, err);
    fv_meshbuf_free(&mb);
    if (st != FV_OK) return st;

    /* The cube rests on the floor (centre at y = 80) near the green wall, where the short block
     * stands, slides to the red wall in front of the tall block while turning, and comes back.
     * Its half diagonal is 113: at z <= 125 it keeps clear of the tall block (whose nearest
     * corner is at z = 247) and at 135 <= x <= 420 of the side walls. */
    const fv_vec3 up = P(0, 1, 0), one = fv_v3s(1.0f);
    const fv_anim_key keys[3] = {
        {0.0, P(150, CUBE_HALF, 125), fv_quat_axis_angle(up, fv_radians(-20.0f)), one},
        {2.0, P(415, CUBE_HALF, 115), fv_quat_axis_angle(up, fv_radians(25.0f)), one},
        {LOOP, P(150, CUBE_HALF, 125), fv_quat_axis_angle(up, fv_radians(-20.0f)), one},
    };
    if ((st = fv_scene_animate_object(s, cube, keys, 3, err)) != FV_OK) return st;

    /* The light: its keys translate it from the circle's centre. */
    fv_light_desc l = {FV_LIGHT_POINT, P(LIGHT_CX, LIGHT_Y, LIGHT_CZ), P(0, -1, 0), fv_v3(17.0f * LIGHT_SCALE, 12.0f * LIGHT_SCALE, 4.0f * LIGHT_SCALE),
                       0.0f, 0.0f};
    if ((st = fv_scene_add_light(s, &l, err)) != FV_OK) return st;
    fv_anim_key lk[LIGHT_KEYS];
    for (int i = 0; i < LIGHT_KEYS; i++) {
        double a = 2.0 * FV_PI * i / (LIGHT_KEYS - 1);
        lk[i] = (fv_anim_key){LOOP * i / (LIGHT_KEYS - 1), P(LIGHT_R * cos(a), 0, LIGHT_R * sin(a)), (fv_quat){0, 0, 0, 1}, one};
    }
    if ((st = fv_scene_animate_light(s, fv_scene_light_count(s) - 1, lk, LIGHT_KEYS, err)) != FV_OK) return st;

    fv_camera cam = fv_cornell_camera();
    fv_view_set_camera(view, &cam);
    return FV_OK;
}
