/* fovea — the registry of rendering techniques, and the instance wrapper every driver uses.
 *
 * Adding a technique: define its fv_technique_class (class.h) in its family's folder and list it
 * here. The class describes the method once, for everything that drives or shows it: its family
 * and the method it is measured against (baseline), a table of every parameter create reads
 * (type, default, range or choices, help: `fovea methods`, its JSON and the CLI's help are made
 * from it, and the conformance suite holds the readers to it), the main parameter an interactive
 * viewer steps, its devices, warm-up frames, samples-per-pixel key, how MPI may split its stills
 * and the scene its family's benchmarks use. Nothing outside src/technique/ switches on a
 * technique's name (scripts/check-includes refuses it); the conformance suite
 * (tests/conformance) runs every class listed here.
 *
 * What every method shares is done here once: parameters are validated on a private copy of the
 * caller's bag (the caller's bag is never marked or changed) and keys the method never read are
 * refused; the film is checked against the frame; a cancel asked through the progress callback is
 * reported as FV_ERR_CANCELLED even by a method that did not notice it.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "scene/query.h"
#include "technique/class.h"

/* The registered classes in the registry's order (families follow their first method), listed
 * once: an entry X names the class fv_technique_X, which this one list both declares and
 * registers, so adding a method is adding its entry here. */
#define FV_CLASSES(X)                                                                                                       \
    X(pt) X(pm) X(pm_t) X(fpm) X(vpolar) X(cartesian) X(cartesian_full) X(linear_falloff) X(logpolar) X(sdf_gt) X(sdf_relaxed) \
        X(ipr) X(fipr) X(ir) X(ir_low) X(fir) X(fpm_guided) X(ppm)

#define FV_CLASS_DECLARE(c) extern const fv_technique_class fv_technique_##c;
#define FV_CLASS_ENTRY(c) &fv_technique_##c,
FV_CLASSES(FV_CLASS_DECLARE)
static const fv_technique_class *const k_classes[] = {FV_CLASSES(FV_CLASS_ENTRY)};

#define N_CLASSES ((int)(sizeof k_classes / sizeof k_classes[0]))

int fv_technique_count(void) { return N_CLASSES; }

const fv_technique_class *fv_technique_class_at(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i] : NULL; }

int fv_technique_index(const char *name)
{
    for (int i = 0; name && i < N_CLASSES; i++)
        if (strcmp(k_classes[i]->name, name) == 0) return i;
    return -1;
}

const fv_technique_class *fv_technique_class_find(const char *name) { return fv_technique_class_at(fv_technique_index(name)); }

fv_status fv_technique_unknown(const char *name, fv_error *err)
{
    char list[512] = "";
    for (int i = 0; i < N_CLASSES; i++) {
        size_t l = strlen(list);
        snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", k_classes[i]->name);
    }
    return fv_error_set(err, FV_ERR_INVALID, "unknown method '%s' (known: %s)", name ? name : "(null)", list);
}

const char *fv_technique_name(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->name : NULL; }
const char *fv_technique_summary(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->summary : NULL; }
const char *fv_technique_spp_param(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->spp_param : NULL; }
bool fv_technique_foveated(int i) { return i >= 0 && i < N_CLASSES && k_classes[i]->foveated; }
const char *fv_technique_family(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->family : NULL; }
const char *fv_technique_baseline(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->baseline : NULL; }
int fv_technique_warmup_frames(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->warmup_frames : 0; }
int fv_technique_still_warmup(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->still_warmup_frames : 0; }
const char *fv_technique_bench_scene(int i)
{
    if (i < 0 || i >= N_CLASSES) return NULL;
    return k_classes[i]->bench_scene ? k_classes[i]->bench_scene : "cornell";
}

const char *fv_technique_block_unit(int i)
{
    if (!fv_technique_param_find(i, "block_first") || !fv_technique_param_find(i, "block_count") || !k_classes[i]->spp_param) return NULL;
    /* what its spp_param counts: pt's "spp" are samples, ppm's "passes" passes */
    return strcmp(k_classes[i]->spp_param, "spp") == 0 ? "samples" : k_classes[i]->spp_param;
}

const char *fv_technique_unsplit(int i, const char **param)
{
    *param = i >= 0 && i < N_CLASSES ? k_classes[i]->unsplit.param : NULL;
    return *param ? k_classes[i]->unsplit.why : NULL;
}

int fv_technique_param_count(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->param_count : 0; }

const fv_param_info *fv_technique_param_at(int i, int j)
{
    return j >= 0 && j < fv_technique_param_count(i) ? &k_classes[i]->params[j] : NULL;
}

