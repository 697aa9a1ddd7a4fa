/* fovea CLI — `fovea methods` and `fovea scenes`: what can be rendered, with what. */
#include <string.h>
#include "cli.h"

int fv_cmd_methods(int argc, char **argv)
{
    if (argc > 1 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
        printf("usage: fovea methods [NAME]\nLists rendering methods; with NAME, that method's parameters.\n");
        return FV_EXIT_OK;
    }
    if (argc > 2) return fv_cli_usage_error("methods", "too many arguments");
    for (int i = 0; i < fv_technique_count(); i++) {
        if (argc == 2 && strcmp(argv[1], fv_technique_name(i))) continue;
        printf("%-16s %s\n", fv_technique_name(i), fv_technique_summary(i));
        const char *h = fv_technique_params_help(i);
        while (h && *h) {
            const char *nl = strchr(h, '\n');
            int len = nl ? (int)(nl - h) : (int)strlen(h);
            printf("%18s--param %.*s\n", "", len, h);
            h = nl ? nl + 1 : h + len;
        }
        /* Every method runs on the CPU; the others are the ones --device may choose. */
        if (fv_technique_has_device(i, FV_DEVICE_PORTABLE) || fv_technique_has_device(i, FV_DEVICE_CUDA))
            printf("%18sdevices: cpu%s%s (--device D or --param device=D; docs/gpu.md)\n", "", fv_technique_has_device(i, FV_DEVICE_PORTABLE) ? ", portable" : "",
                   fv_technique_has_device(i, FV_DEVICE_CUDA) ? ", cuda" : "");
        if (argc == 2) return FV_EXIT_OK;
    }
    if (argc == 2) return fv_cli_usage_error("methods", "unknown method '%s'", argv[1]);
    return FV_EXIT_OK;
}

int fv_cmd_scenes(int argc, char **argv)
{
    if (argc > 1 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
        printf("usage: fovea scenes\nLists the built-in scenes (any .json/.obj/.gltf/.glb/.ply file works too).\n");
        return FV_EXIT_OK;
    }
    if (argc > 1) return fv_cli_usage_error("scenes", "unexpected argument '%s'", argv[1]);
    for (int i = 0; i < fv_builtin_count(); i++) printf("%-14s %s\n", fv_builtin_name(i), fv_builtin_summary(i));
    return FV_EXIT_OK;
}
