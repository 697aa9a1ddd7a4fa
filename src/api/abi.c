/* fovea — the sizes of the public structs, for bindings that mirror them (python/fovea/_capi.py):
 * a binding built for another layout finds out when it loads the library, not by corrupting
 * memory the first time the library writes a struct it allocated too small. */
#include <string.h>
#include "fovea/fovea.h"

size_t fv_abi_sizeof(const char *type_name)
{
    static const struct {
        const char *name;
        size_t size;
    } k[] = {
        {"fv_error", sizeof(fv_error)},           {"fv_log", sizeof(fv_log)},
        {"fv_vec3", sizeof(fv_vec3)},             {"fv_camera", sizeof(fv_camera)},
        {"fv_camera_key", sizeof(fv_camera_key)}, {"fv_camera_path", sizeof(fv_camera_path)},
        {"fv_gaze", sizeof(fv_gaze)},             {"fv_gaze_key", sizeof(fv_gaze_key)},
        {"fv_eye_model", sizeof(fv_eye_model)},   {"fv_light_desc", sizeof(fv_light_desc)},
        {"fv_env_desc", sizeof(fv_env_desc)},     {"fv_stat_entry", sizeof(fv_stat_entry)},
        {"fv_stats", sizeof(fv_stats)},           {"fv_drive_opts", sizeof(fv_drive_opts)},
        {"fv_frame_views", sizeof(fv_frame_views)}, {"fv_image", sizeof(fv_image)},
        {"fv_metric_opts", sizeof(fv_metric_opts)}, {"fv_metric_values", sizeof(fv_metric_values)},
        {"fv_metric_report", sizeof(fv_metric_report)}, {"fv_bench_options", sizeof(fv_bench_options)},
        {"fv_build_info", sizeof(fv_build_info)}, {"fv_heatmap_opts", sizeof(fv_heatmap_opts)},
    };
    for (size_t i = 0; type_name && i < sizeof k / sizeof k[0]; i++)
        if (!strcmp(k[i].name, type_name)) return k[i].size;
    return 0;
}