const fv_param_info *fv_technique_param_find(int i, const char *key)
{
    for (int j = 0; key && j < fv_technique_param_count(i); j++)
        if (strcmp(k_classes[i]->params[j].key, key) == 0) return &k_classes[i]->params[j];
    return NULL;
}

const char *fv_technique_main_param(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i]->main.key : NULL; }

int fv_technique_main_step_count(int i)
{
    int n = 0;
    while (fv_technique_main_param(i) && n < FV_MAIN_STEPS_MAX && k_classes[i]->main.steps[n]) n++;
    return n;
}

const char *fv_technique_main_step(int i, int k) { return k >= 0 && k < fv_technique_main_step_count(i) ? k_classes[i]->main.steps[k] : NULL; }

int fv_technique_main_default_step(int i)
{
    const fv_param_info *p = fv_technique_param_find(i, fv_technique_main_param(i));
    for (int k = 0; p && p->def && k < fv_technique_main_step_count(i); k++)
        if (strcmp(k_classes[i]->main.steps[k], p->def) == 0) return k;
    return -1;
}

bool fv_technique_progressive(int i) { return i >= 0 && i < N_CLASSES && k_classes[i]->main.progressive; }

/* Visual-Polar is the one paper here written for real-time frame rates (its Sec. 1), and vpolar
 * keeps them on a CPU at a viewer's sizes (docs/results.md): what a viewer shows first. */
const char *fv_technique_default_interactive(void) { return fv_technique_vpolar.name; }

fv_status fv_technique_set_spp(const char *name, fv_params *params, int spp, fv_error *err)
{
    const fv_technique_class *cls = fv_technique_class_find(name);
    if (!cls) return fv_technique_unknown(name, err);
    if (!cls->spp_param)
        return fv_error_set(err, FV_ERR_INVALID, "--spp: method '%s' has no samples-per-pixel parameter (%s)", cls->name,
                            cls->spp_instead ? cls->spp_instead : "see fovea methods");
    char v[32];
    snprintf(v, sizeof v, "%d", spp);
    return fv_params_set(params, cls->spp_param, v, err);
}

bool fv_technique_has_device(int i, fv_device d)
{
    if (i < 0 || i >= N_CLASSES) return false;
    return d == FV_DEVICE_CPU || (k_classes[i]->devices & (1u << d)) != 0;
}

/* The methods that run on device d, as a list for a refusal. */
static void methods_on(fv_device d, char *list, size_t n)
{
    list[0] = '\0';
    for (int i = 0; i < N_CLASSES; i++) {
        if (!fv_technique_has_device(i, d)) continue;
        size_t l = strlen(list);
        snprintf(list + l, n - l, "%s%s", l ? ", " : "", k_classes[i]->name);
    }
}

fv_status fv_device_check(const char *method, const char *name, fv_device *out, fv_error *err)
{
    if (fv_technique_index(method) < 0) return fv_error_set(err, FV_ERR_INVALID, "unknown method '%s'", method ? method : "(null)");
    fv_status s = fv_device_parse(name, method, out, err);
    if (s != FV_OK) return s;
    if (!fv_technique_has_device(fv_technique_index(method), *out)) {
        char list[256];
        methods_on(*out, list, sizeof list);
        return fv_error_set(err, FV_ERR_INVALID, "method '%s' does not run on device %s (methods that do: %s)", method, fv_device_name(*out),
                            list);
    }
    char why[256];
    if (!fv_device_available(*out, why, sizeof why))
        return fv_error_set(err, FV_ERR_INVALID, "method '%s' on device %s: %s", method, fv_device_name(*out), why);
    return FV_OK;
}

/* The parameter `device` (what --device sets), checked by fv_device_check. */
static const char *const k_device_names[] = {"cpu", "portable", "cuda", "auto", NULL};
static const fv_param_info k_device_param =
    FV_PARAM_CHOICE("device", "cpu", k_device_names, "where the method runs, among the devices it has (docs/gpu.md; --device)");

const fv_param_info *fv_technique_device_param(void) { return &k_device_param; }

static fv_status read_device(const fv_technique_class *cls, fv_params *p, fv_device *out, fv_error *err)
{
    int k = 0;
    fv_status s = fv_params_choice(p, "device", 0, k_device_names, &k, err);
    return s != FV_OK ? s : fv_device_check(cls->name, k_device_names[k], out, err);
}

struct fv_technique {
    const fv_technique_class *cls;
    void *state;
    int in_flight; /* frames submitted and not collected (fv_technique_submit) */
};

