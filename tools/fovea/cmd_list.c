/* fovea CLI — `fovea methods` and `fovea scenes`: what can be rendered, with what. Everything
 * `fovea methods` says comes from the registry's description of each method (fovea/technique.h):
 * the text here, the JSON from fv_methods_json. */
#include <stdlib.h>
#include <string.h>
#include "cli.h"

/* "cpu, portable, cuda" */
static void print_devices(int i)
{
    printf("cpu%s%s", fv_technique_has_device(i, FV_DEVICE_PORTABLE) ? ", portable" : "",
           fv_technique_has_device(i, FV_DEVICE_CUDA) ? ", cuda" : "");
}

/* "photons = 10000 30000 100000 [300000] 1000000": the default step in brackets. */
static void print_main(int i)
{
    if (!fv_technique_main_param(i)) {
        printf("none");
        return;
    }
    printf("%s =", fv_technique_main_param(i));
    for (int k = 0; k < fv_technique_main_step_count(i); k++)
        printf(k == fv_technique_main_default_step(i) ? " [%s]" : " %s", fv_technique_main_step(i, k));
}

/* One method of the list: name and summary on a line of its own (scripts take the first word of
 * the lines that start with a letter), then what it is measured against and what it costs. */
static void print_entry(int i)
{
    printf("%-16s %s\n", fv_technique_name(i), fv_technique_summary(i));
    printf("%18s%s", "", fv_technique_foveated(i) ? "foveated; " : "");
    if (fv_technique_baseline(i)) printf("against %s; ", fv_technique_baseline(i));
    else printf("the reference; ");
    printf("devices: ");
    print_devices(i);
    if (fv_technique_still_warmup(i) > 0)
        printf("; a still warms up %d frame%s", fv_technique_still_warmup(i), fv_technique_still_warmup(i) == 1 ? "" : "s");
    if (fv_technique_warmup_frames(i) > 0) printf("; an MPI block %d", fv_technique_warmup_frames(i));
    printf("; main parameter ");
    print_main(i);
    printf("\n");
}

/* The whole registry, grouped by family in the order of each family's first method. */
static void print_list(void)
{
    const int n = fv_technique_count();
    for (int i = 0; i < n; i++) {
        bool seen = false;
        for (int k = 0; k < i && !seen; k++) seen = strcmp(fv_technique_family(k), fv_technique_family(i)) == 0;
        if (seen) continue;
        printf("%s# %s\n", i ? "\n" : "", fv_technique_family(i));
        for (int k = i; k < n; k++)
            if (strcmp(fv_technique_family(k), fv_technique_family(i)) == 0) print_entry(k);
    }
}

static void print_param(const fv_param_info *p)
{
    int len = fv_param_info_format(p, NULL, 0);
    char *line = malloc((size_t)len + 1);
    if (!line) return;
    fv_param_info_format(p, line, (size_t)len + 1);
    printf("    %s\n", line);
    free(line);
}

/* One method in full: what the list says, then every parameter. */
static void print_method(int i)
{
    printf("%s: %s\n", fv_technique_name(i), fv_technique_summary(i));
    printf("  family          %s\n", fv_technique_family(i));
    printf("  foveated        %s\n", fv_technique_foveated(i) ? "yes: less effort away from the gaze" : "no");
    printf("  baseline        %s\n", fv_technique_baseline(i) ? fv_technique_baseline(i) : "none: the reference");
    printf("  devices         ");
    print_devices(i);
    printf(" (--device D or --param device=D; docs/gpu.md)\n");
    printf("  still warm-up   %d frame(s) rendered at frame 0's view before the first written (--warmup N)\n", fv_technique_still_warmup(i));
    printf("  block warm-up   %d frame(s) an MPI rank's block of a sequence starts with (docs/distributed.md)\n", fv_technique_warmup_frames(i));
    printf("  --spp N sets    %s\n", fv_technique_spp_param(i) ? fv_technique_spp_param(i) : "nothing (refused)");
    printf("  main parameter  ");
    print_main(i);
    printf("\n  parameters (--param KEY=VALUE):\n");
    for (int j = 0; j < fv_technique_param_count(i); j++) print_param(fv_technique_param_at(i, j));
    if (fv_technique_has_device(i, FV_DEVICE_PORTABLE) || fv_technique_has_device(i, FV_DEVICE_CUDA)) print_param(fv_technique_device_param());
}

int fv_cmd_methods(int argc, char **argv)
{
    const char *name = NULL;
    bool json = false;
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--help") || !strcmp(argv[a], "-h")) {
            printf("usage: fovea methods [NAME] [--json]\n"
                   "Lists the rendering methods by family: foveated or not, the method each is measured against,\n"
                   "devices, warm-up frames and main parameter. With NAME, that method and every parameter it\n"
                   "takes (--param KEY=VALUE). --json: the same as one JSON document (numbers as numbers).\n");
            return FV_EXIT_OK;
        }
        if (!strcmp(argv[a], "--json")) json = true;
        else if (argv[a][0] == '-') return fv_cli_usage_error("methods", "unknown option '%s'", argv[a]);
        else if (name) return fv_cli_usage_error("methods", "too many arguments");
        else name = argv[a];
    }
    fv_error err;
    int i = name ? fv_technique_index(name) : -1;
    if (name && i < 0) {
        fv_technique *t = NULL;
        return fv_cli_fail("methods", fv_technique_create(name, NULL, NULL, NULL, &t, &err), err.msg); /* names the known ones */
    }
    if (json) {
        char *doc = fv_methods_json(name, &err);
        if (!doc) return fv_cli_fail("methods", FV_ERR_NOMEM, err.msg);
        printf("%s\n", doc);
        fv_methods_json_free(doc);
    } else if (name) {
        print_method(i);
    } else {
        print_list();
    }
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
