/* fovea — rendering methods: the reference path tracer, each foveated technique and each baseline,
 * found by name in a registry and driven through one interface.
 *
 * The CLI, the viewer and the benchmark harness drive every method through these calls only (via
 * the sequence driver, fovea/drive.h), so comparisons are fair: same scene, cameras, gaze and film.
 * A method keeps its temporal state (photon maps, history buffers) in its instance between frames.
 *
 * Lifetime: the scene must outlive every technique created on it, and must not be changed (except
 * by fv_scene_set_time between renders) while one renders. Thread-safety: one instance renders one
 * frame at a time; different instances on the same scene may render concurrently.
 *
 * The technique class is private to the library (docs/architecture.md says why): new methods are
 * added in src/technique/ and listed in its registry.
 */
#ifndef FOVEA_TECHNIQUE_H
#define FOVEA_TECHNIQUE_H

#include <stdbool.h>
#include <stddef.h>
#include "fovea/export.h"
#include "fovea/film.h"
#include "fovea/frame.h"
#include "fovea/params.h"
#include "fovea/scene.h"
#include "fovea/stats.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The registry, in a fixed order: name ("pt", "fpm", ...) and one-line summary. NULL for i out of
 * range. Static strings. */
FV_API int fv_technique_count(void);
FV_API const char *fv_technique_name(int i);
FV_API const char *fv_technique_summary(int i);
/* Index of a method by name, -1 when unknown. */
FV_API int fv_technique_index(const char *name);
/* The key of method i's samples-per-pixel parameter ("spp" for pt), NULL when the method has no
 * such notion (or i is out of range). */
FV_API const char *fv_technique_spp_param(int i);
/* Whether method i spends less effort away from the gaze (its image depends on the gaze); false
 * for an index out of range. */
FV_API bool fv_technique_foveated(int i);
/* The family method i belongs to, the kind of light transport its paper is about: "path tracing",
 * "photon mapping", "instant radiosity", "sphere tracing", "visual-polar path tracing". NULL for i
 * out of range. Families follow the registry's order of their first method. */
FV_API const char *fv_technique_family(int i);
/* The method method i is measured against in its paper or its family's benchmarks (fpm: "pm",
 * vpolar: "cartesian-full", ...): a registered method, never i itself, and following baselines
 * always ends at the reference path tracer, the one method without a baseline (NULL). */
FV_API const char *fv_technique_baseline(int i);
/* Frames a method with temporal state (history buffers, photons or VPLs carried over) renders
 * before its image stands for the method's steady state: 0 for a method whose frames do not
 * depend on the ones before; what a block of an MPI-split sequence starts with (docs/distributed.md). */
FV_API int fv_technique_warmup_frames(int i);
/* Frames method i renders before a still (or a sequence's first frame) is converged: `fovea
 * render` runs them unwritten at frame 0's views (fv_drive_opts.warmup). 0 for a method whose
 * first frame is already its steady state (photons, fipr's refresh), and for an index out of range. */
FV_API int fv_technique_still_warmup(int i);
/* The built-in scene method i's family benchmarks it on ("cornell-fpm" for the photon family,
 * "sdf-temple" for the sphere tracers, ...; "cornell" when its family has none of its own): what
 * `fovea bench scaling` renders it in. NULL for i out of range. */
FV_API const char *fv_technique_bench_scene(int i);
/* What a sample block of method i holds ("samples" for pt, "passes" for ppm) when its estimate is
 * the sum of such blocks along one fixed tree (parameters block_first and block_count render a
 * range of them), so that a still may be split over MPI ranks and stay the one-process image bit
 * for bit (docs/distributed.md); NULL for any other method and for i out of range. */
FV_API const char *fv_technique_block_unit(int i);
/* Why a still of method i is rendered in one process when its parameter *param is above 1 (pm:
 * "passes", "averaged and filtered in one process": its passes are not a sum of blocks); NULL,
 * with *param NULL, for a method without such a parameter. */
