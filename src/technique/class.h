/* fovea — the technique class: what a rendering method implements to be driven like every other.
 *
 * Private to the library (docs/architecture.md, "The boundary"): a class is defined in its family's
 * folder and listed in registry.c; drivers only see fovea/technique.h. The registry wraps create
 * and render with what every method shares: parameters are validated on a private copy of the
 * caller's bag and unknown keys refused once, after create; films are checked against the frame.
 */
#ifndef FV_TECHNIQUE_CLASS_H
#define FV_TECHNIQUE_CLASS_H

#include "core/params_read.h"
#include "fovea/device.h"
#include "fovea/technique.h"

#define FV_MAIN_STEPS_MAX 8 /* the most values a main parameter steps through */

/* A class's parameter table and its length, for the class's initializer. */
#define FV_CLASS_PARAMS(table) .params = (table), .param_count = (int)(sizeof(table) / sizeof((table)[0]))

/* Entries of a parameter table (fovea/technique.h, fv_param_info): an int or float in [lo, hi], a
 * bool, one of a NULL-terminated list of choices. An entry with an open end, an int of a few values
 * or a derived default spells out the fields it needs. */
#define FV_PARAM_INT(k, d, lo, hi, h) {.key = (k), .type = FV_PARAM_INT, .def = (d), .min = (lo), .max = (hi), .help = (h)}
#define FV_PARAM_FLOAT(k, d, lo, hi, h) {.key = (k), .type = FV_PARAM_FLOAT, .def = (d), .min = (lo), .max = (hi), .help = (h)}
#define FV_PARAM_BOOL(k, d, h) {.key = (k), .type = FV_PARAM_BOOL, .def = (d), .help = (h)}
#define FV_PARAM_CHOICE(k, d, list, h) {.key = (k), .type = FV_PARAM_CHOICE, .def = (d), .choices = (list), .help = (h)}

/* The families (fovea/technique.h, fv_technique_family), named once. */
#define FV_FAMILY_PT "path tracing"
#define FV_FAMILY_PHOTON "photon mapping"
#define FV_FAMILY_VPL "instant radiosity"
#define FV_FAMILY_SDF "sphere tracing"
#define FV_FAMILY_VPOLAR "visual-polar path tracing"

