/* fovea — a benchmark scenario in memory (parsed from bench/<name>.json, see docs/bench.md). */
#ifndef FV_BENCH_SCENARIO_H
#define FV_BENCH_SCENARIO_H

#include <stdbool.h>
#include "fovea/bench.h"
#include "fovea/camera.h"
#include "fovea/gaze.h"
#include "fovea/scene.h"
#include "fovea/technique.h"

#define FV_BENCH_LABEL_MAX 64
#define FV_BENCH_MAX_EXTRA 4   /* extra references a scenario may measure errors against */
#define FV_BENCH_MAX_SWEEPS 16  /* sweeps in a "sweep" array */
#define FV_BENCH_MAX_ANIMATE 64 /* entries of "animate" */

typedef struct fv_bench_method {
    char label[FV_BENCH_LABEL_MAX];
    char method[FV_BENCH_LABEL_MAX];
    fv_params *params;
    bool from_sweep;
    int sweep;               /* from_sweep: which of fv_scenario.sweeps made it */
    double sweep_value;
    int match;               /* 0: an ordinary row; k > 0: the row "match" search k - 1 chose */
    bool match_reached;
} fv_bench_method;

/* "match": the smallest value of `param` for which `method` reaches the `target` method's
 * error (`metric` in `region`), e.g. the paper's PM_eq: photon mapping with the photon count
 * that matches foveated photon mapping's error in the fovea. */
typedef struct fv_bench_match {
    fv_bench_method base;
    char param[FV_BENCH_LABEL_MAX];
    double values[64];
    int nvalues;
    char target[FV_BENCH_LABEL_MAX];
    char metric[16];   /* "mse", "flip", "e" (lower is better) */
    fv_region region;
} fv_bench_match;

/* One sweep: a method run once per value of one parameter; its rows are methods[first ..
 * first + count - 1]. */
typedef struct fv_bench_sweep {
    char param[FV_BENCH_LABEL_MAX];
    char method[FV_BENCH_LABEL_MAX];
    int first, count;
} fv_bench_sweep;

/* One entry of "animate": keys that replace the animation of a point/spot light or an object of
 * the scene before it is committed (docs/bench.md). */
typedef struct fv_bench_animate {
    int light;                  /* >= 0: the light of this index (fv_scene_add_light order) */
    char object[FV_NAME_MAX];   /* light < 0: the first object of this name */
    fv_anim_key *keys;
    int nkeys;
} fv_bench_animate;

typedef struct fv_scenario {
    char name[FV_BENCH_LABEL_MAX];
    char *description;
    char *scene;             /* built-in name or a path resolved against the scenario's folder */
    bool diffuse;            /* every material made diffuse before commit (fv_scene_make_diffuse) */
    fv_bench_animate *animate; /* applied, in order, before commit */
    int nanimate;
    int width, height;
    int frames;
    int measure_from;        /* errors over frames [measure_from, frames): earlier ones build history */
    double fps, start_time;
    int repeats;
    float exposure;
    unsigned long long seed;
    fv_eye_model eye;        /* the scenario's "eye" block (has_eye), then the one the driver used */
    bool has_eye;
    fv_gaze_path *gaze;      /* NULL: the scene's gaze path, else the centre */
    float stereo;            /* > 0: stereo pairs, eyes this far apart (scene units); 0: mono */
    fv_camera_key *cam_keys; /* optional camera path overriding the scene's */
    int ncam_keys;
    fv_bench_method reference;
    fv_bench_method extra[FV_BENCH_MAX_EXTRA]; /* "extra_references": more errors, e.g. against pt */
    int nextra;
    char baseline[FV_BENCH_LABEL_MAX]; /* label of the method speed-ups are relative to */
    fv_bench_method *methods;          /* listed methods, then the sweep's */
    int nmethods;
    fv_bench_sweep sweeps[FV_BENCH_MAX_SWEEPS];
    int nsweeps;
    bool sweep_array;                  /* "sweep" was an array: one NAME-sweep-PARAM.csv/png each */
    fv_bench_match *matches;
    int nmatches;
} fv_scenario;

fv_status fv_scenario_load(const char *path, fv_bench_mode mode, fv_scenario **out, fv_error *err);
/* The same from JSON text: `label` stands for the file name (messages, default name), `dir` for
 * its folder (relative scene and trace paths). */
fv_status fv_scenario_load_text(const char *text, const char *label, const char *dir, fv_bench_mode mode, fv_scenario **out, fv_error *err);
void fv_scenario_destroy(fv_scenario *s);

#endif