fv_status fv_technique_create(const char *name, const fv_scene *scene, const fv_params *params, const fv_log *log,
                              fv_technique **out, fv_error *err)
{
    *out = NULL;
    const fv_technique_class *cls = fv_technique_class_find(name);
    if (!cls) return fv_technique_unknown(name, err);
    if (!scene) return fv_error_set(err, FV_ERR_INVALID, "method '%s': no scene", name);
    if (cls->sdf_only && fv_scene_sdf_object_count(scene) == 0)
        return fv_error_set(err, FV_ERR_INVALID,
                            "method '%s' sphere-traces signed distance fields and the scene has none (try sdf-primitives, "
                            "sdf-columns, sdf-temple, or a JSON scene with an \"sdf\" object)",
                            name);
    fv_params *own = NULL;
    fv_status s = fv_params_clone(params, &own, err);
    if (s != FV_OK) return s;
    fv_technique *t = calloc(1, sizeof *t);
    if (!t) {
        fv_params_destroy(own);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    t->cls = cls;
    fv_device device = FV_DEVICE_CPU;
    s = read_device(cls, own, &device, err);
    if (s == FV_OK) s = cls->create_on ? cls->create_on(scene, own, device, log, &t->state, err) : cls->create(scene, own, log, &t->state, err);
    if (s == FV_OK && (s = fv_params_check_used(own, cls->name, err)) != FV_OK) cls->destroy(t->state);
    fv_params_destroy(own);
    if (s != FV_OK) {
        free(t);
        return s;
    }
    *out = t;
    return FV_OK;
}

/* Forwards progress to the caller and remembers whether it asked to stop. */
typedef struct relay {
    fv_progress_fn fn;
    void *user;
    bool cancelled;
} relay;

static bool relay_progress(void *user, double fraction)
{
    relay *r = user;
    if (!r->cancelled && !r->fn(r->user, fraction)) r->cancelled = true;
    return !r->cancelled;
}

/* What every render checks of a frame and its film. */
static fv_status check_frame(const fv_frame *frame, const fv_film *film, fv_error *err)
{
    if (!frame->camera) return fv_error_set(err, FV_ERR_INVALID, "render: the frame has no camera");
    if (frame->eye_count < 1 || frame->eye_count > 2 || frame->eye < 0 || frame->eye >= frame->eye_count)
        return fv_error_set(err, FV_ERR_INVALID, "render: eye %d of %d (expected eye 0, or 0 and 1 of a stereo pair)", frame->eye,
                            frame->eye_count);
    if (frame->camera->width != fv_film_width(film) || frame->camera->height != fv_film_height(film))
        return fv_error_set(err, FV_ERR_INVALID, "render: camera size %dx%d differs from the film's %dx%d", frame->camera->width,
                            frame->camera->height, fv_film_width(film), fv_film_height(film));
    return FV_OK;
}

/* A frame whose progress goes through r (unchanged when it has none). */
static void relay_frame(const fv_frame *frame, relay *r, fv_frame *out)
{
    *out = *frame;
    *r = (relay){frame->progress, frame->progress_user, false};
    if (frame->progress) {
        out->progress = relay_progress;
        out->progress_user = r;
    }
}

/* render and render_pair once checked, whatever is in flight (fv_technique_submit renders with them
 * for a method without the split). */
static fv_status render_one(fv_technique *t, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    fv_status s = check_frame(frame, film, err);
    if (s != FV_OK) return s;
    /* Every eye reports the parallel regions it opened (core/parallel.h; docs/threads.md): each
     * region wakes the team, so fewer is better paced. */
    const uint64_t regions = fv_region_count();
    relay r;
    fv_frame f;
    relay_frame(frame, &r, &f);
    s = t->cls->render(t->state, &f, film, stats, err);
    if (s == FV_OK && r.cancelled) s = fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    fv_stats_add_count(stats, "parallel_regions", (double)(fv_region_count() - regions));
    return s;
}

/* What every stereo pair is checked for: each eye's frame and film, and one index and time. */
static fv_status check_pair(const fv_frame frames[2], fv_film *const films[2], fv_error *err)
{
    for (int e = 0; e < 2; e++) {
        if (frames[e].eye != e || frames[e].eye_count != 2)
            return fv_error_set(err, FV_ERR_INVALID, "render: a stereo pair's frame %d is eye %d of %d (expected eye %d of 2)", e, frames[e].eye,
                                frames[e].eye_count, e);
        fv_status s = check_frame(&frames[e], films[e], err);
        if (s != FV_OK) return s;
    }
    if (frames[0].index != frames[1].index || frames[0].time != frames[1].time)
        return fv_error_set(err, FV_ERR_INVALID, "render: a stereo pair's eyes differ in frame index (%d, %d) or time (%g, %g)", frames[0].index,
                            frames[1].index, frames[0].time, frames[1].time);
    return FV_OK;
}

static fv_status render_two(fv_technique *t, const fv_frame frames[2], fv_film *const films[2], fv_stats *stats, fv_error *err)
{
    fv_status s = check_pair(frames, films, err);
    if (s != FV_OK) return s;
    if (!t->cls->render_pair) {
        s = render_one(t, &frames[0], films[0], stats, err);
        return s == FV_OK ? render_one(t, &frames[1], films[1], stats, err) : s;
    }
    const uint64_t regions = fv_region_count();
    relay r[2];
    fv_frame f[2];
    for (int e = 0; e < 2; e++) relay_frame(&frames[e], &r[e], &f[e]);
    s = t->cls->render_pair(t->state, f, films, stats, err);
    if (s == FV_OK && (r[0].cancelled || r[1].cancelled)) s = fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    fv_stats_add_count(stats, "parallel_regions", (double)(fv_region_count() - regions));
    return s;
}

static fv_status refuse_in_flight(const fv_technique *t, fv_error *err)
{
    return fv_error_set(err, FV_ERR_INVALID, "render: %d submitted frame%s not collected (fv_technique_collect)", t->in_flight,
                        t->in_flight == 1 ? " is" : "s are");
}

fv_status fv_technique_render(fv_technique *t, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    if (!t || !frame || !film || !stats) return fv_error_set(err, FV_ERR_INVALID, "render: missing technique, frame, film or stats");
    return t->in_flight ? refuse_in_flight(t, err) : render_one(t, frame, film, stats, err);
}

fv_status fv_technique_render_pair(fv_technique *t, const fv_frame frames[2], fv_film *const films[2], fv_stats *stats, fv_error *err)
{
    if (!t || !frames || !films || !films[0] || !films[1] || !stats)
        return fv_error_set(err, FV_ERR_INVALID, "render: missing technique, frames, films or stats");
    return t->in_flight ? refuse_in_flight(t, err) : render_two(t, frames, films, stats, err);
}

fv_status fv_technique_submit(fv_technique *t, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    if (!t || !frames || !films || !films[0] || (eyes == 2 && !films[1]) || !stats)
        return fv_error_set(err, FV_ERR_INVALID, "submit: missing technique, frames, films or stats");
    if (eyes != 1 && eyes != 2) return fv_error_set(err, FV_ERR_INVALID, "submit: %d eyes (expected 1, or 2 for a stereo pair)", eyes);
    if (t->in_flight >= FV_TECHNIQUE_IN_FLIGHT)
        return fv_error_set(err, FV_ERR_INVALID, "submit: %d frames in flight already (collect one first)", t->in_flight);
    if (!t->cls->submit) {
        /* rendered now: collect only hands it over */
        const fv_status s = eyes == 2 ? render_two(t, frames, films, stats, err) : render_one(t, frames, films[0], stats, err);
        if (s == FV_OK) t->in_flight++;
        return s;
    }
    fv_status s = eyes == 2 ? check_pair(frames, films, err) : check_frame(&frames[0], films[0], err);
    if (s != FV_OK) return s;
    const uint64_t regions = fv_region_count();
    relay r[2];
    fv_frame f[2];
    for (int e = 0; e < eyes; e++) relay_frame(&frames[e], &r[e], &f[e]);
    s = t->cls->submit(t->state, eyes, f, films, stats, err);
    if (s == FV_OK && (r[0].cancelled || (eyes == 2 && r[1].cancelled))) {
        /* cancelled where the method could not stop (a launch already queued): its frame is
         * taken back, so that nothing of it stays in flight */
        fv_error ignored;
        t->cls->collect(t->state, &ignored);
        s = fv_error_set(err, FV_ERR_CANCELLED, "render cancelled");
    } else if (s == FV_OK) {
        t->in_flight++;
    }
    fv_stats_add_count(stats, "parallel_regions", (double)(fv_region_count() - regions));
    return s;
}

fv_status fv_technique_collect(fv_technique *t, fv_error *err)
{
    if (!t) return fv_error_set(err, FV_ERR_INVALID, "collect: missing technique");
    if (!t->in_flight) return fv_error_set(err, FV_ERR_INVALID, "collect: no submitted frame in flight");
    t->in_flight--;
    return t->cls->collect ? t->cls->collect(t->state, err) : FV_OK;
}

int fv_technique_in_flight(const fv_technique *t) { return t ? t->in_flight : 0; }

const char *fv_technique_name_of(const fv_technique *t) { return t->cls->name; }

void fv_technique_destroy(fv_technique *t)
{
    if (!t) return;
    t->cls->destroy(t->state);
    free(t);
}