typedef struct fv_technique_class {
    const char *name;    /* "pt", "fpm", ... */
    const char *summary; /* one line */
    /* fovea/technique.h's fv_technique_family and fv_technique_baseline: the family (one of the
     * FV_FAMILY_* above) and the method this one is measured against (NULL: pt only); the class
     * says where in its paper or benchmarks the pairing comes from. */
    const char *family, *baseline;
    /* Every key create reads, with its type, default, range and meaning: what `fovea methods`, its
     * JSON and the CLI's help print, and what the conformance suite holds the readers to (every key
     * read is declared, the declared defaults change nothing, a value outside the declared range is
     * refused). FV_CLASS_PARAMS(table) sets both. */
    const fv_param_info *params;
    int param_count;
    /* The parameter that sets the method's cost and the values an interactive viewer steps it
     * through, in increasing order (fovea/technique.h, fv_technique_main_param); key NULL: none.
     * progressive: frames are independent estimates of one image, so a still view may average them. */
    struct {
        const char *key;
        const char *steps[FV_MAIN_STEPS_MAX + 1]; /* NULL-terminated */
        bool progressive;
    } main;
    /* Reads its parameters with the fv_params_* readers (keys it never reads are refused after
     * create returns) and prepares its state. The scene is committed and outlives the state. */
    fv_status (*create)(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err);
    /* Renders one eye of one frame (frame->eye) into film, whose size matches frame->camera.
     * Adds stage timings and counters to stats. */
    fv_status (*render)(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err);
    /* Optional: renders both eyes of a stereo frame (frames[0] eye 0, frames[1] eye 1, same index
     * and time; films[e] matches frames[e]'s camera) in one call, so a device can run both eyes
     * without a host round trip between them. Its images and counters must be those of render
     * called for eye 0 then eye 1. NULL: fv_technique_render_pair calls render twice. */
    fv_status (*render_pair)(void *state, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err);
    /* Optional, both or neither: render split in two, so that a sequence queues frame N+1 before it
     * waits for frame N (fovea/technique.h, fv_technique_submit). submit queues one frame of `eyes`
     * eyes (1, or a stereo pair as render_pair takes them) with its read-back into the next of two
     * staging slots, and returns without waiting for the device; collect waits for the oldest
     * frame submitted and delivers it into the films and stats it was submitted with (the class
     * keeps those pointers). The registry keeps at most two frames in flight and calls progress
     * only within submit. A submit that fails or is cancelled waits for what it queued and leaves
     * no frame of its own in flight, the ones before it still collectable; a collect that fails
     * has still taken its frame; destroy drops what is in flight. Images and counters are
     * render's: a class with the split renders as submit then collect. NULL: the registry renders
     * in submit and collect only hands the frame over. */
    fv_status (*submit)(void *state, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err);
    fv_status (*collect)(void *state, fv_error *err);
    void (*destroy)(void *state);
    /* Devices beyond the CPU (fovea/device.h): a bit (1 << FV_DEVICE_*) per device the method
     * also runs on; 0 for a CPU-only method. Such a method is created by create_on, which is told
     * the device the registry resolved from the parameter `device` (create is then unused). */
    unsigned devices;
    fv_status (*create_on)(const fv_scene *scene, fv_params *params, fv_device device, const fv_log *log, void **state, fv_error *err);
    /* The method sphere-traces signed distance fields only: the registry refuses a scene without
     * an SDF object, and the conformance suite runs it in the SDF twins of its scenes. */
    bool sdf_only;
    /* For the conformance suite (tests/conformance): parameters that make a small render cheap
     * in any scene; what the furnace (a unit sphere) adds to them; and the radiance the method
     * should see there, with the relative tolerance its estimator and filters deserve. */
    const char *test_params, *furnace_params;
    double furnace_radiance, furnace_tolerance;
    /* The key of the method's samples-per-pixel parameter (what `--spp N` sets), NULL when it has
     * none; then spp_instead names what to use instead, as a clause of one line. */
    const char *spp_param, *spp_instead;
    /* The method estimates light from photons gathered in a disc about each shading point (the
     * photon family): tests/unit/test_photon_leak.c checks that no light leaks through walls
     * thinner than the disc. */
    bool gathers_photons;
    /* The method spends less effort away from the gaze (fovea/gaze.h's eye model, or a foveal
     * parameter of its own). While the frame's fovea covers the whole screen (fv_frame_fovea_covers:
     * a missing gaze under `--gaze-missing widen`, docs/gaze.md) it renders every pixel as it renders
     * its fovea. The conformance suite checks that such a frame changes its image and makes it
     * independent of the gaze, and that the eye model changes no other method's image. */
    bool foveated;
    /* The method keeps state between the frames of a sequence (history buffers, photons or VPLs
     * carried over, a refresh cycle): the frames a block of a sequence starts with, unwritten,
     * when a sequence is split over MPI ranks (src/dist, docs/distributed.md). 0: no such state;
     * the conformance suite checks that such a method's frame does not depend on the ones before. */
    int warmup_frames;
    /* Frames a still needs before its image is converged: `fovea render` renders them at frame
     * 0's views before the first frame it writes (fv_drive_opts.warmup). Only methods whose first
     * frame is worse than their steady state need any: a temporal filter's history (SVGF) or a
     * light set that is refined over frames (fir's VPL management); photons and fipr's refresh
     * are as good in their first frame (measured in tests/cli/test_still_warmup.sh). */
    int still_warmup_frames;
    /* The built-in scene its family's benchmarks render (fv_technique_bench_scene: what `fovea
     * bench scaling` measures the method on); NULL: "cornell", pt's and Visual-Polar's. */
    const char *bench_scene;
    /* MPI (src/dist, docs/distributed.md): a method whose parameter table declares `block_first`
     * and `block_count` sums its estimate along core/blocks.h's tree of sample blocks of its
     * spp_param, so a still is split over ranks by blocks, bit-identical to one process
     * (fv_technique_block_unit); nothing else is needed here. A method with a parameter whose
     * value above 1 averages frames in one process in a way that is not such a sum names it and
     * says why, as the clause that follows "<method>'s <n> <param> are " in the note of a still
     * rendered on rank 0 alone (pm's passes: a running mean, then filtered). */
    struct {
        const char *param, *why;
    } unsplit;
} fv_technique_class;

/* The class of a registered method by index or name (NULL when unknown). */
const fv_technique_class *fv_technique_class_at(int i);
const fv_technique_class *fv_technique_class_find(const char *name);
/* FV_ERR_INVALID "unknown method 'x' (known: pt, pm, ...)": the one message for a name the
 * registry does not know. */
fv_status fv_technique_unknown(const char *name, fv_error *err);

#endif
