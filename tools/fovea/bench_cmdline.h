/* fovea CLI — `fovea bench --scene SCENE --methods a,b ...`: a comparison scenario built from the
 * command line, run by the same harness (cache and reports) as a scenario file. */
#ifndef FV_CLI_BENCH_CMDLINE_H
#define FV_CLI_BENCH_CMDLINE_H

#include "cli.h"

typedef struct fv_bench_cmdline {
    const char *scene;      /* built-in name or a file (made absolute) */
    const char *methods;    /* "fpm,pm:photons=20000,pm-t": METHOD[:KEY=VALUE...] separated by commas */
    const char *reference;  /* "pt:spp=1024" (NULL: that) */
    const char *gaze_trace; /* a CSV gaze trace, or NULL */
    bool has_gaze;
    float gaze[2];
    int frames, width, height; /* 0: the scenario format's defaults (1 frame, 256x256) */
} fv_bench_cmdline;

/* The scenario as JSON text (free it) and the label it is run under (its name + ".json"); 0, or
 * the exit status after a one-line message naming the bad option. */
int fv_bench_cmdline_json(const char *cmd, const fv_bench_cmdline *c, char **json, char *label, size_t label_n);

#endif
