/* fovea — `furnace`, the white furnace test: the camera sits at the centre of a closed sphere
 * whose inside is diffuse (albedo a = 0.5) and emits Le = 0.5 from both sides. Every path sees
 * L = Le + a L, so the radiance is exactly Le / (1 - a) = 1 in every direction and channel: an
 * end-to-end check of any estimator's energy conservation (tests/unit/test_pt.c). The emissive
 * triangles are the scene's lights, so commit adds no default light.
 *
 * Limits: the sphere is tessellated (2 * 48 * 23 triangles), which does not matter here: the
 * answer holds for any closed surface of uniform albedo and emission.
 */
#include "scene/builtin_impl.h"

fv_status fv_builtin_furnace(fv_scene *s, fv_view *view, const fv_log *log, fv_error *err)
{
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    m.albedo = fv_v3s(0.5f);
    m.emission = fv_v3s(0.5f);
    m.two_sided_emission = true;
    int id;
    fv_status st = fv_builtin_material(s, "furnace", m, &id, err);
    if (st != FV_OK) return st;
    fv_meshbuf mb;
    fv_meshbuf_init(&mb);
    fv_mesh_sphere(&mb, fv_v3(0, 0, 0), 1.0f, 48, 24, true, id);
    st = fv_meshbuf_add(&mb, s, "furnace", log, NULL, err);
    fv_meshbuf_free(&mb);
    if (st != FV_OK) return st;
    const fv_camera cam = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 60.0f, 256, 256};
    fv_view_set_camera(view, &cam);
    return FV_OK;
}
