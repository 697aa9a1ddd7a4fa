/* fovea — the path tracing kernel on the CPU's scene (see path.h): kernel/kpath_impl.h, the
 * estimator every device runs, with Embree answering the ray queries.
 */
#include <math.h>
#include "core/params_read.h"
#include "kernel/kbsdf.h"
#include "scene/light.h"
#include "transport/path.h"

#define FV_PATH_FN fv_path_trace_from
#define FV_PATH_QUAL
#define FV_PATH_SCENE fv_scene
#define FV_PATH_INTERSECT(s, o, d, h) fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, h)
#define FV_PATH_MATERIAL(s, h, buf) fv_hit_material(s, h, buf)
#define FV_PATH_LIGHTS(s) fv_scene_klights(s)
#define FV_PATH_LIGHT_OF(s, h) fv_light_of_triangle(s, (h)->obj, (h)->prim)
#define FV_PATH_VISIBLE(s, p, ng, q) fv_scene_visible(s, FV_TRACE_ALL, p, ng, q)
#define FV_PATH_OFFSET(s, p, ng, d) fv_offset_point(s, p, ng, d)
#include "kernel/kpath_impl.h"

fv_vec3 fv_path_trace(const fv_scene *s, const fv_path_opts *opt, fv_vec3 o, fv_vec3 d, fv_rng *rng, fv_path_first_hit *first,
                      uint64_t *rays)
{
    return fv_path_trace_from(s, opt, o, d, NULL, false, rng, first, rays);
}

fv_status fv_path_read_opts(fv_params *p, fv_path_opts *opt, fv_error *err)
{
    fv_status s;
    if ((s = fv_params_int(p, "spp", 16, 1, 1 << 20, &opt->spp, err)) != FV_OK) return s;
    if ((s = fv_params_int(p, "max_depth", 8, 1, 1024, &opt->max_depth, err)) != FV_OK) return s;
    if ((s = fv_params_int(p, "rr_depth", 3, 1, 1024, &opt->rr_depth, err)) != FV_OK) return s;
    return FV_OK;
}