FV_API const char *fv_technique_unsplit(int i, const char **param);

/* ---- parameters: every key a method reads from its fv_params bag, described once ----
 *
 * Every method also takes `device` (fv_technique_device_param), which the registry reads for it. */
typedef enum fv_param_type {
    FV_PARAM_INT,    /* a decimal integer */
    FV_PARAM_FLOAT,  /* a finite number */
    FV_PARAM_BOOL,   /* on/off, true/false, yes/no, 1/0 */
    FV_PARAM_CHOICE, /* one of `choices` */
    FV_PARAM_STRING  /* any text */
} fv_param_type;

typedef struct fv_param_info {
    const char *key;
    fv_param_type type;
    /* The default, as a --param value would write it ("16", "0.61", "true", "grid"): setting the key
     * to it changes nothing. NULL when the method derives it from the scene or from other
     * parameters; def_note then says how ("Eq. 8", "all from block_first"). */
    const char *def;
    /* A qualifier shown with the default: its derivation, or what bounds it besides (NULL: none). */
    const char *def_note;
    /* int and float: the values accepted lie within [min, max], an end excluded when its _open flag
     * is set. A value outside is refused with FV_ERR_INVALID; other parameters may narrow the range
     * further (the help says so). */
    double min, max;
    bool min_open, max_open;
    /* choice: the values accepted, NULL-terminated. int: when not NULL, the only values accepted. */
    const char *const *choices;
    const char *help; /* what it means, one line */
} fv_param_info;

/* Method i's parameters in the order its help lists them; NULL for an index out of range. */
FV_API int fv_technique_param_count(int i);
FV_API const fv_param_info *fv_technique_param_at(int i, int j);
/* Method i's parameter `key`, NULL when it has none of that name. */
FV_API const fv_param_info *fv_technique_param_find(int i, const char *key);
/* The parameter every method takes: device=cpu|portable|cuda|auto (cpu), read by the registry. */
FV_API const fv_param_info *fv_technique_device_param(void);
/* "int", "float", "bool", "choice", "string". */
FV_API const char *fv_param_type_name(fv_param_type type);
/* One line "key=TYPE (DEFAULT) in RANGE: help" into buf (TYPE is the choices a|b|c of a choice or
 * of an int with choices; RANGE [min, max] of an int or float, an open end written with a
 * parenthesis), no newline; returns what snprintf returns. The text `fovea methods NAME` prints. */
FV_API int fv_param_info_format(const fv_param_info *p, char *buf, size_t n);

/* ---- the main parameter: what sets method i's cost, as an interactive viewer steps it ---- */
/* Its key, NULL when the method has none. */
FV_API const char *fv_technique_main_param(int i);
/* The values offered, in increasing order (+ steps up, - down): the papers' settings around the
 * default, as text. */
FV_API int fv_technique_main_step_count(int i);
FV_API const char *fv_technique_main_step(int i, int k);
/* The step equal to the parameter's default, -1 when none is (or no main parameter). */
FV_API int fv_technique_main_default_step(int i);
/* Whether method i's frames are independent estimates of one image, so that frames rendered while
 * nothing moves may be averaged (a viewer then starts it at its first step). */
FV_API bool fv_technique_progressive(int i);
/* The method an interactive viewer starts with when none is named (a static string). */
FV_API const char *fv_technique_default_interactive(void);

/* ---- the registry as JSON (`fovea methods --json`) ----
 *
 * A document {"families": [{"name", "methods": [names]}], "common_parameters": [device],
 * "methods": [{"name", "summary", "family", "foveated", "baseline", "devices", "warmup_frames", "still_warmup_frames",
 * "spp_param", "spp_instead", "sdf_only", "main_parameter": {"key", "steps", "default_step",
 * "progressive"} or null, "parameters": [{"key", "type", "default", "default_note", "min", "max",
 * "min_open", "max_open", "choices", "help"}]}]}; values of numeric parameters (defaults, bounds,
 * numeric choices and steps) are JSON numbers, a bool's default true or false, a derived default
 * null. name NULL: every method; else that method alone (FV_ERR_INVALID naming the known methods
 * when there is none of that name). Returns a string to release with fv_methods_json_free, NULL on
 * failure (err says why). */
FV_API char *fv_methods_json(const char *name, fv_error *err);
FV_API void fv_methods_json_free(char *json);
/* Sets method `name`'s samples-per-pixel parameter to spp in params (what the CLI's --spp means
 * for every method). FV_ERR_INVALID, with a one-line message naming the parameter to use instead,
 * when the method has none; the message of fv_technique_create when the name is unknown. */
FV_API fv_status fv_technique_set_spp(const char *name, fv_params *params, int spp, fv_error *err);

typedef struct fv_technique fv_technique;

/* Creates method `name` on a committed scene with parameters (NULL: defaults; read, not kept).
 * Unknown name, unknown parameter key or bad value -> FV_ERR_INVALID naming it. Release with
 * fv_technique_destroy, before the scene. log (may be NULL) receives warnings. */
FV_API fv_status fv_technique_create(const char *name, const fv_scene *scene, const fv_params *params, const fv_log *log,
                                     fv_technique **out, fv_error *err);
/* Renders one eye of one frame into film (its size must match the frame's camera). Stats are
 * added to *stats (not cleared). FV_ERR_CANCELLED when the frame's progress callback asked so;
 * the film's contents are then undefined. */
FV_API fv_status fv_technique_render(fv_technique *t, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
/* Renders both eyes of a stereo frame: frames[0] is eye 0 and frames[1] eye 1, both with
 * eye_count 2 and the same index and time, films[e] of frames[e]'s camera's size. The same images
 * and counters as fv_technique_render for eye 0 then eye 1 (what it does for a method without a
 * pair path); a method with one (the sphere tracers on a device, docs/gpu.md) runs both eyes at
 * once, with no host round trip between them on a GPU. Each eye reports progress through its own
 * frame's callback. */
FV_API fv_status fv_technique_render_pair(fv_technique *t, const fv_frame frames[2], fv_film *const films[2], fv_stats *stats,
                                          fv_error *err);
/* ---- frames in flight: a sequence that queues frame N+1 before it waits for frame N ----
 *
 * fv_technique_submit queues one frame, `eyes` 1 (frames[0] into films[0], as fv_technique_render)
 * or 2 (a stereo pair into films[0] and films[1], as fv_technique_render_pair), with the same
 * checks, and returns; on a GPU before the device has run it (the films are read back through two
 * pinned staging slots, docs/gpu.md "Frames in flight"). fv_technique_collect waits for the oldest
 * frame submitted and delivers it into the films and stats it was submitted with: they must stay
 * alive, and the films unread, until then. The images and stats are fv_technique_render's; a
 * method without a device frame (every CPU method) renders in submit, and collect only hands the
 * frame over. At most FV_TECHNIQUE_IN_FLIGHT frames are in flight: a third submit, a collect with
 * none in flight and a render with frames in flight are refused (FV_ERR_INVALID).
 * Progress is reported, and may cancel, within submit only. A submit that fails or is cancelled
 * leaves nothing of its frame queued or in flight (the frames before it stay collectable, so a
 * sequence still writes them); a collect that fails has taken its frame all the same. Destroying
 * the technique drops the frames in flight (their films are left as they were). */
#define FV_TECHNIQUE_IN_FLIGHT 2
FV_API fv_status fv_technique_submit(fv_technique *t, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats,
                                     fv_error *err);
FV_API fv_status fv_technique_collect(fv_technique *t, fv_error *err);
/* Frames submitted and not yet collected (0 for NULL). */
FV_API int fv_technique_in_flight(const fv_technique *t);
/* The method's registry name (a static string). */
FV_API const char *fv_technique_name_of(const fv_technique *t);
/* NULL is ignored. */
FV_API void fv_technique_destroy(fv_technique *t);

#ifdef __cplusplus
}
#endif
#endif
